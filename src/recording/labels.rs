//! A recording's own ground truth, in the form its layout keeps it: what
//! [`Recording::labels`](super::Recording::labels) returns and the evaluation
//! (`pipeline::drive_evaluation::evaluate_recording`) scores tracks against.
//!
//! Not for: reading the label files (see [`crate::kitti`] and [`crate::sim::street`]) or
//! scoring (see [`crate::pipeline::drive_evaluation`]).

use crate::kitti::{TrackingCalib, TrackingLabel, Tracklets};
use crate::sim::street::StreetTruth;

/// A recording's labels.
#[derive(Clone, Debug)]
pub enum RecordingLabels {
    /// A KITTI tracking sequence's `label_02` boxes (rectified camera frame, what camera 2
    /// sees) with the calibration that moves them into the Velodyne frame and tells what
    /// camera 2 sees.
    Camera {
        /// The labels of every frame.
        labels: Vec<TrackingLabel>,
        /// The sequence's calibration.
        calib: Box<TrackingCalib>,
    },
    /// A KITTI raw drive's `tracklet_labels.xml` (Velodyne frame, all around the vehicle).
    Tracklets(Tracklets),
    /// A simulated street's `truth.json`: its objects and walls.
    Street(Box<StreetTruth>),
}

impl RecordingLabels {
    /// Whether scoring against them needs the recording's poses: tracklets and tracking
    /// labels are given per frame in the sensor frame, a simulated street's truth in the
    /// world frame.
    pub fn needs_poses(&self) -> bool {
        !matches!(self, RecordingLabels::Street(_))
    }

    /// What the labels are, for messages.
    pub fn kind(&self) -> &'static str {
        match self {
            RecordingLabels::Camera { .. } => "tracking labels (label_02)",
            RecordingLabels::Tracklets(_) => "tracklets",
            RecordingLabels::Street(_) => "a simulated street's truth",
        }
    }
}
