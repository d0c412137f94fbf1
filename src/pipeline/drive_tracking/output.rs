//! What the drive tracker reports: per frame the confirmed (MAP) planes and clusters with
//! their labels, as serde types, and a whole-drive summary; JSON writing and reading.
//!
//! Frames: plane normals, offsets and `vertices` are in the sensor (Velodyne) frame of that
//! frame, `vertices_world` and cluster `position_world`/`velocity` in the world frame (the
//! Velodyne frame of the drive's first frame, from OXTS); `position_sensor` and `extent` in
//! the sensor frame. Not for: computing any of it (see [`super::tracker`]).

use crate::atomic::write_atomically;
use crate::error::{Error, Result};
use crate::filter::Label;
use std::io::Write;
use std::path::Path;

/// One confirmed wall.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TrackedPlane {
    /// Compact track number (1, 2, … in order of first report; colour index of exports).
    pub id: u32,
    /// The filter's label.
    pub label: Label,
    /// Unit normal (sensor frame), pointing towards the sensor.
    pub normal: [f64; 3],
    /// Offset d of n·p + d = 0 (m, ≥ 0).
    pub offset: f64,
    /// Rectangle corners on the estimated plane (sensor frame), from the last associated
    /// wall detection; `None` before any.
    pub vertices: Option<[[f64; 3]; 4]>,
    /// The same corners in the world frame.
    pub vertices_world: Option<[[f64; 3]; 4]>,
    /// Rectangle area (m²), 0 without vertices.
    pub area: f64,
    /// Existence probability.
    pub existence: f64,
    /// Index of the wall detection of this frame matched to the track, if any.
    pub detection: Option<usize>,
}

/// One confirmed cluster.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TrackedCluster {
    /// Compact track number (see [`TrackedPlane::id`]).
    pub id: u32,
    /// The filter's label.
    pub label: Label,
    /// Position estimate (m, world frame).
    pub position_world: [f64; 3],
    /// Position estimate (m, sensor frame of this frame).
    pub position_sensor: [f64; 3],
    /// Velocity estimate (m/s, world frame).
    pub velocity: [f64; 3],
    /// Size of the axis-aligned box of the last associated detection (m, sensor axes);
    /// `None` before any.
    pub extent: Option<[f64; 3]>,
    /// Existence probability.
    pub existence: f64,
    /// Index of the cluster detection of this frame matched to the track, if any.
    pub detection: Option<usize>,
    /// Most likely class (`Car`, `Van`, `Truck`, `Pedestrian`, `Cyclist`, `Other`) of the
    /// track's class posterior; `None` before any matched detection with a shape.
    #[serde(default)]
    pub class: Option<String>,
    /// Posterior probability of `class`.
    #[serde(default)]
    pub class_probability: f64,
    /// Oriented box in the world frame: centre at the position estimate, size averaged over
    /// the matched detections, heading along the direction of travel once moving.
    #[serde(default)]
    pub box_world: Option<OrientedBox>,
    /// The same box in the sensor frame of this frame.
    #[serde(default)]
    pub box_sensor: Option<OrientedBox>,
    /// Whether the track counts as a road user (not static clutter of class `Other`).
    #[serde(default = "yes")]
    pub road_user: bool,
}

fn yes() -> bool {
    true
}

/// An oriented box upright about z.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct OrientedBox {
    /// Centre of the box (m).
    pub center: [f64; 3],
    /// Length (along the heading), width, height (m).
    pub size: [f64; 3],
    /// Heading of the length axis about z, counter-clockwise from x (rad).
    pub yaw: f64,
}

impl OrientedBox {
    /// As a [`crate::geometry::Box3`].
    pub fn to_box3(&self) -> crate::geometry::Box3 {
        crate::geometry::Box3::new(self.center.into(), self.size, self.yaw)
    }
}

/// Milliseconds spent per stage on one frame.
#[derive(Copy, Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct StageTimes {
    /// Reading the .bin.
    pub read_ms: f64,
    /// Plane segmentation.
    pub planes_ms: f64,
    /// Clustering.
    pub clusters_ms: f64,
    /// Filter step and estimate extraction.
    pub filter_ms: f64,
    /// Lidar odometry, when the ego motion comes from the scans (0 otherwise).
    #[serde(default)]
    pub ego_ms: f64,
    /// What of the stages ran side by side with this frame's segmentation: planes and
    /// clusters plus the work beside them (in the tracking loop the filter's update of the
    /// frame before, its prediction to this one and the read of the next scan; in
    /// [`super::DriveTracker::step_scan`] the prediction) less the wall time of the two
    /// sides. 0 when everything ran one after the other.
    #[serde(default)]
    pub overlap_ms: f64,
}

