//! Point clouds: the [`PointCloud`] type (structure of arrays, f32) and the KITTI Velodyne
//! `.bin` reader and writer.
//!
//! Not for: finding the frames of a recording (see [`crate::kitti`]) or detecting objects in
//! the points.

pub mod kitti_bin;
pub mod planes;
pub mod points;

pub use kitti_bin::{read_kitti_bin, read_kitti_bin_with, write_kitti_bin, BinScan, NonFinite};
pub use points::{Bounds, Point, PointCloud};
