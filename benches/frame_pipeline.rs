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
//! * `frame/voxel_groups_flat`, `frame/voxel_groups_sample`: the frame's points grouped
//!   by 2 m cells, laid flat in scan order (as the wall rounds' bird's-eye grid groups its
//!   pool) and as a random subsample of 6,000 of them (as a RANSAC round groups its sample);
//! * `frame/clusters`: Euclidean clustering of the points left after plane removal;
//! * `frame/clusters_range_image`: the same points clustered on the scan's range image
//!   (building the image included);
//! * `frame/read_planes_clusters`: the three in a row, as a frame is processed;
//! * `frame/filter_update`: one step of the drive tracker (walls and clusters as labelled
//!   objects of one LMB filter, 1000 particles per track) on this frame's detections, after a
//!   warm-up on the same detections that confirms them (a static sensor);
//! * `frame/whole`: read, detect (planes and clusters as the drive tracker selects them by
//!   default: every object-sized cluster of the exact Euclidean clustering within range) and
//!   the filter update in a row;
//! * `frame/whole_predict_beside`: the same as `track` runs it, the filter's prediction
//!   beside the segmentation (`DriveTracker::step_scan`);
//! * `frame/filter_update_range_image`, `frame/whole_range_image`: the same with the range
//!   image's clustering selected;
//! * `frame/boxes_one_search`, `frame/boxes_two_searches`: every cluster's box bare and with a
//!   car's footprint, from one heading search (`BoxOutline`, as the detector does) or from two
//!   separate fits (as it did before).

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use nalgebra::Isometry3;
use smc_lmb::cloud::boxes::{fit_box_of, outline_of, BoxFitParams, BoxScratch, SizePrior};
use smc_lmb::cloud::planes::{extract_planes, PlaneConfig};
use smc_lmb::cloud::range_image::{range_image_clusters, ImageClusterParams, RangeImage};
use smc_lmb::cloud::voxel_groups::VoxelGroups;
use smc_lmb::cloud::{euclidean_clusters_of, read_kitti_bin, Cluster, ClusterParams, PointCloud};
use smc_lmb::pipeline::drive_tracking::{
    detect_objects, ClusterMethod, DriveTracker, FrameDetections, TrackingConfig,
};
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
    voxel_groups(&mut g, &cloud);
    g.bench_function("clusters", |b| {
        b.iter(|| euclidean_clusters_of(&cloud, &seg.remaining, &clusters).unwrap())
    });
    g.bench_function("clusters_range_image", |b| {
        b.iter(|| {
            let image = RangeImage::new(&cloud, &Default::default()).unwrap();
            let params = ImageClusterParams {
                near_distance: 0.5,
                max_distance: 1.0,
                min_points: clusters.min_points,
                max_points: clusters.max_points,
                ..Default::default()
            };
            range_image_clusters(&image, &cloud, &seg.remaining, &params).unwrap()
        })
    });
    g.bench_function("read_planes_clusters", |b| {
        b.iter(|| {
            let cloud = read_kitti_bin(&path).unwrap();
            let seg = extract_planes(&cloud, &planes, &mut seeded(1)).unwrap();
            euclidean_clusters_of(&cloud, &seg.remaining, &clusters).unwrap()
        })
    });
    boxes(&mut g, &cloud, &found);
    filter_update(&mut g, &path, &cloud);
    g.finish();
}

/// The frame's points grouped by 2 m cells: laid flat in scan order, and a random subsample.
fn voxel_groups(
    g: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    cloud: &PointCloud,
) {
    use rand::RngExt;
    let points: Vec<[f32; 3]> = (0..cloud.len())
        .map(|i| [cloud.xs()[i], cloud.ys()[i], cloud.zs()[i]])
        .filter(|p| p.iter().all(|v| v.is_finite()))
        .collect();
    let flat: Vec<[f32; 3]> = points.iter().map(|p| [p[0], p[1], 0.0]).collect();
    let mut rng = seeded(1);
    let sample: Vec<[f32; 3]> = (0..6000)
        .map(|_| points[rng.random_range(0..points.len())])
        .collect();
    g.bench_function("voxel_groups_flat", |b| {
        b.iter(|| VoxelGroups::new(&flat, 2.0))
    });
    g.bench_function("voxel_groups_sample", |b| {
        b.iter(|| VoxelGroups::new(&sample, 2.0))
    });
}

