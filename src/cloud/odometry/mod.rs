//! Lidar odometry: the ego motion of a scanner from its own scans, by KISS-ICP's recipe
//! (Vizzo et al., "KISS-ICP: In Defense of Point-to-Point ICP", RA-L 2023) followed by a
//! point-to-plane refinement against the local map's planes ([`refine`]; on by default,
//! `refine_iterations: 0` leaves KISS-ICP's recipe alone).
//!
//! One file per concept:
//!
//! | module | what |
//! |---|---|
//! | [`config`](mod@config) | [`OdometryConfig`], KISS-ICP's defaults for a 64-beam sensor |
//! | [`downsample`] | range cropping and voxel downsampling |
//! | [`voxel_map`] | [`VoxelHashMap`], the local map and its nearest-neighbour lookup |
//! | [`threshold`] | [`AdaptiveThreshold`], σ from the recent model deviations |
//! | [`se3`] | the SE(3) exponential for the Gauss–Newton updates |
//! | [`registration`] | point-to-point ICP with a Geman–McClure kernel |
//! | [`refine`] | point-to-plane refinement against a plane per map voxel |
//! | [`pipeline`] | [`LidarOdometry`]: preprocess → voxelize → threshold → align → refine → update |
//!
//! ```no_run
//! use smc_lmb::cloud::odometry::{LidarOdometry, OdometryConfig};
//! use smc_lmb::cloud::read_kitti_bin;
//! let mut odometry = LidarOdometry::new(OdometryConfig::default())?;
//! for k in 0..10 {
//!     let scan = read_kitti_bin(format!("velodyne_points/data/{k:010}.bin"))?;
//!     let pose = odometry.register(&scan)?.pose; // scan k → scan 0
//! }
//! # Ok::<(), smc_lmb::Error>(())
//! ```
//!
//! Results do not depend on the number of rayon threads (see [`registration`] and [`refine`]).
//! Deskewing (motion compensation within a sweep) is left out: KITTI `.bin` scans carry no
//! per-point time.
//!
//! Not for: loop closure or global mapping.

pub mod config;
pub mod downsample;
pub mod pipeline;
pub mod refine;
pub mod registration;
pub mod se3;
pub mod threshold;
pub mod voxel_map;

#[cfg(test)]
mod test_scene;

pub use config::OdometryConfig;
pub use downsample::{crop_range, voxel_downsample};
pub use pipeline::{
    odometry_of_files, odometry_of_files_at, odometry_of_frames, odometry_of_frames_with,
    odometry_of_scans_at, Fallback, LidarOdometry, Registered,
};
pub use refine::{fit_plane, refine_point_to_plane, Plane, RefineParams};
pub use registration::{align_points_to_map, Alignment, IcpParams};
pub use threshold::AdaptiveThreshold;
pub use voxel_map::{Voxel, VoxelHashMap};
