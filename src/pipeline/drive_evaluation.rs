//! Scores the output of a drive's tracking run ([`DriveTracks`]) against ground truth: the
//! cluster tracks by OSPA and GOSPA (per frame and averaged) and label switches, against the
//! objects of a simulated street ([`StreetTruth`]), the tracklets of a KITTI raw drive
//! ([`Tracklets`]) or the labels of a KITTI tracking sequence ([`TrackingLabel`]); the wall tracks of a simulated street by the angle between their normals
//! and the truth wall's and the distance of their centres from its plane.
//!
//! Distances are horizontal (x, y of the world frame): a cluster's centroid is the mean of the
//! points the lidar sees, which lie on the object's near faces, while the truth gives the box
//! centre; the two differ by up to half the object's length whatever the tracker does, and
//! mostly in the horizontal plane. Vertical offsets would add the sensor-height bias of
//! partially seen objects, which says nothing about tracking.
//!
//! **Cars and vans by occlusion and range.** Against labels with occlusion levels (a simulated
//! street's truth, a tracking sequence's labels) the evaluation also reports the recall of the
//! counted cars and vans within 40 m by KITTI occlusion level and range ([`car_van_recall`]):
//! this evaluation has no CLEAR matching, so a vehicle is found when a cluster track reported
//! as a car or van lies within the OSPA cut-off of it, pairs taken nearest first, one to one.
//!
//! Not for: producing the tracks (see [`super::drive_tracking`]) or the plane prediction
//! between frames (see [`super::plane_prediction`]).

use super::drive_tracking::DriveTracks;
use crate::error::{Error, Result};
use crate::kitti::ObjectType;
use crate::kitti::{TrackingLabel, Tracklets, VelodyneBox};
use crate::metrics::recall::{match_nearest, RecallBreakdown};
use crate::metrics::{gospa, ospa, percentile, LabelConsistency, LabelStats};
use crate::recording::{Recording, RecordingLabels};
use crate::sim::street::{ObjectState, ObjectTruth, StreetTruth};
use nalgebra::{Isometry3, Point3, Vector3};

/// One truth object in one frame: an identity and its horizontal position (world frame of the
/// tracking output, metres).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct TruthObject {
    /// Stable identity across frames.
    pub id: u64,
    /// x, y (m).
    pub position: [f64; 2],
}

/// Truth objects per frame, indexed by the drive's frame number.
pub type TruthFrames = Vec<Vec<TruthObject>>;

/// The cars and pedestrians of a simulated street, per frame, in the world frame of the
/// tracking output (the first Velodyne frame of the drive). An object counts in a frame only
/// when at least `min_points` lidar points hit it there and its centre is within `max_range`
/// (horizontally) of the sensor: what the sensor cannot see, or the tracker is set not to
/// look at, no tracker can report.
pub fn street_object_truth(truth: &StreetTruth, min_points: usize, max_range: f64) -> TruthFrames {
    let mut frames: TruthFrames = vec![Vec::new(); truth.frames.len()];
    for c in counted_street_states(truth, min_points, max_range) {
        frames[c.state.frame].push(TruthObject {
            id: c.object.id as u64,
            position: c.position,
        });
    }
    frames
}

/// One object of a simulated street in one frame that counts ([`counted_street_states`]).
struct CountedState<'a> {
    object: &'a ObjectTruth,
    state: &'a ObjectState,
    /// Box centre x, y in the world frame of the tracking output (m).
    position: [f64; 2],
    /// Horizontal distance from the sensor (m).
    range: f64,
}

/// The states of a simulated street's objects that count in [`street_object_truth`]: at least
/// `min_points` lidar points, the centre within `max_range` of the sensor, a frame of the
/// truth.
fn counted_street_states(
    truth: &StreetTruth,
    min_points: usize,
    max_range: f64,
) -> impl Iterator<Item = CountedState<'_>> {
    let drive_from_world = truth.world_from_drive.to_isometry().inverse();
    truth.objects.iter().flat_map(move |object| {
        object.states.iter().filter_map(move |state| {
            if state.points < min_points || state.frame >= truth.frames.len() {
                return None;
            }
            let [x, y, z] = state.position;
            let sensor = truth.frames[state.frame].velodyne_pose.translation;
            let range = (x - sensor[0]).hypot(y - sensor[1]);
            if range > max_range {
                return None;
            }
            let centre = drive_from_world * Point3::new(x, y, z + object.size[2] / 2.0);
            Some(CountedState {
                object,
                state,
                position: [centre.x, centre.y],
                range,
            })
        })
    })
}

