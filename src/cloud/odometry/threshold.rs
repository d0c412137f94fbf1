//! [`AdaptiveThreshold`]: the correspondence threshold σ from the deviation of the motion
//! prediction from the registered pose (paper, Sec. III-C, eqs. 4–6).

use nalgebra::Isometry3;

/// The adaptive threshold: σ = sqrt(mean of δ² over the frames that moved), where
/// δ = δ_rot + δ_trans is an upper bound of how far a point within `max_range` was moved by
/// the model deviation (eq. 4–5). Starts at `initial`.
#[derive(Clone, Debug)]
pub struct AdaptiveThreshold {
    min_motion: f64,
    max_range: f64,
    sum_sq: f64,
    samples: usize,
}

impl AdaptiveThreshold {
    /// A threshold that starts at `initial` m and ignores deviations below `min_motion` m.
    pub fn new(initial: f64, min_motion: f64, max_range: f64) -> Self {
        AdaptiveThreshold {
            min_motion,
            max_range,
            sum_sq: initial * initial,
            samples: 1,
        }
    }

    /// The current σ, metres (eq. 6).
    pub fn threshold(&self) -> f64 {
        (self.sum_sq / self.samples as f64).sqrt()
    }

    /// Adds the deviation between the predicted and the registered pose of one frame.
    pub fn update(&mut self, deviation: &Isometry3<f64>) {
        let delta = model_error(deviation, self.max_range);
        if delta > self.min_motion {
            self.sum_sq += delta * delta;
            self.samples += 1;
        }
    }
}

/// δ = 2·r_max·sin(θ/2) + ‖t‖: how far a rotation by θ and a translation t move a point at
/// most `max_range` from the origin (eqs. 4–5).
pub fn model_error(deviation: &Isometry3<f64>, max_range: f64) -> f64 {
    let theta = deviation.rotation.angle();
    2.0 * max_range * (theta / 2.0).sin() + deviation.translation.vector.norm()
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn small_deviations_keep_the_initial_threshold() {
        let mut t = AdaptiveThreshold::new(2.0, 0.1, 100.0);
        t.update(&Isometry3::translation(0.05, 0.0, 0.0));
        assert_eq!(t.threshold(), 2.0);
    }

    #[test]
    fn threshold_is_the_rms_of_the_moving_deviations() {
        let mut t = AdaptiveThreshold::new(2.0, 0.1, 100.0);
        t.update(&Isometry3::translation(1.0, 0.0, 0.0));
        assert!((t.threshold() - (5.0f64 / 2.0).sqrt()).abs() < 1e-12);
        let rot = Isometry3::new(Vector3::zeros(), Vector3::new(0.0, 0.0, 0.01));
        assert!((model_error(&rot, 100.0) - 200.0 * 0.005f64.sin()).abs() < 1e-12);
    }
}
