//! Multi-object performance metrics for judging a tracker against ground truth.
//!
//! Everything here is a pure function of truth and estimates (plus one small frame-by-frame
//! accumulator for label statistics); nothing here runs or steers a filter.
//!
//! | Module | Measures |
//! |---|---|
//! | [`ospa`](mod@ospa) | OSPA distance between two point sets, split into localisation and cardinality |
//! | [`gospa`](mod@gospa) | GOSPA (α = 2) with localisation / missed / false-alarm parts |
//! | [`ospa2`](mod@ospa2) | OSPA(2) between sets of tracks over a time window (and a sliding series) |
//! | [`cardinality`] | Per-step and mean error in the number of objects |
//! | [`detection_ap`] | KITTI's average precision of 3-D detections (11 and 40 recall points, easy / moderate / hard) |
//! | [`labels`] | Label switches and label persistence of estimates matched to truth |
//! | [`plane_prediction`] | Area, vertex-distance and normal-angle errors of predicted plane patches |
//! | [`recall`] | Found-of-how-many tallies, and recall by KITTI occlusion level and range |
//! | [`rmse`] | RMS error of error vectors and the averaged-NIS consistency check |
//! | [`tracking`](mod@tracking) | HOTA, CLEAR MOT and IDF1 of tracks against truth, computed as TrackEval does |
//! | [`trajectory`] | Relative pose errors and KITTI's segment errors of an ego trajectory |
//!
//! Points are slices of `f64` coordinates of any (common) dimension; all distances between
//! points are Euclidean. Functions accept anything that derefs to `[f64]` per point, so a
//! `Vec<Vec<f64>>` can be passed as `&v`.
//!
//! Inputs that would make a metric meaningless (a cut-off that is not positive and finite, an
//! order below one, non-finite coordinates, points of different dimensions) are reported as
//! [`Error::InvalidInput`](crate::Error::InvalidInput) values; empty inputs are never errors
//! for the set metrics.

pub mod cardinality;
pub mod detection_ap;
pub mod gospa;
pub mod labels;
pub mod ospa;
pub mod ospa2;
pub mod plane_prediction;
mod points;
pub mod recall;
pub mod rmse;
pub mod tracking;
pub mod trajectory;

pub use cardinality::{cardinality_error, CardinalityError};
pub use gospa::{gospa, Gospa};
pub use labels::{LabelConsistency, LabelStats, TruthLabels};
pub use ospa::{ospa, Ospa};
pub use ospa2::{ospa2, ospa2_parts, ospa2_series, tracks_from_frames, TrackHistory};
pub use plane_prediction::{
    associate_planes, percentile, PlanePairError, PlanePredictionSummary, WallGate,
};
pub use rmse::{average_nis, chi_square_quantile, rms_error, NisCheck};
pub use trajectory::{
    path_length, relative_pose_errors, segment_errors, PoseError, SegmentErrors, Spread,
    KITTI_SEGMENT_LENGTHS,
};
