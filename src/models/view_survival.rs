//! Survival that depends on whether an object is inside a sensor's field of view: objects the
//! sensor can see keep a high p_S, objects that left the sector (behind a moving robot, beyond
//! its range) are forgotten at a faster rate, since no measurement will ever confirm them.
//!
//! Not for: occlusion inside the field of view (an occluded object is still there; see
//! [`super::occlusion`] for its detection probability).

use super::detection::FieldOfViewDetection;
use super::{StepContext, SurvivalModel};
use crate::error::{ensure_probability, Result};
use crate::filter::ParticleSet;

/// p_S(x) = `inside` when x lies in the sector of `fov` at the step, `outside` elsewhere
/// (the sector's own detection probabilities are not used).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct FieldOfViewSurvival {
    fov: FieldOfViewDetection,
    inside: f64,
    outside: f64,
}

impl FieldOfViewSurvival {
    /// Survival `inside` / `outside` the sector of `fov`, both in [0, 1].
    pub fn new(fov: FieldOfViewDetection, inside: f64, outside: f64) -> Result<Self> {
        ensure_probability("survival inside the field of view", inside)?;
        ensure_probability("survival outside the field of view", outside)?;
        Ok(FieldOfViewSurvival {
            fov,
            inside,
            outside,
        })
    }
}

impl SurvivalModel for FieldOfViewSurvival {
    fn survival_probability(&self, particles: &ParticleSet, ctx: &StepContext, out: &mut [f64]) {
        if particles.dim() < 3 {
            out.fill(self.outside);
            return;
        }
        let (sx, sy, c, s) = self.fov.sensor(ctx);
        let xs = particles.component(0);
        let ys = particles.component(2);
        for ((o, &x), &y) in out.iter_mut().zip(xs).zip(ys) {
            *o = if self.fov.contains_from(x, y, sx, sy, c, s) {
                self.inside
            } else {
                self.outside
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    #[test]
    fn inside_and_outside_the_sector() {
        let fov = FieldOfViewDetection::new(0.9, 0.0, 10.0, FRAC_PI_2).unwrap();
        let m = FieldOfViewSurvival::new(fov, 0.99, 0.7).unwrap();
        let rows = vec![
            vec![5.0, 0.0, 0.0, 0.0],  // ahead
            vec![-5.0, 0.0, 0.0, 0.0], // behind
            vec![20.0, 0.0, 0.0, 0.0], // too far
        ];
        let set = ParticleSet::from_rows(&rows, &[1.0; 3]).unwrap();
        let mut out = vec![0.0; 3];
        m.survival_probability(&set, &StepContext::new(1, 0.1, 0.1), &mut out);
        assert_eq!(out, vec![0.99, 0.7, 0.7]);
        assert!(FieldOfViewSurvival::new(fov, 1.2, 0.7).is_err());
    }
}