/// The tracklet boxes of a KITTI raw drive, per frame, moved into the world frame of the
/// tracking output with the drive's Velodyne poses (`RawDrive::poses`, one per frame).
/// Frames beyond the poses are left empty.
pub fn tracklet_truth(tracklets: &Tracklets, poses: &[Isometry3<f64>]) -> TruthFrames {
    (0..poses.len())
        .map(|k| {
            tracklets
                .objects_at(k)
                .iter()
                .map(|o| {
                    let c = poses[k] * o.center();
                    TruthObject {
                        id: o.id as u64,
                        position: [c.x, c.y],
                    }
                })
                .collect()
        })
        .collect()
}

/// The objects of KITTI tracking labels (`label_02`, `DontCare` regions left out), per frame,
/// moved into the Velodyne frame with `rect_from_velo` (the sequence's
/// [`TrackingCalib::rect_from_velo`](crate::kitti::TrackingCalib::rect_from_velo)) and then
/// into the world frame of the tracking output with the sequence's Velodyne poses (one per
/// frame). An object counts only when `keep` accepts its box in the Velodyne frame (a range
/// limit, the camera's view). KITTI's labels cover the front camera's view only, so tracks of
/// objects beside or behind the vehicle count as false unless the caller drops them too. Frames
/// beyond the poses are left out; the identity is the track id.
pub fn label_truth(
    labels: &[TrackingLabel],
    rect_from_velo: &Isometry3<f64>,
    poses: &[Isometry3<f64>],
    keep: impl Fn(&VelodyneBox) -> bool,
) -> TruthFrames {
    let mut frames: TruthFrames = vec![Vec::new(); poses.len()];
    for (l, _, c) in kept_labels(labels, rect_from_velo, poses, keep) {
        if l.is_object() {
            frames[l.frame].push(TruthObject {
                id: l.track_id as u64,
                position: [c.x, c.y],
            });
        }
    }
    frames
}

/// The labels of [`label_truth`] that lie in a frame of `poses`, have a track id and whose
/// Velodyne-frame box `keep` accepts: each with that box and its centre in the world frame.
fn kept_labels<'a>(
    labels: &'a [TrackingLabel],
    rect_from_velo: &'a Isometry3<f64>,
    poses: &'a [Isometry3<f64>],
    keep: impl Fn(&VelodyneBox) -> bool + 'a,
) -> impl Iterator<Item = (&'a TrackingLabel, VelodyneBox, Point3<f64>)> + 'a {
    labels.iter().filter_map(move |l| {
        if l.frame >= poses.len() || l.track_id < 0 {
            return None;
        }
        let b = l.to_velodyne(rect_from_velo);
        if !keep(&b) {
            return None;
        }
        let c = poses[l.frame] * b.center;
        Some((l, b, c))
    })
}

/// Drops from every frame of `tracks` the cluster tracks that `keep` refuses (given the
/// position in the sensor frame of that frame), e.g. those outside a camera's view when the
/// truth covers that view only.
pub fn retain_clusters(tracks: &mut DriveTracks, keep: impl Fn(&[f64; 3]) -> bool) {
    for f in &mut tracks.frames {
        f.clusters.retain(|c| keep(&c.position_sensor));
    }
}

/// OSPA / GOSPA settings.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ClusterEvaluationConfig {
    /// Cut-off c (m).
    pub cutoff: f64,
    /// Order p.
    pub order: f64,
}

impl Default for ClusterEvaluationConfig {
    /// c = 3 m (larger than the half-length of a car, the largest bias between a visible-surface
    /// centroid and the box centre), p = 1.
    fn default() -> Self {
        ClusterEvaluationConfig {
            cutoff: 3.0,
            order: 1.0,
        }
    }
}

