//! The KITTI object benchmark's average precision (AP) of detections of one class at one
//! difficulty level (Geiger, Lenz & Urtasun, CVPR 2012), both the original 11-point
//! interpolation and the 40-point one the benchmark switched to in 2019 (Simonelli et al.,
//! ICCV 2019).
//!
//! The computation follows the devkit's `cpp/evaluate_object.cpp` and its Python port
//! (second.pytorch / OpenPCDet `kitti_object_eval_python/eval.py`) step by step:
//!
//! 1. Every labelled object gets a role: *counted* (the evaluated class, within the
//!    difficulty's limits on 2-D box height, occlusion and truncation), *ignored* (a
//!    neighbouring class such as Van for Car, or the evaluated class outside the limits: it may
//!    absorb a detection, which then is neither a true nor a false positive, and missing it is
//!    no false negative) or *not considered* (any other class). Every detection is *ignored*
//!    when its 2-D box is lower than the difficulty's minimum height (whatever its class),
//!    else *counted* when it is of the evaluated class, else *not considered*.
//! 2. A first pass over the frames lets every labelled object, in order, take the
//!    highest-scoring still unassigned detection whose overlap exceeds the minimum (strictly);
//!    the scores of the counted/counted pairs are the true-positive scores.
//! 3. At most 41 score thresholds are picked from those scores so that recall rises by about
//!    1/40 from one to the next (the devkit's `getThresholds`).
//! 4. For each threshold a second pass, using only detections scoring at least the threshold,
//!    lets every labelled object take the counted detection of largest overlap (or, failing
//!    that, an ignored one) and counts true positives, false positives (counted detections
//!    left unassigned) and false negatives (counted objects left unmatched).
//! 5. Precision per threshold is made non-increasing (`p[i] = max p[i..]`); AP_R11 is the mean
//!    of `p[0], p[4], …, p[40]`, AP_R40 the mean of `p[1..=40]`.
//!
//! The thresholds sit at the *score* quantiles of the true positives, not at recall 0, 1/40,
//! …, 1, so with few counted objects the curve is short and the AP is low even for perfect
//! detections: fewer than 41 counted objects leave the tail of the precision array at zero
//! (one perfectly detected object gives AP_R11 = 1/11 and AP_R40 = 0, 40 of them 10/11 and
//! 39/40). That is the benchmark's behaviour and is kept here.
//!
//! The overlap of every detection with every labelled object is handed in, so the module works
//! for the bird's-eye-view and 3-D metrics alike (and for anything else measured as an
//! overlap). Only the 2-D image metric discounts detections falling on DontCare regions; the
//! BEV and 3-D metrics do not, so DontCare labels are simply left out of the input.
//!
//! Not for: computing overlaps (IoU of rotated boxes), reading label files, the 2-D image
//! metric's DontCare handling, average orientation similarity (AOS), or choosing the
//! benchmark's per-class minimum overlaps (0.7 for Car, 0.5 for Pedestrian and Cyclist in the
//! official setting) — those are the caller's.

use crate::error::{Error, Result};

/// Number of points of the sampled precision curve (the devkit's `N_SAMPLE_PTS`).
pub const SAMPLE_POINTS: usize = 41;

/// KITTI's difficulty levels, each a set of limits a counted object must meet.
///
/// | Level | min 2-D box height (px) | max occlusion level | max truncation |
/// |---|---|---|---|
/// | Easy | 40 | 0 (fully visible) | 0.15 |
/// | Moderate | 25 | 1 (partly occluded) | 0.30 |
/// | Hard | 25 | 2 (largely occluded) | 0.50 |
///
/// A labelled object must be *higher* than the minimum height; a detection is ignored only when
/// it is *lower* than it (both as in the devkit).
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum Difficulty {
    /// Large, fully visible, barely truncated objects.
    Easy,
    /// The benchmark's ranking level.
    Moderate,
    /// Everything up to largely occluded and half truncated objects.
    Hard,
}

impl Difficulty {
    /// The three levels, easiest first.
    pub const ALL: [Difficulty; 3] = [Difficulty::Easy, Difficulty::Moderate, Difficulty::Hard];

    /// Minimum height of the 2-D image box, pixels.
    pub fn min_height_px(self) -> f64 {
        match self {
            Difficulty::Easy => 40.0,
            Difficulty::Moderate | Difficulty::Hard => 25.0,
        }
    }

    /// Largest occlusion level of a counted object (KITTI's 0 visible, 1 partly occluded,
    /// 2 largely occluded, 3 unknown).
    pub fn max_occlusion(self) -> u8 {
        match self {
            Difficulty::Easy => 0,
            Difficulty::Moderate => 1,
            Difficulty::Hard => 2,
        }
    }

    /// Largest truncation (fraction of the object outside the image) of a counted object.
    pub fn max_truncation(self) -> f64 {
        match self {
            Difficulty::Easy => 0.15,
            Difficulty::Moderate => 0.30,
            Difficulty::Hard => 0.50,
        }
    }
}

