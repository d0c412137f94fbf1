//! KITTI data on disk: raw drives ([`RawDrive`]: Velodyne scans, OXTS packets, time stamps,
//! calibration), OXTS → poses and planar vehicle states, object tracklets, the odometry
//! benchmark layout ([`OdometrySequence`]) and the tracking benchmark layout
//! ([`TrackingSequence`]) with its `label_02` labels ([`TrackingLabel`]). Each reader returns
//! errors that name the file, line and field at fault.
//!
//! Not for: detecting or tracking anything in the data; point-cloud storage lives in
//! [`crate::cloud`].

pub mod calib;
pub mod drive;
pub mod frames;
pub mod issue;
pub mod labels;
pub mod object;
pub mod odometry;
pub mod oxts;
pub mod poses;
mod text;
pub mod timestamps;
pub mod tracking;
pub mod tracklets;

pub use calib::{read_cam_to_cam, read_rigid_calib, CalibFile, CamToCamCalib, RigidCalib};
pub use drive::RawDrive;
pub use frames::{frame_file_name, ScanFolder};
pub use issue::Issue;
pub use labels::{
    read_tracking_labels, write_tracking_labels, ObjectType, TrackingLabel, VelodyneBox,
};
pub use odometry::OdometrySequence;
pub use oxts::{
    read_oxts_dir, read_oxts_file, write_oxts_dir, write_oxts_file, OxtsPacket, OXTS_FIELDS,
};
pub use poses::{imu_poses, vehicle_states, velodyne_poses, Mercator, VehicleState};
pub use timestamps::{read_timestamps, write_timestamps, Timestamp, Timestamps};
pub use tracking::{TrackingCalib, TrackingSequence};
pub use tracklets::{read_tracklets, write_tracklets, ObjectAt, Tracklet, TrackletPose, Tracklets};
