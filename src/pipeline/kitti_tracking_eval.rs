//! KITTI's tracking evaluation rules on `label_02` files: which truth and tracker objects
//! count, per class, before the scores of [`crate::metrics::tracking`] are computed.
//!
//! Per frame and class (Car, or Pedestrian), following TrackEval's `Kitti2DBox`
//! preprocessing, and by the same rules for two groups KITTI's benchmark does not score
//! (Car+Van, and every road user whatever its type; see [`EvalClass`]):
//! 1. Truth objects of the class and of its distractor class (Van for Car, Person_sitting for
//!    Pedestrian; the groups have none) take part; tracker objects of the class only (of any
//!    type the group holds); negative ids are dropped.
//! 2. Truth and tracker objects are matched one-to-one (Hungarian, similarity at least the
//!    match threshold). A tracker object matched to a truth object that does not count — a
//!    distractor, occluded beyond level 2, truncated at all (truncation level > 0), or outside
//!    the optional range / camera view — is removed.
//! 3. An unmatched tracker object is removed when more than half of its image box lies in a
//!    `DontCare` region, when its image box is at most 25 px tall (2-D mode only) or when it
//!    lies outside the optional range / camera view.
//! 4. Only the truth objects that count are scored.
//!
//! Similarities ([`Similarity`]): `Iou2d` is the IoU of the image boxes (TrackEval's KITTI
//! 2-D box benchmark, match threshold 0.5); `BevDistance { max }` is max(0, 1 − d/max) with d
//! the bird's-eye distance of the box positions (camera x and z); a CLEAR / identity match
//! needs d < max (threshold 10⁻⁶: within max·(1 − 10⁻⁶)), so `max = 2` is "centre distance
//! within 2 m" and HOTA's α sweeps d from 1.9 m down to 0.1 m; `Iou3d` is the 3-D IoU of the
//! oriented boxes ([`crate::geometry::iou_3d`], the camera's y axis vertical), match threshold
//! 0.25. 3-D results whose image boxes are empty (zero area) are never inside a `DontCare`
//! region.
//!
//! **Recall by occlusion and range.** For the Car+Van group the evaluation also splits the
//! recall of the scored truth objects within 40 m of the camera (x–z plane, as the range limit)
//! by KITTI occlusion level and by 10 m range bin ([`RecallBreakdown`]), counted per frame: a
//! truth object is found when CLEAR's own matching (see
//! [`crate::metrics::tracking::clear_matches`]) pairs it with a tracker object of the group.
//! Objects occluded beyond `max_occlusion` (level 3, unknown, by KITTI's rules) are not scored
//! and so not in it.
//!
//! Not for: the metrics themselves, reading files, or scoring `track`'s JSON output (see
//! [`super::drive_evaluation`]).

use crate::error::{Error, Result};
use crate::geometry::{iou_3d, Box3};
use crate::kitti::{ObjectType, TrackingCalib, TrackingLabel};
use crate::metrics::recall::RecallBreakdown;
use crate::metrics::tracking::{
    clear_matches, evaluate, ScoreConfig, TrackingFrame, TrackingScores,
};
use nalgebra::Point3;
use serde::{Deserialize, Serialize};

const EPS: f64 = f64::EPSILON;

/// How alike a truth and a tracker box are, in [0, 1].
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "mode", rename_all = "snake_case")]
pub enum Similarity {
    /// IoU of the image boxes of camera 2.
    Iou2d,
    /// max(0, 1 − d/max), d the distance of the box positions in the camera's x–z plane (m).
    BevDistance {
        /// Distance at which the similarity reaches 0 (m).
        max: f64,
    },
    /// 3-D IoU of the oriented boxes, the camera's y axis taken as vertical.
    Iou3d,
}

impl Similarity {
    /// The mode's match threshold for CLEAR, identity and distractor matching: 0.5 for image
    /// IoU (TrackEval's), 10⁻⁶ for the bird's-eye distance (any distance below `max`).
    pub fn default_threshold(&self) -> f64 {
        match self {
            Similarity::Iou2d => 0.5,
            Similarity::BevDistance { .. } => 1e-6,
            Similarity::Iou3d => 0.25,
        }
    }

