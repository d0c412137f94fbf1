//! Track life cycle shared by the baseline trackers: a track is born tentative, confirmed once
//! it was detected in M of its first N steps, and deleted when tentative and unable to reach M,
//! or when confirmed and unobserved for longer than a time limit (3.5 s in seed 000, Sec. 5.1).
//! Also the label maker: labels are (birth step, index among that step's births), as in the
//! LMB filter.
//!
//! Not for: existence probabilities (the LMB filter keeps those).

use crate::error::{Error, Result};
use crate::filter::Label;

/// When tracks are confirmed and deleted.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LifecycleConfig {
    /// Detections M needed within the first `confirm_window` steps. Default 3.
    pub confirm_hits: u32,
    /// Steps N in which a tentative track must collect `confirm_hits`. Default 5.
    pub confirm_window: u32,
    /// A confirmed track unobserved for longer than this (s) is deleted. Default 3.5 s.
    pub max_unobserved: f64,
}

impl Default for LifecycleConfig {
    fn default() -> Self {
        LifecycleConfig {
            confirm_hits: 3,
            confirm_window: 5,
            max_unobserved: 3.5,
        }
    }
}

impl LifecycleConfig {
    /// Checks 1 ≤ M ≤ N ≤ 64 and a positive time limit.
    pub fn validate(&self) -> Result<()> {
        if self.confirm_hits == 0
            || self.confirm_hits > self.confirm_window
            || self.confirm_window > 64
        {
            return Err(Error::invalid(
                "track confirmation",
                format!(
                    "{} of {} (need 1 ≤ M ≤ N ≤ 64)",
                    self.confirm_hits, self.confirm_window
                ),
            ));
        }
        crate::error::ensure_positive("max_unobserved", self.max_unobserved)
    }
}

/// Where one track stands in its life.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lifecycle {
    steps: u32,
    hits: u32,
    confirmed: bool,
    last_seen: f64,
}

impl Lifecycle {
    /// A track born from a detection at `time` (the birth counts as its first hit).
    pub fn born(time: f64) -> Self {
        Lifecycle {
            steps: 1,
            hits: 1,
            confirmed: false,
            last_seen: time,
        }
    }

    /// Records whether the track was detected at `time`.
    pub fn record(&mut self, detected: bool, time: f64, config: &LifecycleConfig) {
        self.steps += 1;
        if detected {
            self.hits += 1;
            self.last_seen = time;
        }
        if !self.confirmed
            && self.steps <= config.confirm_window
            && self.hits >= config.confirm_hits
        {
            self.confirmed = true;
        }
    }

    /// Whether the track is confirmed.
    pub fn confirmed(&self) -> bool {
        self.confirmed
    }

    /// Time of the last detection (s).
    pub fn last_seen(&self) -> f64 {
        self.last_seen
    }

    /// Whether the track should be deleted at `time`.
    pub fn is_dead(&self, time: f64, config: &LifecycleConfig) -> bool {
        if self.confirmed {
            time - self.last_seen > config.max_unobserved
        } else {
            let left = config.confirm_window.saturating_sub(self.steps);
            self.hits + left < config.confirm_hits
        }
    }
}

/// Hands out labels (birth step, index).
#[derive(Clone, Debug, Default)]
pub struct LabelMaker {
    step: u32,
    next: u32,
}

impl LabelMaker {
    /// Starts step `step`: indices restart at 0.
    pub fn start_step(&mut self, step: u32) {
        self.step = step;
        self.next = 0;
    }

    /// The next label of the current step.
    pub fn next_label(&mut self) -> Label {
        let l = Label::new(self.step, self.next);
        self.next += 1;
        l
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn three_of_five_confirms_and_two_misses_in_a_row_early_kill() {
        let cfg = LifecycleConfig::default();
        let mut a = Lifecycle::born(0.0);
        a.record(true, 0.1, &cfg);
        assert!(!a.confirmed());
        a.record(true, 0.2, &cfg);
        assert!(a.confirmed());
        // born, miss, miss, miss: 1 hit + 1 step left < 3 → dead
        let mut b = Lifecycle::born(0.0);
        for t in [0.1, 0.2, 0.3] {
            b.record(false, t, &cfg);
        }
        assert!(b.is_dead(0.3, &cfg));
        // confirmed tracks die only after 3.5 s without detection
        assert!(!a.is_dead(3.7, &cfg));
        assert!(a.is_dead(3.71, &cfg));
        assert!(LifecycleConfig {
            confirm_hits: 4,
            confirm_window: 3,
            max_unobserved: 1.0
        }
        .validate()
        .is_err());
    }
}
