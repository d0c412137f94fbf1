//! A user's own motion model plugged into the filter: velocity as an Ornstein–Uhlenbeck
//! process (the Singer idea applied one derivative lower: manoeuvres decay with time constant τ),
//!
//!   v_{k+1} = e^{−T/τ} v_k + σ √(1 − e^{−2T/τ}) ε,   x_{k+1} = x_k + T v_{k+1},
//!
//! on the usual state layout [x, ẋ, y, ẏ], so the built-in position measurement fits it. The
//! model is the `impl TransitionModel` block below: a dimension and one `predict` that moves the
//! whole particle set. Three objects are simulated with the same process and tracked.
//!
//! ```text
//! cargo run --release --example custom_transition
//! ```

use rand::RngExt;
use rand_distr::{Distribution, StandardNormal};
use smc_lmb::filter::{check_state_dim, StepContext, TransitionModel};
use smc_lmb::filter::{
    AdaptiveBirth, Frame, LmbConfig, LmbFilter, Measurements, ParticleSet, PositionBirthSampler,
};
use smc_lmb::metrics::ospa;
use smc_lmb::models::{ConstantDetection, PositionMeasurement, UniformClutter};
use smc_lmb::rng::seeded;
use smc_lmb::FilterRng;

/// Mean-reverting velocity with time constant `tau` (s) and stationary spread `sigma` (m/s).
struct OrnsteinUhlenbeck {
    tau: f64,
    sigma: f64,
}

impl TransitionModel for OrnsteinUhlenbeck {
    fn state_dim(&self) -> usize {
        4
    }

    fn predict(
        &self,
        particles: &mut ParticleSet,
        ctx: &StepContext,
        rng: &mut FilterRng,
    ) -> Result<(), smc_lmb::Error> {
        // A state too short for [x, ẋ, y, ẏ] is an error, never a silent no-op.
        check_state_dim("OrnsteinUhlenbeck", 4, particles)?;
        let decay = (-ctx.dt / self.tau).exp();
        let kick = self.sigma * (1.0 - decay * decay).sqrt();
        let mut c = particles.components_mut(); // [x, ẋ, y, ẏ] as contiguous columns
        for axis in [0, 2] {
            let (pos, vel) = c.split_at_mut(axis + 1);
            for (x, v) in pos[axis].iter_mut().zip(vel[0].iter_mut()) {
                let e: f64 = StandardNormal.sample(rng);
                *v = decay * *v + kick * e;
                *x += ctx.dt * *v;
            }
        }
        Ok(())
    }
}

fn main() -> Result<(), smc_lmb::Error> {
    let model = OrnsteinUhlenbeck {
        tau: 5.0,
        sigma: 1.5,
    };
    let mut filter = LmbFilter::builder()
        .transition(OrnsteinUhlenbeck {
            tau: 5.0,
            sigma: 1.5,
        })
        .measurement(PositionMeasurement::new(2, 0.5)?)
        .detection(ConstantDetection::new(0.9)?)
        .clutter(UniformClutter::rectangle(
            3.0,
            [-60.0, 60.0],
            [-60.0, 60.0],
        )?)
        .birth(AdaptiveBirth::new(
            PositionBirthSampler {
                position_std: 0.5,
                velocity_std: 1.5,
            },
            0.1,
            0.1,
            500,
        )?)
        .config(LmbConfig {
            particles: 500,
            ..LmbConfig::default()
        })
        .build()?;

    // Simulate three objects with the same model (one particle each) and noisy detections.
    let mut sim_rng = seeded(7);
    let mut truth = ParticleSet::from_rows(
        &[
            vec![-30.0, 1.0, 0.0, 0.5],
            vec![20.0, -1.0, 20.0, 0.0],
            vec![0.0, 0.0, -30.0, 1.0],
        ],
        &[1.0, 1.0, 1.0],
    )
    .expect("three 4-D states");
    let mut filter_rng = seeded(8);
    let mut total = 0.0;
    let steps = 60;
    for k in 0..steps {
        let ctx = StepContext::new(k, k as f64, 1.0);
        if k > 0 {
            model.predict(&mut truth, &ctx, &mut sim_rng).unwrap();
        }
        let objects: Vec<Vec<f64>> = (0..3)
            .map(|i| vec![truth.component(0)[i], truth.component(2)[i]])
            .collect();
        let mut z: Vec<Vec<f64>> = Vec::new();
        for p in &objects {
            if sim_rng.random::<f64>() < 0.9 {
                let (ex, ey): (f64, f64) = (
                    StandardNormal.sample(&mut sim_rng),
                    StandardNormal.sample(&mut sim_rng),
                );
                z.push(vec![p[0] + 0.5 * ex, p[1] + 0.5 * ey]);
            }
        }
        for _ in 0..sim_rng.random_range(0..6) {
            z.push(vec![
                sim_rng.random_range(-60.0..60.0),
                sim_rng.random_range(-60.0..60.0),
            ]);
        }
        let est = filter.step(
            &Frame::new(k as f64, Measurements::from_rows(2, &z)?),
            &mut filter_rng,
        )?;
        let x: Vec<Vec<f64>> = est.iter().map(|e| vec![e.state[0], e.state[2]]).collect();
        let d = ospa(&objects, &x, 5.0, 1.0)?.distance;
        total += d;
        if k % 10 == 9 {
            println!(
                "step {:>2}: {} tracks, OSPA(c = 5 m) {:.2} m",
                k + 1,
                est.len(),
                d
            );
        }
    }
    println!(
        "mean OSPA over {steps} steps: {:.2} m",
        total / steps as f64
    );
    Ok(())
}
