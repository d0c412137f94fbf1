//! End-to-end processing chains that combine readers, detectors, models and metrics, e.g.
//! segmenting walls in consecutive LiDAR frames, predicting them forward and scoring the
//! prediction ([`plane_prediction`]); tracking walls and clusters through a whole drive
//! ([`drive_tracking`]) and scoring the tracks against ground truth ([`drive_evaluation`]);
//! scoring the tracker's detector on single labelled scans ([`object_frame_eval`]);
//! tracking people in planar laser scans and scoring the trackers ([`people_tracking`]).
//!
//! Not for: the filter itself (see [`crate::filter`]) or command-line parsing.

#[cfg(feature = "kitti")]
pub mod plane_prediction;

#[cfg(feature = "kitti")]
pub use plane_prediction::{
    predict_pairs, predict_planes_between, predict_walls, segment_walls, EgoMotion, PairPrediction,
    PlanePredictionConfig,
};

#[cfg(feature = "kitti")]
pub mod drive_tracking;
#[cfg(feature = "kitti")]
pub use drive_tracking::{track_recording, DriveTracker, DriveTracks, TrackingConfig};

#[cfg(feature = "kitti")]
pub mod drive_evaluation;
#[cfg(feature = "kitti")]
pub mod kitti_tracking_eval;
#[cfg(feature = "kitti")]
pub mod object_frame_eval;

#[cfg(feature = "kitti")]
pub mod box_baseline;
#[cfg(feature = "kitti")]
pub mod kitti_results;

#[cfg(feature = "laser2d")]
pub mod people_tracking;
#[cfg(feature = "kitti")]
pub use drive_evaluation::{evaluate_clusters, evaluate_walls, ClusterEvaluation, WallEvaluation};
