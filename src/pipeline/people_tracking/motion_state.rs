//! Static or dynamic: whether a tracked object is moving, from its velocity posterior.
//!
//! For a particle set with velocity components ẋ (component 1) and ẏ (component 3), the
//! probability that the object moves is P(|v| > v_min) = Σᵢ wᵢ · [ẋᵢ² + ẏᵢ² > v_min²].
//! A track's class switches with hysteresis so that one noisy scan does not flip it: a static
//! track becomes dynamic when P ≥ `enter`, a dynamic track becomes static again when
//! P ≤ `exit` (with `exit` < `enter`); in between it keeps its class. New tracks start static
//! and stay so for their first `min_age` scans: a fresh track's velocity is its birth prior
//! (spread around zero by about a walking speed), which says nothing about the object yet.
//!
//! Not for: deciding moving versus static from the scan points themselves (background
//! models), or for the motion model.

use crate::error::{Error, Result};
use crate::filter::{Label, ParticleSet};
use std::collections::HashMap;

/// Thresholds of the static/dynamic decision.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MotionConfig {
    /// Speed (m/s) above which an object counts as moving. Default 0.3 m/s (slow walking is
    /// about 0.5 m/s; a standing person's velocity posterior spreads around zero).
    pub v_min: f64,
    /// P(moving) at or above which a static track becomes dynamic. Default 0.8.
    pub enter: f64,
    /// P(moving) at or below which a dynamic track becomes static. Default 0.3.
    pub exit: f64,
    /// Tracks younger than this many scans are static. Default 8.
    pub min_age: u32,
}

impl Default for MotionConfig {
    fn default() -> Self {
        MotionConfig {
            v_min: 0.3,
            enter: 0.8,
            exit: 0.3,
            min_age: 8,
        }
    }
}

impl MotionConfig {
    /// Checks `v_min ≥ 0` and `0 ≤ exit < enter ≤ 1`.
    pub fn validate(&self) -> Result<()> {
        if !(self.v_min.is_finite() && self.v_min >= 0.0) {
            return Err(Error::invalid(
                "motion threshold v_min",
                format!("{} must be finite and ≥ 0", self.v_min),
            ));
        }
        if !(0.0 <= self.exit && self.exit < self.enter && self.enter <= 1.0) {
            return Err(Error::invalid(
                "motion hysteresis",
                format!(
                    "need 0 ≤ exit < enter ≤ 1, got exit {} and enter {}",
                    self.exit, self.enter
                ),
            ));
        }
        Ok(())
    }
}

/// P(speed > v_min) of a particle set with state [x, ẋ, y, ẏ, …]; 0 for states with fewer
/// than four components.
pub fn probability_moving(particles: &ParticleSet, v_min: f64) -> f64 {
    if particles.dim() < 4 {
        return 0.0;
    }
    let v2 = v_min * v_min;
    let (vx, vy) = (particles.component(1), particles.component(3));
    particles
        .weights()
        .iter()
        .zip(vx)
        .zip(vy)
        .filter(|((_, &a), &b)| a * a + b * b > v2)
        .map(|((w, _), _)| w)
        .sum::<f64>()
        .clamp(0.0, 1.0)
}

/// Keeps each track's static/dynamic class across scans (hysteresis, see the module
/// documentation).
#[derive(Clone, Debug, Default)]
pub struct MotionClassifier {
    config: MotionConfig,
    moving: HashMap<Label, bool>,
}

impl MotionClassifier {
    /// A classifier with checked thresholds.
    pub fn new(config: MotionConfig) -> Result<Self> {
        config.validate()?;
        Ok(MotionClassifier {
            config,
            moving: HashMap::new(),
        })
    }

    /// The thresholds.
    pub fn config(&self) -> &MotionConfig {
        &self.config
    }

    /// Feeds this scan's P(moving) of track `label`, `age` scans old; returns its class
    /// (true = dynamic).
    pub fn update(&mut self, label: Label, p_moving: f64, age: u32) -> bool {
        let state = self.moving.entry(label).or_insert(false);
        if age < self.config.min_age {
            *state = false;
        } else if *state {
            if p_moving <= self.config.exit {
                *state = false;
            }
        } else if p_moving >= self.config.enter {
            *state = true;
        }
        *state
    }

    /// Forgets every track not in `alive`.
    pub fn retain(&mut self, alive: impl Fn(Label) -> bool) {
        self.moving.retain(|l, _| alive(*l));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn set(velocities: &[(f64, f64)], weights: &[f64]) -> ParticleSet {
        let rows: Vec<Vec<f64>> = velocities
            .iter()
            .map(|&(vx, vy)| vec![0.0, vx, 0.0, vy])
            .collect();
        ParticleSet::from_rows(&rows, weights).unwrap()
    }

    #[test]
    fn probability_counts_weight_above_the_threshold() {
        // speeds 0.1, 0.5 (3-4-5 scaled), 1.0 with weights 0.5, 0.25, 0.25
        let p = set(&[(0.1, 0.0), (0.3, 0.4), (0.0, -1.0)], &[2.0, 1.0, 1.0]);
        assert!((probability_moving(&p, 0.3) - 0.5).abs() < 1e-12);
        assert!((probability_moving(&p, 0.05) - 1.0).abs() < 1e-12);
        assert_eq!(probability_moving(&p, 2.0), 0.0);
        assert_eq!(probability_moving(&ParticleSet::zeroed(2, 3), 0.1), 0.0);
    }

    #[test]
    fn hysteresis_switches_both_ways() {
        let mut c = MotionClassifier::new(MotionConfig::default()).unwrap();
        let l = Label::new(0, 0);
        // too young: static whatever the velocity says
        assert!(!c.update(l, 0.95, 3));
        // starts static; 0.6 is between exit and enter → stays static
        assert!(!c.update(l, 0.6, 10));
        assert!(c.update(l, 0.85, 11)); // enters dynamic
        assert!(c.update(l, 0.5, 12)); // in the band: keeps dynamic
        assert!(!c.update(l, 0.2, 13)); // back to static
        assert!(!c.update(l, 0.7, 14));
        assert!(c.update(l, 0.9, 15));
        // other labels are independent; forgetting resets to static
        assert!(!c.update(Label::new(1, 0), 0.5, 20));
        c.retain(|x| x != l);
        assert!(!c.update(l, 0.5, 20));
    }

    #[test]
    fn bad_thresholds_are_rejected() {
        let bad = MotionConfig {
            enter: 0.3,
            exit: 0.5,
            ..MotionConfig::default()
        };
        assert!(MotionClassifier::new(bad).is_err());
        let neg = MotionConfig {
            v_min: -1.0,
            ..MotionConfig::default()
        };
        assert!(neg.validate().is_err());
    }
}
