//! The drive tracker's road-user detector scored on single labelled scans (KITTI's 3-D object
//! benchmark layout, [`ObjectFrames`]): what it finds of the labelled cars and vans, by KITTI's
//! occlusion level and by range, how many of its car-like detections are real, and KITTI's
//! bird's-eye average precision for Car.
//!
//! Each frame runs the tracker's own detection ([`detect_objects`]: ground and walls removed,
//! clusters, oriented boxes, the one-frame class likelihood) with the tracking configuration the
//! user gives, so a change of the detector shows here exactly as the tracker will see it.
//! KITTI labels only what camera 2 sees, so only detections whose box centre appears in its
//! image count as false or enter the average precision; a labelled car whose visible part
//! lies in the image may be found by a detection whose box centre lies just outside it.
//!
//! Two views of the same detections:
//!
//! - **Recall and precision** as the tracking scores count them: a labelled car or van within
//!   [`ObjectEvalConfig::within`] of the sensor is found when a detection reported as a
//!   vehicle (Car, Van or Truck) has its box centre within [`ObjectEvalConfig::match_distance`]
//!   in bird's-eye view (nearest pairs first, each used once). A reported vehicle within range
//!   that matches nothing is a false detection, unless it lies on another labelled object (a
//!   truck, a tram, a cyclist, a car beyond the range: neither found nor false) or its centre
//!   appears inside a `DontCare` region of the image. The same recall counted with clusters
//!   of any class tells the segmentation's misses from the one-frame class's.
//! - **Average precision** ([`crate::metrics::detection_ap`]): every cluster in the image is a
//!   Car candidate scored by its one-frame probability of being a car or a van (under the
//!   default class prior), its overlap with a label the rotated bird's-eye IoU in the Velodyne
//!   frame (KITTI takes it in the camera's x–z plane, which differs by the calibration's small
//!   tilt), its 2-D height that of its projected box clipped to the image.
//!
//! Not for: tracks (see [`super::kitti_tracking_eval`]) or the detector itself (see
//! [`super::drive_tracking::detect`]).

use super::drive_tracking::detect::detect_objects;
use super::drive_tracking::TrackingConfig;
use crate::cloud::classes::{default_prior, ClassBelief, ClassModel, ObjectClass, CLASS_COUNT};
use crate::error::{Error, Result};
use crate::geometry::{iou_bev, Box3};
use crate::kitti::object::ObjectFrames;
use crate::kitti::tracking::IMAGE_SIZE;
use crate::kitti::{ObjectType, TrackingCalib, TrackingLabel};
use crate::metrics::detection_ap::{
    average_precision, AveragePrecision, Detection, Difficulty, FrameInput, TruthClass, TruthObject,
};
use crate::rng::stream;
use nalgebra::Point3;

/// What is scored and how.
#[derive(Clone, Debug)]
pub struct ObjectEvalConfig {
    /// The detector's configuration (its `clusters` and `planes` sections are used).
    pub tracking: TrackingConfig,
    /// Labelled cars and vans count for recall within this bird's-eye range of the sensor (m).
    pub within: f64,
    /// A detection finds a label when their box centres are this close in bird's-eye view (m).
    pub match_distance: f64,
    /// Seed of the segmentation's random draws (frame `k` draws from its own stream).
    pub seed: u64,
}

impl Default for ObjectEvalConfig {
    fn default() -> Self {
        ObjectEvalConfig {
            tracking: TrackingConfig::default(),
            within: 40.0,
            match_distance: 2.0,
            seed: 1,
        }
    }
}

/// One cluster of a frame as scored here (Velodyne frame).
#[derive(Clone, Debug, PartialEq)]
pub struct ScoredDetection {
    /// The box the tracker measures (the visible-face model's).
    pub bbox: Box3,
    /// The one-frame class the tracker reports.
    pub class: ObjectClass,
    /// Probability of a car or a van from this frame alone, under the default prior.
    pub car_score: f64,
    /// Height of the projected box in camera 2's image, clipped to it (pixels).
    pub height_px: f64,
    /// Points in the cluster.
    pub points: usize,
    /// Whether the box centre appears in camera 2's image.
    pub in_view: bool,
}

