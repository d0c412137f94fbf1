//! Lidar odometry on real KITTI scans: drive 0005, frames 0–49 (a slow left bend, ~0.35 m a
//! frame, 17.4 m in all) against the drive's OXTS Velodyne poses. Skipped with a note when
//! `../shared/data` is absent (a failure under CI=true).
//!
//! The bounds come from KISS-ICP itself (pip package `kiss-icp` 1.3.0, default configuration,
//! no deskewing) on the same 50 scans, scored the same way (see `docs/odometry.md`): mean
//! per-frame errors of 0.0384 m and 0.0876°, and an end-point drift of 0.577 m (3.3 % of the
//! path; part of it is the OXTS reference's own error). The test asks for that level with
//! about a third of margin: 5 cm, 0.12° and 4.5 % of the path.

mod common;

use smc_lmb::cloud::odometry::{odometry_of_files, OdometryConfig};
use smc_lmb::kitti::RawDrive;
use smc_lmb::metrics::{path_length, relative_pose_errors, Spread};

const DRIVE: &str = "kitti_raw/2011_09_26/2011_09_26_drive_0005_sync";

fn follows_oxts(frames: usize) {
    let Some(dir) = common::shared_data(DRIVE) else {
        return;
    };
    let drive = RawDrive::open(&dir).expect("drive 0005");
    let reference = drive.poses().expect("OXTS Velodyne poses");
    let scans: Vec<_> = (0..frames).map(|k| drive.scans().path(k)).collect();
    let start = std::time::Instant::now();
    let estimate = odometry_of_files(&scans, &OdometryConfig::default(), |_, _| {}).unwrap();
    let ms = start.elapsed().as_secs_f64() * 1e3 / scans.len() as f64;

    let reference = &reference[..frames];
    let rpe = relative_pose_errors(&estimate, reference).unwrap();
    let t: Vec<f64> = rpe.iter().map(|e| e.translation).collect();
    let r: Vec<f64> = rpe.iter().map(|e| e.rotation_deg).collect();
    let (t, r) = (Spread::of(&t).unwrap(), Spread::of(&r).unwrap());
    let path = path_length(reference);
    let last = estimate.len() - 1;
    let drift = (reference[last].inverse() * estimate[last])
        .translation
        .vector
        .norm();
    println!(
        "{frames} frames, {ms:.0} ms/scan; path {path:.2} m (estimated {:.2} m); translation \
         mean {:.4} m, median {:.4} m, max {:.4} m; rotation mean {:.4}°, max {:.4}°; drift \
         {drift:.3} m",
        path_length(&estimate),
        t.mean,
        t.median,
        t.max,
        r.mean,
        r.max
    );
    // Scale: drive 0005 moves ~3.5 m/s, ~0.35 m a frame.
    let per_frame = path / last as f64;
    assert!(
        (0.3..0.4).contains(&per_frame),
        "reference {per_frame} m a frame"
    );
    assert!(t.mean < 0.05, "mean translational RPE {} m", t.mean);
    assert!(r.mean < 0.12, "mean rotational RPE {}°", r.mean);
    assert!(drift < 0.045 * path, "drift {drift} m over {path} m");
}

#[test]
fn drive_0005_follows_the_oxts_trajectory() {
    follows_oxts(50);
}
