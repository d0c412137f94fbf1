//! A user's model that returns a NaN log-likelihood or moves particles to a non-finite state
//! makes `LmbFilter::step` fail with an error naming the track — it never leaves the track
//! silently blind.

use smc_lmb::filter::{
    AdaptiveBirth, Frame, LmbConfig, LmbFilter, MeasurementModel, Measurements, ParticleSet,
    PositionBirthSampler, StepContext, TransitionModel,
};
use smc_lmb::models::{ConstantDetection, ConstantVelocity, PositionMeasurement, UniformClutter};
use smc_lmb::rng::seeded;
use smc_lmb::FilterRng;

/// The position likelihood, but NaN for every particle once `after` steps have passed.
struct NanAfter {
    inner: PositionMeasurement,
    nan_from_x: f64,
}

impl MeasurementModel for NanAfter {
    fn measurement_dim(&self) -> usize {
        2
    }
    fn log_likelihood(&self, z: &[f64], p: &ParticleSet, ctx: &StepContext, out: &mut [f64]) {
        self.inner.log_likelihood(z, p, ctx, out);
        if z[0] >= self.nan_from_x {
            out.iter_mut().for_each(|v| *v = f64::NAN);
        }
    }
}

/// Constant velocity that turns the positions into NaN when they pass `x_max`.
struct BlowsUp {
    inner: ConstantVelocity,
    x_max: f64,
}

impl TransitionModel for BlowsUp {
    fn state_dim(&self) -> usize {
        4
    }
    fn predict(
        &self,
        p: &mut ParticleSet,
        ctx: &StepContext,
        rng: &mut FilterRng,
    ) -> smc_lmb::Result<()> {
        self.inner.predict(p, ctx, rng)?;
        for x in p.component_mut(0) {
            if *x > self.x_max {
                *x = f64::INFINITY;
            }
        }
        Ok(())
    }
}

fn filter(
    transition: impl TransitionModel + 'static,
    measurement: impl MeasurementModel + 'static,
) -> LmbFilter {
    LmbFilter::builder()
        .transition(transition)
        .measurement(measurement)
        .detection(ConstantDetection::new(0.9).unwrap())
        .clutter(UniformClutter::rectangle(1.0, [-50.0, 50.0], [-50.0, 50.0]).unwrap())
        .birth(
            AdaptiveBirth::new(
                PositionBirthSampler {
                    position_std: 0.3,
                    velocity_std: 2.0,
                },
                0.1,
                0.5,
                200,
            )
            .unwrap(),
        )
        .config(LmbConfig {
            particles: 200,
            ..LmbConfig::default()
        })
        .build()
        .unwrap()
}

/// Steps an object moving +2 m per step along x from x = −10; returns the first error.
fn run(mut f: LmbFilter) -> Option<String> {
    let mut rng = seeded(3);
    for k in 0..10 {
        let z = Measurements::from_rows(2, &[[-10.0 + 2.0 * k as f64, 5.0]]).unwrap();
        if let Err(e) = f.step(&Frame::new(k as f64, z), &mut rng) {
            return Some(format!("step {k}: {e}"));
        }
    }
    None
}

#[test]
fn a_nan_log_likelihood_is_an_error_naming_the_track() {
    let ok = filter(
        ConstantVelocity::new(2, 0.5).unwrap(),
        NanAfter {
            inner: PositionMeasurement::new(2, 0.3).unwrap(),
            nan_from_x: f64::INFINITY,
        },
    );
    assert_eq!(run(ok), None);
    let bad = filter(
        ConstantVelocity::new(2, 0.5).unwrap(),
        NanAfter {
            inner: PositionMeasurement::new(2, 0.3).unwrap(),
            nan_from_x: -3.0,
        },
    );
    let e = run(bad).expect("the NaN must surface");
    assert!(
        e.contains("log-likelihood") && e.contains("track") && e.contains("NaN"),
        "{e}"
    );
}

#[test]
fn a_non_finite_particle_state_is_an_error_naming_the_track() {
    let bad = filter(
        BlowsUp {
            inner: ConstantVelocity::new(2, 0.5).unwrap(),
            x_max: -3.0,
        },
        PositionMeasurement::new(2, 0.3).unwrap(),
    );
    let e = run(bad).expect("the infinite state must surface");
    assert!(
        e.contains("transition model") && e.contains("track") && e.contains("inf"),
        "{e}"
    );
}