/// Scores of one frame.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FrameScore {
    /// Frame number.
    pub frame: usize,
    /// Truth objects counted.
    pub truth: usize,
    /// Confirmed cluster tracks.
    pub estimates: usize,
    /// OSPA distance (m).
    pub ospa: f64,
    /// Its localisation part (m).
    pub ospa_localisation: f64,
    /// Its cardinality part (m).
    pub ospa_cardinality: f64,
    /// GOSPA distance (m, α = 2).
    pub gospa: f64,
    /// Truth objects left unpaired by GOSPA.
    pub missed: usize,
    /// Tracks left unpaired by GOSPA.
    pub false_tracks: usize,
}

/// Scores of a whole drive.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ClusterEvaluation {
    /// Settings used.
    pub config: ClusterEvaluationConfig,
    /// Per frame.
    pub frames: Vec<FrameScore>,
    /// Mean OSPA over the frames (m).
    pub mean_ospa: f64,
    /// Mean GOSPA over the frames (m).
    pub mean_gospa: f64,
    /// Label statistics (a switch is a truth object paired, within c, with another label than
    /// the last time).
    pub labels: LabelStats,
}

/// Scores the confirmed cluster tracks of `tracks` against `truth` (indexed by frame number;
/// frames of `tracks` beyond `truth` are an error: the truth does not describe them).
pub fn evaluate_clusters(
    tracks: &DriveTracks,
    truth: &[Vec<TruthObject>],
    config: &ClusterEvaluationConfig,
) -> Result<ClusterEvaluation> {
    if tracks.frames.is_empty() {
        return Err(Error::invalid(
            "tracking output",
            "has no frames to evaluate",
        ));
    }
    let mut labels = LabelConsistency::new(config.cutoff)?;
    let mut frames = Vec::with_capacity(tracks.frames.len());
    for f in &tracks.frames {
        let Some(objects) = truth.get(f.frame) else {
            return Err(Error::invalid(
                format!("tracking output frame {}", f.frame),
                format!("the truth has only {} frames", truth.len()),
            ));
        };
        let x: Vec<[f64; 2]> = objects.iter().map(|o| o.position).collect();
        let y: Vec<[f64; 2]> = f
            .clusters
            .iter()
            .map(|c| [c.position_world[0], c.position_world[1]])
            .collect();
        let o = ospa(&x, &y, config.cutoff, config.order)?;
        let g = gospa(&x, &y, config.cutoff, config.order)?;
        let truth_ids: Vec<(u64, [f64; 2])> = objects.iter().map(|o| (o.id, o.position)).collect();
        let estimates: Vec<_> = f
            .clusters
            .iter()
            .zip(&y)
            .map(|(c, p)| (c.label, *p))
            .collect();
        labels.add_step(&truth_ids, &estimates)?;
        frames.push(FrameScore {
            frame: f.frame,
            truth: x.len(),
            estimates: y.len(),
            ospa: o.distance,
            ospa_localisation: o.localisation,
            ospa_cardinality: o.cardinality,
            gospa: g.distance,
            missed: g.n_missed,
            false_tracks: g.n_false,
        });
    }
    let n = frames.len() as f64;
    Ok(ClusterEvaluation {
        config: *config,
        mean_ospa: frames.iter().map(|f| f.ospa).sum::<f64>() / n,
        mean_gospa: frames.iter().map(|f| f.gospa).sum::<f64>() / n,
        frames,
        labels: labels.finish(),
    })
}

/// Accuracy of the wall tracks against the walls of a simulated street.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct WallEvaluation {
    /// Confirmed wall reports with a rectangle (over all frames).
    pub reports: usize,
    /// Reports within 2° and 0.5 m of a truth wall.
    pub matched: usize,
    /// Median angle between a report's normal and its closest truth wall's (degrees).
    pub median_normal_angle_deg: f64,
    /// 90th percentile of that angle (degrees).
    pub p90_normal_angle_deg: f64,
    /// Median distance of a report's rectangle centre from its truth wall's plane (m).
    pub median_offset_m: f64,
    /// 90th percentile of that distance (m).
    pub p90_offset_m: f64,
    /// Distinct truth walls matched at least once.
    pub walls_matched: usize,
}

