//! Multi-object tracking scores computed the way TrackEval computes them (Luiten et al.):
//! HOTA with its detection, association and localisation parts ([`hota`](mod@hota)), the CLEAR
//! MOT metrics ([`clear`](mod@clear)) and the identity metrics IDF1/IDP/IDR
//! ([`identity`](mod@identity)).
//!
//! The input is geometry-free, exactly TrackEval's: per frame the ground-truth ids, the
//! tracker ids and a gt × tracker similarity matrix with values in [0, 1] (an IoU, or a
//! distance mapped to 1 at zero distance and 0 at a cut-off). Ids are any integers, unique
//! within a frame; they are relabelled 0.. in ascending order as TrackEval does, so the
//! matchings, ties included, are solved on the same matrices. Every matching follows
//! TrackEval's code: HOTA's per-frame Hungarian assignment on global alignment × similarity,
//! thresholded per α; CLEAR's assignment that keeps the previous frame's match with a bonus of
//! 1000 and then maximises similarity; the identity metrics' one global id assignment.
//!
//! Not for: deciding which objects count (classes, distractors, ignore regions — see
//! `crate::pipeline::kitti_tracking_eval` for KITTI's rules) or computing similarities.

pub mod clear;
pub mod hota;
pub mod identity;

pub use clear::{clear, clear_matches, Clear};
pub use hota::{hota, Hota, HotaAtAlpha, HOTA_ALPHAS};
pub use identity::{identity, Identity};

use crate::assignment;
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// numpy's `np.finfo(float).eps`, the slack TrackEval gives its threshold comparisons.
pub(crate) const EPS: f64 = f64::EPSILON;

/// One frame of a sequence: who is there and how alike each truth/tracker pair is.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TrackingFrame {
    /// Ground-truth object ids present in the frame (unique).
    pub gt_ids: Vec<i64>,
    /// Tracker ids present in the frame (unique).
    pub tracker_ids: Vec<i64>,
    /// Row-major `gt_ids.len() × tracker_ids.len()` similarities in [0, 1].
    pub similarity: Vec<f64>,
}

impl TrackingFrame {
    /// A frame, checked: ids unique within the frame, one finite similarity in [0, 1] per pair.
    pub fn new(gt_ids: Vec<i64>, tracker_ids: Vec<i64>, similarity: Vec<f64>) -> Result<Self> {
        let f = TrackingFrame {
            gt_ids,
            tracker_ids,
            similarity,
        };
        f.check("frame")?;
        Ok(f)
    }

    /// The similarity of gt `g` and tracker `t` (indices into the id lists).
    pub fn sim(&self, g: usize, t: usize) -> f64 {
        self.similarity[g * self.tracker_ids.len() + t]
    }

    fn check(&self, what: &str) -> Result<()> {
        let (g, t) = (self.gt_ids.len(), self.tracker_ids.len());
        if self.similarity.len() != g * t {
            return Err(Error::invalid(
                what,
                format!(
                    "{} similarities for {g} truth × {t} tracker objects",
                    self.similarity.len()
                ),
            ));
        }
        if let Some(s) = self
            .similarity
            .iter()
            .find(|s| !(s.is_finite() && (0.0..=1.0).contains(*s)))
        {
            return Err(Error::invalid(
                what,
                format!("similarity {s} (must lie in [0, 1])"),
            ));
        }
        for (name, ids) in [("truth", &self.gt_ids), ("tracker", &self.tracker_ids)] {
            let mut sorted = ids.clone();
            sorted.sort_unstable();
            if let Some(w) = sorted.windows(2).find(|w| w[0] == w[1]) {
                return Err(Error::invalid(
                    what,
                    format!("{name} id {} appears twice", w[0]),
                ));
            }
        }
        Ok(())
    }
}

/// Thresholds of the CLEAR and identity metrics (HOTA integrates over its own α).
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ScoreConfig {
    /// Least similarity of a CLEAR match (TrackEval's default 0.5).
    pub clear_threshold: f64,
    /// Least similarity of an identity match (TrackEval's default 0.5).
    pub identity_threshold: f64,
}