use crate::metrics::recall::match_nearest;
pub use crate::metrics::recall::{Tally, RANGE_BINS};

/// One average-precision figure.
#[derive(Clone, Debug, PartialEq)]
pub struct ApRow {
    /// The IoU a detection must exceed.
    pub min_iou: f64,
    /// KITTI's difficulty.
    pub difficulty: Difficulty,
    /// The figures.
    pub ap: AveragePrecision,
}

/// The scores over a set of frames.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ObjectFrameReport {
    /// Frames scored.
    pub frames: usize,
    /// Labelled cars and vans within range found, all occlusion levels.
    pub recall: Tally,
    /// The same found by a cluster of any class: what the segmentation finds, before the
    /// one-frame class decides whether it is reported as a vehicle.
    pub cluster_recall: Tally,
    /// The same by KITTI occlusion level 0 (fully visible), 1 (partly), 2 (largely), 3
    /// (unknown).
    pub recall_by_occlusion: [Tally; 4],
    /// The same by range, bins [`RANGE_BINS`].
    pub recall_by_range: [Tally; 4],
    /// Detections reported as vehicles within range that are real (hits) of those scored.
    pub precision: Tally,
    /// Bird's-eye average precision for Car at IoU 0.5 and 0.7, easy / moderate / hard.
    pub bev_ap: Vec<ApRow>,
    /// Every counted car or van that was not found, with what lay nearest to it.
    pub misses: Vec<Miss>,
}

/// A labelled car or van within range that no vehicle detection found.
#[derive(Clone, Debug, PartialEq)]
pub struct Miss {
    /// The frame.
    pub frame: usize,
    /// The label's type.
    pub object_type: ObjectType,
    /// KITTI's occlusion level of the label.
    pub occluded: i32,
    /// Bird's-eye range of the label's centre from the sensor (m).
    pub range: f64,
    /// The nearest detection, whatever its class: its bird's-eye centre distance (m), class
    /// and points.
    pub nearest: Option<(f64, ObjectClass, usize)>,
}

/// Whether a class is reported as a vehicle.
fn is_vehicle(c: ObjectClass) -> bool {
    matches!(c, ObjectClass::Car | ObjectClass::Van | ObjectClass::Truck)
}

/// The car-or-van probability of a cluster's class log-likelihoods: one frame's Bayes update
/// of the default prior.
fn car_probability(ll: &[f64; CLASS_COUNT]) -> Result<f64> {
    let mut belief = ClassBelief::new(default_prior())?;
    belief.update(ll, 0.0)?;
    Ok(belief.probability(ObjectClass::Car) + belief.probability(ObjectClass::Van))
}

/// Height in pixels of `b`'s projection into camera 2's image, clipped to the image; 0 when
/// no corner is in front of the camera.
fn image_height(b: &Box3, calib: &TrackingCalib) -> f64 {
    let vs: Vec<f64> = b
        .corners()
        .iter()
        .filter_map(|c| calib.project_to_image2(c))
        .map(|[_, v]| v.clamp(0.0, IMAGE_SIZE[1]))
        .collect();
    let lo = vs.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = vs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if vs.is_empty() {
        0.0
    } else {
        hi - lo
    }
}

/// The clusters of frame `k`, scored.
pub fn detect_object_frame(
    frames: &ObjectFrames,
    k: usize,
    calib: &TrackingCalib,
    config: &ObjectEvalConfig,
) -> Result<Vec<ScoredDetection>> {
    let cloud = frames.velodyne(k)?;
    let mut rng = stream(config.seed, k as u64);
    let found = detect_objects(&cloud, &config.tracking, &mut rng)?;
    let model = ClassModel::default();
    let mut out = Vec::new();
    for d in &found.clusters {
        let Some(shape) = &d.shape else { continue };
        out.push(ScoredDetection {
            in_view: calib.in_image2(&shape.bbox.center),
            bbox: shape.bbox,
            class: shape.class,
            car_score: car_probability(&model.log_likelihoods(&shape.features)?)?,
            height_px: image_height(&shape.bbox, calib),
            points: d.indices.len(),
        });
    }
    Ok(out)
}

