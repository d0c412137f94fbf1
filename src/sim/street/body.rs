//! The vehicle body's roll, pitch and heave on its suspension: small, smooth oscillations
//! around the level pose at the nominal height, as a real car's attitude wanders over an
//! uneven road.
//!
//! On KITTI drive 0005 (OXTS, 50 frames at 10 Hz) roll and pitch change by 0.17° and 0.23° a
//! frame (standard deviation), on drive 0001 by 0.07° and 0.06°; the ranges are 1.3° and 2.0°
//! with the road's grade included. A lidar feels this: 0.1° of pitch moves the ground ring of a
//! beam that meets the road 30 m away by about 0.9 m, so the ground does not look the same
//! from frame to frame the way it does from a perfectly level sensor.
//!
//! **Model.** Each of roll, pitch and heave is a sum of [`COMPONENTS`] sinusoids
//! aᵢ·sin(2π fᵢ t + φᵢ) with frequencies drawn uniformly from `frequency_hz`, phases uniformly
//! from [0, 2π) and amplitudes aᵢ = A/√COMPONENTS (A the configured amplitude, so the
//! oscillation's standard deviation is A/√2), all drawn from the seed. Rates are the exact
//! derivatives. All amplitudes zero = the level body at constant height.
//!
//! Not for: the planar motion (see [`super::ego`]) or the ground's shape (see
//! [`super::ground`]).

use crate::error::{ensure_non_negative, ensure_positive, Error, Result};
use crate::rng::FilterRng;
use rand::RngExt;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Sinusoids per degree of freedom.
pub const COMPONENTS: usize = 3;

/// How much the body rolls, pitches and heaves.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BodyMotionConfig {
    /// Roll amplitude A, degrees.
    pub roll_deg: f64,
    /// Pitch amplitude A, degrees.
    pub pitch_deg: f64,
    /// Heave amplitude A, metres.
    pub heave: f64,
    /// Range of the sinusoids' frequencies, Hz.
    pub frequency_hz: [f64; 2],
}

impl Default for BodyMotionConfig {
    /// About 0.1° of roll and pitch change a frame at 10 Hz, between drives 0001 and 0005.
    fn default() -> Self {
        BodyMotionConfig {
            roll_deg: 0.3,
            pitch_deg: 0.4,
            heave: 0.01,
            frequency_hz: [0.3, 1.2],
        }
    }
}

impl BodyMotionConfig {
    /// A level body at constant height.
    pub fn level() -> Self {
        BodyMotionConfig {
            roll_deg: 0.0,
            pitch_deg: 0.0,
            heave: 0.0,
            ..BodyMotionConfig::default()
        }
    }

    /// Checks every field; errors name the field.
    pub fn validate(&self) -> Result<()> {
        for (what, v, max) in [
            ("body.roll_deg", self.roll_deg, 10.0),
            ("body.pitch_deg", self.pitch_deg, 10.0),
            ("body.heave", self.heave, 0.5),
        ] {
            ensure_non_negative(what, v)?;
            if v > max {
                return Err(Error::invalid(what, format!("{v} (at most {max})")));
            }
        }
        let f = self.frequency_hz;
        ensure_positive("body.frequency_hz", f[0])?;
        ensure_positive("body.frequency_hz", f[1])?;
        if f[1] < f[0] {
            return Err(Error::invalid(
                "body.frequency_hz",
                format!("[{}, {}] is decreasing", f[0], f[1]),
            ));
        }
        Ok(())
    }
}

/// One degree of freedom: (amplitude, angular frequency, phase) per sinusoid.
#[derive(Clone, Debug, PartialEq)]
struct Oscillation([(f64, f64, f64); COMPONENTS]);

