//! Planar (2D) laser scanners: scans and the adaptive breakpoint segmentation that turns a
//! scan into candidate objects.
//!
//! * [`scan`]: [`Scan`] (polar beams, "no return" policy, Cartesian points), [`Pose2`],
//!   [`OdometryRecord`].
//! * [`segment`]: the adaptive breakpoint detector (seed 000, eq. 15) and [`Segment`]s.
//!
//! Not for: background subtraction, shape features, tracking or mapping — segments are the
//! hand-over point to the detectors and the filter.

pub mod scan;
pub mod segment;

pub use self::scan::{attach_odometry, OdometryRecord, Pose2, Scan};
pub use self::segment::{breakpoint_threshold, segment_scan, BreakpointConfig, Segment};