/// How a labelled object's class relates to the class being evaluated.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash)]
pub enum TruthClass {
    /// The evaluated class itself.
    Evaluated,
    /// A neighbouring class that neither counts nor penalises (Van when evaluating Car,
    /// Person_sitting when evaluating Pedestrian): it may absorb one detection.
    Neighbour,
    /// Any other class: not considered at all.
    Other,
}

/// One labelled (ground-truth) object of a frame.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct TruthObject {
    /// Its class relative to the evaluated one.
    pub class: TruthClass,
    /// KITTI occlusion level: 0 visible, 1 partly occluded, 2 largely occluded, 3 unknown.
    pub occluded: u8,
    /// KITTI truncation, 0 (inside the image) to 1 (leaving it).
    pub truncated: f64,
    /// Height of the 2-D image box (bottom − top), pixels.
    pub height_px: f64,
}

/// One detection of a frame.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Detection {
    /// Whether the detector labelled it with the evaluated class.
    pub evaluated_class: bool,
    /// Confidence score; higher is more confident.
    pub score: f64,
    /// Height of the 2-D image box, pixels (its absolute value is used, as in the devkit).
    pub height_px: f64,
}

/// One frame's labelled objects, detections and their overlaps.
#[derive(Copy, Clone, Debug)]
pub struct FrameInput<'a> {
    /// The labelled objects (DontCare labels left out).
    pub truth: &'a [TruthObject],
    /// The detections, of all classes.
    pub detections: &'a [Detection],
    /// `overlap[d][t]`: overlap (usually an IoU in [0, 1]) of detection `d` with labelled
    /// object `t`; one row per detection, each as long as `truth`.
    pub overlap: &'a [Vec<f64>],
}

/// The average precision of one class at one difficulty and one minimum overlap.
#[derive(Clone, Debug, PartialEq)]
pub struct AveragePrecision {
    /// AP over 40 recall points (`precision[1..=40]`), in [0, 1].
    pub ap_r40: f64,
    /// AP over 11 recall points (`precision[0]`, `precision[4]`, …, `precision[40]`), in [0, 1].
    pub ap_r11: f64,
    /// Interpolated precision at each score threshold (`p[i] = max p[i..]`); entries past the
    /// last threshold are 0. A threshold with neither true nor false positives has precision 0.
    pub precision: [f64; SAMPLE_POINTS],
    /// Recall at each score threshold, not interpolated (as in the devkit; the Python port
    /// replaces it by its running maximum from the end); entries past the last threshold are 0.
    pub recall: [f64; SAMPLE_POINTS],
    /// The score thresholds, highest first (at most [`SAMPLE_POINTS`]).
    pub thresholds: Vec<f64>,
    /// Number of counted labelled objects (the recall denominator).
    pub truth_count: usize,
}

/// KITTI's average precision of `frames` at `difficulty`, matching detections to labelled
/// objects whose overlap is strictly greater than `min_overlap`.
///
/// With no counted labelled object at all, there is no true positive and no threshold, so
/// every precision and both APs are 0 (what the devkit reports too) and `truth_count` is 0;
/// this is not an error, so that a class absent from a split can still be tabulated.
///
/// Errors: `min_overlap` not in (0, 1]; an overlap matrix whose number of rows differs from
/// the frame's detections or whose rows differ in length from its labelled objects; a
/// non-finite overlap, score, height or truncation.
///
/// ```
/// use smc_lmb::metrics::detection_ap::{
///     average_precision, Detection, Difficulty, FrameInput, TruthClass, TruthObject,
/// };
/// let car = TruthObject { class: TruthClass::Evaluated, occluded: 0, truncated: 0.0, height_px: 60.0 };
/// let hit = Detection { evaluated_class: true, score: 0.9, height_px: 58.0 };
/// let overlap = vec![vec![0.8]];
/// let frame = FrameInput { truth: &[car], detections: &[hit], overlap: &overlap };
/// let ap = average_precision(&[frame], Difficulty::Moderate, 0.7).unwrap();
/// assert_eq!(ap.truth_count, 1);
/// assert_eq!(ap.precision[0], 1.0);
/// // One object fills only the first point of the curve.
/// assert!((ap.ap_r11 - 1.0 / 11.0).abs() < 1e-12);
/// assert_eq!(ap.ap_r40, 0.0);
/// ```
pub fn average_precision(
    frames: &[FrameInput<'_>],
    difficulty: Difficulty,
    min_overlap: f64,
) -> Result<AveragePrecision> {
    if !(min_overlap > 0.0 && min_overlap <= 1.0) {
        return Err(Error::invalid(
            "minimum overlap",
            format!("{min_overlap} (must be in (0, 1])"),
        ));
    }
    for (k, frame) in frames.iter().enumerate() {
        validate_frame(k, frame)?;
    }

    let prepared: Vec<Prepared<'_>> = frames
        .iter()
        .map(|f| Prepared::new(f, difficulty))
        .collect();
    let truth_count = prepared
        .iter()
        .map(|p| p.truth.iter().filter(|&&r| r == Role::Counted).count())
        .sum();

    let mut assigned = Vec::new();
    let mut tp_scores = Vec::new();
    for p in &prepared {
        tally_frame(p, min_overlap, Pass::Scores, &mut assigned, |s| {
            tp_scores.push(s)
        });
    }
    let thresholds = score_thresholds(&mut tp_scores, truth_count);

    let mut precision = [0.0; SAMPLE_POINTS];
    let mut recall = [0.0; SAMPLE_POINTS];
    for (i, &threshold) in thresholds.iter().enumerate() {
        let mut total = Tally::default();
        for p in &prepared {
            let t = tally_frame(
                p,
                min_overlap,
                Pass::AtThreshold(threshold),
                &mut assigned,
                |_| {},
            );
            total.tp += t.tp;
            total.fp += t.fp;
            total.fn_ += t.fn_;
        }
        precision[i] = ratio(total.tp, total.tp + total.fp);
        recall[i] = ratio(total.tp, total.tp + total.fn_);
    }
    for i in (0..SAMPLE_POINTS - 1).rev() {
        precision[i] = precision[i].max(precision[i + 1]);
    }

    let ap_r40 = precision[1..].iter().sum::<f64>() / (SAMPLE_POINTS - 1) as f64;
    let ap_r11 = precision.iter().step_by(4).sum::<f64>() / 11.0;
    Ok(AveragePrecision {
        ap_r40,
        ap_r11,
        precision,
        recall,
        thresholds,
        truth_count,
    })
}

/// What an object or detection counts for (the devkit's ignored flags 0 / 1 / −1).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
enum Role {
    /// Evaluated: a true positive, false positive or false negative.
    Counted,
    /// May be paired, but the pair counts for nothing.
    Ignored,
    /// Skipped entirely.
    Excluded,
}

/// A frame with the roles of its objects and detections.
struct Prepared<'a> {
    input: &'a FrameInput<'a>,
    truth: Vec<Role>,
    detections: Vec<Role>,
}

