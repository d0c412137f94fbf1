//! Markov detectability: a detector that misses an object in runs of scans rather than
//! independently at each scan.
//!
//! A moving-object front end (background attenuation) stops reporting a person for several
//! scans at a time — while they slow down, turn, or stand where the background map has not
//! settled — and then reports them for many scans in a row. With a constant p_D an LMB track
//! loses a factor (1 − p_D) of existence odds at every miss, so a run of five misses ends a
//! track that the detector will report again a second later, and the person comes back under a
//! new label.
//!
//! The remedy, as in the two-state visibility chain of IPDA-type trackers: each object carries
//! a hidden mode, *detectable* or *undetectable*, that flips between scans as a Markov chain
//! (detectable → undetectable with probability `lose`, undetectable → detectable with
//! `regain`). The mode is one more state component (1 = detectable, 0 = undetectable; read as
//! detectable when ≥ 0.5, so resampling jitter cannot change it), so each track's particle set
//! carries the joint density of kinematics and mode and the filter itself needs nothing new:
//!
//! - [`DetectabilityTransition`] wraps any transition: the inner model moves the kinematic
//!   components, then each particle's mode flips with the chain's probabilities;
//! - [`DetectabilityDetection`] wraps any detection model:
//!   p_D(x, m) = p_D,inner(x) for a detectable particle and `undetectable_share` · p_D,inner(x)
//!   for an undetectable one.
//!
//! After a few misses a track's weight moves to its undetectable particles, whose misses cost
//! (almost) nothing, so the existence decays at the rate at which undetectable objects become
//! detectable again instead of at (1 − p_D) per scan; a detection moves the weight back.
//!
//! Not for: geometric visibility (field of view, occlusion: [`super::OcclusionDetection`]) or
//! objects that are missed because they stand next to another ([`super::ResolutionDetection`]).

use crate::error::{ensure_probability, Error, Result};
use crate::filter::ParticleSet;
use crate::filter::{check_state_dim, DetectionModel, StepContext, TransitionModel};
use crate::rng::FilterRng;
use rand::RngExt;

/// The two-state detectability chain (module documentation).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Detectability {
    /// Probability per step that a detectable object becomes undetectable.
    pub lose: f64,
    /// Probability per step that an undetectable object becomes detectable again.
    pub regain: f64,
    /// p_D of an undetectable object as a share of the inner model's. Small but positive, so
    /// that the geometric p_D can be recovered from the filter's ([`Self::mode_factor`]).
    pub undetectable_share: f64,
}

impl Detectability {
    /// Checks that every field is a probability, `regain` positive (else an object once
    /// undetectable stays so) and `undetectable_share` positive.
    pub fn validate(&self) -> Result<()> {
        ensure_probability("detectability lose", self.lose)?;
        ensure_probability("detectability regain", self.regain)?;
        ensure_probability("detectability undetectable share", self.undetectable_share)?;
        if self.regain == 0.0 || self.undetectable_share == 0.0 {
            return Err(Error::invalid(
                "detectability",
                "`regain` and `undetectable_share` must be positive",
            ));
        }
        Ok(())
    }

    /// Long-run share of scans in which an object is detectable: regain / (lose + regain).
    pub fn stationary_detectable(&self) -> f64 {
        if self.lose + self.regain == 0.0 {
            1.0
        } else {
            self.regain / (self.lose + self.regain)
        }
    }

    /// The p_D factor of a particle whose mode component is `mode`.
    pub fn mode_factor(&self, mode: f64) -> f64 {
        if is_detectable(mode) {
            1.0
        } else {
            self.undetectable_share
        }
    }
}

/// Whether a mode component value means detectable.
pub fn is_detectable(mode: f64) -> bool {
    mode >= 0.5
}

/// A transition that also steps the detectability mode kept in state component `component`
/// (module documentation).
#[derive(Clone, Debug)]
pub struct DetectabilityTransition<T> {
    inner: T,
    chain: Detectability,
    component: usize,
}

impl<T: TransitionModel> DetectabilityTransition<T> {
    /// `inner` for the kinematic components; the mode is the component right after them.
    pub fn new(inner: T, chain: Detectability) -> Result<Self> {
        chain.validate()?;
        let component = inner.state_dim();
        Ok(DetectabilityTransition {
            inner,
            chain,
            component,
        })
    }

    /// The state component that holds the mode.
    pub fn mode_component(&self) -> usize {
        self.component
    }
}

impl<T: TransitionModel> TransitionModel for DetectabilityTransition<T> {
    fn state_dim(&self) -> usize {
        self.component + 1
    }

    fn predict(
        &self,
        particles: &mut ParticleSet,
        ctx: &StepContext,
        rng: &mut FilterRng,
    ) -> Result<()> {
        check_state_dim(&self.name(), self.state_dim(), particles)?;
        self.inner.predict(particles, ctx, rng)?;
        let (lose, regain) = (self.chain.lose, self.chain.regain);
        for m in particles.component_mut(self.component) {
            let u: f64 = rng.random();
            let flip = if is_detectable(*m) {
                u < lose
            } else {
                u < regain
            };
            let detectable = is_detectable(*m) != flip;
            *m = if detectable { 1.0 } else { 0.0 };
        }
        Ok(())
    }
}

/// A detection model lowered to `undetectable_share` for particles in the undetectable mode
/// (module documentation).
#[derive(Clone, Debug)]
pub struct DetectabilityDetection<D> {
    inner: D,
    chain: Detectability,
    component: usize,
}

