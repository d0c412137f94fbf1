//! Criterion benchmark of a whole recording as `track` runs it: eight frames of drive 0005
//! (seed 001's drive, with its OXTS poses) from the shared data, tracked
//!
//! * `recording/overlapped`: by `track_recording`, which segments scan k while the filter updates
//!   frame k − 1, predicts to frame k and reads scan k + 1;
//! * `recording/one_after_another`: by a plain loop that reads, segments and steps one frame
//!   after the other (the same tracks).
//!
//! Throughput is in frames. Without the shared data it says so and measures nothing.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use smc_lmb::kitti::RawDrive;
use smc_lmb::pipeline::drive_tracking::{
    detect_objects, segment_rng, track_recording, DriveTracker, TrackingConfig,
};
use smc_lmb::recording::Recording;
use std::path::Path;
use std::time::Duration;

const FRAMES: usize = 8;
const SEED: u64 = 1;

fn recording(c: &mut Criterion) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data/kitti_raw/2011_09_26/2011_09_26_drive_0005_sync");
    let Ok(drive) = RawDrive::open(&dir) else {
        println!("recording: {} is absent, nothing measured", dir.display());
        return;
    };
    let config = TrackingConfig::default();
    let poses = drive.poses().expect("OXTS poses");
    let times = drive.timestamps().expect("time stamps").seconds;
    let mut g = c.benchmark_group("recording");
    g.sample_size(10)
        .measurement_time(Duration::from_secs(6))
        .warm_up_time(Duration::from_millis(500));
    g.throughput(Throughput::Elements(FRAMES as u64));
    g.bench_function("overlapped", |b| {
        b.iter(|| track_recording(&drive, Some(0..FRAMES), &config, SEED, |_| Ok(())).unwrap())
    });
    g.bench_function("one_after_another", |b| {
        b.iter(|| {
            let mut tracker = DriveTracker::new(&config, SEED).unwrap();
            (0..FRAMES)
                .map(|k| {
                    let cloud = drive.scan(k).unwrap();
                    let det = detect_objects(&cloud, &config, &mut segment_rng(SEED, k)).unwrap();
                    tracker.step(k, times[k], poses[k], None, &det).unwrap()
                })
                .count()
        })
    });
    g.finish();
}

criterion_group!(benches, recording);
criterion_main!(benches);