impl<'a> Prepared<'a> {
    fn new(input: &'a FrameInput<'a>, difficulty: Difficulty) -> Self {
        let truth = input
            .truth
            .iter()
            .map(|t| {
                let outside = t.occluded > difficulty.max_occlusion()
                    || t.truncated > difficulty.max_truncation()
                    || t.height_px <= difficulty.min_height_px();
                match t.class {
                    TruthClass::Evaluated if !outside => Role::Counted,
                    TruthClass::Evaluated | TruthClass::Neighbour => Role::Ignored,
                    TruthClass::Other => Role::Excluded,
                }
            })
            .collect();
        let detections = input
            .detections
            .iter()
            .map(|d| {
                if d.height_px.abs() < difficulty.min_height_px() {
                    Role::Ignored
                } else if d.evaluated_class {
                    Role::Counted
                } else {
                    Role::Excluded
                }
            })
            .collect();
        Prepared {
            input,
            truth,
            detections,
        }
    }
}

/// The two matching passes of the devkit's `computeStatistics`.
#[derive(Copy, Clone, Debug)]
enum Pass {
    /// All detections take part; each object takes the highest-scoring candidate.
    Scores,
    /// Only detections scoring at least the threshold take part; each object prefers the
    /// counted candidate of largest overlap, else any ignored one; false positives are counted.
    AtThreshold(f64),
}

/// Counts of one frame (or a sum of frames) at one threshold.
#[derive(Copy, Clone, Debug, Default)]
struct Tally {
    tp: usize,
    fp: usize,
    fn_: usize,
}

/// Matches one frame's objects, in order, to its detections; calls `on_tp` with the score of
/// each true positive. `assigned` is scratch space.
fn tally_frame(
    p: &Prepared<'_>,
    min_overlap: f64,
    pass: Pass,
    assigned: &mut Vec<bool>,
    mut on_tp: impl FnMut(f64),
) -> Tally {
    let dets = p.input.detections;
    assigned.clear();
    assigned.resize(dets.len(), false);
    let takes_part = |j: usize| {
        p.detections[j] != Role::Excluded
            && match pass {
                Pass::Scores => true,
                Pass::AtThreshold(t) => dets[j].score >= t,
            }
    };

    let mut tally = Tally::default();
    for (i, &truth_role) in p.truth.iter().enumerate() {
        if truth_role == Role::Excluded {
            continue;
        }
        let mut chosen: Option<usize> = None;
        // Only used by the threshold pass.
        let mut best_overlap = 0.0;
        let mut chosen_is_ignored = false;
        for j in 0..dets.len() {
            let overlap = p.input.overlap[j][i];
            if assigned[j] || !takes_part(j) || overlap <= min_overlap {
                continue;
            }
            match pass {
                Pass::Scores => {
                    if chosen.is_none_or(|c| dets[j].score > dets[c].score) {
                        chosen = Some(j);
                    }
                }
                Pass::AtThreshold(_) => match p.detections[j] {
                    Role::Counted if overlap > best_overlap || chosen_is_ignored => {
                        chosen = Some(j);
                        best_overlap = overlap;
                        chosen_is_ignored = false;
                    }
                    Role::Ignored if chosen.is_none() => {
                        chosen = Some(j);
                        chosen_is_ignored = true;
                    }
                    _ => {}
                },
            }
        }
        match chosen {
            None => {
                if truth_role == Role::Counted {
                    tally.fn_ += 1;
                }
            }
            Some(j) => {
                assigned[j] = true;
                if truth_role == Role::Counted && p.detections[j] == Role::Counted {
                    tally.tp += 1;
                    on_tp(dets[j].score);
                }
            }
        }
    }

    if let Pass::AtThreshold(t) = pass {
        tally.fp = (0..dets.len())
            .filter(|&j| p.detections[j] == Role::Counted && !assigned[j] && dets[j].score >= t)
            .count();
    }
    tally
}

