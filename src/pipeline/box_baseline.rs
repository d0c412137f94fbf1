//! The AB3DMOT baseline over a whole sequence: per-frame box detections in a world frame in,
//! per-frame tracks out, and the glue to KITTI results (boxes moved back into each frame's
//! Velodyne frame).
//!
//! The caller moves its detections into one world frame with the ego poses
//! ([`move_box`] with the pose world ← Velodyne of the frame) so that the constant-velocity
//! model sees the objects' own motion, runs [`run_box_baseline`], and turns the tracks into
//! [`ResultObject`]s with [`baseline_results`] (the inverse poses) for
//! [`super::kitti_results`].
//!
//! Not for: detecting boxes (the caller's detector), the LMB tracker (see
//! [`super::drive_tracking`]) or the tracker itself (see [`crate::trackers::ab3dmot`]).

use super::kitti_results::ResultObject;
use crate::error::{Error, Result};
use crate::geometry::box3::Box3;
use crate::geometry::wrap_angle;
use crate::kitti::labels::ObjectType;
use crate::trackers::ab3dmot::{Ab3dmot, Ab3dmotConfig, BoxDetection, TrackedBox};
use nalgebra::{Isometry3, Vector3};

/// One frame's detections: box (world frame), class name, score.
pub type FrameBoxes = Vec<(Box3, String, f64)>;

/// Runs AB3DMOT with `config` over `frames` (one entry per frame, empty for frames without
/// detections) and returns the reported tracks of every frame. Errors name the frame of a
/// bad detection.
pub fn run_box_baseline(
    frames: &[FrameBoxes],
    config: &Ab3dmotConfig,
) -> Result<Vec<Vec<TrackedBox>>> {
    let mut tracker = Ab3dmot::new(config.clone())?;
    let mut dets = Vec::new();
    frames
        .iter()
        .enumerate()
        .map(|(k, frame)| {
            dets.clear();
            dets.extend(
                frame
                    .iter()
                    .map(|(b, class, score)| BoxDetection::new(*b, class.clone(), *score)),
            );
            tracker.step(&dets).map_err(|e| match e {
                Error::InvalidInput { what, reason } => {
                    Error::invalid(format!("frame {k}: {what}"), reason)
                }
                other => other,
            })
        })
        .collect()
}

/// `b` seen from the frame `pose` maps from (p_to = pose·p_from): centre moved, heading turned
/// by the heading of the moved x axis in the new x–y plane. Exact for poses that turn about z
/// only; for KITTI's nearly level ego poses the box stays upright to within their roll and
/// pitch.
pub fn move_box(b: &Box3, pose: &Isometry3<f64>) -> Box3 {
    let (s, c) = b.yaw.sin_cos();
    let heading = pose.rotation * Vector3::new(c, s, 0.0);
    Box3 {
        center: pose * b.center,
        size: b.size,
        yaw: wrap_angle(heading.y.atan2(heading.x)),
    }
}

/// The tracks of every frame as KITTI results: each box moved into its frame's Velodyne frame
/// with `velo_from_world[k]`, its class named by `class_type` (tracks whose class it maps to
/// `None` are left out), its score kept. Errors when there are fewer poses than frames.
pub fn baseline_results(
    tracks: &[Vec<TrackedBox>],
    velo_from_world: &[Isometry3<f64>],
    class_type: impl Fn(&str) -> Option<ObjectType>,
) -> Result<Vec<ResultObject>> {
    if velo_from_world.len() < tracks.len() {
        return Err(Error::invalid(
            "baseline results",
            format!(
                "{} poses for {} frames of tracks",
                velo_from_world.len(),
                tracks.len()
            ),
        ));
    }
    let mut out = Vec::new();
    for (k, frame) in tracks.iter().enumerate() {
        for t in frame {
            if let Some(object_type) = class_type(&t.class) {
                out.push(ResultObject {
                    frame: k,
                    track_id: t.id,
                    object_type,
                    bbox: move_box(&t.bbox, &velo_from_world[k]),
                    score: t.score,
                });
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Point3, Translation3, UnitQuaternion};
    use std::f64::consts::FRAC_PI_2;

    fn car(x: f64, y: f64, yaw: f64) -> Box3 {
        Box3 {
            center: Point3::new(x, y, 0.0),
            size: [4.0, 1.8, 1.5],
            yaw,
        }
    }

    #[test]
    fn moving_a_box_by_hand() {
        // A quarter turn about z and a shift by (10, 0, 1): (1, 2, 0) → (10 − 2, 1, 1).
        let pose = Isometry3::from_parts(
            Translation3::new(10.0, 0.0, 1.0),
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), FRAC_PI_2),
        );
        let m = move_box(&car(1.0, 2.0, 0.5), &pose);
        assert!((m.center - Point3::new(8.0, 1.0, 1.0)).norm() < 1e-12);
        assert!((m.yaw - (0.5 + FRAC_PI_2)).abs() < 1e-12);
        let back = move_box(&m, &pose.inverse());
        assert!((back.center - Point3::new(1.0, 2.0, 0.0)).norm() < 1e-12);
        assert!((back.yaw - 0.5).abs() < 1e-12);
    }

    #[test]
    fn a_sequence_through_the_baseline_and_back_into_sensor_frames() {
        // The ego car drives along x at 1 m per frame; a parked car stands at world (20, 5).
        // In the Velodyne frame of frame k it is at (20 − k, 5); moved to the world frame the
        // detections do not move, so the track's velocity is zero.
        let world_from_velo: Vec<Isometry3<f64>> = (0..8)
            .map(|k| Isometry3::translation(k as f64, 0.0, 0.0))
            .collect();
        let frames: Vec<FrameBoxes> = (0..8)
            .map(|k| {
                let seen = car(20.0 - k as f64, 5.0, 0.1);
                vec![(move_box(&seen, &world_from_velo[k]), "Car".to_string(), 0.7)]
            })
            .collect();
        let tracks = run_box_baseline(&frames, &Ab3dmotConfig::default()).unwrap();
        assert_eq!(tracks.len(), 8);
        assert!(tracks[1].is_empty() && tracks[2].len() == 1);
        let last = &tracks[7][0];
        assert!(last.velocity.iter().all(|v| v.abs() < 1e-9), "{last:?}");
        let inverse: Vec<Isometry3<f64>> = world_from_velo.iter().map(|p| p.inverse()).collect();
        let results = baseline_results(&tracks, &inverse, ObjectType::from_name).unwrap();
        assert_eq!(results.len(), 6);
        for r in &results {
            assert_eq!(
                (r.track_id, r.object_type, r.score),
                (0, ObjectType::Car, 0.7)
            );
            let want = Point3::new(20.0 - r.frame as f64, 5.0, 0.0);
            assert!((r.bbox.center - want).norm() < 1e-9, "{r:?}");
        }
        // Unknown classes are left out; too few poses is an error.
        assert!(baseline_results(&tracks, &inverse, |_| None)
            .unwrap()
            .is_empty());
        assert!(baseline_results(&tracks, &inverse[..3], ObjectType::from_name).is_err());
        // A bad detection names its frame.
        let mut bad = frames.clone();
        bad[4][0].2 = f64::NAN;
        let msg = run_box_baseline(&bad, &Ab3dmotConfig::default())
            .unwrap_err()
            .to_string();
        assert!(msg.contains("frame 4"), "{msg}");
    }
}
