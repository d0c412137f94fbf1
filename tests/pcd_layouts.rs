//! Recordings kept as PCD: a raw drive, a tracking sequence and an odometry sequence whose
//! scan folders hold `.pcd` files instead of `.bin` read the same clouds, and a drive tracked
//! from PCD gives the same tracks as from `.bin`.

use smc_lmb::cloud::{read_kitti_bin, write_kitti_bin, write_pcd, PcdEncoding, PointCloud};
use smc_lmb::kitti::{OdometrySequence, RawDrive, TrackingSequence};
use smc_lmb::pipeline::drive_tracking::{track_recording, TrackingConfig};
use smc_lmb::recording::Recording;
use std::path::{Path, PathBuf};

/// The vendored real frame and a copy of it shifted 0.3 m forward (a second, different scan).
fn scans() -> Vec<PointCloud> {
    let bin = Path::new(env!("CARGO_MANIFEST_DIR")).join(
        "tests/data/kitti/2011_09_26/2011_09_26_drive_UNKNOWN_sync/velodyne_points/data/0000000000.bin",
    );
    let first = read_kitti_bin(&bin).unwrap();
    let mut second = first.clone();
    for x in second.columns_mut().0 {
        *x += 0.3;
    }
    vec![first, second]
}

/// Writes `clouds` into `dir` as `.bin` or `.pcd` files named by `name(k)`.
fn write_scans(dir: &Path, clouds: &[PointCloud], pcd: bool, name: impl Fn(usize) -> String) {
    std::fs::create_dir_all(dir).unwrap();
    for (k, c) in clouds.iter().enumerate() {
        let stem = name(k);
        if pcd {
            let encoding = [PcdEncoding::Binary, PcdEncoding::BinaryCompressed][k % 2];
            write_pcd(dir.join(format!("{stem}.pcd")), c, encoding).unwrap();
        } else {
            write_kitti_bin(dir.join(format!("{stem}.bin")), c).unwrap();
        }
    }
}

fn raw_drive(root: &Path, clouds: &[PointCloud], pcd: bool) -> PathBuf {
    let drive = root.join("2011_09_26/2011_09_26_drive_0000_sync");
    write_scans(&drive.join("velodyne_points/data"), clouds, pcd, |k| {
        format!("{k:010}")
    });
    drive
}

#[test]
fn every_layout_reads_pcd_scan_folders() {
    let clouds = scans();
    let tmp = tempfile::tempdir().unwrap();

    let drive = RawDrive::open(raw_drive(tmp.path(), &clouds, true)).unwrap();
    assert_eq!(drive.frame_count(), 2);
    assert!(drive.scans().path(1).ends_with("0000000001.pcd"));
    for (k, c) in clouds.iter().enumerate() {
        assert_eq!(&drive.scan(k).unwrap(), c, "raw drive frame {k}");
    }

    let tracking = tmp.path().join("tracking/training");
    write_scans(&tracking.join("velodyne/0004"), &clouds, true, |k| {
        format!("{k:06}")
    });
    let seq = TrackingSequence::open(&tracking, 4).unwrap();
    assert_eq!(seq.frame_count(), 2);
    assert_eq!(&seq.scan(1).unwrap(), &clouds[1]);

    let odometry = tmp.path().join("odometry");
    write_scans(
        &odometry.join("sequences/07/velodyne"),
        &clouds,
        true,
        |k| format!("{k:06}"),
    );
    let seq = OdometrySequence::open(&odometry, 7).unwrap();
    assert_eq!(seq.frame_count(), 2);
    assert_eq!(&seq.scan(0).unwrap(), &clouds[0]);
}

#[test]
fn a_folder_with_both_kinds_is_refused_naming_it() {
    let clouds = scans();
    let tmp = tempfile::tempdir().unwrap();
    let drive = raw_drive(tmp.path(), &clouds, true);
    write_kitti_bin(
        drive.join("velodyne_points/data/0000000002.bin"),
        &clouds[0],
    )
    .unwrap();
    let e = RawDrive::open(&drive).unwrap_err().to_string();
    assert!(
        e.contains("velodyne_points/data") && e.contains("both .bin (1) and .pcd (2)"),
        "{e}"
    );
}

#[test]
fn a_drive_tracked_from_pcd_matches_the_same_drive_from_bin() {
    let clouds = scans();
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let config = TrackingConfig {
        filter: smc_lmb::filter::LmbConfig {
            particles: 200,
            ..TrackingConfig::default().filter
        },
        ..TrackingConfig::default()
    };
    let run = |dir: PathBuf| {
        let drive = RawDrive::open(dir).unwrap();
        let mut t = track_recording(&drive, None, &config, 3, |_| Ok(())).unwrap();
        for f in &mut t.frames {
            f.times = Default::default();
        }
        t.drive = String::new();
        t.summary = Default::default();
        t
    };
    let from_bin = run(raw_drive(a.path(), &clouds, false));
    let from_pcd = run(raw_drive(b.path(), &clouds, true));
    assert_eq!(from_bin.frames.len(), 2);
    assert_eq!(from_pcd, from_bin);
}