    /// The similarity of a truth and a tracker label.
    pub fn between(&self, gt: &TrackingLabel, tr: &TrackingLabel) -> f64 {
        let s = match *self {
            Similarity::Iou2d => box_iou(&gt.bbox, &tr.bbox),
            Similarity::BevDistance { max } => {
                let d = (gt.location[0] - tr.location[0]).hypot(gt.location[2] - tr.location[2]);
                (1.0 - d / max).max(0.0)
            }
            Similarity::Iou3d => iou_3d(&upright_box(gt), &upright_box(tr)),
        };
        if s.is_finite() {
            s.clamp(0.0, 1.0)
        } else {
            0.0
        }
    }

    fn check(&self) -> Result<()> {
        match *self {
            Similarity::Iou2d | Similarity::Iou3d => Ok(()),
            Similarity::BevDistance { max } => {
                crate::error::ensure_positive("BEV distance max", max)
            }
        }
    }
}

/// A label's 3-D box in a z-up frame made from the rectified camera frame by (x, y, z) →
/// (z, −x, −y): forward, left, up. The label's location is its bottom-face centre.
pub fn upright_box(l: &TrackingLabel) -> Box3 {
    let [h, w, len] = l.dimensions;
    let [x, y, z] = l.location;
    let (s, c) = l.rotation_y.sin_cos();
    // The length axis (cos ry, 0, −sin ry) in the camera frame is (−sin ry, −cos ry, 0) here.
    Box3::new(Point3::new(z, -x, h / 2.0 - y), [len, w, h], (-c).atan2(-s))
}

/// IoU of two image boxes (left, top, right, bottom), TrackEval's way: 0 when either box or
/// the union has no area.
pub fn box_iou(a: &[f64; 4], b: &[f64; 4]) -> f64 {
    let inter = overlap(a, b);
    let (aa, ab) = (area(a), area(b));
    let union = aa + ab - inter;
    if aa <= EPS || ab <= EPS || union <= EPS {
        0.0
    } else {
        inter / union
    }
}

/// The part of box `a`'s area that lies in box `b` (0 when `a` has no area).
pub fn box_ioa(a: &[f64; 4], b: &[f64; 4]) -> f64 {
    let aa = area(a);
    if aa > EPS {
        overlap(a, b) / aa
    } else {
        0.0
    }
}

fn area(a: &[f64; 4]) -> f64 {
    (a[2] - a[0]) * (a[3] - a[1])
}

fn overlap(a: &[f64; 4], b: &[f64; 4]) -> f64 {
    (a[2].min(b[2]) - a[0].max(b[0])).max(0.0) * (a[3].min(b[3]) - a[1].max(b[1])).max(0.0)
}

/// What is scored: KITTI's tracking benchmark classes (Car, Pedestrian) and two groups of
/// labelled types that it does not score but a road-user tracker is judged by.
///
/// A group has no distractor: every truth object of its types counts, and a tracker object of
/// any of its types may match any of them (a van reported as a car is found in `CarVan`, a
/// cyclist reported as a pedestrian in `RoadUser`).
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EvalClass {
    /// Cars; Vans are distractors.
    Car,
    /// Pedestrians; sitting persons are distractors.
    Pedestrian,
    /// Cars and vans together.
    CarVan,
    /// Every labelled road user: Car, Van, Truck, Pedestrian, Person_sitting, Cyclist, Tram.
    RoadUser,
}

impl EvalClass {
    /// KITTI's benchmark classes, in KITTI's order.
    pub const ALL: [EvalClass; 2] = [EvalClass::Car, EvalClass::Pedestrian];

    /// Everything [`evaluate_kitti_tracking`] scores: KITTI's classes, then the two groups.
    pub const SCORED: [EvalClass; 4] = [
        EvalClass::Car,
        EvalClass::Pedestrian,
        EvalClass::CarVan,
        EvalClass::RoadUser,
    ];

