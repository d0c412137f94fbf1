//! Point clouds: the [`PointCloud`] type (structure of arrays, f32) and the KITTI Velodyne
//! `.bin` reader and writer, LAS, PLY and PCD import/export, a scan read by its format
//! ([`read_scan_with`]) (optionally coloured by label),
//! Euclidean clustering of points into object candidates, the range image of a spinning
//! scan with its ground and angle-criterion clusters ([`range_image`]), and lidar odometry
//! (the scanner's motion from its own scans, [`odometry`]).
//!
//! Not for: finding the frames of a recording (see [`crate::kitti`]) or fitting
//! planes to the points.

pub mod boxes;
pub mod classes;
pub mod cluster;
pub mod fragments;
pub mod kitti_bin;
pub mod las_io;
pub mod odometry;
pub mod other_class;
pub mod palette;
pub mod pcd_io;
pub mod planes;
pub mod ply_io;
pub mod points;
pub mod range_image;
pub mod scan_file;
pub mod voxel_groups;

/// Azimuth spacing of a KITTI HDL-64E's points at 10 Hz (rad): about 2,000 points per laser
/// and turn (≈ 125,000 points per scan over 64 lasers), 2π / 2,000 ≈ 0.0031. The default of
/// every setting that needs the scanner's sampling step along a turn.
pub const HDL64E_AZIMUTH_STEP: f64 = 0.0031;

pub use cluster::{euclidean_clusters, euclidean_clusters_of, Cluster, ClusterParams};
pub use kitti_bin::{read_kitti_bin, read_kitti_bin_with, write_kitti_bin, BinScan, NonFinite};
pub use las_io::{read_las, write_las, write_las_labelled};
pub use palette::label_colour;
pub use pcd_io::{
    decode_pcd, encode_pcd, read_pcd, read_pcd_with, write_pcd, write_pcd_labelled, PcdEncoding,
    PcdScan,
};
pub use ply_io::{read_ply, write_ply, write_ply_labelled};
pub use points::{Bounds, Point, PointCloud};
pub use scan_file::{is_pcd, read_scan_with};