/// One frame's labels in the Velodyne frame, `DontCare` regions apart.
struct FrameTruth {
    objects: Vec<(TrackingLabel, Box3)>,
    dont_care: Vec<[f64; 4]>,
}

fn frame_truth(labels: &[TrackingLabel], calib: &TrackingCalib) -> FrameTruth {
    let rect = calib.rect_from_velo();
    let mut t = FrameTruth {
        objects: Vec::new(),
        dont_care: Vec::new(),
    };
    for l in labels {
        if l.object_type == ObjectType::DontCare {
            t.dont_care.push(l.bbox);
        } else {
            t.objects.push((*l, l.to_velodyne(&rect).to_box3()));
        }
    }
    t
}

fn bev_range(p: &Point3<f64>) -> f64 {
    p.x.hypot(p.y)
}

fn is_car_or_van(t: ObjectType) -> bool {
    matches!(t, ObjectType::Car | ObjectType::Van)
}

/// Detections paired with labels whose bird's-eye centres are within `gate`, nearest pairs
/// first, each used once ([`match_nearest`]): the label of each detection and whether each
/// label was found.
fn match_centres(
    detections: &[&ScoredDetection],
    truth: &FrameTruth,
    gate: f64,
) -> (Vec<Option<usize>>, Vec<bool>) {
    let at: Vec<[f64; 2]> = detections
        .iter()
        .map(|d| [d.bbox.center.x, d.bbox.center.y])
        .collect();
    let labels: Vec<[f64; 2]> = truth
        .objects
        .iter()
        .map(|(_, b)| [b.center.x, b.center.y])
        .collect();
    match_nearest(&at, &labels, gate)
}

/// The recall and precision counts of one frame, added to `report`.
fn count_frame(
    detections: &[ScoredDetection],
    truth: &FrameTruth,
    calib: &TrackingCalib,
    config: &ObjectEvalConfig,
    report: &mut ObjectFrameReport,
) {
    let reported: Vec<&ScoredDetection> =
        detections.iter().filter(|d| is_vehicle(d.class)).collect();
    let (det_match, truth_found) = match_centres(&reported, truth, config.match_distance);
    let all: Vec<&ScoredDetection> = detections.iter().collect();
    let (_, truth_clustered) = match_centres(&all, truth, config.match_distance);
    let counted = |j: usize| {
        let (l, b) = &truth.objects[j];
        is_car_or_van(l.object_type) && bev_range(&b.center) <= config.within
    };
    for (j, (l, b)) in truth.objects.iter().enumerate() {
        if !counted(j) {
            continue;
        }
        let found = truth_found[j];
        report.cluster_recall.add(truth_clustered[j]);
        if !found {
            let nearest = detections
                .iter()
                .map(|d| {
                    let dist = (d.bbox.center.x - b.center.x).hypot(d.bbox.center.y - b.center.y);
                    (dist, d.class, d.points)
                })
                .min_by(|a, b| a.0.total_cmp(&b.0));
            report.misses.push(Miss {
                frame: l.frame,
                object_type: l.object_type,
                occluded: l.occluded,
                range: bev_range(&b.center),
                nearest,
            });
        }
        report.recall.add(found);
        report.recall_by_occlusion[l.occluded.clamp(0, 3) as usize].add(found);
        let r = bev_range(&b.center);
        if let Some(bin) = RANGE_BINS.windows(2).position(|w| r >= w[0] && r < w[1]) {
            report.recall_by_range[bin].add(found);
        }
    }
    for (i, d) in reported.iter().enumerate() {
        if !d.in_view || bev_range(&d.bbox.center) > config.within {
            continue;
        }
        match det_match[i] {
            Some(j) if counted(j) => report.precision.add(true),
            Some(_) => {}
            None => {
                let in_dont_care = calib
                    .project_to_image2(&d.bbox.center)
                    .is_some_and(|[u, v]| {
                        truth
                            .dont_care
                            .iter()
                            .any(|b| u >= b[0] && u <= b[2] && v >= b[1] && v <= b[3])
                    });
                if !in_dont_care {
                    report.precision.add(false);
                }
            }
        }
    }
}

