//! Planar (2D) laser scanners: scans, the readers that load them from real recordings, and
//! the adaptive breakpoint segmentation that turns a scan into candidate objects.
//!
//! * [`scan`]: [`Scan`] (polar beams, "no return" policy, Cartesian points), [`Pose2`],
//!   [`OdometryRecord`].
//! * [`carmen`]: CARMEN logs (`FLASER`, `ROBOTLASER1`, `ODOM`; plain, `.gz`, `.bz2`),
//!   streamed line by line.
//! * [`rosbag`]: `sensor_msgs/LaserScan` and `nav_msgs/Odometry` from ROS 1 bags.
//! * [`csv`]: the project's own one-scan-per-line text format, read and written.
//! * [`segment`]: the adaptive breakpoint detector (seed 000, eq. 15) and [`Segment`]s.
//! * [`moving`]: moving-object detection from a moving platform (seed 003), built from
//!   [`rigid`] (planar motions), [`icp`] (scan matching), [`local_map`] (averaged static
//!   points), [`background`] (per-beam background map), [`features`] (segment shape
//!   features) and [`fuzzy_art`] (on-line shape categories).
//!   [`moving_rule`] decides which clusters are moving; [`front_end`] turns a scan into the
//!   trackers' measurements (every person-sized segment, or only the moving ones).
//! * [`tracking`]: people tracking with the LMB filter; [`people_birth`] its birth model,
//!   [`innovation`] the innovations of its tracks for consistency checks,
//!   [`motion_state`] the static/dynamic classification of its tracks, [`person_groups`]
//!   the grouping of returns into person candidates, [`people_run`] a whole recording.
//!
//! Not for: tracking or global mapping — segments and moving clusters are the hand-over
//! point to the filter.
//!
//! ```
//! use smc_lmb::laser2d::{segment_scan, BreakpointConfig, Scan};
//! let ranges = vec![3.0_f32; 30];
//! let scan = Scan::new(0.0, -0.3, 0.02, ranges, 0.0, 30.0).unwrap();
//! let segments = segment_scan(&scan, &BreakpointConfig::default()).unwrap();
//! assert_eq!(segments.len(), 1);
//! ```

pub mod background;
pub mod carmen;
pub mod csv;
pub mod evaluate;
pub mod features;
pub mod front_end;
pub mod fuzzy_art;
pub mod icp;
pub mod innovation;
pub mod local_map;
pub mod motion_state;
pub mod moving;
pub mod moving_rule;
pub mod people_birth;
pub mod people_run;
pub mod person_groups;
pub mod rigid;
pub mod rosbag;
pub mod scan;
pub mod segment;
pub mod tracking;

pub use self::carmen::{
    read_carmen, CarmenLog, CarmenOptions, CarmenReader, CarmenRecord, CarmenStats, OnMalformed,
    TimeOrder,
};
pub use self::csv::{read_scan_csv, write_scan_csv};
pub use self::motion_state::{probability_moving, MotionClassifier, MotionConfig};
pub use self::moving::{
    MovingCluster, MovingDetections, MovingDetectorConfig, MovingObjectDetector,
};
pub use self::people_birth::PeopleBirth;
pub use self::people_run::{
    config_for_scans, track_scans, track_scans_with, write_people_json, PeopleRun, PersonTrack,
    ScanPeople,
};
pub use self::person_groups::{person_groups, PersonGroup, PersonGrouping};
pub use self::rosbag::{bag_topics, read_bag, BagOptions, BagScans, BagTopic, OdometryTopic};
pub use self::scan::{attach_odometry, OdometryRecord, Pose2, Scan};
pub use self::segment::{breakpoint_threshold, segment_scan, BreakpointConfig, Segment};
pub use self::tracking::{
    centre_noise, person_measurements, person_segments, PeopleTracker, PeopleTrackerConfig,
    PersonEstimate,
};
