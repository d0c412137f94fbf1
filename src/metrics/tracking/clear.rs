//! The CLEAR MOT metrics (Bernardin & Stiefelhagen 2008) with the extras TrackEval reports:
//! MOTA, MOTP, MODA, id switches, fragmentations, mostly tracked / partly tracked / mostly
//! lost, the TP/FN/FP counts, recall and precision.
//!
//! Matching per frame, as TrackEval does it: a pair is eligible when its similarity reaches
//! the threshold; among eligible pairs the assignment maximises 1000·[the tracker id is the one
//! this truth object was matched to in the previous frame that had both truth and tracker
//! objects] + similarity, so continuing matches win and similarity breaks the rest. An id
//! switch is a truth object matched to another tracker id than at its last match (any number
//! of frames back); a fragmentation is a resumed match after a frame in which it was not
//! tracked. MT: tracked in more than 80 % of its frames, ML: fewer than 20 %.
//!
//! Not for: deciding which objects count (see the parent module).

use super::{check_threshold, max_assignment, Sequence, TrackingFrame, EPS};
use crate::error::Result;
use serde::{Deserialize, Serialize};

/// CLEAR MOT scores of a sequence. As in TrackEval, a sequence without any tracker object or
/// without any truth object keeps MOTA, MOTP, MODA, recall and precision at 0.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Clear {
    /// (TP − FP − IDSW) / max(1, TP + FN).
    pub mota: f64,
    /// Mean similarity of the matches.
    pub motp: f64,
    /// (TP − FP) / max(1, TP + FN).
    pub moda: f64,
    /// TP / max(1, TP + FN).
    pub recall: f64,
    /// TP / max(1, TP + FP).
    pub precision: f64,
    /// Matches.
    pub tp: u64,
    /// Unmatched truth objects, summed over frames.
    pub fn_count: u64,
    /// Unmatched tracker objects, summed over frames.
    pub fp: u64,
    /// Id switches.
    pub idsw: u64,
    /// Fragmentations.
    pub frag: u64,
    /// Mostly tracked truth objects.
    pub mt: u64,
    /// Partly tracked truth objects.
    pub pt: u64,
    /// Mostly lost truth objects.
    pub ml: u64,
    /// The threshold used.
    pub threshold: f64,
}

/// CLEAR MOT of a sequence with matches needing a similarity of at least `threshold` (in
/// (0, 1]; TrackEval's default 0.5).
pub fn clear(frames: &[TrackingFrame], threshold: f64) -> Result<Clear> {
    clear_of(&Sequence::new(frames)?, threshold)
}

/// Which truth objects CLEAR's matching (as in [`clear`]) pairs with a tracker object: per
/// frame, one flag per entry of the frame's `gt_ids`.
pub fn clear_matches(frames: &[TrackingFrame], threshold: f64) -> Result<Vec<Vec<bool>>> {
    let seq = Sequence::new(frames)?;
    let mut matched: Vec<Vec<bool>> = frames.iter().map(|f| vec![false; f.gt_ids.len()]).collect();
    clear_with(&seq, threshold, Some(&mut matched))?;
    Ok(matched)
}

pub(crate) fn clear_of(seq: &Sequence, threshold: f64) -> Result<Clear> {
    clear_with(seq, threshold, None)
}

/// CLEAR MOT of `seq`; `matched`, when given (one flag per truth object of each frame), gets
/// the truth objects that are matched.
fn clear_with(
    seq: &Sequence,
    threshold: f64,
    mut matched: Option<&mut Vec<Vec<bool>>>,
) -> Result<Clear> {
    check_threshold("CLEAR threshold", threshold)?;
    let mut r = Clear {
        threshold,
        ..Clear::default()
    };
    if seq.num_tracker_dets == 0 {
        r.fn_count = seq.num_gt_dets as u64;
        r.ml = seq.num_gt_ids as u64;
        return Ok(r);
    }
    if seq.num_gt_dets == 0 {
        r.fp = seq.num_tracker_dets as u64;
        return Ok(r);
    }
    let ng = seq.num_gt_ids;
    let mut gt_count = vec![0u64; ng];
    let mut matched_count = vec![0u64; ng];
    let mut frag_count = vec![0u64; ng];
    let mut last_tracker: Vec<Option<usize>> = vec![None; ng];
    let mut prev_frame_tracker: Vec<Option<usize>> = vec![None; ng];
    let mut motp_sum = 0.0;
    for (k, ((f, gids), tids)) in seq.frames.iter().zip(&seq.gt).zip(&seq.tracker).enumerate() {
        let (g, t) = (gids.len(), tids.len());
        if g == 0 {
            r.fp += t as u64;
            continue;
        }
        if t == 0 {
            r.fn_count += g as u64;
            gids.iter().for_each(|&i| gt_count[i] += 1);
            continue;
        }
        let mut score = vec![0.0; g * t];
        for (i, &gi) in gids.iter().enumerate() {
            for (j, &tj) in tids.iter().enumerate() {
                let s = f.sim(i, j);
                if s >= threshold - EPS {
                    let bonus = if prev_frame_tracker[gi] == Some(tj) {
                        1000.0
                    } else {
                        0.0
                    };
                    score[i * t + j] = bonus + s;
                }
            }
        }
        let pairs: Vec<(usize, usize)> = max_assignment(&score, g, t)
            .into_iter()
            .filter(|&(i, j)| score[i * t + j] > EPS)
            .collect();
        for &(i, j) in &pairs {
            if last_tracker[gids[i]].is_some_and(|p| p != tids[j]) {
                r.idsw += 1;
            }
        }
        gids.iter().for_each(|&i| gt_count[i] += 1);
        let was_tracked: Vec<bool> = prev_frame_tracker.iter().map(Option::is_some).collect();
        prev_frame_tracker.iter_mut().for_each(|p| *p = None);
        if let Some(m) = matched.as_deref_mut() {
            for &(i, _) in &pairs {
                m[k][i] = true;
            }
        }
        for &(i, j) in &pairs {
            matched_count[gids[i]] += 1;
            last_tracker[gids[i]] = Some(tids[j]);
            prev_frame_tracker[gids[i]] = Some(tids[j]);
            if !was_tracked[gids[i]] {
                frag_count[gids[i]] += 1;
            }
            motp_sum += f.sim(i, j);
        }
        let n = pairs.len() as u64;
        r.tp += n;
        r.fn_count += g as u64 - n;
        r.fp += t as u64 - n;
    }
    for k in 0..ng {
        if gt_count[k] == 0 {
            continue;
        }
        let ratio = matched_count[k] as f64 / gt_count[k] as f64;
        if ratio > 0.8 {
            r.mt += 1;
        } else if ratio >= 0.2 {
            r.pt += 1;
        }
    }
    r.ml = ng as u64 - r.mt - r.pt;
    r.frag = frag_count.iter().map(|&c| c.saturating_sub(1)).sum();
    let (tp, fne, fp) = (r.tp as f64, r.fn_count as f64, r.fp as f64);
    r.motp = motp_sum / tp.max(1.0);
    r.moda = (tp - fp) / (tp + fne).max(1.0);
    r.mota = (tp - fp - r.idsw as f64) / (tp + fne).max(1.0);
    r.recall = tp / (tp + fne).max(1.0);
    r.precision = tp / (tp + fp).max(1.0);
    Ok(r)
}
