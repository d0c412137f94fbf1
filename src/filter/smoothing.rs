//! Fixed-lag smoothing of the filter's reported tracks: the estimate of step k − L is given
//! once step k has been filtered, its states refined by the L measurements that came after.
//!
//! With [`LmbConfig::smoothing_lag`](crate::filter::LmbConfig::smoothing_lag) ≥ L, every track's
//! particles carry their ancestors' states over the last L steps
//! ([`ParticleSet::keep_history`](crate::filter::ParticleSet::keep_history)); the weighted
//! mean of those pasts under today's weights is the fixed-lag smoothed state (the genealogy
//! smoother; why not a backward pass is said in the particle history's module). The
//! [`FixedLagSmoother`] holds each step's estimates for L steps and then hands them out with
//! their states smoothed.
//!
//! Only the states change: which tracks are reported at a step, their labels and
//! existences, stay the filter's decision at that step. A track pruned since, or younger than
//! the lag at the step it is asked about, keeps its filtered state. A smoothed estimate comes
//! L steps late, so this is for offline use (evaluation, maps, trajectories), not for a
//! controller.
//!
//! ```
//! use smc_lmb::filter::{FixedLagSmoother, LmbConfig};
//! let config = LmbConfig { smoothing_lag: 5, ..LmbConfig::default() };
//! let smoother = FixedLagSmoother::new(5);
//! assert_eq!((config.smoothing_lag, smoother.lag()), (5, 5));
//! // After each `filter.step(..)`: `if let Some(late) = smoother.push(&filter, estimates)? {..}`,
//! // and `smoother.finish(&filter)` after the last.
//! ```
//!
//! Not for: smoothing existence or the number of objects.

use super::{Estimate, LmbFilter};
use crate::error::{Error, Result};
use std::collections::VecDeque;

/// Holds each step's estimates for `lag` steps and hands them out smoothed. See the module
/// documentation.
#[derive(Clone, Debug, Default)]
pub struct FixedLagSmoother {
    lag: usize,
    /// Estimates of the steps not yet handed out, oldest first.
    pending: VecDeque<Vec<Estimate>>,
}

impl FixedLagSmoother {
    /// A smoother that hands out each step's estimates `lag` steps later (0: at once, as
    /// filtered).
    pub fn new(lag: usize) -> Self {
        FixedLagSmoother {
            lag,
            pending: VecDeque::with_capacity(lag + 1),
        }
    }

    /// The lag in steps.
    pub fn lag(&self) -> usize {
        self.lag
    }

    /// Takes the estimates `filter` has just returned from a step; returns those of the step
    /// `lag` steps back, with their states smoothed, once there is such a step. An error when
    /// the filter keeps less history than the lag.
    pub fn push(
        &mut self,
        filter: &LmbFilter,
        estimates: Vec<Estimate>,
    ) -> Result<Option<Vec<Estimate>>> {
        let kept = filter.config().smoothing_lag;
        if kept < self.lag {
            return Err(Error::invalid(
                "fixed-lag smoother",
                format!(
                    "lag {} needs the filter's smoothing_lag at least as long, it is {kept}",
                    self.lag
                ),
            ));
        }
        self.pending.push_back(estimates);
        if self.pending.len() <= self.lag {
            return Ok(None);
        }
        let oldest = self.pending.pop_front().unwrap_or_default();
        Ok(Some(smoothed(filter, oldest, self.lag)))
    }

    /// After the last step: the estimates still held, oldest first, each smoothed with every
    /// step that came after it.
    pub fn finish(self, filter: &LmbFilter) -> Vec<Vec<Estimate>> {
        let n = self.pending.len();
        self.pending
            .into_iter()
            .enumerate()
            .map(|(i, e)| smoothed(filter, e, n - 1 - i))
            .collect()
    }
}

/// `estimates` of the step `steps_back` steps before the filter's last, each state replaced by
/// the mean of its track's particle pasts when the track is still there and carries them.
fn smoothed(filter: &LmbFilter, mut estimates: Vec<Estimate>, steps_back: usize) -> Vec<Estimate> {
    if steps_back == 0 {
        return estimates;
    }
    for e in &mut estimates {
        let past = filter
            .tracks()
            .iter()
            .find(|t| t.label == e.label)
            .and_then(|t| t.particles.lagged_mean(steps_back));
        if let Some(state) = past {
            e.state = state;
        }
    }
    estimates
}