impl StageTimes {
    /// Read, planes, clusters and filter less what of them ran side by side: the frame's
    /// wall time without lidar odometry.
    pub fn total_ms(&self) -> f64 {
        self.read_ms + self.planes_ms + self.clusters_ms + self.filter_ms - self.overlap_ms
    }
}

/// One frame of the tracking output.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TrackedFrame {
    /// Frame number in the drive.
    pub frame: usize,
    /// Seconds since the first frame of the drive.
    pub time: f64,
    /// Sensor position in the world (m).
    pub ego_position: [f64; 3],
    /// Sensor heading (yaw about world z, rad).
    pub ego_yaw: f64,
    /// Wall detections of the frame.
    pub detected_planes: usize,
    /// Cluster detections of the frame.
    pub detected_clusters: usize,
    /// Confirmed walls.
    pub planes: Vec<TrackedPlane>,
    /// Confirmed clusters.
    pub clusters: Vec<TrackedCluster>,
    /// Stage times.
    pub times: StageTimes,
}

/// Whole-drive figures.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TrackingSummary {
    /// Frames tracked.
    pub frames: usize,
    /// Mean confirmed walls per frame.
    pub mean_planes: f64,
    /// Mean confirmed clusters per frame.
    pub mean_clusters: f64,
    /// Distinct wall labels ever confirmed.
    pub plane_labels: usize,
    /// Distinct cluster labels ever confirmed.
    pub cluster_labels: usize,
    /// Mean stage times per frame.
    pub mean_times: StageTimes,
    /// Frames whose lidar odometry was not trusted and kept the constant-velocity pose
    /// ([`crate::cloud::odometry::Fallback`]); 0 with recorded poses.
    #[serde(default)]
    pub ego_fallbacks: usize,
}

impl TrackingSummary {
    /// The summary of `frames`.
    pub fn of(frames: &[TrackedFrame]) -> Self {
        let n = frames.len();
        if n == 0 {
            return TrackingSummary::default();
        }
        let nf = n as f64;
        let mut planes = std::collections::BTreeSet::new();
        let mut clusters = std::collections::BTreeSet::new();
        let mut t = StageTimes::default();
        for f in frames {
            planes.extend(f.planes.iter().map(|p| p.label));
            clusters.extend(f.clusters.iter().map(|c| c.label));
            t.read_ms += f.times.read_ms / nf;
            t.ego_ms += f.times.ego_ms / nf;
            t.planes_ms += f.times.planes_ms / nf;
            t.clusters_ms += f.times.clusters_ms / nf;
            t.filter_ms += f.times.filter_ms / nf;
            t.overlap_ms += f.times.overlap_ms / nf;
        }
        TrackingSummary {
            frames: n,
            mean_planes: frames.iter().map(|f| f.planes.len()).sum::<usize>() as f64 / nf,
            mean_clusters: frames.iter().map(|f| f.clusters.len()).sum::<usize>() as f64 / nf,
            plane_labels: planes.len(),
            cluster_labels: clusters.len(),
            mean_times: t,
            ego_fallbacks: 0,
        }
    }
}

/// The whole output of one drive.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DriveTracks {
    /// Drive name (folder name).
    pub drive: String,
    /// Random seed of the run.
    pub seed: u64,
    /// Particles per track.
    pub particles: usize,
    /// Where the ego motion came from: `oxts`, `oxts+ect` or `none` (identity poses).
    pub ego: String,
    /// Per frame.
    pub frames: Vec<TrackedFrame>,
    /// Whole-drive figures.
    pub summary: TrackingSummary,
}

impl DriveTracks {
    /// Writes pretty JSON atomically.
    pub fn write_json(&self, path: &Path) -> Result<()> {
        write_atomically(path, |w| {
            serde_json::to_writer_pretty(&mut *w, self).map_err(std::io::Error::other)?;
            w.write_all(b"\n")
        })
    }

    /// Reads a file written by [`DriveTracks::write_json`].
    pub fn read_json(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        serde_json::from_str(&text).map_err(|e| {
            Error::parse(
                path,
                e.line(),
                "tracking output",
                format!("not a tracking output: {e}"),
            )
        })
    }
}