/// What [`evaluate_labels`] and [`evaluate_recording`] count and how.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct EvaluationOptions {
    /// OSPA / GOSPA settings.
    pub clusters: ClusterEvaluationConfig,
    /// A simulated object counts in a frame only with at least this many lidar points.
    pub min_points: usize,
    /// Simulated and tracking-labelled objects count only within this horizontal range of
    /// the sensor (m); tracklets count wherever they are.
    pub max_range: f64,
    /// Score only what camera 2 sees — labelled objects and cluster tracks whose centre
    /// appears in its image — as KITTI's tracking labels cover only that view (needs
    /// [`RecordingLabels::Camera`]).
    pub camera_view: bool,
}

impl Default for EvaluationOptions {
    /// The default OSPA settings, 15 points, 40 m (the tracker's default cluster range), the
    /// whole view.
    fn default() -> Self {
        EvaluationOptions {
            clusters: ClusterEvaluationConfig::default(),
            min_points: 15,
            max_range: 40.0,
            camera_view: false,
        }
    }
}

/// The scores of a tracking run against labels.
#[derive(Clone, Debug, PartialEq)]
pub struct Evaluation {
    /// The cluster tracks.
    pub clusters: ClusterEvaluation,
    /// The wall tracks, when the labels have walls (a simulated street).
    pub walls: Option<WallEvaluation>,
    /// Recall of the cars and vans within 40 m by occlusion level and range
    /// ([`car_van_recall`]), when the labels have occlusion levels (a simulated street's
    /// truth, a tracking sequence's labels).
    pub car_van_recall: Option<RecallBreakdown>,
}

/// A labelled car or van in one frame, for [`car_van_recall`].
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct LabelledVehicle {
    /// x, y in the world frame of the tracking output (m).
    pub position: [f64; 2],
    /// KITTI occlusion level.
    pub occluded: i32,
    /// Horizontal distance from the sensor (m).
    pub range: f64,
}

/// The cars and vans (parked or moving) of a simulated street that count in
/// [`street_object_truth`] (`min_points`, `max_range`), per frame, with the truth's occlusion
/// levels.
pub fn street_vehicles(
    truth: &StreetTruth,
    min_points: usize,
    max_range: f64,
) -> Vec<Vec<LabelledVehicle>> {
    use crate::sim::street::ObjectKind;
    let mut frames = vec![Vec::new(); truth.frames.len()];
    for c in counted_street_states(truth, min_points, max_range) {
        if matches!(
            c.object.kind,
            ObjectKind::Car | ObjectKind::ParkedCar | ObjectKind::Van | ObjectKind::ParkedVan
        ) {
            frames[c.state.frame].push(LabelledVehicle {
                position: c.position,
                occluded: c.state.occluded,
                range: c.range,
            });
        }
    }
    frames
}

/// The cars and vans of KITTI tracking labels that `keep` accepts (as [`label_truth`]), per
/// frame, in the world frame of the tracking output, with their labelled occlusion levels.
pub fn label_vehicles(
    labels: &[TrackingLabel],
    rect_from_velo: &Isometry3<f64>,
    poses: &[Isometry3<f64>],
    keep: impl Fn(&VelodyneBox) -> bool,
) -> Vec<Vec<LabelledVehicle>> {
    let mut frames = vec![Vec::new(); poses.len()];
    for (l, b, c) in kept_labels(labels, rect_from_velo, poses, keep) {
        if matches!(l.object_type, ObjectType::Car | ObjectType::Van) {
            frames[l.frame].push(LabelledVehicle {
                position: [c.x, c.y],
                occluded: l.occluded,
                range: b.center.x.hypot(b.center.y),
            });
        }
    }
    frames
}