/// Every cluster's box bare and with a car's footprint: one heading search or two fits.
fn boxes(
    g: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    cloud: &PointCloud,
    clusters: &[Cluster],
) {
    let params = BoxFitParams::default();
    let car = SizePrior {
        length: 3.9,
        width: 1.6,
    };
    let mut scratch = BoxScratch::default();
    g.bench_function("boxes_one_search", |b| {
        b.iter(|| {
            for c in clusters {
                let idx = &c.indices;
                let outline = outline_of(cloud, idx, Some(-1.73), &params, &mut scratch).unwrap();
                std::hint::black_box((
                    outline.fit(None).unwrap(),
                    outline.fit(Some(&car)).unwrap(),
                ));
            }
        })
    });
    g.bench_function("boxes_two_searches", |b| {
        b.iter(|| {
            for c in clusters {
                let idx = &c.indices;
                let bare = fit_box_of(cloud, idx, Some(-1.73), None, &params, &mut scratch);
                let with = fit_box_of(cloud, idx, Some(-1.73), Some(&car), &params, &mut scratch);
                std::hint::black_box((bare.unwrap(), with.unwrap()));
            }
        })
    });
}

/// The drive tracker's filter step on this frame's walls and clusters, and the whole frame.
fn filter_update(
    g: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    path: &Path,
    cloud: &PointCloud,
) {
    let mut config = TrackingConfig::default();
    for method in [ClusterMethod::Euclidean, ClusterMethod::RangeImage] {
        config.clusters.method = method;
        tracker_group(g, path, cloud, &config);
    }
}

/// `filter_update` and `whole` with one cluster configuration (suffixed `_range_image` for the
/// range image's clustering).
fn tracker_group(
    g: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    path: &Path,
    cloud: &PointCloud,
    config: &TrackingConfig,
) {
    let config = config.clone();
    let suffix = match config.clusters.method {
        ClusterMethod::Euclidean => "",
        ClusterMethod::RangeImage => "_range_image",
    };
    let det = detect_objects(cloud, &config, &mut seeded(1)).expect("detections");
    println!(
        "tracked objects{suffix}: {} walls, {} clusters",
        det.walls.len(),
        det.clusters.len()
    );
    let pose = Isometry3::identity();
    // Each bench steps a tracker of its own, started by the same five frames, so that its
    // time does not depend on which benches ran before it (and for how many iterations).
    let k = std::cell::Cell::new(0usize);
    let step = |tracker: &mut DriveTracker, det: &FrameDetections| {
        let f = tracker
            .step(k.get(), k.get() as f64 * 0.1, pose, None, det)
            .expect("step");
        k.set(k.get() + 1);
        f
    };
    let started = || {
        k.set(0);
        let mut tracker = DriveTracker::new(&config, 1).expect("default config is valid");
        for _ in 0..5 {
            step(&mut tracker, &det);
        }
        tracker
    };
    let mut tracker = started();
    g.bench_function(format!("filter_update{suffix}"), |b| {
        b.iter(|| step(&mut tracker, &det))
    });
    let mut tracker = started();
    g.bench_function(format!("whole{suffix}"), |b| {
        b.iter(|| {
            let cloud = read_kitti_bin(path).unwrap();
            let det = detect_objects(&cloud, &config, &mut seeded(1)).unwrap();
            step(&mut tracker, &det)
        })
    });
    // What `track` does: the filter predicts while the scan is segmented.
    let mut tracker = started();
    g.bench_function(format!("whole_predict_beside{suffix}"), |b| {
        b.iter(|| {
            let cloud = read_kitti_bin(path).unwrap();
            let f = k.get();
            k.set(f + 1);
            tracker
                .step_scan(f, f as f64 * 0.1, pose, None, &cloud, &mut seeded(1))
                .expect("step")
        })
    });
}

criterion_group!(benches, frame);
criterion_main!(benches);