/// The devkit's `getThresholds`: walking the true-positive scores from the highest, keep a
/// score whenever its recall is at least as close to the next 1/40 step as the following
/// score's would be (the last score is always kept).
fn score_thresholds(scores: &mut [f64], truth_count: usize) -> Vec<f64> {
    let mut thresholds = Vec::new();
    if truth_count == 0 {
        return thresholds;
    }
    scores.sort_by(|a, b| b.total_cmp(a));
    let n = truth_count as f64;
    let step = 1.0 / (SAMPLE_POINTS - 1) as f64;
    let mut current_recall = 0.0;
    for (i, &score) in scores.iter().enumerate() {
        let last = i + 1 == scores.len();
        let left = (i + 1) as f64 / n;
        let right = if last { left } else { (i + 2) as f64 / n };
        if !last && right - current_recall < current_recall - left {
            continue;
        }
        // At most one score per true positive and at most one per recall step; the length
        // check only guards against rounding in gigantic inputs.
        if thresholds.len() == SAMPLE_POINTS {
            break;
        }
        thresholds.push(score);
        current_recall += step;
    }
    thresholds
}

/// `a / b`, or 0 when `b` is 0.
fn ratio(a: usize, b: usize) -> f64 {
    if b == 0 {
        0.0
    } else {
        a as f64 / b as f64
    }
}

