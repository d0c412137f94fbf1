//! A lidar recording, whatever its layout on disk: frames, which of them have a scan, the
//! scans, their times, the sensor poses and the vehicle's measured motion when the recording
//! has them. [`Recording`] is what the pipelines take (`track_recording`, `predict_pairs`,
//! `odometry_of_scans_at`); the KITTI raw drive, tracking and odometry layouts implement it
//! (`recording/kitti.rs`) and so does a plain folder of `.bin` or `.pcd` scans with an
//! optional pose file and time file ([`ScanDirectory`]). A user's own layout is one more
//! implementation. A recording with ground truth hands it over as [`RecordingLabels`]
//! ([`Recording::labels`]), which `evaluate_recording` scores tracks against.
//!
//! Not for: reading the files of a layout (see [`crate::kitti`] and [`crate::cloud`]) or
//! scoring (see [`crate::pipeline::drive_evaluation`]).

mod kitti;
mod labels;
mod scan_directory;

pub use labels::RecordingLabels;
pub use scan_directory::ScanDirectory;

use crate::cloud::{is_pcd, NonFinite, PointCloud};
use crate::error::{Error, Result};
use crate::models::VehicleState;
use nalgebra::Isometry3;

/// The vehicle's measured motion in a recording, which a vehicle ego model starts from.
#[derive(Clone, Debug, PartialEq)]
pub struct VehicleMotion {
    /// Measured planar kinematics of every frame.
    pub states: Vec<VehicleState>,
    /// Vehicle (IMU) → sensor transform, `p_sensor = C p_vehicle`.
    pub vehicle_to_sensor: Isometry3<f64>,
    /// The step lengths (s) between frame k and k + 1 the vehicle's measurements imply.
    pub intervals: Vec<f64>,
}

/// A lidar recording (module documentation). Frames are numbered 0..[`frame_count`]; a frame
/// may lack its scan (KITTI drops one now and then) and keep its number.
///
/// [`frame_count`]: Recording::frame_count
pub trait Recording: Sync {
    /// A short name for outputs: a drive folder's name, `tracking_NNNN`, `odometry_NN`, a scan
    /// folder's name.
    fn name(&self) -> String;
    /// What the recording is, for messages: `drive /path/to/it`.
    fn describe(&self) -> String;
    /// The number of frames, those without a scan included.
    fn frame_count(&self) -> usize;
    /// Whether frame `k` has a scan.
    fn has_scan(&self, k: usize) -> bool {
        k < self.frame_count()
    }
    /// The scan of frame `k`, in the sensor frame. Errors name the file.
    fn scan(&self, k: usize) -> Result<PointCloud>;
    /// Scan `k` in messages: its file when the recording keeps scans in files.
    fn scan_name(&self, k: usize) -> String {
        format!("frame {k} of {}", self.describe())
    }
    /// Where the scans are (for an error when there is none), if in one folder.
    fn scan_dir(&self) -> Option<std::path::PathBuf> {
        None
    }
    /// The time of every frame (s), when the recording has times (else `None`: callers take a
    /// fixed period).
    fn times(&self) -> Result<Option<Vec<f64>>>;
    /// Whether the recording has sensor poses of its own.
    fn has_poses(&self) -> bool;
    /// The sensor pose of every frame (sensor frame k → the first frame's sensor frame, or any
    /// fixed world frame), at least one per frame; an error when [`Recording::has_poses`] is
    /// false.
    fn poses(&self) -> Result<Vec<Isometry3<f64>>>;
    /// Where the poses come from, for outputs: `oxts`, `odometry`, `poses`.
    fn pose_source(&self) -> &'static str {
        "poses"
    }
    /// Whether the recording has the vehicle's measured motion ([`Recording::vehicle`]).
    fn has_vehicle(&self) -> bool {
        false
    }
    /// The vehicle's measured motion, which a vehicle ego model needs; an error naming the
    /// recording by default.
    fn vehicle(&self) -> Result<VehicleMotion> {
        Err(Error::invalid(
            self.describe(),
            "has no measured vehicle motion (OXTS packets), which a vehicle ego model needs",
        ))
    }
    /// The recording's own ground truth, `None` when it has none (the default). A labels
    /// file that is there but cannot be read is an error naming it.
    fn labels(&self) -> Result<Option<RecordingLabels>> {
        Ok(None)
    }
    /// The sensor's height over the road (m) when the recording knows it (a folder of scans
    /// given one); the tracker's configured height (`ClusterTuning::sensor_height`, KITTI's
    /// 1.73 m by default) otherwise. The tracker uses it where a frame has no ground plane.
    fn sensor_height(&self) -> Option<f64> {
        None
    }
}

impl<R: Recording + ?Sized> Recording for &R {
    fn name(&self) -> String {
        (**self).name()
    }
    fn describe(&self) -> String {
        (**self).describe()
    }
    fn frame_count(&self) -> usize {
        (**self).frame_count()
    }
    fn has_scan(&self, k: usize) -> bool {
        (**self).has_scan(k)
    }
    fn scan(&self, k: usize) -> Result<PointCloud> {
        (**self).scan(k)
    }
    fn scan_name(&self, k: usize) -> String {
        (**self).scan_name(k)
    }
    fn scan_dir(&self) -> Option<std::path::PathBuf> {
        (**self).scan_dir()
    }
    fn times(&self) -> Result<Option<Vec<f64>>> {
        (**self).times()
    }
    fn has_poses(&self) -> bool {
        (**self).has_poses()
    }
    fn poses(&self) -> Result<Vec<Isometry3<f64>>> {
        (**self).poses()
    }
    fn pose_source(&self) -> &'static str {
        (**self).pose_source()
    }
    fn has_vehicle(&self) -> bool {
        (**self).has_vehicle()
    }
    fn vehicle(&self) -> Result<VehicleMotion> {
        (**self).vehicle()
    }
    fn labels(&self) -> Result<Option<RecordingLabels>> {
        (**self).labels()
    }
    fn sensor_height(&self) -> Option<f64> {
        (**self).sensor_height()
    }
}

/// A folder's own name (its last component), or the whole path when it has none: the output
/// name of a recording that is a folder.
pub fn folder_name(dir: &std::path::Path) -> String {
    dir.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| dir.display().to_string())
}

/// How a recording reads the points of a scan file with a non-finite value: a PCD file's are
/// left out (organised clouds mark missing returns so), a `.bin` file's are an error naming the
/// file and point.
pub fn non_finite_policy(path: &std::path::Path) -> NonFinite {
    if is_pcd(path) {
        NonFinite::Skip
    } else {
        NonFinite::Error
    }
}