    /// The name printed in tables.
    pub fn name(self) -> &'static str {
        match self {
            EvalClass::Car => "Car",
            EvalClass::Pedestrian => "Pedestrian",
            EvalClass::CarVan => "Car+Van",
            EvalClass::RoadUser => "Road users",
        }
    }

    /// Whether truth and tracker objects of type `t` belong to the class.
    pub fn holds(self, t: ObjectType) -> bool {
        match self {
            EvalClass::Car => t == ObjectType::Car,
            EvalClass::Pedestrian => t == ObjectType::Pedestrian,
            EvalClass::CarVan => matches!(t, ObjectType::Car | ObjectType::Van),
            // Every labelled object but `Misc` (and `DontCare`, a region, not an object).
            EvalClass::RoadUser => !matches!(t, ObjectType::Misc | ObjectType::DontCare),
        }
    }

    /// Whether truth objects of type `t` are distractors: a tracker object matched to one is
    /// neither rewarded nor punished.
    pub fn is_distractor(self, t: ObjectType) -> bool {
        match self {
            EvalClass::Car => t == ObjectType::Van,
            EvalClass::Pedestrian => t == ObjectType::PersonSitting,
            EvalClass::CarVan | EvalClass::RoadUser => false,
        }
    }
}

/// The evaluation rules.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct KittiEvalConfig {
    /// The similarity of a box pair.
    pub similarity: Similarity,
    /// Least similarity of a CLEAR / identity / distractor match.
    pub match_threshold: f64,
    /// Truth occluded beyond this level does not count (KITTI: 2).
    pub max_occlusion: i32,
    /// Truth truncated beyond this level (the integer part of the field) does not count
    /// (KITTI: 0).
    pub max_truncation: i64,
    /// Unmatched tracker boxes at most this tall in the image (px) are removed (KITTI 2-D:
    /// 25; `None` for 3-D results, whose image boxes may be empty).
    pub min_height_px: Option<f64>,
    /// Unmatched tracker boxes with more than this part of their image box inside a
    /// `DontCare` region are removed (KITTI: 0.5).
    pub dontcare_overlap: f64,
    /// Only objects within this horizontal distance of the camera (m, x–z plane) count.
    pub max_range: Option<f64>,
}

impl KittiEvalConfig {
    /// TrackEval's KITTI 2-D box evaluation.
    pub fn iou_2d() -> Self {
        KittiEvalConfig {
            similarity: Similarity::Iou2d,
            match_threshold: 0.5,
            max_occlusion: 2,
            max_truncation: 0,
            min_height_px: Some(25.0),
            dontcare_overlap: 0.5,
            max_range: None,
        }
    }

    /// Bird's-eye centre distance, matches within `max` metres.
    pub fn bev(max: f64) -> Self {
        let similarity = Similarity::BevDistance { max };
        KittiEvalConfig {
            similarity,
            match_threshold: similarity.default_threshold(),
            min_height_px: None,
            ..Self::iou_2d()
        }
    }

    /// 3-D IoU of the oriented boxes, a match at IoU ≥ 0.25.
    pub fn iou_3d() -> Self {
        KittiEvalConfig {
            similarity: Similarity::Iou3d,
            match_threshold: Similarity::Iou3d.default_threshold(),
            min_height_px: None,
            ..Self::iou_2d()
        }
    }

    fn check(&self) -> Result<()> {
        self.similarity.check()?;
        if !(self.match_threshold > 0.0 && self.match_threshold <= 1.0) {
            return Err(Error::invalid(
                "match threshold",
                format!("{} (must lie in (0, 1])", self.match_threshold),
            ));
        }
        if let Some(r) = self.max_range {
            crate::error::ensure_positive("range limit", r)?;
        }
        Ok(())
    }
}

/// Scores of one class.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ClassScores {
    /// The class.
    pub class: EvalClass,
    /// Truth objects scored (summed over frames).
    pub truth_objects: usize,
    /// Tracker objects scored (summed over frames), after the removals.
    pub tracker_objects: usize,
    /// Tracker objects of the class removed by the rules.
    pub tracker_removed: usize,
    /// HOTA, CLEAR and identity scores.
    pub scores: TrackingScores,
    /// Car+Van only: the scored truth objects within 40 m of the camera (horizontally, as
    /// `max_range`), found or not by CLEAR's matching, in all, by occlusion level and by range
    /// (see the module notes).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub recall_breakdown: Option<RecallBreakdown>,
}

/// A whole sequence's evaluation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct KittiTrackingEvaluation {
    /// The rules.
    pub config: KittiEvalConfig,
    /// Frames scored (0 .. frames).
    pub frames: usize,
    /// Whether only what camera 2 sees was scored.
    pub camera_view: bool,
    /// Result lines with a frame number beyond the scored frames (not scored).
    pub results_outside_frames: usize,
    /// Per class.
    pub classes: Vec<ClassScores>,
}