/// One frame's input to the average precision of Car.
struct ApFrame {
    truth: Vec<TruthObject>,
    detections: Vec<Detection>,
    overlap: Vec<Vec<f64>>,
}

fn ap_frame(detections: &[ScoredDetection], truth: &FrameTruth) -> ApFrame {
    let detections: Vec<&ScoredDetection> = detections.iter().filter(|d| d.in_view).collect();
    let class = |t: ObjectType| match t {
        ObjectType::Car => TruthClass::Evaluated,
        ObjectType::Van => TruthClass::Neighbour,
        _ => TruthClass::Other,
    };
    ApFrame {
        truth: truth
            .objects
            .iter()
            .map(|(l, _)| TruthObject {
                class: class(l.object_type),
                occluded: l.occluded.clamp(0, 3) as u8,
                truncated: l.truncated,
                height_px: l.bbox[3] - l.bbox[1],
            })
            .collect(),
        detections: detections
            .iter()
            .map(|d| Detection {
                evaluated_class: true,
                score: d.car_score,
                height_px: d.height_px,
            })
            .collect(),
        overlap: detections
            .iter()
            .map(|d| {
                truth
                    .objects
                    .iter()
                    .map(|(_, b)| iou_bev(&d.bbox, b))
                    .collect()
            })
            .collect(),
    }
}

/// Scores detections already made against their frames' labels and calibrations (one entry a
/// frame, in any order).
pub fn score_object_frames(
    frames: &[(Vec<ScoredDetection>, Vec<TrackingLabel>, TrackingCalib)],
    config: &ObjectEvalConfig,
) -> Result<ObjectFrameReport> {
    if !(config.within > 0.0 && config.match_distance > 0.0) {
        return Err(Error::invalid(
            "object-frame scoring",
            format!(
                "range {} m and match distance {} m must be positive",
                config.within, config.match_distance
            ),
        ));
    }
    let mut report = ObjectFrameReport {
        frames: frames.len(),
        ..ObjectFrameReport::default()
    };
    let mut ap_frames = Vec::with_capacity(frames.len());
    for (detections, labels, calib) in frames {
        let truth = frame_truth(labels, calib);
        count_frame(detections, &truth, calib, config, &mut report);
        ap_frames.push(ap_frame(detections, &truth));
    }
    let inputs: Vec<FrameInput> = ap_frames
        .iter()
        .map(|f| FrameInput {
            truth: &f.truth,
            detections: &f.detections,
            overlap: &f.overlap,
        })
        .collect();
    for min_iou in [0.5, 0.7] {
        for difficulty in [Difficulty::Easy, Difficulty::Moderate, Difficulty::Hard] {
            let ap = average_precision(&inputs, difficulty, min_iou)?;
            report.bev_ap.push(ApRow {
                min_iou,
                difficulty,
                ap,
            });
        }
    }
    Ok(report)
}

