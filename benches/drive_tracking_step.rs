//! Criterion benchmark of one frame of the drive tracker's filter update: ~10 wall planes and
//! ~30 clusters, each a track of 1000 particles, in one mixed LMB filter (a static sensor,
//! the same detections every frame, after a warm-up that confirms every object).

use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::{Isometry3, Point3, Vector3};
use smc_lmb::geometry::{Plane, PlanePatch};
use smc_lmb::pipeline::drive_tracking::{
    ClusterDetection, DriveTracker, FrameDetections, TrackingConfig, WallDetection,
};
use std::time::Duration;

fn detections() -> FrameDetections {
    let walls = (0..10)
        .map(|i| {
            let a = (i as f64 * 36.0).to_radians();
            let r = 8.0 + i as f64;
            let (dir, side) = (
                Vector3::new(a.cos(), a.sin(), 0.0),
                Vector3::new(-a.sin(), a.cos(), 0.0),
            );
            let plane = Plane::new(-dir, r).expect("unit normal");
            let c = Point3::from(dir * r);
            let corners: Vec<Point3<f64>> = [(-5.0, -1.7), (5.0, -1.7), (5.0, 3.0), (-5.0, 3.0)]
                .iter()
                .map(|&(s, z)| c + side * s + Vector3::z() * z)
                .collect();
            WallDetection {
                patch: PlanePatch::from_points(plane, &corners).expect("finite corners"),
                indices: Vec::new(),
            }
        })
        .collect();
    let clusters = (0..30)
        .map(|j| {
            let a = (j as f64 * 12.0 + 5.0).to_radians();
            let r = 5.0 + (j % 6) as f64 * 1.5;
            ClusterDetection::around([r * a.cos(), r * a.sin(), -0.8], [1.0, 1.0, 1.5])
        })
        .collect();
    FrameDetections {
        walls,
        clusters,
        ..FrameDetections::default()
    }
}

fn drive_step(c: &mut Criterion) {
    let config = TrackingConfig::default();
    let det = detections();
    let mut tracker = DriveTracker::new(&config, 1).expect("default config is valid");
    let pose = Isometry3::identity();
    let mut k = 0usize;
    for _ in 0..5 {
        tracker
            .step(k, k as f64 * 0.1, pose, None, &det)
            .expect("step");
        k += 1;
    }
    let mut g = c.benchmark_group("drive_tracking");
    g.sample_size(10).measurement_time(Duration::from_secs(10));
    g.bench_function("step/10_walls_30_clusters_1000_particles", |b| {
        b.iter(|| {
            let f = tracker
                .step(k, k as f64 * 0.1, pose, None, &det)
                .expect("step");
            k += 1;
            f
        })
    });
    g.finish();
}

criterion_group!(benches, drive_step);
criterion_main!(benches);
