//! HOTA (Luiten et al., "HOTA: A Higher Order Metric for Evaluating Multi-Object Tracking",
//! IJCV 2021) as TrackEval computes it: for each α = 0.05, 0.10, …, 0.95 a detection part
//! DetA = TP / (TP + FN + FP), an association part AssA = mean over true positives c of
//! |TPA(c)| / (|TPA(c)| + |FNA(c)| + |FPA(c)|), HOTA = √(DetA·AssA) and the localisation
//! LocA = mean similarity of the true positives. The per-frame matching is a Hungarian
//! assignment on (global alignment score of the id pair) × similarity, computed once for all
//! α; a pair is a true positive at α when its similarity is at least α.
//!
//! Not for: choosing similarities or which objects count (see the parent module).

use super::{max_assignment, Sequence, TrackingFrame, EPS};
use crate::error::Result;
use serde::{Deserialize, Serialize};

/// Number of α values (0.05 … 0.95 in steps of 0.05).
pub const HOTA_ALPHAS: usize = 19;

/// The α values, computed as numpy's `arange(0.05, 0.99, 0.05)` does (0.05 + k·0.05).
pub fn alphas() -> [f64; HOTA_ALPHAS] {
    std::array::from_fn(|k| 0.05 + k as f64 * 0.05)
}

/// HOTA and its parts at one α.
#[derive(Copy, Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct HotaAtAlpha {
    /// The localisation threshold α.
    pub alpha: f64,
    /// √(DetA·AssA).
    pub hota: f64,
    /// TP / max(1, TP + FN + FP).
    pub det_a: f64,
    /// Association accuracy.
    pub ass_a: f64,
    /// TP / max(1, TP + FN).
    pub det_re: f64,
    /// TP / max(1, TP + FP).
    pub det_pr: f64,
    /// Association recall.
    pub ass_re: f64,
    /// Association precision.
    pub ass_pr: f64,
    /// Mean similarity of the true positives (1 when there are none).
    pub loc_a: f64,
    /// True positives.
    pub tp: u64,
    /// False negatives.
    pub fn_count: u64,
    /// False positives.
    pub fp: u64,
}

/// HOTA of a sequence: every α, and the means over α that TrackEval reports.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Hota {
    /// Mean HOTA over α.
    pub hota: f64,
    /// Mean DetA over α.
    pub det_a: f64,
    /// Mean AssA over α.
    pub ass_a: f64,
    /// Mean LocA over α.
    pub loc_a: f64,
    /// Mean DetRe over α.
    pub det_re: f64,
    /// Mean DetPr over α.
    pub det_pr: f64,
    /// Mean AssRe over α.
    pub ass_re: f64,
    /// Mean AssPr over α.
    pub ass_pr: f64,
    /// HOTA at the lowest α (TrackEval's `HOTA(0)`).
    pub hota_0: f64,
    /// LocA at the lowest α (TrackEval's `LocA(0)`).
    pub loc_a_0: f64,
    /// The values at each α, in increasing α.
    pub per_alpha: Vec<HotaAtAlpha>,
}

/// HOTA of a sequence of frames (checked as in [`super::evaluate`]).
pub fn hota(frames: &[TrackingFrame]) -> Result<Hota> {
    Ok(hota_of(&Sequence::new(frames)?))
}