/// Runs the detector on frames `ks` of `frames` (every frame when `None`) and scores it.
/// `progress` is called after each frame.
pub fn evaluate_object_frames(
    frames: &ObjectFrames,
    ks: Option<&[usize]>,
    config: &ObjectEvalConfig,
    mut progress: impl FnMut(usize),
) -> Result<ObjectFrameReport> {
    let all;
    let ks = match ks {
        Some(ks) => ks,
        None => {
            all = frames.frames()?;
            &all
        }
    };
    if ks.is_empty() {
        return Err(Error::invalid(
            format!("object folder {}", frames.root().display()),
            "has no frame to score (no velodyne/NNNNNN.bin)",
        ));
    }
    let mut scored = Vec::with_capacity(ks.len());
    for &k in ks {
        let calib = frames.calib(k)?;
        let labels = frames.labels(k)?;
        let detections = detect_object_frame(frames, k, &calib, config)?;
        scored.push((detections, labels, calib));
        progress(k);
    }
    score_object_frames(&scored, config)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    /// A calibration whose cameras look along the Velodyne's x axis from its origin (camera
    /// x = −y, y = −z, z = x), focal length 700 px, principal point (600, 180).
    fn calib() -> TrackingCalib {
        let p = "700 0 600 0 0 700 180 0 0 0 1 0";
        let text = format!(
            "P0: {p}\nP1: {p}\nP2: {p}\nP3: {p}\nR0_rect: 1 0 0 0 1 0 0 0 1\n\
             Tr_velo_to_cam: 0 -1 0 0 0 0 -1 0 1 0 0 0\nTr_imu_to_velo: 1 0 0 0 0 1 0 0 0 0 1 0\n"
        );
        TrackingCalib::parse(Path::new("calib.txt"), &text).unwrap()
    }

    /// A label of `t` whose box (1.5 m high, 1.8 wide, 4 long, along x) is centred at the
    /// Velodyne point (x, y, −1).
    fn label(t: ObjectType, x: f64, y: f64, occluded: i32) -> TrackingLabel {
        let h = 1.5;
        TrackingLabel {
            frame: 0,
            track_id: -1,
            object_type: t,
            truncated: 0.0,
            occluded,
            alpha: 0.0,
            bbox: [500.0, 100.0, 700.0, 250.0],
            dimensions: [h, 1.8, 4.0],
            // Camera (−y, −z, x) of the centre, moved down to the bottom face (+h/2 in y).
            location: [-y, 1.0 + h / 2.0, x],
            // Along the camera's −z … its x axis: rotation_y = −yaw − π/2 with yaw 0.
            rotation_y: -std::f64::consts::FRAC_PI_2,
            score: None,
        }
    }

    fn dont_care(bbox: [f64; 4]) -> TrackingLabel {
        TrackingLabel {
            object_type: ObjectType::DontCare,
            occluded: -1,
            bbox,
            ..label(ObjectType::DontCare, 0.0, 0.0, 0)
        }
    }

    fn detection(class: ObjectClass, x: f64, y: f64, score: f64) -> ScoredDetection {
        ScoredDetection {
            bbox: Box3::new(Point3::new(x, y, -1.0), [4.0, 1.8, 1.5], 0.0),
            class,
            car_score: score,
            height_px: 100.0,
            points: 100,
            in_view: calib().in_image2(&Point3::new(x, y, -1.0)),
        }
    }

    #[test]
    fn a_label_box_comes_back_where_it_was_placed() {
        let b = label(ObjectType::Car, 8.0, 1.0, 0)
            .to_velodyne(&calib().rect_from_velo())
            .to_box3();
        assert!(
            (b.center - Point3::new(8.0, 1.0, -1.0)).norm() < 1e-12,
            "{b:?}"
        );
        assert!(b.yaw.sin().abs() < 1e-12, "{}", b.yaw);
    }

    #[test]
    fn recall_and_precision_count_as_documented() {
        let labels = vec![
            label(ObjectType::Car, 8.0, 0.0, 0), // found: range 0–10, visible
            label(ObjectType::Van, 25.0, 3.0, 2), // missed: only a pedestrian on it
            label(ObjectType::Truck, 15.0, -4.0, 1), // a vehicle on it: neither
            label(ObjectType::Car, 45.0, 0.0, 0), // beyond 40 m: not counted
            label(ObjectType::Car, 4.0, 3.0, 0), // in view, found from just outside it
            // Around the pixel of a point 30 m ahead, 6 m left and 1 m down:
            // (600 − 700·6/30, 180 + 700·1/30) = (460, 203.3).
            dont_care([420.0, 170.0, 500.0, 230.0]),
        ];
        let detections = vec![
            detection(ObjectClass::Car, 8.9, 0.3, 0.9),
            detection(ObjectClass::Pedestrian, 25.2, 3.0, 0.1),
            detection(ObjectClass::Truck, 15.5, -4.0, 0.5),
            detection(ObjectClass::Car, 30.0, 6.0, 0.8), // in the DontCare region
            detection(ObjectClass::Van, 20.0, -8.0, 0.7), // false
            detection(ObjectClass::Car, 44.0, 0.0, 0.6), // beyond range: not scored
            detection(ObjectClass::Car, 2.0, 9.0, 0.9),  // out of view, on nothing: not scored
            // Out of view (y/x = 0.94 > 600/700) and 0.8 m from the last label.
            detection(ObjectClass::Car, 3.2, 3.0, 0.9),
        ];
        let config = ObjectEvalConfig::default();
        let r = score_object_frames(&[(detections, labels, calib())], &config).unwrap();
        assert_eq!(r.recall, Tally { hits: 2, total: 3 });
        // The pedestrian cluster on the van finds it as a cluster, not as a vehicle.
        assert_eq!(r.cluster_recall, Tally { hits: 3, total: 3 });
        assert_eq!(r.recall_by_occlusion[0], Tally { hits: 2, total: 2 });
        assert_eq!(r.recall_by_occlusion[2], Tally { hits: 0, total: 1 });
        assert_eq!(r.recall_by_range[0], Tally { hits: 2, total: 2 });
        assert_eq!(r.recall_by_range[2], Tally { hits: 0, total: 1 });
        assert_eq!(r.precision, Tally { hits: 1, total: 2 });
        assert_eq!(r.bev_ap.len(), 6);
    }

    #[test]
    fn the_average_precision_sees_each_detection_at_its_overlap() {
        let labels = vec![
            label(ObjectType::Car, 8.0, 0.0, 0),
            label(ObjectType::Car, 20.0, 5.0, 0),
        ];
        let detections = vec![
            detection(ObjectClass::Car, 8.0, 0.0, 0.9),
            // IoU of two 4 × 1.8 footprints shifted 1 m along their length: 3/5 = 0.6.
            detection(ObjectClass::Car, 21.0, 5.0, 0.8),
        ];
        let r = score_object_frames(
            &[(detections, labels, calib())],
            &ObjectEvalConfig::default(),
        )
        .unwrap();
        // KITTI's thresholds are the true positives' scores: both at IoU 0.5, the first only
        // at 0.7. With fewer than 41 cars the devkit credits each threshold with one of its
        // 40 recall steps (the first, recall 0, left out of AP_R40): 1/40 and 0, and one of
        // the 11 points (1/11) either way.
        for row in &r.bev_ap {
            let (thresholds, r40) = if row.min_iou < 0.6 {
                (vec![0.9, 0.8], 1.0 / 40.0)
            } else {
                (vec![0.9], 0.0)
            };
            let what = format!("IoU {} {:?}: {:?}", row.min_iou, row.difficulty, row.ap);
            assert_eq!(row.ap.thresholds, thresholds, "{what}");
            assert!((row.ap.ap_r40 - r40).abs() < 1e-12, "{what}");
            assert!((row.ap.ap_r11 - 1.0 / 11.0).abs() < 1e-12, "{what}");
            assert_eq!(row.ap.truth_count, 2, "{what}");
        }
    }

    #[test]
    fn equal_evidence_gives_the_prior_share_of_cars_and_vans() {
        // The prior's road-user counts (KITTI's label statistics), road users at 1/2.
        let want = 0.5 * (28_742.0 + 2_914.0) / (28_742.0 + 2_914.0 + 1_094.0 + 4_709.0 + 1_627.0);
        assert!((car_probability(&[-3.0; CLASS_COUNT]).unwrap() - want).abs() < 1e-12);
    }

    #[test]
    fn a_box_ahead_projects_to_its_height_in_pixels() {
        // 0.25–1.75 m below the sensor, 10–12 m ahead: from the near bottom edge,
        // 180 + 700·1.75/10, up to the far top edge, 180 + 700·0.25/12.
        let b = Box3::new(Point3::new(11.0, 0.0, -1.0), [2.0, 1.0, 1.5], 0.0);
        let h = image_height(&b, &calib());
        assert!(
            (h - (700.0 * 1.75 / 10.0 - 700.0 * 0.25 / 12.0)).abs() < 1e-9,
            "{h}"
        );
        let behind = Box3::new(Point3::new(-11.0, 0.0, -1.0), [2.0, 1.0, 1.5], 0.0);
        assert_eq!(image_height(&behind, &calib()), 0.0);
    }

    #[test]
    fn a_bad_range_is_an_error() {
        let config = ObjectEvalConfig {
            within: 0.0,
            ..ObjectEvalConfig::default()
        };
        assert!(score_object_frames(&[], &config).is_err());
    }
}
