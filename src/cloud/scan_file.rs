//! One lidar scan file of a recording, whatever its format: a KITTI `.bin` or a PCD (what PCL
//! and ROS write), chosen by the extension, so that every recording layout takes folders of
//! either.
//!
//! Not for: finding the scan files of a recording (see [`crate::kitti`]).

use super::kitti_bin::{read_kitti_bin_with, BinScan, NonFinite};
use super::pcd_io::read_pcd_with;
use crate::error::Result;
use std::path::Path;

/// Whether `path` names a PCD file (extension `pcd`, any case).
pub fn is_pcd(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("pcd"))
}

/// Reads a scan: a PCD file by [`read_pcd_with`] (its labels dropped), anything else as a
/// KITTI `.bin`; `policy` decides what a point with a non-finite value does. Errors name the
/// file.
pub fn read_scan_with(path: impl AsRef<Path>, policy: NonFinite) -> Result<BinScan> {
    let path = path.as_ref();
    if is_pcd(path) {
        let scan = read_pcd_with(path, policy)?;
        Ok(BinScan {
            cloud: scan.cloud,
            skipped: scan.skipped,
        })
    } else {
        read_kitti_bin_with(path, policy)
    }
}