/// Checks the shape of frame `k`'s overlap matrix and that every number is finite.
fn validate_frame(k: usize, f: &FrameInput<'_>) -> Result<()> {
    let (n_det, n_truth) = (f.detections.len(), f.truth.len());
    if f.overlap.len() != n_det {
        return Err(Error::invalid(
            format!("overlap matrix of frame {k}"),
            format!(
                "{} rows for {n_det} detections (one row per detection)",
                f.overlap.len()
            ),
        ));
    }
    for (j, row) in f.overlap.iter().enumerate() {
        if row.len() != n_truth {
            return Err(Error::invalid(
                format!("overlap matrix of frame {k}"),
                format!(
                    "row {j} has {} entries for {n_truth} labelled objects",
                    row.len()
                ),
            ));
        }
        if let Some(i) = row.iter().position(|v| !v.is_finite()) {
            return Err(Error::invalid(
                format!("overlap of detection {j} with labelled object {i} in frame {k}"),
                format!("{} (must be finite)", row[i]),
            ));
        }
    }
    for (j, d) in f.detections.iter().enumerate() {
        for (name, v) in [("score", d.score), ("2-D box height", d.height_px)] {
            if !v.is_finite() {
                return Err(Error::invalid(
                    format!("{name} of detection {j} in frame {k}"),
                    format!("{v} (must be finite)"),
                ));
            }
        }
    }
    for (i, t) in f.truth.iter().enumerate() {
        for (name, v) in [("truncation", t.truncated), ("2-D box height", t.height_px)] {
            if !v.is_finite() {
                return Err(Error::invalid(
                    format!("{name} of labelled object {i} in frame {k}"),
                    format!("{v} (must be finite)"),
                ));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    /// A counted Car for every difficulty: visible, not truncated, 60 px high.
    fn car() -> TruthObject {
        TruthObject {
            class: TruthClass::Evaluated,
            occluded: 0,
            truncated: 0.0,
            height_px: 60.0,
        }
    }

    fn det(score: f64) -> Detection {
        Detection {
            evaluated_class: true,
            score,
            height_px: 60.0,
        }
    }

    /// One frame's owned truth, detections and overlap matrix.
    type OwnedFrame = (Vec<TruthObject>, Vec<Detection>, Vec<Vec<f64>>);

    /// Owned frame data; `frames` borrows it as inputs.
    struct Owned(Vec<OwnedFrame>);

    impl Owned {
        fn frames(&self) -> Vec<FrameInput<'_>> {
            self.0
                .iter()
                .map(|(t, d, o)| FrameInput {
                    truth: t,
                    detections: d,
                    overlap: o,
                })
                .collect()
        }

        /// `n` frames, each one car and one detection on it (overlap 0.9), scores 1 − i/100.
        fn perfect(n: usize) -> Owned {
            Owned(
                (0..n)
                    .map(|i| {
                        (
                            vec![car()],
                            vec![det(1.0 - i as f64 / 100.0)],
                            vec![vec![0.9]],
                        )
                    })
                    .collect(),
            )
        }
    }

    fn ap(o: &Owned, difficulty: Difficulty, min_overlap: f64) -> AveragePrecision {
        average_precision(&o.frames(), difficulty, min_overlap).unwrap()
    }

    #[test]
    fn single_match_fills_only_the_first_point() {
        // One counted object, one detection on it. TP scores [0.9], one object: the only
        // threshold is 0.9 (the last score is always kept). At 0.9: TP 1, FP 0 → p[0] = 1,
        // p[1..] = 0. AP_R11 = p[0] / 11 = 1/11; AP_R40 = (p[1] + … + p[40]) / 40 = 0.
        let o = Owned(vec![(vec![car()], vec![det(0.9)], vec![vec![0.8]])]);
        let a = ap(&o, Difficulty::Moderate, 0.7);
        assert_eq!(a.truth_count, 1);
        assert_eq!(a.thresholds, vec![0.9]);
        assert_eq!(a.precision[0], 1.0);
        assert_eq!(a.recall[0], 1.0);
        assert!(a.precision[1..].iter().all(|&p| p == 0.0));
        assert_relative_eq!(a.ap_r11, 1.0 / 11.0, epsilon = 1e-15);
        assert_eq!(a.ap_r40, 0.0);
    }

    #[test]
    fn perfect_detections_of_41_objects_give_one() {
        // n = 41 objects, TP scores s_0 > … > s_40. getThresholds with current recall
        // c = i/40 after i kept scores: left = (i+1)/41, right = (i+2)/41;
        // c − left = (i − 40)/1640 ≤ 0 < right − c = (80 − i)/1640, so no score is skipped:
        // 41 thresholds, each with TP = i+1, FP = 0 → precision 1 everywhere → both APs 1.
        let a = ap(&Owned::perfect(41), Difficulty::Easy, 0.7);
        assert_eq!(a.thresholds.len(), 41);
        assert_eq!(a.precision, [1.0; SAMPLE_POINTS]);
        assert_relative_eq!(a.ap_r40, 1.0, epsilon = 1e-12);
        assert_relative_eq!(a.ap_r11, 1.0, epsilon = 1e-12);
        assert_relative_eq!(a.recall[40], 1.0, epsilon = 1e-15);
        assert_relative_eq!(a.recall[0], 1.0 / 41.0, epsilon = 1e-15);
    }

    #[test]
    fn perfect_detections_of_40_objects_leave_the_last_point_empty() {
        // n = 40: as above no score is skipped, 40 thresholds → p[0..40] = 1, p[40] = 0.
        // AP_R40 = 39/40 (p[1..=39]); AP_R11 = 10/11 (p[0], p[4], …, p[36]; p[40] = 0).
        let a = ap(&Owned::perfect(40), Difficulty::Easy, 0.7);
        assert_eq!(a.thresholds.len(), 40);
        assert_relative_eq!(a.ap_r40, 39.0 / 40.0, epsilon = 1e-12);
        assert_relative_eq!(a.ap_r11, 10.0 / 11.0, epsilon = 1e-12);
    }

    #[test]
    fn hand_case_two_objects_three_detections() {
        // Frame: objects T1, T2; detections D1 (0.9, overlaps nothing: a FP scored highest),
        // D2 (0.8, IoU 0.8 with T1), D3 (0.7, IoU 0.6 with T2); minimum overlap 0.5.
        // First pass: T1 ← D2 (0.8), T2 ← D3 (0.7). TP scores [0.8, 0.7], n = 2.
        // Thresholds: i = 0: left 0.5, right 1.0, c = 0: 1.0 − 0 < 0 − 0.5 false → keep 0.8,
        //   c = 1/40; i = 1 is last → keep 0.7. Thresholds [0.8, 0.7].
        // At 0.8: D1, D2 take part. T1 ← D2 (TP), T2 unmatched (FN), D1 unassigned (FP).
        //   precision 1/2, recall 1/2.
        // At 0.7: all take part. TP 2 (D2, D3), FP 1 (D1), FN 0. precision 2/3, recall 1.
        // Interpolated: p[0] = max(1/2, 2/3) = 2/3, p[1] = 2/3, p[2..] = 0.
        // AP_R40 = p[1] / 40 = (2/3)/40 = 1/60. AP_R11 = p[0] / 11 = (2/3)/11 = 2/33.
        let o = Owned(vec![(
            vec![car(), car()],
            vec![det(0.9), det(0.8), det(0.7)],
            vec![vec![0.0, 0.0], vec![0.8, 0.0], vec![0.0, 0.6]],
        )]);
        let a = ap(&o, Difficulty::Hard, 0.5);
        assert_eq!(a.truth_count, 2);
        assert_eq!(a.thresholds, vec![0.8, 0.7]);
        assert_relative_eq!(a.precision[0], 2.0 / 3.0, epsilon = 1e-15);
        assert_relative_eq!(a.precision[1], 2.0 / 3.0, epsilon = 1e-15);
        assert!(a.precision[2..].iter().all(|&p| p == 0.0));
        assert_relative_eq!(a.recall[0], 0.5, epsilon = 1e-15);
        assert_relative_eq!(a.recall[1], 1.0, epsilon = 1e-15);
        assert_relative_eq!(a.ap_r40, 1.0 / 60.0, epsilon = 1e-15);
        assert_relative_eq!(a.ap_r11, 2.0 / 33.0, epsilon = 1e-15);
    }

    #[test]
    fn hand_case_skipped_scores_and_a_false_positive() {
        // 80 objects, each detected (scores s_i = 1 − i/100, i = 0..79), plus one FP scored
        // 0.995 in a frame of its own. TP scores s_0..s_79, n = 80.
        // getThresholds with k kept so far (c = k/40): skip i (not last) when
        // right − c < c − left ⇔ 2c > (2i+3)/80 ⇔ 4k > 2i + 3.
        // i=0,k=0: keep; i=1,k=1: 4 > 5 no → keep; i=2,k=2: 8 > 7 skip; i=3: 8 > 9 no → keep;
        // generally after i=1 the even i are skipped, the odd kept; i=78 (k=40): 160 > 159
        // skip; i=79 is last → keep. Thresholds s_0, s_1, s_3, …, s_77, s_79: 41 of them.
        // At s_0 = 1.0: TP 1, FP 0 → 1. At s_j (j odd): TP j+1, FP 1 (0.995 ≥ s_j) →
        // (j+1)/(j+2), rising with j to 80/81 at s_79.
        // Interpolated: p[0] = 1, p[1..=40] = 80/81.
        // AP_R40 = 80/81. AP_R11 = (1 + 10·80/81)/11 = 881/891.
        let mut o = Owned::perfect(80);
        o.0.push((vec![], vec![det(0.995)], vec![vec![]]));
        let a = ap(&o, Difficulty::Moderate, 0.7);
        assert_eq!(a.truth_count, 80);
        let expected: Vec<f64> = std::iter::once(0)
            .chain((1..=79).step_by(2))
            .map(|i| 1.0 - i as f64 / 100.0)
            .collect();
        assert_eq!(a.thresholds, expected);
        assert_eq!(a.precision[0], 1.0);
        for p in &a.precision[1..] {
            assert_relative_eq!(*p, 80.0 / 81.0, epsilon = 1e-15);
        }
        assert_relative_eq!(a.ap_r40, 80.0 / 81.0, epsilon = 1e-12);
        assert_relative_eq!(a.ap_r11, 881.0 / 891.0, epsilon = 1e-12);
    }

    #[test]
    fn overlap_equal_to_the_minimum_does_not_match() {
        // IoU exactly 0.5 at minimum 0.5: no TP, no threshold, AP 0. Just above: AP_R11 1/11.
        let at = Owned(vec![(vec![car()], vec![det(0.9)], vec![vec![0.5]])]);
        let a = ap(&at, Difficulty::Moderate, 0.5);
        assert!(a.thresholds.is_empty());
        assert_eq!((a.ap_r40, a.ap_r11), (0.0, 0.0));
        let above = Owned(vec![(vec![car()], vec![det(0.9)], vec![vec![0.5 + 1e-12]])]);
        let b = ap(&above, Difficulty::Moderate, 0.5);
        assert_relative_eq!(b.ap_r11, 1.0 / 11.0, epsilon = 1e-15);
    }

    #[test]
    fn neighbour_absorbs_a_detection() {
        // 41 perfect pairs (AP 1) plus a frame whose object is a Van (Neighbour) under a Car
        // detection scored 0.999 (above every threshold): it is absorbed, so no FP, AP stays 1.
        let mut o = Owned::perfect(41);
        let van = TruthObject {
            class: TruthClass::Neighbour,
            ..car()
        };
        o.0.push((vec![van], vec![det(0.999)], vec![vec![0.9]]));
        let a = ap(&o, Difficulty::Moderate, 0.7);
        assert_eq!(a.truth_count, 41);
        assert_relative_eq!(a.ap_r40, 1.0, epsilon = 1e-12);
        assert_relative_eq!(a.ap_r11, 1.0, epsilon = 1e-12);

        // Control: the same object of another class (say a Tram) absorbs nothing, so the
        // detection is a FP at every threshold it reaches: all but the first (s_0 = 1.0 >
        // 0.999). Raw precision: p[0] = 1/1, p[i] = (i+1)/(i+2) for i = 1..=40, rising to
        // 41/42; interpolated p[0] = 1, p[1..=40] = 41/42.
        // AP_R40 = 41/42; AP_R11 = (1 + 10·41/42)/11 = 452/462 = 226/231.
        let tram = TruthObject {
            class: TruthClass::Other,
            ..car()
        };
        o.0.last_mut().unwrap().0[0] = tram;
        let b = ap(&o, Difficulty::Moderate, 0.7);
        assert_eq!(b.truth_count, 41);
        assert_relative_eq!(b.ap_r40, 41.0 / 42.0, epsilon = 1e-12);
        assert_relative_eq!(b.ap_r11, 226.0 / 231.0, epsilon = 1e-12);
    }

    #[test]
    fn low_detection_is_neither_true_nor_false_positive() {
        // A 20 px Car detection (below 25 px) on nothing would be a FP scored above all;
        // it is ignored, so the 41 perfect pairs keep AP 1.
        let mut o = Owned::perfect(41);
        let low = Detection {
            height_px: 20.0,
            ..det(0.999)
        };
        o.0.push((vec![], vec![low], vec![vec![]]));
        let a = ap(&o, Difficulty::Moderate, 0.7);
        assert_relative_eq!(a.ap_r40, 1.0, epsilon = 1e-12);

        // A low detection (scored 0.999, above every threshold) that is the only one on a
        // counted object: the first pass pairs them (no TP), so the object adds no threshold;
        // at every threshold it is again taken by the ignored detection (the only candidate),
        // so it is no FN either.
        // 41 perfect pairs + this object: n = 42, TP scores s_0..s_40 (41 of them).
        // getThresholds: skip i (not last) when 2k/40 > (2i+3)/42 ⇔ 84k > 80i + 120 with
        // k = i until i = 31 (2604 > 2600 → skip); afterwards k = i − 1 and
        // 84(i−1) > 80i + 120 ⇔ i > 51 never; i = 40 is last. 40 thresholds, TP i+1, FP 0,
        // FN 0 at the last one → precision 1 at 0..40, 0 at 40 → AP_R40 = 39/40; recall at
        // the last threshold (s_40) = 41/(41+0) = 1.
        let mut o = Owned::perfect(41);
        let low = Detection {
            height_px: 20.0,
            ..det(0.999)
        };
        o.0.push((vec![car()], vec![low], vec![vec![0.9]]));
        let a = ap(&o, Difficulty::Moderate, 0.7);
        assert_eq!(a.truth_count, 42);
        assert_eq!(a.thresholds.len(), 40);
        assert_relative_eq!(a.ap_r40, 39.0 / 40.0, epsilon = 1e-12);
        assert_relative_eq!(a.recall[39], 1.0, epsilon = 1e-15);
    }

    #[test]
    fn easy_ignores_a_partly_occluded_object() {
        // 41 perfect pairs plus a partly occluded Car (occluded = 1) with a detection on it
        // scored 0.999. Easy (max occlusion 0): the object is ignored, absorbs the detection
        // (no FP) and is no FN: truth_count 41, AP 1.
        let mut o = Owned::perfect(41);
        let occluded = TruthObject {
            occluded: 1,
            ..car()
        };
        o.0.push((vec![occluded], vec![det(0.999)], vec![vec![0.9]]));
        let a = ap(&o, Difficulty::Easy, 0.7);
        assert_eq!(a.truth_count, 41);
        assert_relative_eq!(a.ap_r40, 1.0, epsilon = 1e-12);
        assert_relative_eq!(a.ap_r11, 1.0, epsilon = 1e-12);
        assert_relative_eq!(a.recall[40], 1.0, epsilon = 1e-15);

        // Moderate counts it: 42 objects all found. getThresholds (see the low-detection test
        // for n = 42) skips exactly one score of 42 → 41 thresholds, precision 1 → AP 1.
        let b = ap(&o, Difficulty::Moderate, 0.7);
        assert_eq!(b.truth_count, 42);
        assert_eq!(b.thresholds.len(), 41);
        assert_relative_eq!(b.ap_r40, 1.0, epsilon = 1e-12);
    }

    #[test]
    fn threshold_pass_prefers_largest_overlap() {
        // One object with detections A (0.9, IoU 0.6) and B (0.8, IoU 0.95), plus 41 perfect
        // pairs elsewhere scored s_i = 1 − i/100 (down to s_40 = 0.6).
        // First pass: the object takes A (highest score) → TP score 0.9; B stays free.
        // At any threshold ≤ 0.8 the object takes B (largest overlap) and A becomes a FP;
        // at thresholds in (0.8, 0.9] it takes A and B does not take part. So the curve has
        // a FP at low thresholds that the first pass did not see: AP_R40 < 1.
        let mut o = Owned::perfect(41);
        o.0.push((
            vec![car()],
            vec![det(0.9), det(0.8)],
            vec![vec![0.6], vec![0.95]],
        ));
        let a = ap(&o, Difficulty::Moderate, 0.5);
        assert_eq!(a.truth_count, 42);
        assert!(a.ap_r40 < 1.0);
        // The lowest threshold is s_40 = 0.6 ≤ 0.8: TP 42, FP 1 → raw precision 42/43, which
        // is also the interpolated value at the last threshold.
        let last = a.thresholds.len() - 1;
        assert_relative_eq!(a.precision[last], 42.0 / 43.0, epsilon = 1e-15);
        assert_relative_eq!(a.recall[last], 1.0, epsilon = 1e-15);
    }

    #[test]
    fn no_counted_objects_give_zero() {
        let o = Owned(vec![(vec![], vec![det(0.9)], vec![vec![]])]);
        let a = ap(&o, Difficulty::Hard, 0.5);
        assert_eq!(a.truth_count, 0);
        assert!(a.thresholds.is_empty());
        assert_eq!((a.ap_r40, a.ap_r11), (0.0, 0.0));
        let empty = average_precision(&[], Difficulty::Hard, 0.5).unwrap();
        assert_eq!(empty.ap_r40, 0.0);
    }

    fn message(e: Error) -> String {
        e.to_string()
    }

    #[test]
    fn rejects_wrong_overlap_shapes() {
        let rows = Owned(vec![
            (vec![car()], vec![det(0.9)], vec![vec![0.8]]),
            (vec![car()], vec![det(0.9), det(0.8)], vec![vec![0.8]]),
        ]);
        let e = message(average_precision(&rows.frames(), Difficulty::Easy, 0.7).unwrap_err());
        assert!(
            e.contains("frame 1") && e.contains("1 rows for 2 detections"),
            "{e}"
        );

        let cols = Owned(vec![(vec![car(), car()], vec![det(0.9)], vec![vec![0.8]])]);
        let e = message(average_precision(&cols.frames(), Difficulty::Easy, 0.7).unwrap_err());
        assert!(
            e.contains("frame 0") && e.contains("1 entries for 2"),
            "{e}"
        );
    }

    #[test]
    fn rejects_non_finite_numbers() {
        let nan_score = Owned(vec![(vec![car()], vec![det(f64::NAN)], vec![vec![0.8]])]);
        let e = average_precision(&nan_score.frames(), Difficulty::Easy, 0.7).unwrap_err();
        assert!(message(e).contains("score of detection 0 in frame 0"));

        let nan_overlap = Owned(vec![(vec![car()], vec![det(0.9)], vec![vec![f64::NAN]])]);
        assert!(average_precision(&nan_overlap.frames(), Difficulty::Easy, 0.7).is_err());

        let inf_height = Owned(vec![(
            vec![TruthObject {
                height_px: f64::INFINITY,
                ..car()
            }],
            vec![],
            vec![],
        )]);
        assert!(average_precision(&inf_height.frames(), Difficulty::Easy, 0.7).is_err());
    }

    #[test]
    fn rejects_min_overlap_outside_unit_interval() {
        let o = Owned::perfect(1);
        for bad in [0.0, -0.1, 1.5, f64::NAN] {
            let e = average_precision(&o.frames(), Difficulty::Easy, bad).unwrap_err();
            assert!(message(e).contains("minimum overlap"));
        }
        assert!(average_precision(&o.frames(), Difficulty::Easy, 1.0).is_ok());
    }

    #[test]
    fn difficulty_limits() {
        let limits: Vec<_> = Difficulty::ALL
            .iter()
            .map(|d| (d.min_height_px(), d.max_occlusion(), d.max_truncation()))
            .collect();
        assert_eq!(
            limits,
            vec![(40.0, 0, 0.15), (25.0, 1, 0.30), (25.0, 2, 0.50)]
        );
    }

    fn truth_strategy() -> impl Strategy<Value = TruthObject> {
        (0u8..3, 0u8..4, 0.0f64..0.6, 10.0f64..80.0).prop_map(|(c, occluded, truncated, h)| {
            TruthObject {
                class: [
                    TruthClass::Evaluated,
                    TruthClass::Neighbour,
                    TruthClass::Other,
                ][c as usize],
                occluded,
                truncated,
                height_px: h,
            }
        })
    }

    fn detection_strategy() -> impl Strategy<Value = Detection> {
        (prop::bool::weighted(0.8), 0.0f64..1.0, 10.0f64..80.0).prop_map(
            |(evaluated_class, score, height_px)| Detection {
                evaluated_class,
                score,
                height_px,
            },
        )
    }

    fn frame_strategy() -> impl Strategy<Value = OwnedFrame> {
        (0usize..5, 0usize..6).prop_flat_map(|(nt, nd)| {
            let overlap = prop_oneof![Just(0.0), 0.0f64..1.0];
            (
                prop::collection::vec(truth_strategy(), nt),
                prop::collection::vec(detection_strategy(), nd),
                prop::collection::vec(prop::collection::vec(overlap, nt), nd),
            )
        })
    }

    proptest! {
        #[test]
        fn ap_within_unit_interval_and_unmoved_by_a_lowest_stray_detection(
            frames in prop::collection::vec(frame_strategy(), 0..8),
            pick in any::<prop::sample::Index>(),
            difficulty in prop::sample::select(Difficulty::ALL.to_vec()),
            min_overlap in 0.1f64..0.9,
        ) {
            let mut owned = Owned(frames);
            let before = average_precision(&owned.frames(), difficulty, min_overlap).unwrap();
            for v in [before.ap_r40, before.ap_r11] {
                prop_assert!((0.0..=1.0).contains(&v), "AP {}", v);
            }
            for v in before.precision.iter().chain(&before.recall) {
                prop_assert!((0.0..=1.0).contains(v));
            }
            prop_assert!(before.thresholds.len() <= SAMPLE_POINTS);

            // A counted detection overlapping nothing, scored below every other one.
            let lowest = owned
                .0
                .iter()
                .flat_map(|f| f.1.iter().map(|d| d.score))
                .fold(0.0f64, f64::min);
            if owned.0.is_empty() {
                owned.0.push((vec![], vec![], vec![]));
            }
            let k = pick.index(owned.0.len());
            let frame = &mut owned.0[k];
            frame.1.push(det(lowest - 1.0));
            frame.2.push(vec![0.0; frame.0.len()]);
            let after = average_precision(&owned.frames(), difficulty, min_overlap).unwrap();
            prop_assert!(after.ap_r40 <= before.ap_r40, "{} > {}", after.ap_r40, before.ap_r40);
            prop_assert!(after.ap_r11 <= before.ap_r11);
        }
    }
}