pub(crate) fn hota_of(seq: &Sequence) -> Hota {
    let alphas = alphas();
    let mut per: Vec<HotaAtAlpha> = alphas
        .iter()
        .map(|&alpha| HotaAtAlpha {
            alpha,
            ..HotaAtAlpha::default()
        })
        .collect();
    if seq.num_tracker_dets == 0 || seq.num_gt_dets == 0 {
        for p in &mut per {
            p.fn_count = seq.num_gt_dets as u64;
            p.fp = seq.num_tracker_dets as u64;
            p.loc_a = 1.0;
        }
        return finish(per);
    }
    let (ng, nt) = (seq.num_gt_ids, seq.num_tracker_ids);
    // Global alignment: similarity-weighted potential matches of every id pair.
    let mut potential = vec![0.0; ng * nt];
    let mut gt_count = vec![0.0; ng];
    let mut tr_count = vec![0.0; nt];
    for ((f, gids), tids) in seq.frames.iter().zip(&seq.gt).zip(&seq.tracker) {
        let (g, t) = (gids.len(), tids.len());
        let mut row_sum = vec![0.0; g];
        let mut col_sum = vec![0.0; t];
        for (i, r) in row_sum.iter_mut().enumerate() {
            for (j, c) in col_sum.iter_mut().enumerate() {
                *r += f.sim(i, j);
                *c += f.sim(i, j);
            }
        }
        for (i, &gi) in gids.iter().enumerate() {
            for (j, &tj) in tids.iter().enumerate() {
                let s = f.sim(i, j);
                let denom = col_sum[j] + row_sum[i] - s;
                if denom > EPS {
                    potential[gi * nt + tj] += s / denom;
                }
            }
        }
        gids.iter().for_each(|&i| gt_count[i] += 1.0);
        tids.iter().for_each(|&j| tr_count[j] += 1.0);
    }
    let alignment: Vec<f64> = (0..ng * nt)
        .map(|k| potential[k] / (gt_count[k / nt] + tr_count[k % nt] - potential[k]))
        .collect();

    let mut matches = vec![vec![0.0; ng * nt]; HOTA_ALPHAS];
    let mut loc_sum = [0.0; HOTA_ALPHAS];
    for ((f, gids), tids) in seq.frames.iter().zip(&seq.gt).zip(&seq.tracker) {
        let (g, t) = (gids.len(), tids.len());
        if g == 0 || t == 0 {
            for p in &mut per {
                p.fp += t as u64;
                p.fn_count += g as u64;
            }
            continue;
        }
        let mut score = vec![0.0; g * t];
        for (i, &gi) in gids.iter().enumerate() {
            for (j, &tj) in tids.iter().enumerate() {
                score[i * t + j] = alignment[gi * nt + tj] * f.sim(i, j);
            }
        }
        let pairs = max_assignment(&score, g, t);
        for (a, p) in per.iter_mut().enumerate() {
            let mut n = 0u64;
            for &(i, j) in &pairs {
                let s = f.sim(i, j);
                if s >= p.alpha - EPS {
                    n += 1;
                    loc_sum[a] += s;
                    matches[a][gids[i] * nt + tids[j]] += 1.0;
                }
            }
            p.tp += n;
            p.fn_count += g as u64 - n;
            p.fp += t as u64 - n;
        }
    }
    for (a, p) in per.iter_mut().enumerate() {
        let tp = (p.tp as f64).max(1.0);
        let (mut ass_a, mut ass_re, mut ass_pr) = (0.0, 0.0, 0.0);
        for (k, &m) in matches[a].iter().enumerate() {
            if m == 0.0 {
                continue;
            }
            let (gc, tc) = (gt_count[k / nt], tr_count[k % nt]);
            ass_a += m * m / (gc + tc - m).max(1.0);
            ass_re += m * m / gc.max(1.0);
            ass_pr += m * m / tc.max(1.0);
        }
        p.ass_a = ass_a / tp;
        p.ass_re = ass_re / tp;
        p.ass_pr = ass_pr / tp;
        p.loc_a = loc_sum[a].max(1e-10) / (p.tp as f64).max(1e-10);
    }
    finish(per)
}

/// The fields that follow from the counts, and the means over α.
fn finish(mut per: Vec<HotaAtAlpha>) -> Hota {
    for p in &mut per {
        let (tp, fne, fp) = (p.tp as f64, p.fn_count as f64, p.fp as f64);
        p.det_re = tp / (tp + fne).max(1.0);
        p.det_pr = tp / (tp + fp).max(1.0);
        p.det_a = tp / (tp + fne + fp).max(1.0);
        p.hota = (p.det_a * p.ass_a).sqrt();
    }
    let mean = |f: fn(&HotaAtAlpha) -> f64| per.iter().map(f).sum::<f64>() / per.len() as f64;
    Hota {
        hota: mean(|p| p.hota),
        det_a: mean(|p| p.det_a),
        ass_a: mean(|p| p.ass_a),
        loc_a: mean(|p| p.loc_a),
        det_re: mean(|p| p.det_re),
        det_pr: mean(|p| p.det_pr),
        ass_re: mean(|p| p.ass_re),
        ass_pr: mean(|p| p.ass_pr),
        hota_0: per[0].hota,
        loc_a_0: per[0].loc_a,
        per_alpha: per,
    }
}