impl<D: DetectionModel> DetectabilityDetection<D> {
    /// `inner` with the mode read from state component `component`.
    pub fn new(inner: D, chain: Detectability, component: usize) -> Result<Self> {
        chain.validate()?;
        Ok(DetectabilityDetection {
            inner,
            chain,
            component,
        })
    }

    /// Divides the mode factor out of p_D values `out` of `particles` (as written by
    /// [`DetectionModel::detection_probability`]), leaving the inner model's.
    pub fn remove_mode(&self, particles: &ParticleSet, out: &mut [f64]) {
        if particles.dim() <= self.component {
            return;
        }
        for (o, &m) in out.iter_mut().zip(particles.component(self.component)) {
            *o /= self.chain.mode_factor(m);
        }
    }
}

impl<D: DetectionModel> DetectionModel for DetectabilityDetection<D> {
    fn detection_probability(&self, particles: &ParticleSet, ctx: &StepContext, out: &mut [f64]) {
        self.inner.detection_probability(particles, ctx, out);
        if particles.dim() <= self.component {
            return;
        }
        for (o, &m) in out.iter_mut().zip(particles.component(self.component)) {
            *o *= self.chain.mode_factor(m);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::{ConstantDetection, ConstantVelocity};
    use crate::rng::seeded;
    use proptest::prelude::*;

    fn chain() -> Detectability {
        Detectability {
            lose: 0.06,
            regain: 0.2,
            undetectable_share: 0.01,
        }
    }

    fn set_with_modes(modes: &[f64]) -> ParticleSet {
        let mut p = ParticleSet::zeroed(5, modes.len());
        p.component_mut(4).copy_from_slice(modes);
        p
    }

    #[test]
    fn rejects_chains_that_never_come_back() {
        for bad in [
            Detectability {
                regain: 0.0,
                ..chain()
            },
            Detectability {
                undetectable_share: 0.0,
                ..chain()
            },
            Detectability {
                lose: 1.5,
                ..chain()
            },
            Detectability {
                regain: f64::NAN,
                ..chain()
            },
        ] {
            assert!(bad.validate().is_err(), "{bad:?}");
        }
        assert!(chain().validate().is_ok());
    }

    #[test]
    fn the_mode_is_the_component_after_the_inner_state() {
        let t =
            DetectabilityTransition::new(ConstantVelocity::new(2, 0.3).unwrap(), chain()).unwrap();
        assert_eq!(t.mode_component(), 4);
        assert_eq!(t.state_dim(), 5);
    }

    /// Over many particles and steps the flips happen at the chain's rates: starting all
    /// detectable, after one step a share `lose` is undetectable; after many steps the share
    /// detectable is regain / (lose + regain) = 0.769.
    #[test]
    fn modes_flip_at_the_chain_rates() {
        let t =
            DetectabilityTransition::new(ConstantVelocity::new(2, 0.3).unwrap(), chain()).unwrap();
        let n = 20_000;
        let mut p = set_with_modes(&vec![1.0; n]);
        let mut rng = seeded(7);
        let ctx = StepContext::new(1, 0.125, 0.125);
        t.predict(&mut p, &ctx, &mut rng).unwrap();
        let undetectable = p.component(4).iter().filter(|&&m| m == 0.0).count();
        let share = undetectable as f64 / n as f64;
        // binomial standard error ≈ 0.0017
        assert!((share - 0.06).abs() < 0.008, "{share}");
        for _ in 0..60 {
            t.predict(&mut p, &ctx, &mut rng).unwrap();
        }
        let detectable = p.component(4).iter().filter(|&&m| m == 1.0).count() as f64 / n as f64;
        assert!((detectable - 0.2 / 0.26).abs() < 0.015, "{detectable}");
        assert!(p.component(4).iter().all(|&m| m == 0.0 || m == 1.0));
    }

    /// The inner transition still moves the kinematic components as before.
    #[test]
    fn kinematics_move_as_the_inner_model_says() {
        let cv = ConstantVelocity::new(2, 0.0).unwrap();
        let t = DetectabilityTransition::new(cv, chain()).unwrap();
        let mut p = set_with_modes(&[1.0, 0.0]);
        p.component_mut(1).copy_from_slice(&[1.0, -2.0]);
        let ctx = StepContext::new(1, 0.5, 0.5);
        t.predict(&mut p, &ctx, &mut seeded(1)).unwrap();
        assert_eq!(p.component(0), &[0.5, -1.0]);
    }

    proptest! {
        /// p_D is the inner model's for detectable particles and `undetectable_share` of it
        /// for undetectable ones, and `remove_mode` gives the inner model's back.
        #[test]
        fn detection_scales_by_mode(
            modes in proptest::collection::vec(0.0f64..1.0, 1..40),
            pd in 0.05f64..1.0,
        ) {
            let d = DetectabilityDetection::new(ConstantDetection::new(pd).unwrap(), chain(), 4)
                .unwrap();
            let p = set_with_modes(&modes);
            let mut out = vec![0.0; modes.len()];
            d.detection_probability(&p, &StepContext::new(1, 0.0, 0.1), &mut out);
            for (o, &m) in out.iter().zip(&modes) {
                let want = if m >= 0.5 { pd } else { 0.01 * pd };
                prop_assert!((o - want).abs() < 1e-12);
            }
            d.remove_mode(&p, &mut out);
            for o in &out {
                prop_assert!((o - pd).abs() < 1e-12);
            }
        }
    }
}
