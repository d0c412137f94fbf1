//! Criterion benchmarks of the range-image path on a real KITTI HDL-64E frame, against the
//! exact Euclidean clustering it replaces in the drive detector.
//!
//! The frame is `0000000000.bin` of the shared raw drive (`../shared/data/kitti_raw/…`,
//! ~117,700 points) when that folder sits beside the checkout, otherwise the vendored
//! subsampled copy under `tests/data/kitti/…` (every 8th point); the frame used is printed.
//!
//! Groups (`range_image/…`):
//! * `build`: rings from the scan order, azimuth bins, the cell grid;
//! * `ground`: column-wise ground segmentation on the image;
//! * `clusters`: angle-criterion clustering of the points on neither ground nor wall (the
//!   plane stage's `remaining`), on the already built image;
//! * `build_ground_clusters`: the three in a row (ground removed by the image's own ground);
//! * `euclidean`: the exact Euclidean clustering of the same `remaining` points.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use smc_lmb::cloud::planes::{extract_planes, PlaneConfig};
use smc_lmb::cloud::range_image::{
    ground_mask, range_image_clusters, GroundParams, ImageClusterParams, RangeImage,
    RangeImageConfig,
};
use smc_lmb::cloud::{euclidean_clusters_of, read_kitti_bin, ClusterParams};
use smc_lmb::rng::seeded;
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

fn range_image(c: &mut Criterion) {
    let path = frame_path();
    let cloud = read_kitti_bin(&path).expect("readable frame");
    let config = RangeImageConfig::default();
    let image = RangeImage::new(&cloud, &config).expect("range image");
    let seg = extract_planes(&cloud, &PlaneConfig::default(), &mut seeded(1)).expect("planes");
    let ground = GroundParams::default();
    let image_params = ImageClusterParams {
        near_distance: 0.5,
        max_distance: 1.0,
        min_points: 15,
        max_points: 20_000,
        ..Default::default()
    };
    let exact = ClusterParams {
        tolerance: 0.5,
        min_points: 15,
        max_points: 20_000,
    };
    println!(
        "frame: {} ({} points), image {:?} {}×{}, {} remaining after planes",
        path.display(),
        cloud.len(),
        image.source(),
        image.rows(),
        image.cols(),
        seg.remaining.len()
    );

    let mut g = c.benchmark_group("range_image");
    g.sample_size(20)
        .measurement_time(Duration::from_secs(3))
        .warm_up_time(Duration::from_millis(500));
    g.throughput(Throughput::Elements(cloud.len() as u64));
    g.bench_function("build", |b| {
        b.iter(|| RangeImage::new(&cloud, &config).unwrap())
    });
    g.bench_function("ground", |b| {
        b.iter(|| ground_mask(&image, &cloud, &ground).unwrap())
    });
    g.bench_function("clusters", |b| {
        b.iter(|| range_image_clusters(&image, &cloud, &seg.remaining, &image_params).unwrap())
    });
    g.bench_function("build_ground_clusters", |b| {
        b.iter(|| {
            let image = RangeImage::new(&cloud, &config).unwrap();
            let mask = ground_mask(&image, &cloud, &ground).unwrap();
            let rest: Vec<u32> = (0..cloud.len() as u32)
                .filter(|&i| !mask[i as usize])
                .collect();
            range_image_clusters(&image, &cloud, &rest, &image_params).unwrap()
        })
    });
    g.bench_function("euclidean", |b| {
        b.iter(|| euclidean_clusters_of(&cloud, &seg.remaining, &exact).unwrap())
    });
    g.finish();
}

criterion_group!(benches, range_image);
criterion_main!(benches);