/// Where objects count: the range limit and, given a calibration, camera 2's view (the box
/// centre projects into the image).
struct Region<'a> {
    max_range: Option<f64>,
    view: Option<(&'a TrackingCalib, nalgebra::Isometry3<f64>)>,
}

impl Region<'_> {
    fn contains(&self, l: &TrackingLabel) -> bool {
        let in_range = self
            .max_range
            .is_none_or(|r| l.location[0].hypot(l.location[2]) <= r);
        in_range
            && self
                .view
                .as_ref()
                .is_none_or(|(calib, rfv)| calib.in_image2(&l.to_velodyne(rfv).center))
    }
}

/// The frames of one class after KITTI's rules (see the module notes), ready for
/// [`crate::metrics::tracking::evaluate`]; also the number of tracker objects removed.
pub fn class_frames(
    truth: &[TrackingLabel],
    results: &[TrackingLabel],
    class: EvalClass,
    frames: usize,
    config: &KittiEvalConfig,
    camera_view: Option<&TrackingCalib>,
) -> Result<(Vec<TrackingFrame>, usize)> {
    let (f, removed, _) = scored_frames(truth, results, class, frames, config, camera_view)?;
    Ok((f, removed))
}

/// The scored truth labels of one frame, in the order of its [`TrackingFrame::gt_ids`].
type ScoredTruth<'a> = Vec<&'a TrackingLabel>;

/// [`class_frames`], also returning the scored truth labels of each frame.
fn scored_frames<'a>(
    truth: &'a [TrackingLabel],
    results: &[TrackingLabel],
    class: EvalClass,
    frames: usize,
    config: &KittiEvalConfig,
    camera_view: Option<&TrackingCalib>,
) -> Result<(Vec<TrackingFrame>, usize, Vec<ScoredTruth<'a>>)> {
    config.check()?;
    let region = Region {
        max_range: config.max_range,
        view: camera_view.map(|c| (c, c.rect_from_velo())),
    };
    let mut gt_by_frame: Vec<Vec<&TrackingLabel>> = vec![Vec::new(); frames];
    let mut dontcare: Vec<Vec<[f64; 4]>> = vec![Vec::new(); frames];
    for l in truth.iter().filter(|l| l.frame < frames) {
        if l.object_type == ObjectType::DontCare {
            dontcare[l.frame].push(l.bbox);
        } else if l.track_id >= 0
            && (class.holds(l.object_type) || class.is_distractor(l.object_type))
        {
            gt_by_frame[l.frame].push(l);
        }
    }
    let mut tr_by_frame: Vec<Vec<&TrackingLabel>> = vec![Vec::new(); frames];
    for l in results.iter().filter(|l| l.frame < frames) {
        if l.track_id >= 0 && class.holds(l.object_type) {
            tr_by_frame[l.frame].push(l);
        }
    }
    let counts = |l: &TrackingLabel| {
        class.holds(l.object_type)
            && l.occluded <= config.max_occlusion
            && (l.truncated.trunc() as i64) <= config.max_truncation
            && region.contains(l)
    };
    let mut out = Vec::with_capacity(frames);
    let mut scored = Vec::with_capacity(frames);
    let mut removed_total = 0;
    for (k, (gts, trs)) in gt_by_frame.iter().zip(&tr_by_frame).enumerate() {
        let (g, t) = (gts.len(), trs.len());
        let sim: Vec<f64> = gts
            .iter()
            .flat_map(|a| trs.iter().map(|b| config.similarity.between(a, b)))
            .collect();
        let gt_counts: Vec<bool> = gts.iter().map(|l| counts(l)).collect();
        let mut removed = vec![false; t];
        let mut matched = vec![false; t];
        if g > 0 && t > 0 {
            let score: Vec<f64> = sim
                .iter()
                .map(|&s| {
                    if s < config.match_threshold - EPS {
                        0.0
                    } else {
                        s
                    }
                })
                .collect();
            for (i, j) in crate::metrics::tracking::max_assignment(&score, g, t) {
                if score[i * t + j] > EPS {
                    matched[j] = true;
                    removed[j] = !gt_counts[i];
                }
            }
        }
        for (j, l) in trs.iter().enumerate() {
            if matched[j] {
                continue;
            }
            let b = &l.bbox;
            let too_small = config.min_height_px.is_some_and(|h| b[3] - b[1] <= h + EPS);
            let ignored = dontcare[k]
                .iter()
                .any(|d| box_ioa(b, d) > config.dontcare_overlap + EPS);
            removed[j] = too_small || ignored || !region.contains(l);
        }
        removed_total += removed.iter().filter(|&&r| r).count();
        let keep_g: Vec<usize> = (0..g).filter(|&i| gt_counts[i]).collect();
        let keep_t: Vec<usize> = (0..t).filter(|&j| !removed[j]).collect();
        let similarity = keep_g
            .iter()
            .flat_map(|&i| keep_t.iter().map(move |&j| (i, j)))
            .map(|(i, j)| sim[i * t + j])
            .collect();
        let frame = TrackingFrame::new(
            keep_g.iter().map(|&i| gts[i].track_id).collect(),
            keep_t.iter().map(|&j| trs[j].track_id).collect(),
            similarity,
        )
        .map_err(|e| Error::invalid(format!("frame {k}, class {class:?}"), e.to_string()))?;
        out.push(frame);
        scored.push(keep_g.iter().map(|&i| gts[i]).collect());
    }
    Ok((out, removed_total, scored))
}