/// Recall of labelled cars and vans (`vehicles`, indexed by frame number) within 40 m by
/// occlusion level and range, counted per frame of `tracks`: a vehicle is found when a
/// confirmed cluster track reported as `Car` or `Van` is paired with it by a one-to-one
/// nearest matching within `gate` metres (horizontal distance; nearest pairs first). The
/// drive evaluation has no CLEAR matching of its own, so this is the matching of
/// `kitti-tools objects`, with the OSPA cut-off as the gate.
pub fn car_van_recall(
    tracks: &DriveTracks,
    vehicles: &[Vec<LabelledVehicle>],
    gate: f64,
) -> RecallBreakdown {
    let mut r = RecallBreakdown::default();
    for f in &tracks.frames {
        let Some(labelled) = vehicles.get(f.frame) else {
            continue;
        };
        let reported: Vec<[f64; 2]> = f
            .clusters
            .iter()
            .filter(|c| matches!(c.class.as_deref(), Some("Car" | "Van")))
            .map(|c| [c.position_world[0], c.position_world[1]])
            .collect();
        let positions: Vec<[f64; 2]> = labelled.iter().map(|v| v.position).collect();
        for (v, found) in labelled
            .iter()
            .zip(match_nearest(&reported, &positions, gate).1)
        {
            r.add(v.occluded, v.range, found);
        }
    }
    r
}

/// Scores `tracks` against `labels`; `poses` are the recording's sensor poses, which
/// tracklets and tracking labels need to reach the tracks' world frame (an error naming the
/// labels when they are missing).
pub fn evaluate_labels(
    tracks: &DriveTracks,
    labels: &RecordingLabels,
    poses: Option<&[Isometry3<f64>]>,
    options: &EvaluationOptions,
) -> Result<Evaluation> {
    let need_poses = || {
        poses.ok_or_else(|| {
            Error::invalid(
                format!("scoring against {}", labels.kind()),
                "needs the recording's poses",
            )
        })
    };
    if options.camera_view && !matches!(labels, RecordingLabels::Camera { .. }) {
        return Err(Error::invalid(
            format!("scoring against {}", labels.kind()),
            "the camera view needs a tracking sequence's labels and calibration",
        ));
    }
    let mut in_view;
    let mut tracks = tracks;
    let (frames, walls, vehicles) = match labels {
        RecordingLabels::Street(t) => (
            street_object_truth(t, options.min_points, options.max_range),
            Some(evaluate_walls(tracks, t)?),
            Some(street_vehicles(t, options.min_points, options.max_range)),
        ),
        RecordingLabels::Tracklets(t) => (tracklet_truth(t, need_poses()?), None, None),
        RecordingLabels::Camera { labels, calib } => {
            if options.camera_view {
                in_view = tracks.clone();
                retain_clusters(&mut in_view, |p| {
                    calib.in_image2(&Point3::new(p[0], p[1], p[2]))
                });
                tracks = &in_view;
            }
            let keep = |b: &VelodyneBox| {
                b.center.x.hypot(b.center.y) <= options.max_range
                    && (!options.camera_view || calib.in_image2(&b.center))
            };
            let rect_from_velo = calib.rect_from_velo();
            (
                label_truth(labels, &rect_from_velo, need_poses()?, keep),
                None,
                Some(label_vehicles(labels, &rect_from_velo, need_poses()?, keep)),
            )
        }
    };
    let clusters = evaluate_clusters(tracks, &frames, &options.clusters)?;
    let car_van_recall = vehicles.map(|v| car_van_recall(tracks, &v, options.clusters.cutoff));
    Ok(Evaluation {
        clusters,
        walls,
        car_van_recall,
    })
}

/// Scores `tracks` against `recording`'s own labels ([`Recording::labels`]): the one entry
/// point of the evaluation for a recording. A recording without labels is an error naming it.
pub fn evaluate_recording(
    tracks: &DriveTracks,
    recording: &dyn Recording,
    options: &EvaluationOptions,
) -> Result<Evaluation> {
    let Some(labels) = recording.labels()? else {
        return Err(Error::invalid(
            recording.describe(),
            "has no labels to score against (a tracking sequence's label_02, a drive's \
             tracklet_labels.xml or a simulated street's truth.json)",
        ));
    };
    let poses = if labels.needs_poses() {
        Some(recording.poses()?)
    } else {
        None
    };
    evaluate_labels(tracks, &labels, poses.as_deref(), options)
}

