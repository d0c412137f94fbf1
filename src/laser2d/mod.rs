//! Planar (2D) laser scanners: scans, the readers that load them from real recordings, and
//! the adaptive breakpoint segmentation that turns a scan into candidate objects.
//!
//! * [`scan`]: [`Scan`] (polar beams, "no return" policy, Cartesian points),
//!   [`OdometryRecord`] (poses are [`crate::geometry::Pose2`]).
//! * [`carmen`]: CARMEN logs (`FLASER`, `ROBOTLASER1`, `ODOM`; plain, `.gz`, `.bz2`),
//!   streamed line by line.
//! * [`rosbag`]: `sensor_msgs/LaserScan` and `nav_msgs/Odometry` from ROS 1 bags.
//! * [`csv`]: the project's own one-scan-per-line text format, read and written.
//! * [`segment`]: the adaptive breakpoint detector (seed 000, eq. 15) and [`Segment`]s;
//!   [`person_groups`](mod@person_groups): the grouping of noisy returns into person-sized candidates.
//! * [`moving`]: moving-object detection from a moving platform (seed 003), built from
//!   [`icp`] (scan matching), [`local_map`] (averaged static points), [`background`]
//!   (per-beam background map), [`features`] (segment shape features) and [`fuzzy_art`]
//!   (on-line shape categories); [`moving_rule`] decides which clusters are moving.
//! * [`mounting`]: the mounting poses of several lasers on one platform, estimated by
//!   registering their overlapping views of a static scene.
//! * [`legs`]: people found by their legs, segments classed by a boosted classifier
//!   ([`boost`]) trained on annotated recordings.
//!
//! Not for: tracking — segments, person candidates and moving clusters are the hand-over
//! point to the people-tracking pipeline ([`crate::pipeline::people_tracking`]) — or global
//! mapping.
//!
//! ```
//! use smc_lmb::laser2d::{segment_scan, BreakpointConfig, Scan};
//! let ranges = vec![3.0_f32; 30];
//! let scan = Scan::new(0.0, -0.3, 0.02, ranges, 0.0, 30.0).unwrap();
//! let segments = segment_scan(&scan, &BreakpointConfig::default()).unwrap();
//! assert_eq!(segments.len(), 1);
//! ```

pub mod background;
pub mod boost;
pub mod carmen;
pub mod csv;
pub mod features;
pub mod fuzzy_art;
pub mod icp;
pub mod leg_augment;
pub mod legs;
pub mod local_map;
pub mod mounting;
pub mod moving;
pub mod moving_rule;
pub mod nearest;
pub mod person_groups;
pub mod rosbag;
pub mod scan;
pub mod segment;

pub use self::carmen::{
    read_carmen, CarmenLog, CarmenOptions, CarmenReader, CarmenRecord, CarmenStats, OnMalformed,
    TimeOrder,
};
pub use self::csv::{read_scan_csv, write_scan_csv};
pub use self::moving::{
    MovingCluster, MovingDetections, MovingDetectorConfig, MovingObjectDetector, PoseFallback,
};
pub use self::person_groups::{person_groups, PersonGroup, PersonGrouping};
pub use self::rosbag::{
    bag_topics, read_bag, read_pose_arrays, BagOptions, BagScans, BagTopic, OdometryTopic,
    PoseArrayRecord,
};
pub use self::scan::{attach_odometry, OdometryRecord, Scan};
pub use self::segment::{breakpoint_threshold, segment_scan, BreakpointConfig, Segment};
pub use crate::geometry::Pose2;
