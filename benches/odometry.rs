//! Criterion benchmarks of the lidar odometry on a real KITTI HDL-64E frame pair.
//!
//! The pair is scans 0 and 1 of the shared raw drive 0005 (`../shared/data/kitti_raw/…`,
//! ~123,000 points each) when that folder sits beside the checkout; otherwise the vendored
//! subsampled frame under `tests/data/kitti/…` (14,714 points) and the same frame seen
//! 0.35 m further on (the drive's motion per frame). The frames used are printed first.
//!
//! Groups:
//! * `odometry/voxelize`: range crop and the two voxel downsamplings of one scan;
//! * `odometry/align`: ICP of the second scan's registration points to a map of the first;
//! * `odometry/refine`: the point-to-plane refinement of the second scan's map sampling against
//!   the map, from the pose `align` found (two passes, as in the pipeline);
//! * `odometry/pair`: the whole pipeline on both scans (a fresh map each time);
//!   `odometry/pair_no_refine` without the refinement (KISS-ICP's recipe);
//! * `odometry/nearest_voxel_hash` and `odometry/nearest_kiddo`: the closest map point of
//!   every registration point, by the 27-voxel lookup and by a k-d tree
//!   (kiddo, built once) — the choice KISS-ICP made, measured; `odometry/kiddo_build` is the
//!   cost of that tree, which a k-d tree map would pay once a frame;
//!   `odometry/nearest_voxel_hash_within` the lookup ICP makes, which skips the voxels
//!   beyond its correspondence distance.

use criterion::{criterion_group, criterion_main, Criterion};
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use nalgebra::{Isometry3, Vector3};
use smc_lmb::cloud::odometry::{
    align_points_to_map, crop_range, refine_point_to_plane, voxel_downsample, IcpParams,
    LidarOdometry, OdometryConfig, RefineParams, VoxelHashMap,
};
use smc_lmb::cloud::{read_kitti_bin, PointCloud};
use std::path::{Path, PathBuf};
use std::time::Duration;

const SHARED: &str =
    "../shared/data/kitti_raw/2011_09_26/2011_09_26_drive_0005_sync/velodyne_points/data";
const VENDORED: &str =
    "tests/data/kitti/2011_09_26/2011_09_26_drive_UNKNOWN_sync/velodyne_points/data/0000000000.bin";

/// Scans 0 and 1 of drive 0005, or the vendored frame and a copy of it 0.35 m ahead.
fn frame_pair() -> (PointCloud, PointCloud) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let shared: PathBuf = root.join(SHARED);
    if shared.join("0000000001.bin").is_file() {
        let a = shared.join("0000000000.bin");
        let b = shared.join("0000000001.bin");
        println!("frames: {} and {}", a.display(), b.display());
        return (read_kitti_bin(a).unwrap(), read_kitti_bin(b).unwrap());
    }
    let path = root.join(VENDORED);
    println!("frames: {} and the same moved by 0.35 m", path.display());
    let a = read_kitti_bin(path).unwrap();
    let mut b = PointCloud::with_capacity(a.len());
    for p in a.iter() {
        b.push(p.x - 0.35, p.y, p.z, p.intensity);
    }
    (a, b)
}

fn odometry(c: &mut Criterion) {
    let (a, b) = frame_pair();
    let config = OdometryConfig::default();
    let v = config.voxel_size;
    let voxelize = |cloud: &PointCloud| {
        let frame = crop_range(cloud, config.min_range, config.max_range);
        let down = voxel_downsample(&frame, 0.5 * v);
        let source = voxel_downsample(&down, 1.5 * v);
        (down, source)
    };
    let (map_points, _) = voxelize(&a);
    let (down, source) = voxelize(&b);
    let mut map = VoxelHashMap::new(v, config.max_range, config.max_points_per_voxel);
    map.update(&map_points, &Isometry3::identity());
    println!(
        "{} + {} points; map {} points in {} voxels; {} registration points",
        a.len(),
        b.len(),
        map.point_count(),
        map.voxel_count(),
        source.len()
    );
    let params = IcpParams {
        max_correspondence: 3.0 * config.initial_threshold,
        kernel: config.initial_threshold / 3.0,
        max_iterations: config.max_iterations,
        convergence: config.convergence,
    };

    let mut g = c.benchmark_group("odometry");
    g.sample_size(10)
        .measurement_time(Duration::from_secs(4))
        .warm_up_time(Duration::from_millis(500));
    g.bench_function("voxelize", |bench| bench.iter(|| voxelize(&b)));
    g.bench_function("align", |bench| {
        bench.iter(|| align_points_to_map(&source, &map, &Isometry3::identity(), &params))
    });
    let coarse = align_points_to_map(&source, &map, &Isometry3::identity(), &params).pose;
    let fine = RefineParams {
        scale: config.refine_scale,
        thickness: config.refine_thickness,
        radius: config.refine_radius,
        passes: config.refine_passes,
        max_iterations: config.refine_iterations,
        convergence: 1e-6,
    };
    println!("{} refinement points", down.len());
    g.bench_function("refine", |bench| {
        bench.iter(|| refine_point_to_plane(&down, &map, &coarse, &fine))
    });
    g.bench_function("pair", |bench| {
        bench.iter(|| {
            let mut odometry = LidarOdometry::new(config.clone()).unwrap();
            odometry.register(&a).unwrap();
            odometry.register(&b).unwrap().pose
        })
    });
    let p2p = OdometryConfig {
        refine_iterations: 0,
        ..config.clone()
    };
    g.bench_function("pair_no_refine", |bench| {
        bench.iter(|| {
            let mut odometry = LidarOdometry::new(p2p.clone()).unwrap();
            odometry.register(&a).unwrap();
            odometry.register(&b).unwrap().pose
        })
    });

    let all: Vec<Vector3<f64>> = map.points();
    let flat: Vec<[f64; 3]> = all.iter().map(|p| [p.x, p.y, p.z]).collect();
    let tree = ImmutableKdTree::<f64, 3>::new_from_slice(&flat).expect("a k-d tree of the map");
    g.bench_function("nearest_voxel_hash", |bench| {
        bench.iter(|| {
            source
                .iter()
                .filter_map(|p| map.closest(p))
                .map(|(_, d2)| d2)
                .sum::<f64>()
        })
    });
    // ICP asks only for pairs within its correspondence distance (3σ of the adaptive
    // threshold, here 0.6 m): neighbour voxels farther than that are not looked up.
    g.bench_function("nearest_voxel_hash_within", |bench| {
        bench.iter(|| {
            source
                .iter()
                .filter_map(|p| map.closest_within(p, 0.36))
                .map(|(_, d2)| d2)
                .sum::<f64>()
        })
    });
    g.bench_function("kiddo_build", |bench| {
        bench.iter(|| ImmutableKdTree::<f64, 3>::new_from_slice(&flat).unwrap())
    });
    g.bench_function("nearest_kiddo", |bench| {
        bench.iter(|| {
            source
                .iter()
                .map(|p| {
                    tree.query(&[p.x, p.y, p.z])
                        .nearest_one::<SquaredEuclidean<f64>>()
                        .execute()
                        .distance
                })
                .sum::<f64>()
        })
    });
    g.finish();
}

criterion_group!(benches, odometry);
criterion_main!(benches);
