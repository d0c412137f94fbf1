//! Point clouds: the [`PointCloud`] type (structure of arrays, f32) and the KITTI Velodyne
//! `.bin` reader and writer,
//! and Euclidean clustering of points into object candidates.
//!
//! Not for: finding the frames of a recording (see [`crate::kitti`]) or fitting
//! planes to the points.

pub mod cluster;
pub mod kitti_bin;
pub mod planes;
pub mod points;

pub use cluster::{euclidean_clusters, euclidean_clusters_of, Cluster, ClusterParams};
pub use kitti_bin::{read_kitti_bin, read_kitti_bin_with, write_kitti_bin, BinScan, NonFinite};
pub use points::{Bounds, Point, PointCloud};
