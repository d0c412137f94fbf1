//! Survival probability that does not depend on the state.
//!
//! p_S(x) = p for every x. Not for: survival that depends on where an object is (write a
//! [`SurvivalModel`] of your own for that).

use crate::error::{Error, Result};
use crate::filter::ParticleSet;
use crate::filter::{StepContext, SurvivalModel};

/// p_S(x) = `self.0` everywhere.
///
/// Values outside [0, 1] are clamped when used (NaN counts as 0); [`ConstantSurvival::new`]
/// rejects them up front.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ConstantSurvival(pub f64);

impl ConstantSurvival {
    /// A survival probability `p` in [0, 1].
    pub fn new(p: f64) -> Result<Self> {
        if (0.0..=1.0).contains(&p) {
            Ok(ConstantSurvival(p))
        } else {
            Err(Error::invalid(
                "survival probability",
                format!("{p} (must lie in [0, 1])"),
            ))
        }
    }

    /// The probability actually used: `self.0` clamped to [0, 1], NaN mapped to 0.
    pub fn probability(&self) -> f64 {
        clamp_probability(self.0)
    }
}

/// Clamps to [0, 1]; NaN becomes 0.
pub(crate) fn clamp_probability(p: f64) -> f64 {
    if p.is_nan() {
        0.0
    } else {
        p.clamp(0.0, 1.0)
    }
}

impl SurvivalModel for ConstantSurvival {
    fn survival_probability(&self, _particles: &ParticleSet, _ctx: &StepContext, out: &mut [f64]) {
        out.fill(self.probability());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fills_every_particle() {
        let p = ParticleSet::zeroed(4, 3);
        let mut out = vec![0.0; 3];
        ConstantSurvival::new(0.99).unwrap().survival_probability(
            &p,
            &StepContext::new(0, 0.0, 1.0),
            &mut out,
        );
        assert_eq!(out, vec![0.99; 3]);
    }

    #[test]
    fn validates_and_clamps() {
        assert!(ConstantSurvival::new(1.5).is_err());
        assert!(ConstantSurvival::new(-0.1).is_err());
        assert!(ConstantSurvival::new(f64::NAN).is_err());
        assert_eq!(ConstantSurvival(1.5).probability(), 1.0);
        assert_eq!(ConstantSurvival(f64::NAN).probability(), 0.0);
    }
}
