//! The smallest complete use of the filter: one object moving along a line, seen with noise
//! and some clutter, tracked with a constant-velocity model and measurement-driven birth.
//!
//! ```text
//! cargo run --release --example quickstart
//! ```

use smc_lmb::filter::{
    AdaptiveBirth, Frame, LmbConfig, LmbFilter, Measurements, PositionBirthSampler,
};
use smc_lmb::models::{ConstantDetection, ConstantVelocity, PositionMeasurement, UniformClutter};
use smc_lmb::rng::seeded;

fn main() -> Result<(), smc_lmb::Error> {
    let mut filter = LmbFilter::builder()
        .transition(ConstantVelocity::new(2, 0.5)?) // state [x, ẋ, y, ẏ], σ_a = 0.5 m/s²
        .measurement(PositionMeasurement::new(2, 0.3)?) // z = (x, y) + N(0, 0.3² I)
        .detection(ConstantDetection::new(0.9)?)
        .clutter(UniformClutter::rectangle(
            1.0,
            [-50.0, 50.0],
            [-50.0, 50.0],
        )?)
        .birth(AdaptiveBirth::new(
            PositionBirthSampler {
                position_std: 0.3,
                velocity_std: 2.0,
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

    let mut rng = seeded(42);
    for k in 0..10 {
        let t = k as f64;
        // the object at (−10 + 2t, 5) with a little noise, plus one clutter point scattered
        // over the field
        let clutter = [(k * 37 % 100) as f64 - 50.0, (k * 61 % 100) as f64 - 50.0];
        let z = [
            [
                -10.0 + 2.0 * t + 0.1 * (t * 1.7).sin(),
                5.0 - 0.1 * (t * 2.3).cos(),
            ],
            clutter,
        ];
        let frame = Frame::new(t, Measurements::from_rows(2, &z)?);
        for e in filter.step(&frame, &mut rng)? {
            println!(
                "t = {t:>2}: track {} (r = {:.2}) at ({:6.2}, {:5.2}) moving ({:5.2}, {:5.2})",
                e.label, e.existence, e.state[0], e.state[2], e.state[1], e.state[3]
            );
        }
    }
    Ok(())
}
