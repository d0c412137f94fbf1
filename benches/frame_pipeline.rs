//! Criterion benchmarks of the per-frame 3-D path on a real KITTI HDL-64E frame.
//!
//! The frame is `0000000000.bin` of the shared raw drive (`../shared/data/kitti_raw/…`,
//! ~117,700 points) when that folder sits beside the checkout, otherwise the vendored
//! subsampled copy under `tests/data/kitti/…` (every 8th point, 14,714 points); the name of
//! the frame used is printed first.
//!
//! Groups:
//! * `frame/read`: read and decode the `.bin`;
//! * `frame/planes`: ground and wall segmentation (`extract_planes`, default configuration);
//! * `frame/clusters`: Euclidean clustering of the points left after plane removal;
//! * `frame/read_planes_clusters`: the three in a row, as a frame is processed;
//! * `frame/filter_update`: reserved for the tracking filter's update on the frame's planes
//!   and clusters, once that pipeline exists (see `filter_update` below);
//! * `frame/standin_lmb_step_40x1000`: a STAND-IN for that update — one `LmbFilter` step
//!   with 40 tracks × 1000 particles of the 3-D constant-velocity model and a 3-D position
//!   measurement, one detection per track; it is not the plane/cluster tracking filter.

use criterion::{criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use smc_lmb::cloud::planes::{extract_planes, PlaneConfig};
use smc_lmb::cloud::{euclidean_clusters_of, read_kitti_bin, ClusterParams};
use smc_lmb::filter::birth::BirthEvidence;
use smc_lmb::filter::{
    BirthModel, BirthTerm, BirthTrack, Frame, LmbConfig, LmbFilter, Measurements, StaticBirth,
};
use smc_lmb::models::{
    ConstantDetection, ConstantVelocity, PositionMeasurement, StepContext, UniformClutter,
};
use smc_lmb::rng::seeded;
use smc_lmb::FilterRng;
use std::path::{Path, PathBuf};
use std::time::Duration;

const DRIVE: &str = "2011_09_26/2011_09_26_drive_UNKNOWN_sync/velodyne_points/data/0000000000.bin";

/// The full shared frame when present, else the vendored subsampled one.
fn frame_path() -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let shared = root.join("../shared/data/kitti_raw").join(DRIVE);
    if shared.is_file() {
        shared
    } else {
        root.join("tests/data/kitti").join(DRIVE)
    }
}

fn frame(c: &mut Criterion) {
    let path = frame_path();
    let cloud = read_kitti_bin(&path).expect("readable frame");
    println!("frame: {} ({} points)", path.display(), cloud.len());
    let planes = PlaneConfig::default();
    let clusters = ClusterParams::default();
    let seg = extract_planes(&cloud, &planes, &mut seeded(1)).expect("segmentation");
    let found = euclidean_clusters_of(&cloud, &seg.remaining, &clusters).expect("clusters");
    println!(
        "ground: {}, walls: {}, remaining: {}, clusters: {}",
        seg.ground.is_some(),
        seg.walls.len(),
        seg.remaining.len(),
        found.len()
    );

    let mut g = c.benchmark_group("frame");
    g.sample_size(20)
        .measurement_time(Duration::from_secs(4))
        .warm_up_time(Duration::from_millis(500));
    g.throughput(Throughput::Elements(cloud.len() as u64));
    g.bench_function("read", |b| b.iter(|| read_kitti_bin(&path).unwrap()));
    g.bench_function("planes", |b| {
        b.iter(|| extract_planes(&cloud, &planes, &mut seeded(1)).unwrap())
    });
    g.bench_function("clusters", |b| {
        b.iter(|| euclidean_clusters_of(&cloud, &seg.remaining, &clusters).unwrap())
    });
    g.bench_function("read_planes_clusters", |b| {
        b.iter(|| {
            let cloud = read_kitti_bin(&path).unwrap();
            let seg = extract_planes(&cloud, &planes, &mut seeded(1)).unwrap();
            euclidean_clusters_of(&cloud, &seg.remaining, &clusters).unwrap()
        })
    });
    filter_update(&mut g);
    standin_lmb_step(&mut g);
    g.finish();
}

/// Place for the tracking filter's update on one frame (~10 plane and ~30 cluster tracks at
/// 1000 particles each) once the tracking pipeline exists; add it to the group here and to
/// `read_planes_clusters` so the whole frame is timed together.
fn filter_update(_g: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>) {}

/// Births only at the first step: the tracks under test, and nothing new afterwards.
struct FirstStepOnly(StaticBirth);

impl BirthModel for FirstStepOnly {
    fn birth(
        &self,
        ctx: &StepContext,
        ev: Option<&BirthEvidence<'_>>,
        rng: &mut FilterRng,
    ) -> Vec<BirthTrack> {
        if ctx.step == 0 {
            self.0.birth(ctx, ev, rng)
        } else {
            Vec::new()
        }
    }
}

/// Stand-in for the tracking update: a 3-D CV filter with `targets` tracks of `particles`
/// particles each (objects 10 m apart), and the frame of the next step.
fn standin_filter(targets: usize, particles: usize) -> (LmbFilter, Frame) {
    let positions: Vec<[f64; 3]> = (0..targets)
        .map(|i| [10.0 * (i % 8) as f64, 10.0 * (i / 8) as f64, 0.5])
        .collect();
    let terms = positions
        .iter()
        .map(|p| BirthTerm {
            existence: 0.9,
            mean: vec![p[0], 1.0, p[1], 0.0, p[2], 0.0],
            std: vec![0.5, 0.5, 0.5, 0.5, 0.2, 0.1],
        })
        .collect();
    let mut filter = LmbFilter::builder()
        .transition(ConstantVelocity::new(3, 1.0).unwrap())
        .measurement(PositionMeasurement::new(3, 0.3).unwrap())
        .detection(ConstantDetection(0.9))
        .clutter(UniformClutter::new(5.0, 200.0 * 200.0 * 6.0).unwrap())
        .birth(FirstStepOnly(StaticBirth::new(terms, particles).unwrap()))
        .config(LmbConfig {
            particles,
            ..LmbConfig::default()
        })
        .build()
        .unwrap();
    let measure = |k: usize| {
        let z: Vec<[f64; 3]> = positions
            .iter()
            .map(|p| [p[0] + 0.1 * k as f64, p[1], p[2]])
            .collect();
        Frame::new(0.1 * k as f64, Measurements::from_rows(3, &z).unwrap())
    };
    filter.step(&measure(0), &mut seeded(1)).unwrap();
    (filter, measure(1))
}

fn standin_lmb_step(g: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>) {
    g.throughput(Throughput::Elements(40 * 1000));
    g.bench_function("standin_lmb_step_40x1000", |b| {
        b.iter_batched(
            || standin_filter(40, 1000),
            |(mut f, z)| f.step(&z, &mut seeded(2)).unwrap(),
            BatchSize::LargeInput,
        )
    });
}

criterion_group!(benches, frame);
criterion_main!(benches);
