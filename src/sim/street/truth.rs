//! Ground truth of a simulated street drive, as written to `truth.json` in the drive folder:
//! per frame the time and the poses, the walls as rectangles and planes, the objects with
//! their per-frame states, how many lidar points hit each wall and object, and how much of
//! each object the lidar's rays see, as KITTI's occlusion level ([`occlusion_level`]).
//!
//! **Frames.** "World" is the simulation frame: x east, y north, z up, ground at z = 0, origin
//! at the ego vehicle's start (the OXTS unit's ground projection). The *drive frame* is the
//! frame that [`crate::kitti::RawDrive::poses`] expresses poses in: the Velodyne frame of
//! frame 0. `world_from_drive` maps drive-frame coordinates to world coordinates (it is the
//! Velodyne pose of frame 0 in the world), and each frame's `drive_pose` is exactly what
//! `RawDrive::poses()` returns for it. Planes follow the crate's convention n·p + d = 0.
//!
//! Not for: producing the truth (see [`super::generate`]) or scoring against it.

use super::clutter::Clutter;
use super::ego::EgoState;
use super::world::ObjectKind;
use super::StreetConfig;
use crate::error::{Error, Result};
use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// A rigid transform as a translation and a row-major rotation matrix.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PoseTruth {
    /// Translation, metres.
    pub translation: [f64; 3],
    /// Rotation matrix, rows.
    pub rotation: [[f64; 3]; 3],
}

impl PoseTruth {
    /// From an isometry.
    pub fn from_isometry(iso: &Isometry3<f64>) -> PoseTruth {
        let r = iso.rotation.to_rotation_matrix().into_inner();
        let t = iso.translation.vector;
        PoseTruth {
            translation: [t.x, t.y, t.z],
            rotation: [
                [r[(0, 0)], r[(0, 1)], r[(0, 2)]],
                [r[(1, 0)], r[(1, 1)], r[(1, 2)]],
                [r[(2, 0)], r[(2, 1)], r[(2, 2)]],
            ],
        }
    }

    /// As an isometry (the rotation snapped to the nearest exact rotation).
    pub fn to_isometry(&self) -> Isometry3<f64> {
        let r = &self.rotation;
        let m = Matrix3::new(
            r[0][0], r[0][1], r[0][2], r[1][0], r[1][1], r[1][2], r[2][0], r[2][1], r[2][2],
        );
        let rot = Rotation3::from_matrix_eps(&m, 1e-15, 100, Rotation3::identity());
        Isometry3::from_parts(
            Translation3::from(Vector3::from(self.translation)),
            UnitQuaternion::from_rotation_matrix(&rot),
        )
    }
}

/// One frame of the drive.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FrameTruth {
    /// Frame index (file number).
    pub index: usize,
    /// Seconds since frame 0.
    pub time: f64,
    /// Velodyne pose in the world (Velodyne coordinates → world).
    pub velodyne_pose: PoseTruth,
    /// Velodyne pose relative to frame 0 (what `RawDrive::poses()` returns).
    pub drive_pose: PoseTruth,
    /// IMU (OXTS unit) pose in the world.
    pub imu_pose: PoseTruth,
    /// The ego vehicle's planar state in the world (position of the OXTS unit).
    pub ego: EgoState,
    /// Points in the scan.
    pub points: usize,
    /// Points on the ground.
    pub ground_points: usize,
}

/// One building wall.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WallTruth {
    /// Identifier (matches `Surface::Wall`).
    pub id: u32,
    /// Corners in the world: ground start, ground end, top end, top start.
    pub vertices: [[f64; 3]; 4],
    /// Unit normal in the world, horizontal, pointing towards the street.
    pub normal: [f64; 3],
    /// d of n·p + d = 0 in the world.
    pub offset: f64,
    /// Length along the ground, metres.
    pub width: f64,
    /// Height, metres.
    pub height: f64,
    /// Lidar points on the wall, per frame.
    pub points: Vec<usize>,
}

/// An object's state in one frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ObjectState {
    /// Frame index.
    pub frame: usize,
    /// Centre of the footprint in the world (z = 0), metres.
    pub position: [f64; 3],
    /// Velocity in the world, m/s.
    pub velocity: [f64; 3],
    /// Heading, rad counter-clockwise from the world x axis.
    pub yaw: f64,
    /// Lidar points on the object in this frame.
    pub points: usize,
    /// Lidar rays whose line meets the object within the lidar's range in this frame,
    /// returned or not (see [`ObjectView`](super::lidar::ObjectView); absent from older files).
    #[serde(default)]
    pub rays: usize,
    /// Of those, the rays whose first hit is another shape nearer the sensor.
    #[serde(default)]
    pub hidden_rays: usize,
    /// KITTI's occlusion level from the hidden share ([`occlusion_level`]): 0 fully visible,
    /// 1 partly occluded, 2 largely occluded, 3 unknown (no ray meets the object, or a file
    /// written before the field).
    #[serde(default = "unknown_occlusion")]
    pub occluded: i32,
}