impl Default for ScoreConfig {
    fn default() -> Self {
        ScoreConfig {
            clear_threshold: 0.5,
            identity_threshold: 0.5,
        }
    }
}

/// HOTA, CLEAR and identity scores of one sequence.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrackingScores {
    /// HOTA and its parts, per α and averaged.
    pub hota: Hota,
    /// CLEAR MOT.
    pub clear: Clear,
    /// IDF1, IDP, IDR.
    pub identity: Identity,
}

/// Scores one sequence with every metric; errors on a malformed frame or a threshold outside
/// (0, 1].
pub fn evaluate(frames: &[TrackingFrame], config: &ScoreConfig) -> Result<TrackingScores> {
    let seq = Sequence::new(frames)?;
    Ok(TrackingScores {
        hota: hota::hota_of(&seq),
        clear: clear::clear_of(&seq, config.clear_threshold)?,
        identity: identity::identity_of(&seq, config.identity_threshold)?,
    })
}

pub(crate) fn check_threshold(what: &str, t: f64) -> Result<()> {
    if t.is_finite() && t > 0.0 && t <= 1.0 {
        Ok(())
    } else {
        Err(Error::invalid(what, format!("{t} (must lie in (0, 1])")))
    }
}

/// A checked sequence with ids relabelled to 0.. (ascending original id) over the sequence.
pub(crate) struct Sequence<'a> {
    pub frames: &'a [TrackingFrame],
    pub gt: Vec<Vec<usize>>,
    pub tracker: Vec<Vec<usize>>,
    pub num_gt_ids: usize,
    pub num_tracker_ids: usize,
    pub num_gt_dets: usize,
    pub num_tracker_dets: usize,
}

impl<'a> Sequence<'a> {
    pub fn new(frames: &'a [TrackingFrame]) -> Result<Self> {
        for (k, f) in frames.iter().enumerate() {
            f.check(&format!("frame {k}"))?;
        }
        let relabel = |ids: &dyn Fn(&TrackingFrame) -> &Vec<i64>| {
            let mut map = BTreeMap::new();
            for f in frames {
                for &id in ids(f) {
                    map.insert(id, 0usize);
                }
            }
            for (k, v) in map.values_mut().enumerate() {
                *v = k;
            }
            let dense: Vec<Vec<usize>> = frames
                .iter()
                .map(|f| ids(f).iter().map(|id| map[id]).collect())
                .collect();
            (dense, map.len())
        };
        let (gt, num_gt_ids) = relabel(&|f| &f.gt_ids);
        let (tracker, num_tracker_ids) = relabel(&|f| &f.tracker_ids);
        Ok(Sequence {
            frames,
            num_gt_dets: gt.iter().map(Vec::len).sum(),
            num_tracker_dets: tracker.iter().map(Vec::len).sum(),
            gt,
            tracker,
            num_gt_ids,
            num_tracker_ids,
        })
    }
}

/// The assignment maximising the summed `score` (row-major `rows × cols`, finite), as
/// (row, col) pairs; min(rows, cols) pairs, like scipy's `linear_sum_assignment`.
pub(crate) fn max_assignment(score: &[f64], rows: usize, cols: usize) -> Vec<(usize, usize)> {
    if rows == 0 || cols == 0 {
        return Vec::new();
    }
    if rows <= cols {
        let cost: Vec<f64> = score.iter().map(|s| -s).collect();
        let (a, _) = assignment::solve(&cost, rows, cols).unwrap_or_default();
        a.into_iter().enumerate().collect()
    } else {
        let mut cost = vec![0.0; rows * cols];
        for r in 0..rows {
            for c in 0..cols {
                cost[c * rows + r] = -score[r * cols + c];
            }
        }
        let (a, _) = assignment::solve(&cost, cols, rows).unwrap_or_default();
        let mut pairs: Vec<(usize, usize)> =
            a.into_iter().enumerate().map(|(c, r)| (r, c)).collect();
        pairs.sort_unstable();
        pairs
    }
}

#[cfg(test)]
mod tests;
