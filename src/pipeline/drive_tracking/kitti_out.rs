//! A drive's road users as KITTI tracking results, from the LMB's cluster tracks and from the
//! AB3DMOT-style baseline run on the same detections.
//!
//! * [`lmb_results`]: every reported cluster track with a class other than `Other` and a box
//!   becomes one result object per frame (track id = the track's compact id, score = its
//!   existence probability, box in the frame's sensor frame).
//! * [`BaselineBoxes`]: collects each frame's cluster detections (their boxes with the
//!   visible-face model and their frame's class) in the world frame while the LMB runs, then
//!   runs [`crate::trackers::ab3dmot`] over them, so both trackers see the same detections.
//!
//! The world frame is the planar ego pose of each frame (position, heading) the report
//! carries; moving boxes out and back with the same pose keeps them exact in the sensor frame.
//!
//! Not for: writing the lines (see [`crate::pipeline::kitti_results`]) or scoring them.

use super::{DriveTracks, FrameView, TrackedFrame};
use crate::error::Result;
use crate::kitti::ObjectType;
use crate::pipeline::box_baseline::{baseline_results, move_box, run_box_baseline, FrameBoxes};
use crate::pipeline::kitti_results::ResultObject;
use crate::trackers::ab3dmot::Ab3dmotConfig;
use nalgebra::{Isometry3, Vector3};

/// The KITTI type of a class name (`Other` and unknown names have none).
pub fn kitti_type(class: &str) -> Option<ObjectType> {
    match class {
        "Other" => None,
        name => ObjectType::from_name(name).filter(|t| *t != ObjectType::DontCare),
    }
}

/// The sensor → world pose of a frame's report (planar: position and heading).
pub fn frame_pose(f: &TrackedFrame) -> Isometry3<f64> {
    Isometry3::new(Vector3::from(f.ego_position), Vector3::z() * f.ego_yaw)
}

/// The LMB's reported cluster tracks as result objects (see the module notes).
pub fn lmb_results(tracks: &DriveTracks) -> Vec<ResultObject> {
    let mut out = Vec::new();
    for f in &tracks.frames {
        for c in &f.clusters {
            let (Some(class), Some(b)) = (&c.class, &c.box_sensor) else {
                continue;
            };
            if let Some(object_type) = kitti_type(class) {
                out.push(ResultObject {
                    frame: f.frame,
                    track_id: u64::from(c.id),
                    object_type,
                    bbox: b.to_box3(),
                    score: c.existence,
                });
            }
        }
    }
    out
}

/// Each frame's detections in the world frame, gathered for the baseline.
#[derive(Clone, Debug, Default)]
pub struct BaselineBoxes {
    frames: Vec<usize>,
    boxes: Vec<FrameBoxes>,
    velo_from_world: Vec<Isometry3<f64>>,
}

impl BaselineBoxes {
    /// An empty collection.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds one frame (call from the tracking loop's per-frame callback, in frame order).
    pub fn add(&mut self, view: &FrameView<'_>) {
        let pose = frame_pose(view.tracked);
        let boxes = view
            .detections
            .clusters
            .iter()
            .filter_map(|c| c.shape.as_ref())
            .map(|s| (move_box(&s.bbox, &pose), s.class.name().to_string(), 1.0))
            .collect();
        self.frames.push(view.tracked.frame);
        self.boxes.push(boxes);
        self.velo_from_world.push(pose.inverse());
    }

    /// Frames collected.
    pub fn len(&self) -> usize {
        self.frames.len()
    }

    /// True before any frame.
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    /// Runs the baseline over the collected frames and returns its reported tracks as result
    /// objects, numbered by the drive's frame numbers.
    pub fn results(&self, config: &Ab3dmotConfig) -> Result<Vec<ResultObject>> {
        let tracks = run_box_baseline(&self.boxes, config)?;
        let mut out = baseline_results(&tracks, &self.velo_from_world, kitti_type)?;
        for o in &mut out {
            o.frame = self.frames[o.frame];
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn class_names_map_to_kitti_types_and_other_has_none() {
        assert_eq!(kitti_type("Car"), Some(ObjectType::Car));
        assert_eq!(kitti_type("Cyclist"), Some(ObjectType::Cyclist));
        assert_eq!(kitti_type("Other"), None);
        assert_eq!(kitti_type("DontCare"), None);
    }

    #[test]
    fn frame_pose_turns_about_z_and_moves() {
        let f = TrackedFrame {
            frame: 3,
            time: 0.3,
            ego_position: [1.0, 2.0, 0.0],
            ego_yaw: std::f64::consts::FRAC_PI_2,
            detected_planes: 0,
            detected_clusters: 0,
            planes: Vec::new(),
            clusters: Vec::new(),
            times: Default::default(),
        };
        let p = frame_pose(&f) * nalgebra::Point3::new(1.0, 0.0, 0.0);
        assert!(
            (p.x - 1.0).abs() < 1e-12 && (p.y - 3.0).abs() < 1e-12,
            "{p:?}"
        );
    }
}