/// Compares every confirmed wall report that has a rectangle with the truth wall closest to
/// it (smallest angle, then centre-to-plane distance, among walls within 10°).
pub fn evaluate_walls(tracks: &DriveTracks, truth: &StreetTruth) -> Result<WallEvaluation> {
    let world_from_drive = truth.world_from_drive.to_isometry();
    let (mut angles, mut offsets) = (Vec::new(), Vec::new());
    let (mut reports, mut matched) = (0, 0);
    let mut walls = std::collections::BTreeSet::new();
    for f in &tracks.frames {
        for plane in &f.planes {
            let Some(v) = plane.vertices_world else {
                continue;
            };
            reports += 1;
            let p: Vec<Point3<f64>> = v
                .iter()
                .map(|q| world_from_drive * Point3::from(*q))
                .collect();
            let centre =
                Point3::from((p[0].coords + p[1].coords + p[2].coords + p[3].coords) / 4.0);
            let normal = (p[1] - p[0]).cross(&(p[3] - p[0]));
            if normal.norm() == 0.0 {
                continue;
            }
            let normal = normal.normalize();
            let best = truth
                .walls
                .iter()
                .map(|w| {
                    let n = Vector3::from(w.normal);
                    let angle = normal.dot(&n).abs().min(1.0).acos();
                    let offset = (n.dot(&centre.coords) + w.offset).abs();
                    (w.id, angle, offset)
                })
                .filter(|(_, a, _)| *a < 10f64.to_radians())
                .min_by(|a, b| (a.2 + 10.0 * a.1).total_cmp(&(b.2 + 10.0 * b.1)));
            if let Some((id, angle, offset)) = best {
                angles.push(angle.to_degrees());
                offsets.push(offset);
                if angle < 2f64.to_radians() && offset < 0.5 {
                    matched += 1;
                    walls.insert(id);
                }
            }
        }
    }
    let stat = |v: &[f64], q: f64| {
        if v.is_empty() {
            f64::NAN
        } else {
            percentile(v, q)
        }
    };
    Ok(WallEvaluation {
        reports,
        matched,
        median_normal_angle_deg: stat(&angles, 50.0),
        p90_normal_angle_deg: stat(&angles, 90.0),
        median_offset_m: stat(&offsets, 50.0),
        p90_offset_m: stat(&offsets, 90.0),
        walls_matched: walls.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kitti::TrackingLabel;
    use nalgebra::{Matrix3, Translation3, UnitQuaternion};
    use std::path::Path;

    #[test]
    fn label_truth_by_hand() {
        // The ideal rig without offsets: velo x → cam z, velo y → cam −x, velo z → cam −y.
        let r = Matrix3::new(0.0, -1.0, 0.0, 0.0, 0.0, -1.0, 1.0, 0.0, 0.0);
        let rect_from_velo =
            Isometry3::from_parts(Translation3::identity(), UnitQuaternion::from_matrix(&r));
        let line = "1 4 Cyclist 0 0 0 0 0 10 10 1.8 0.6 1.7 -2 1.7 12 0";
        let cyclist = TrackingLabel::parse_line(line, Path::new("l.txt"), 1).unwrap();
        let mut far = cyclist;
        far.track_id = 5;
        far.location = [0.0, 1.7, 50.0];
        let mut region = cyclist;
        region.object_type = ObjectType::DontCare;
        region.track_id = -1;
        // Frame 1's sensor is 3 m ahead of frame 0's, turned by 90° to the left.
        let poses = [
            Isometry3::identity(),
            Isometry3::from_parts(
                Translation3::new(3.0, 0.0, 0.0),
                UnitQuaternion::from_euler_angles(0.0, 0.0, std::f64::consts::FRAC_PI_2),
            ),
        ];
        let frames = label_truth(&[cyclist, far, region], &rect_from_velo, &poses, |b| {
            b.center.x.hypot(b.center.y) <= 40.0
        });
        assert_eq!(frames.len(), 2);
        assert!(frames[0].is_empty());
        assert_eq!(frames[1].len(), 1, "{frames:?}");
        // Velodyne (12, 2, ·) of frame 1 → world (3 − 2, 12).
        let o = frames[1][0];
        assert_eq!(o.id, 4);
        assert!((o.position[0] - 1.0).abs() < 1e-12, "{o:?}");
        assert!((o.position[1] - 12.0).abs() < 1e-12, "{o:?}");
    }
}