/// The recall breakdown of scored truth labels (`scored`, per frame in the frames' truth
/// order) from CLEAR's matching of `frames` at `threshold`: a label within 40 m of the camera
/// (x–z plane) counts, found when matched.
fn recall_breakdown(
    frames: &[TrackingFrame],
    scored: &[ScoredTruth],
    threshold: f64,
) -> Result<RecallBreakdown> {
    let matched = clear_matches(frames, threshold)?;
    let mut r = RecallBreakdown::default();
    for (labels, found) in scored.iter().zip(&matched) {
        for (l, &f) in labels.iter().zip(found) {
            r.add(l.occluded, l.location[0].hypot(l.location[2]), f);
        }
    }
    Ok(r)
}

/// Scores `results` against `truth` over frames 0 .. `frames`, per class of
/// [`EvalClass::SCORED`], with KITTI's rules;
/// `camera_view` (a calibration) limits both to what camera 2 sees.
pub fn evaluate_kitti_tracking(
    truth: &[TrackingLabel],
    results: &[TrackingLabel],
    frames: usize,
    config: &KittiEvalConfig,
    camera_view: Option<&TrackingCalib>,
) -> Result<KittiTrackingEvaluation> {
    let score_config = ScoreConfig {
        clear_threshold: config.match_threshold,
        identity_threshold: config.match_threshold,
    };
    let mut classes = Vec::new();
    for class in EvalClass::SCORED {
        let (f, removed, scored) =
            scored_frames(truth, results, class, frames, config, camera_view)?;
        let recall_breakdown = if class == EvalClass::CarVan {
            Some(recall_breakdown(&f, &scored, config.match_threshold)?)
        } else {
            None
        };
        classes.push(ClassScores {
            class,
            truth_objects: f.iter().map(|f| f.gt_ids.len()).sum(),
            tracker_objects: f.iter().map(|f| f.tracker_ids.len()).sum(),
            tracker_removed: removed,
            scores: evaluate(&f, &score_config)?,
            recall_breakdown,
        });
    }
    Ok(KittiTrackingEvaluation {
        config: *config,
        frames,
        camera_view: camera_view.is_some(),
        results_outside_frames: results.iter().filter(|l| l.frame >= frames).count(),
        classes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::recall::Tally;

    fn label(
        frame: usize,
        id: i64,
        t: ObjectType,
        bbox: [f64; 4],
        x: f64,
        z: f64,
    ) -> TrackingLabel {
        TrackingLabel {
            frame,
            track_id: id,
            object_type: t,
            truncated: 0.0,
            occluded: 0,
            alpha: 0.0,
            bbox,
            dimensions: [1.5, 1.6, 4.0],
            location: [x, 1.6, z],
            rotation_y: 0.0,
            score: None,
        }
    }

    const B: [f64; 4] = [100.0, 100.0, 200.0, 200.0];

    fn car(frame: usize, id: i64, x: f64, z: f64) -> TrackingLabel {
        label(frame, id, ObjectType::Car, B, x, z)
    }

    fn class(e: &KittiTrackingEvaluation, c: EvalClass) -> &ClassScores {
        e.classes.iter().find(|s| s.class == c).unwrap()
    }

    #[test]
    fn iou_and_ioa_by_hand() {
        // Two 10 × 10 boxes overlapping in a 5 × 10 strip: IoU 50 / 150, IoA 1/2.
        let a = [0.0, 0.0, 10.0, 10.0];
        let b = [5.0, 0.0, 15.0, 10.0];
        assert!((box_iou(&a, &b) - 1.0 / 3.0).abs() < 1e-15);
        assert!((box_ioa(&a, &b) - 0.5).abs() < 1e-15);
        assert_eq!(box_iou(&a, &[0.0, 0.0, 0.0, 10.0]), 0.0);
        assert_eq!(box_ioa(&[3.0, 3.0, 3.0, 3.0], &a), 0.0);
    }

    #[test]
    fn bev_shift_gives_hand_computed_loca_and_motp() {
        // Two cars over three frames, every tracker box moved by (0.33, 0.44) m: d = 0.55 m,
        // similarity 1 − 0.55/2 = 0.725 everywhere.
        let truth: Vec<_> = (0..3)
            .flat_map(|f| [car(f, 1, 0.0, 10.0), car(f, 2, 5.0, 20.0)])
            .collect();
        let results: Vec<_> = truth
            .iter()
            .map(|l| {
                let mut r = *l;
                r.location[0] += 0.33;
                r.location[2] += 0.44;
                r.track_id += 10;
                r
            })
            .collect();
        let e =
            evaluate_kitti_tracking(&truth, &results, 3, &KittiEvalConfig::bev(2.0), None).unwrap();
        let s = &class(&e, EvalClass::Car).scores;
        assert!((s.clear.motp - 0.725).abs() < 1e-12);
        assert!((s.clear.mota - 1.0).abs() < 1e-12);
        // α = 0.05 … 0.70 (14 values) match with LocA 0.725; α = 0.75 … 0.95 (5) match
        // nothing and have LocA 1.
        assert!((s.hota.loc_a - (14.0 * 0.725 + 5.0) / 19.0).abs() < 1e-12);
        assert!((s.hota.det_a - 14.0 / 19.0).abs() < 1e-12);
        assert!((s.hota.hota - 14.0 / 19.0).abs() < 1e-12);
        assert_eq!(s.identity.idtp, 6);
        let p = &class(&e, EvalClass::Pedestrian).scores;
        assert_eq!(p.clear.tp + p.clear.fp + p.clear.fn_count, 0);
    }

    #[test]
    fn iou_3d_by_hand() {
        // 2 × 2 × 2 m cubes one metre apart along the camera's x: overlap 1 × 2 × 2 = 4 m³,
        // union 8 + 8 − 4 = 12 m³.
        let mut a = car(0, 1, 0.0, 10.0);
        a.dimensions = [2.0, 2.0, 2.0];
        let mut b = a;
        b.location[0] += 1.0;
        assert!((Similarity::Iou3d.between(&a, &b) - 1.0 / 3.0).abs() < 1e-12);
        // The same shift along the camera's y (vertical): half the height overlaps.
        let mut c = a;
        c.location[1] += 1.0;
        assert!((Similarity::Iou3d.between(&a, &c) - 1.0 / 3.0).abs() < 1e-12);
        // A 4 × 2 footprint turned by a half turn is the same box; by a quarter turn about
        // the same centre the footprints share 2 × 2 of 8 + 8 − 4 m².
        let mut d = a;
        d.dimensions = [2.0, 2.0, 4.0];
        let mut e = d;
        e.rotation_y = std::f64::consts::PI;
        assert!((Similarity::Iou3d.between(&d, &e) - 1.0).abs() < 1e-12);
        e.rotation_y = std::f64::consts::FRAC_PI_2;
        assert!((Similarity::Iou3d.between(&d, &e) - 1.0 / 3.0).abs() < 1e-12);
        // The box stands on its location: its centre is h/2 above it (camera y down).
        let u = upright_box(&d);
        assert!((u.center.z - (1.0 - 1.6)).abs() < 1e-12);
        assert!((u.center.x - 10.0).abs() < 1e-12 && u.center.y.abs() < 1e-12);
    }

    #[test]
    fn bev_match_needs_distance_below_max() {
        let truth = vec![car(0, 1, 0.0, 10.0)];
        let near = vec![car(0, 5, 1.99, 10.0)];
        let far = vec![car(0, 5, 2.01, 10.0)];
        let cfg = KittiEvalConfig::bev(2.0);
        let e = evaluate_kitti_tracking(&truth, &near, 1, &cfg, None).unwrap();
        assert_eq!(class(&e, EvalClass::Car).scores.clear.tp, 1);
        let e = evaluate_kitti_tracking(&truth, &far, 1, &cfg, None).unwrap();
        let c = &class(&e, EvalClass::Car).scores.clear;
        assert_eq!((c.tp, c.fn_count, c.fp), (0, 1, 1));
    }

    #[test]
    fn distractors_dontcare_small_boxes_and_range_remove_tracker_boxes() {
        let mut truth = vec![
            label(0, 1, ObjectType::Van, B, 0.0, 10.0),
            label(
                0,
                -1,
                ObjectType::DontCare,
                [500.0, 100.0, 700.0, 300.0],
                -10.0,
                -1.0,
            ),
            car(0, 2, 0.0, 60.0),
        ];
        truth[2].bbox = [300.0, 100.0, 400.0, 200.0];
        let mut truncated = car(0, 3, 0.0, 30.0);
        truncated.bbox = [800.0, 100.0, 900.0, 200.0];
        truncated.truncated = 1.0;
        truth.push(truncated);
        let results = vec![
            car(0, 10, 0.0, 10.0), // matches the Van: removed
            label(
                0,
                11,
                ObjectType::Car,
                [550.0, 150.0, 650.0, 250.0],
                9.0,
                9.0,
            ), // in DontCare
            label(0, 12, ObjectType::Car, [0.0, 0.0, 50.0, 20.0], 20.0, 20.0), // 20 px tall
            label(
                0,
                13,
                ObjectType::Car,
                [300.0, 100.0, 400.0, 200.0],
                0.0,
                60.0,
            ), // truth 2
            label(
                0,
                14,
                ObjectType::Car,
                [800.0, 100.0, 900.0, 200.0],
                0.0,
                30.0,
            ), // truncated
            label(
                0,
                15,
                ObjectType::Car,
                [900.0, 100.0, 1000.0, 200.0],
                9.0,
                30.0,
            ), // a FP
        ];
        let cfg = KittiEvalConfig::iou_2d();
        let e = evaluate_kitti_tracking(&truth, &results, 1, &cfg, None).unwrap();
        let c = class(&e, EvalClass::Car);
        assert_eq!(
            (c.truth_objects, c.tracker_objects, c.tracker_removed),
            (1, 2, 4)
        );
        assert_eq!((c.scores.clear.tp, c.scores.clear.fp), (1, 1));
        // With a 40 m range the truth at 60 m stops counting, and so does its match.
        let cfg = KittiEvalConfig {
            max_range: Some(40.0),
            ..cfg
        };
        let e = evaluate_kitti_tracking(&truth, &results, 1, &cfg, None).unwrap();
        let c = class(&e, EvalClass::Car);
        assert_eq!(
            (c.truth_objects, c.tracker_objects, c.tracker_removed),
            (0, 1, 5)
        );
    }

    #[test]
    fn the_groups_score_every_type_they_hold_whatever_the_reported_type() {
        // A van, a cyclist and a sitting person; the results: a car on the van, a pedestrian on
        // the cyclist, a cyclist on the sitting person and a car where nothing is.
        let truth = vec![
            label(0, 1, ObjectType::Van, B, 0.0, 10.0),
            label(0, 2, ObjectType::Cyclist, B, 5.0, 10.0),
            label(0, 3, ObjectType::PersonSitting, B, -5.0, 10.0),
        ];
        let results = vec![
            label(0, 10, ObjectType::Car, B, 0.5, 10.0),
            label(0, 11, ObjectType::Pedestrian, B, 5.0, 10.5),
            label(0, 12, ObjectType::Cyclist, B, -5.0, 10.0),
            label(0, 13, ObjectType::Car, B, 0.0, 30.0),
        ];
        let e =
            evaluate_kitti_tracking(&truth, &results, 1, &KittiEvalConfig::bev(2.0), None).unwrap();
        let counts = |c: EvalClass| {
            let s = class(&e, c);
            let cl = &s.scores.clear;
            (
                s.truth_objects,
                s.tracker_objects,
                cl.tp,
                cl.fp,
                cl.fn_count,
            )
        };
        // Car: the van is a distractor, so the car on it is removed; the other car is false.
        assert_eq!(counts(EvalClass::Car), (0, 1, 0, 1, 0));
        // Pedestrian: the sitting person is a distractor, but only pedestrian reports take
        // part, and the one on the cyclist matches nothing of the class.
        assert_eq!(counts(EvalClass::Pedestrian), (0, 1, 0, 1, 0));
        // Car+Van: the van is found by the car on it; the far car is false.
        assert_eq!(counts(EvalClass::CarVan), (1, 2, 1, 1, 0));
        // Every road user: three found, whatever their reported types, one false.
        assert_eq!(counts(EvalClass::RoadUser), (3, 4, 3, 1, 0));
        let r = &class(&e, EvalClass::RoadUser).scores.clear;
        assert!((r.mota - (1.0 - 1.0 / 3.0)).abs() < 1e-12);
        assert!((r.precision - 0.75).abs() < 1e-12 && (r.recall - 1.0).abs() < 1e-12);
        let names: Vec<_> = e.classes.iter().map(|c| c.class.name()).collect();
        assert_eq!(names, ["Car", "Pedestrian", "Car+Van", "Road users"]);
    }

    #[test]
    fn car_van_recall_splits_by_occlusion_and_range() {
        // Frame 0: a visible car at 5 m (found), a largely occluded van at 25 m (missed), a
        // partly occluded car at 45 m (beyond 40 m) and a car of unknown occlusion (not
        // scored). Frame 1: the visible car again, now missed (the tracker lies 3 m off).
        let mut van = label(0, 2, ObjectType::Van, B, 0.0, 25.0);
        van.occluded = 2;
        let mut far = car(0, 3, 0.0, 45.0);
        far.occluded = 1;
        let mut unknown = car(0, 4, 10.0, 10.0);
        unknown.occluded = 3;
        let truth = vec![car(0, 1, 3.0, 4.0), van, far, unknown, car(1, 1, 3.0, 4.0)];
        let results = vec![car(0, 10, 3.0, 4.5), car(1, 10, 3.0, 7.0)];
        let e =
            evaluate_kitti_tracking(&truth, &results, 2, &KittiEvalConfig::bev(2.0), None).unwrap();
        assert!(class(&e, EvalClass::Car).recall_breakdown.is_none());
        let r = class(&e, EvalClass::CarVan)
            .recall_breakdown
            .clone()
            .unwrap();
        assert_eq!(r.recall, Tally { hits: 1, total: 3 });
        assert_eq!(r.by_occlusion[0], Tally { hits: 1, total: 2 });
        assert_eq!(r.by_occlusion[2], Tally { hits: 0, total: 1 });
        assert_eq!(r.by_occlusion[1], Tally::default());
        // The car is 5 m away (3, 4 in the camera's x–z plane), the van 25 m.
        assert_eq!(r.by_range[0], Tally { hits: 1, total: 2 });
        assert_eq!(r.by_range[2], Tally { hits: 0, total: 1 });
    }

    #[test]
    fn results_beyond_the_frames_are_counted_not_scored() {
        let truth = vec![car(0, 1, 0.0, 10.0)];
        let results = vec![car(0, 1, 0.0, 10.0), car(7, 1, 0.0, 10.0)];
        let e =
            evaluate_kitti_tracking(&truth, &results, 1, &KittiEvalConfig::iou_2d(), None).unwrap();
        assert_eq!(e.results_outside_frames, 1);
        assert!((class(&e, EvalClass::Car).scores.hota.hota - 1.0).abs() < 1e-12);
    }

    #[test]
    fn duplicate_tracker_ids_and_bad_config_are_errors() {
        let truth = vec![car(0, 1, 0.0, 10.0)];
        let results = vec![car(0, 4, 0.0, 10.0), car(0, 4, 5.0, 10.0)];
        let cfg = KittiEvalConfig::bev(2.0);
        let err = evaluate_kitti_tracking(&truth, &results, 1, &cfg, None).unwrap_err();
        assert!(err.to_string().contains("frame 0"), "{err}");
        assert!(evaluate_kitti_tracking(&truth, &[], 1, &KittiEvalConfig::bev(0.0), None).is_err());
    }
}
