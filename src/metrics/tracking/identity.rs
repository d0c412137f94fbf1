//! The identity metrics (Ristani et al. 2016) as TrackEval computes them: one global
//! assignment of truth ids to tracker ids (each possibly unassigned) minimising identity false
//! negatives plus false positives, a pair's detections counting as identity true positives in
//! the frames where their similarity reaches the threshold; then IDF1 = 2·IDTP / (2·IDTP +
//! IDFP + IDFN), IDP and IDR.
//!
//! Not for: deciding which objects count (see the parent module).

use super::{check_threshold, Sequence, TrackingFrame};
use crate::assignment;
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// Identity scores of a sequence.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Identity {
    /// IDTP / max(1, IDTP + (IDFP + IDFN)/2).
    pub idf1: f64,
    /// Identity precision IDTP / max(1, IDTP + IDFP).
    pub idp: f64,
    /// Identity recall IDTP / max(1, IDTP + IDFN).
    pub idr: f64,
    /// Identity true positives.
    pub idtp: u64,
    /// Identity false negatives.
    pub idfn: u64,
    /// Identity false positives.
    pub idfp: u64,
    /// The threshold used.
    pub threshold: f64,
}

/// Identity metrics of a sequence; a detection pair counts when its similarity is at least
/// `threshold` (in (0, 1]; TrackEval's default 0.5).
pub fn identity(frames: &[TrackingFrame], threshold: f64) -> Result<Identity> {
    identity_of(&Sequence::new(frames)?, threshold)
}

pub(crate) fn identity_of(seq: &Sequence, threshold: f64) -> Result<Identity> {
    check_threshold("identity threshold", threshold)?;
    let mut r = Identity {
        threshold,
        ..Identity::default()
    };
    if seq.num_tracker_dets == 0 {
        r.idfn = seq.num_gt_dets as u64;
        return Ok(r);
    }
    if seq.num_gt_dets == 0 {
        r.idfp = seq.num_tracker_dets as u64;
        return Ok(r);
    }
    let (ng, nt) = (seq.num_gt_ids, seq.num_tracker_ids);
    let mut potential = vec![0.0; ng * nt];
    let mut gt_count = vec![0.0; ng];
    let mut tr_count = vec![0.0; nt];
    for ((f, gids), tids) in seq.frames.iter().zip(&seq.gt).zip(&seq.tracker) {
        for (i, &gi) in gids.iter().enumerate() {
            for (j, &tj) in tids.iter().enumerate() {
                if f.sim(i, j) >= threshold {
                    potential[gi * nt + tj] += 1.0;
                }
            }
        }
        gids.iter().for_each(|&i| gt_count[i] += 1.0);
        tids.iter().for_each(|&j| tr_count[j] += 1.0);
    }
    // Rows: truth ids, then one "unassigned" row per tracker id; columns: tracker ids, then
    // one "unassigned" column per truth id. TrackEval's matrices, 1e10 forbidding a pairing.
    let n = ng + nt;
    let mut fn_mat = vec![0.0; n * n];
    let mut fp_mat = vec![0.0; n * n];
    for row in ng..n {
        for c in 0..nt {
            fp_mat[row * n + c] = 1e10;
        }
    }
    for row in 0..ng {
        for c in nt..n {
            fn_mat[row * n + c] = 1e10;
        }
    }
    for gi in 0..ng {
        for c in 0..nt {
            fn_mat[gi * n + c] = gt_count[gi];
        }
        fn_mat[gi * n + nt + gi] = gt_count[gi];
    }
    for tj in 0..nt {
        for row in 0..ng {
            fp_mat[row * n + tj] = tr_count[tj];
        }
        fp_mat[(tj + ng) * n + tj] = tr_count[tj];
    }
    for gi in 0..ng {
        for tj in 0..nt {
            fn_mat[gi * n + tj] -= potential[gi * nt + tj];
            fp_mat[gi * n + tj] -= potential[gi * nt + tj];
        }
    }
    let cost: Vec<f64> = fn_mat.iter().zip(&fp_mat).map(|(a, b)| a + b).collect();
    let (cols, _) = assignment::solve(&cost, n, n)
        .ok_or_else(|| Error::invalid("identity assignment", "no solution"))?;
    let (mut idfn, mut idfp) = (0.0, 0.0);
    for (row, &c) in cols.iter().enumerate() {
        idfn += fn_mat[row * n + c];
        idfp += fp_mat[row * n + c];
    }
    r.idfn = idfn as u64;
    r.idfp = idfp as u64;
    r.idtp = (gt_count.iter().sum::<f64>() - idfn) as u64;
    let (tp, fne, fp) = (r.idtp as f64, r.idfn as f64, r.idfp as f64);
    r.idr = tp / (tp + fne).max(1.0);
    r.idp = tp / (tp + fp).max(1.0);
    r.idf1 = tp / (tp + 0.5 * fp + 0.5 * fne).max(1.0);
    Ok(r)
}