impl Oscillation {
    fn draw(amplitude: f64, freq: [f64; 2], rng: &mut FilterRng) -> Oscillation {
        let a = amplitude / (COMPONENTS as f64).sqrt();
        let mut parts = [(0.0, 0.0, 0.0); COMPONENTS];
        for p in &mut parts {
            let f = if freq[1] > freq[0] {
                rng.random_range(freq[0]..freq[1])
            } else {
                freq[0]
            };
            let phase = rng.random_range(0.0..2.0 * PI);
            *p = (a, 2.0 * PI * f, phase);
        }
        Oscillation(parts)
    }

    fn value(&self, t: f64) -> f64 {
        // From +0.0, so that a zero amplitude gives +0.0 (as written to OXTS files).
        self.0
            .iter()
            .fold(0.0, |s, (a, w, p)| s + a * (w * t + p).sin())
    }

    fn rate(&self, t: f64) -> f64 {
        self.0
            .iter()
            .map(|(a, w, p)| a * w * (w * t + p).cos())
            .sum()
    }
}

/// The body's attitude and heave over time.
#[derive(Clone, Debug, PartialEq)]
pub struct BodyMotion {
    roll: Oscillation,
    pitch: Oscillation,
    heave: Oscillation,
}

impl BodyMotion {
    /// Draws the oscillations of `config` from `rng`.
    pub fn new(config: &BodyMotionConfig, rng: &mut FilterRng) -> BodyMotion {
        let f = config.frequency_hz;
        BodyMotion {
            roll: Oscillation::draw(config.roll_deg.to_radians(), f, rng),
            pitch: Oscillation::draw(config.pitch_deg.to_radians(), f, rng),
            heave: Oscillation::draw(config.heave, f, rng),
        }
    }

    /// Roll and pitch at time t, rad.
    pub fn attitude(&self, t: f64) -> (f64, f64) {
        (self.roll.value(t), self.pitch.value(t))
    }

    /// Roll and pitch rates at time t, rad/s.
    pub fn attitude_rate(&self, t: f64) -> (f64, f64) {
        (self.roll.rate(t), self.pitch.rate(t))
    }

    /// Height above the nominal one at time t, metres.
    pub fn heave(&self, t: f64) -> f64 {
        self.heave.value(t)
    }

    /// Vertical velocity at time t, m/s.
    pub fn heave_rate(&self, t: f64) -> f64 {
        self.heave.rate(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::seeded;

    #[test]
    fn level_config_gives_a_level_body() {
        let b = BodyMotion::new(&BodyMotionConfig::level(), &mut seeded(1));
        for k in 0..50 {
            let t = 0.1 * k as f64;
            assert_eq!(b.attitude(t), (0.0, 0.0));
            assert_eq!(b.heave(t), 0.0);
        }
    }

    #[test]
    fn oscillations_stay_bounded_and_rates_are_derivatives() {
        let c = BodyMotionConfig::default();
        c.validate().unwrap();
        let b = BodyMotion::new(&c, &mut seeded(7));
        let bound = c.pitch_deg.to_radians() * (COMPONENTS as f64).sqrt();
        let (mut sum2, mut n) = (0.0, 0);
        for k in 0..2000 {
            let t = 0.05 * k as f64;
            let (_, p) = b.attitude(t);
            assert!(p.abs() <= bound + 1e-12);
            sum2 += p * p;
            n += 1;
            // Central difference of the value against the stated rate.
            let h = 1e-5;
            let numeric = (b.attitude(t + h).1 - b.attitude(t - h).1) / (2.0 * h);
            assert!((numeric - b.attitude_rate(t).1).abs() < 1e-7);
            let numeric = (b.heave(t + h) - b.heave(t - h)) / (2.0 * h);
            assert!((numeric - b.heave_rate(t)).abs() < 1e-7);
        }
        // It moves: the RMS pitch over 100 s is a fair part of the amplitude.
        let rms = (sum2 / n as f64).sqrt();
        assert!(rms > 0.2 * c.pitch_deg.to_radians(), "{rms}");
        let mut bad = c.clone();
        bad.frequency_hz = [2.0, 1.0];
        assert!(bad
            .validate()
            .unwrap_err()
            .to_string()
            .contains("frequency"));
    }
}