impl ObjectState {
    /// The share of the rays meeting the object that are hidden, in [0, 1]; `None` without
    /// rays.
    pub fn hidden_share(&self) -> Option<f64> {
        (self.rays > 0).then(|| self.hidden_rays as f64 / self.rays as f64)
    }
}

fn unknown_occlusion() -> i32 {
    OCCLUSION_UNKNOWN
}

/// KITTI's occlusion level "unknown".
pub const OCCLUSION_UNKNOWN: i32 = 3;

/// Largest hidden share of a fully visible object (level 0).
pub const FULLY_VISIBLE_MAX_HIDDEN: f64 = 0.1;

/// Largest hidden share of a partly occluded object (level 1); beyond it, largely occluded.
pub const PARTLY_OCCLUDED_MAX_HIDDEN: f64 = 0.5;

/// KITTI's occlusion level of an object whose rays are hidden in the share `hidden` (see
/// [`ObjectView`](super::lidar::ObjectView)): 0 (fully visible) up to
/// [`FULLY_VISIBLE_MAX_HIDDEN`], 1 (partly occluded) up to [`PARTLY_OCCLUDED_MAX_HIDDEN`],
/// 2 (largely occluded) above, 3 (unknown) without rays.
///
/// KITTI's annotators judged the levels by eye in the image (Geiger et al. 2013 give no
/// numbers). The cuts follow the plain reading of the words: "largely" is more than half
/// hidden; "fully visible" allows a tenth, as a label's box is drawn around the whole vehicle
/// and a pole, a mirror or a neighbour's bumper across a corner does not make a labeller call
/// it occluded. nuScenes' visibility bins (Caesar et al. 2020), in image area, put their
/// lowest cut at 40 % visible, near this 50 %.
pub fn occlusion_level(hidden: Option<f64>) -> i32 {
    match hidden {
        None => OCCLUSION_UNKNOWN,
        Some(h) if h <= FULLY_VISIBLE_MAX_HIDDEN => 0,
        Some(h) if h <= PARTLY_OCCLUDED_MAX_HIDDEN => 1,
        Some(_) => 2,
    }
}

/// A road user.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ObjectTruth {
    /// Identifier (matches `Surface::Object`).
    pub id: u32,
    /// Kind.
    pub kind: ObjectKind,
    /// Length, width, height, metres (a pedestrian: diameter, diameter, height).
    pub size: [f64; 3],
    /// States in the frames where the object exists, in frame order.
    pub states: Vec<ObjectState>,
}

/// The ground truth of a drive.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StreetTruth {
    /// Drive folder name.
    pub drive: String,
    /// Seed the drive was generated with.
    pub seed: u64,
    /// The configuration used.
    pub config: StreetConfig,
    /// Maps drive-frame (Velodyne frame 0) coordinates to world coordinates.
    pub world_from_drive: PoseTruth,
    /// The IMU→Velodyne calibration used (p_velo = T·p_imu), as the reader snaps it.
    pub imu_to_velo: PoseTruth,
    /// Frames in order.
    pub frames: Vec<FrameTruth>,
    /// Building walls.
    pub walls: Vec<WallTruth>,
    /// Road users.
    pub objects: Vec<ObjectTruth>,
    /// Poles, trunks, hedges and low walls (not road users; absent from older files).
    #[serde(default)]
    pub clutter: Vec<Clutter>,
}

impl StreetTruth {
    /// Reads `truth.json`; errors name the file (and line for malformed JSON).
    pub fn read(path: impl AsRef<Path>) -> Result<StreetTruth> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        serde_json::from_str(&text)
            .map_err(|e| Error::parse(path, e.line(), "truth", e.to_string()))
    }

    /// The truth as pretty JSON.
    pub fn to_json(&self) -> Result<String> {
        serde_json::to_string_pretty(self)
            .map_err(|e| Error::invalid("street truth", e.to_string()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn occlusion_levels_by_hand() {
        assert_eq!(occlusion_level(None), 3);
        assert_eq!(occlusion_level(Some(0.0)), 0);
        assert_eq!(occlusion_level(Some(0.1)), 0);
        assert_eq!(occlusion_level(Some(0.11)), 1);
        assert_eq!(occlusion_level(Some(0.5)), 1);
        assert_eq!(occlusion_level(Some(0.51)), 2);
        assert_eq!(occlusion_level(Some(1.0)), 2);
    }

    #[test]
    fn a_state_written_before_the_ray_counts_reads_as_unknown_occlusion() {
        let old = r#"{"frame": 4, "position": [1.0, 2.0, 0.0], "velocity": [0.0, 0.0, 0.0],
                      "yaw": 0.5, "points": 12}"#;
        let s: ObjectState = serde_json::from_str(old).unwrap();
        assert_eq!((s.rays, s.hidden_rays, s.occluded), (0, 0, 3));
        assert_eq!(s.hidden_share(), None);
        let s = ObjectState {
            rays: 40,
            hidden_rays: 30,
            ..s
        };
        assert_eq!(s.hidden_share(), Some(0.75));
    }
}
