//! Plane segmentation on real KITTI Velodyne frames: the vendored subsampled frame (always)
//! and four full frames from the shared data directory (skipped with a note when absent,
//! failing under `CI=true`).
//!
//! Not for: accuracy against ground truth (KITTI has no plane labels); these tests check that
//! the ground and building walls come out with plausible geometry.

mod common;

use nalgebra::{Point3, Vector3};
use smc_lmb::cloud::planes::{
    extract_planes, PlaneConfig, PlaneDetection, PlaneSegmentation, RejectReason,
};
use smc_lmb::cloud::read_kitti_bin;
use smc_lmb::recording::Recording;
use smc_lmb::rng::seeded;
use std::path::Path;
use std::time::Instant;

const DRIVE: &str = "kitti_raw/2011_09_26/2011_09_26_drive_UNKNOWN_sync/velodyne_points/data";

fn segment(path: &Path) -> (usize, PlaneSegmentation) {
    segment_with(path, &PlaneConfig::default())
}

fn segment_with(path: &Path, config: &PlaneConfig) -> (usize, PlaneSegmentation) {
    let cloud = read_kitti_bin(path).expect("readable frame");
    let t = Instant::now();
    let seg = extract_planes(&cloud, config, &mut seeded(1)).expect("segment");
    let dt = t.elapsed();
    println!(
        "{}: {} points, {:.1} ms, ground {:?}, {} walls, {} rejected, {} remaining",
        path.display(),
        cloud.len(),
        dt.as_secs_f64() * 1e3,
        seg.ground
            .as_ref()
            .map(|g| (g.inliers.len(), g.patch.plane.as_vector())),
        seg.walls.len(),
        seg.rejected.len(),
        seg.remaining.len()
    );
    for w in &seg.walls {
        println!(
            "  wall: n = [{:.3}, {:.3}, {:.3}], d = {:.2} m, area = {:.1} m², extent = ({:.1}, {:.1}) m, {} points, rms {:.3} m, centre {:.1?}",
            w.patch.plane.normal.x,
            w.patch.plane.normal.y,
            w.patch.plane.normal.z,
            w.patch.plane.offset,
            w.patch.area,
            w.patch.extent.0,
            w.patch.extent.1,
            w.inliers.len(),
            w.rms,
            w.patch.centre().coords.as_slice()
        );
    }
    for r in &seg.rejected {
        println!("  rejected: {} points, {:?}", r.points, r.reason);
    }
    (cloud.len(), seg)
}

fn check_ground(seg: &PlaneSegmentation) {
    let g = seg.ground.as_ref().expect("ground plane found");
    let n = g.patch.plane.normal;
    assert!(
        n.z.abs().min(1.0).acos() < 5f64.to_radians(),
        "ground normal {n:?}"
    );
    // Canonical form: normal points up towards the sensor, offset = height of the sensor.
    assert!(n.z > 0.0);
    let h = g.patch.plane.offset;
    assert!((1.6..=1.9).contains(&h), "sensor height above ground {h}");
}

#[test]
fn vendored_subsampled_frame() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/kitti")
        .join(DRIVE.trim_start_matches("kitti_raw/"))
        .join("0000000000.bin");
    let (n, seg) = segment(&path);
    assert!(n > 10_000);
    check_ground(&seg);
}

/// Whether a wall passes the facade test of `WallQuality::BUILDING`, recomputed here from the
/// wall's points: top above the sensor, RMS ≤ 0.08 m, within 5° of plumb relative to the
/// ground's normal.
fn is_facade(cloud_path: &Path, w: &PlaneDetection, ground: &Vector3<f64>) -> bool {
    let cloud = read_kitti_bin(cloud_path).expect("readable frame");
    let plane = &w.patch.plane;
    let sq: f64 = w
        .inliers
        .iter()
        .map(|&i| {
            let i = i as usize;
            let p = Point3::new(
                cloud.xs()[i] as f64,
                cloud.ys()[i] as f64,
                cloud.zs()[i] as f64,
            );
            plane.signed_distance(&p).powi(2)
        })
        .sum();
    let rms = (sq / w.inliers.len() as f64).sqrt();
    let top = w
        .patch
        .vertices
        .iter()
        .map(|v| v.z)
        .fold(f64::MIN, f64::max);
    let lean = plane.normal.dot(ground).abs().asin();
    rms <= 0.08 && top >= 0.0 && lean <= 5f64.to_radians()
}

/// The four UNKNOWN frames hold few high returns (frame 0: 2,553 points above z = 1 m, 308
/// above z = 2 m, mostly 30-60 m away): the vertical planes RANSAC extracts there are thick
/// bands of vegetation (RMS ≈ 0.1 m), not facades. Every wall the default keeps must be a
/// facade by the test above, and every building-scale vertical piece it drops as not
/// building-scale must fail it.
#[test]
fn full_frames() {
    let Some(dir) = common::shared_data(DRIVE) else {
        return;
    };
    for k in 0..4 {
        let path = dir.join(format!("{k:010}.bin"));
        let (n, seg) = segment(&path);
        assert!(n > 100_000);
        check_ground(&seg);
        let up = seg.ground.as_ref().unwrap().patch.plane.normal;
        for w in &seg.walls {
            assert!(w.patch.area >= 15.0);
            assert!(is_facade(&path, w, &up), "frame {k}: {w:?}");
        }
        let (_, loose) = segment_with(&path, &PlaneConfig::any_vertical());
        assert!(
            loose.walls.len() >= 2,
            "frame {k}: only {} vertical pieces of building size",
            loose.walls.len()
        );
        let facades: Vec<_> = loose
            .walls
            .iter()
            .filter(|w| is_facade(&path, w, &up))
            .cloned()
            .collect();
        assert_eq!(seg.walls, facades, "frame {k}");
        let not_building = seg
            .rejected
            .iter()
            .filter(|r| matches!(r.reason, RejectReason::NotBuildingScale { .. }))
            .count();
        assert_eq!(not_building, loose.walls.len() - facades.len(), "frame {k}");
    }
}

const SEED_DRIVE: &str = "kitti_raw/2011_09_26/2011_09_26_drive_0005_sync";

/// Walls repeat from scan to scan on seed 001's drive (frames 0–49): the prediction of every
/// frame's walls into the next frame meets the targets set for real drives — median normal
/// angle ≤ 0.5°, median vertex distance ≤ 0.3 m, 90th percentile angle ≤ 3°, at least two
/// wall pairs per frame pair — with the measured poses and with the vehicle model.
#[test]
fn seed_drive_walls_repeat() {
    use smc_lmb::kitti::RawDrive;
    use smc_lmb::metrics::PlanePredictionSummary;
    use smc_lmb::pipeline::{predict_pairs, PlanePredictionConfig};
    let Some(dir) = common::shared_data(SEED_DRIVE) else {
        return;
    };
    let drive = RawDrive::open(&dir).expect("drive");
    let last = drive.frame_count() - 1;
    for (measured, runs) in [(true, 1), (false, 10)] {
        let config = PlanePredictionConfig {
            use_vehicle_model: !measured,
            ..PlanePredictionConfig::default()
        };
        let results = predict_pairs(&drive, Some(0..last), &config, runs, &mut seeded(1)).unwrap();
        let pairs: Vec<_> = results.iter().flat_map(|r| r.pairs.clone()).collect();
        let s = PlanePredictionSummary::from_pairs(&pairs, &[]);
        println!(
            "measured {measured}: {} pairs over {last} frame pairs, angle median {:.3}° p90 \
             {:.3}°, vertex median {:.3} m",
            s.pairs, s.median_normal_angle_deg, s.p90_normal_angle_deg, s.median_vertex_distance_m
        );
        assert!(s.pairs >= 2 * last, "{} pairs", s.pairs);
        assert!(s.median_normal_angle_deg <= 0.5, "{s:?}");
        assert!(s.p90_normal_angle_deg <= 3.0, "{s:?}");
        assert!(s.median_vertex_distance_m <= 0.3, "{s:?}");
    }
}

/// The same targets with the ego motion from lidar odometry on the scans instead of OXTS, as
/// for a recording without poses.
#[test]
fn seed_drive_walls_repeat_with_lidar_odometry() {
    use smc_lmb::cloud::odometry::{odometry_of_frames, OdometryConfig};
    use smc_lmb::kitti::RawDrive;
    use smc_lmb::metrics::PlanePredictionSummary;
    use smc_lmb::pipeline::plane_prediction::{predict_pairs_with_poses, PlanePredictionConfig};
    let Some(dir) = common::shared_data(SEED_DRIVE) else {
        return;
    };
    let drive = RawDrive::open(&dir).expect("drive");
    let count = drive.velodyne_count();
    let load = |k: usize| drive.scan(k);
    let poses = odometry_of_frames(count, &load, &OdometryConfig::default()).unwrap();
    let config = PlanePredictionConfig::default();
    let results = predict_pairs_with_poses(
        0..count - 1,
        &|_| true,
        &load,
        &poses,
        "drive 0005",
        &config,
        1,
        &mut seeded(1),
    )
    .unwrap();
    let pairs: Vec<_> = results.iter().flat_map(|r| r.pairs.clone()).collect();
    let s = PlanePredictionSummary::from_pairs(&pairs, &[]);
    println!("lidar odometry: {s:?}");
    assert!(s.pairs >= 2 * (count - 1), "{} pairs", s.pairs);
    assert!(s.median_normal_angle_deg <= 0.5, "{s:?}");
    assert!(s.p90_normal_angle_deg <= 3.0, "{s:?}");
    assert!(s.median_vertex_distance_m <= 0.3, "{s:?}");
}

/// For every wall of at least `min_area` m² in scan k, the best match among scan k + 1's
/// walls after moving its plane by the relative pose of the two scans: (area, normal angle
/// in degrees, offset difference in metres), `None` when scan k + 1 has no wall at all.
fn walls_again(
    clouds: &[smc_lmb::cloud::PointCloud],
    poses: &[nalgebra::Isometry3<f64>],
    min_area: f64,
) -> Vec<(f64, Option<(f64, f64)>)> {
    use smc_lmb::models::plane::plane_residual;
    let segs: Vec<PlaneSegmentation> = clouds
        .iter()
        .map(|c| extract_planes(c, &PlaneConfig::default(), &mut seeded(1)).expect("segment"))
        .collect();
    let mut out = Vec::new();
    for k in 0..clouds.len() - 1 {
        // Scan k's coordinates to scan k + 1's.
        let step = poses[k + 1].inverse() * poses[k];
        for w in segs[k].walls.iter().filter(|w| w.patch.area >= min_area) {
            let moved = w.patch.plane.transform(&step);
            let best = segs[k + 1]
                .walls
                .iter()
                .map(|v| {
                    // Normals aligned first: the same plane may come out with the other sign.
                    let (angle, dd) =
                        plane_residual(&moved.as_vector(), &v.patch.plane.as_vector());
                    (angle.to_degrees(), dd.abs())
                })
                .min_by(|a, b| (a.0 + 5.0 * a.1).total_cmp(&(b.0 + 5.0 * b.1)));
            out.push((w.patch.area, best));
        }
    }
    out
}

/// The walls target on the four shared scans: registered by lidar odometry (KISS-ICP's
/// recipe), every wall of 20 m² or more is segmented again in the next scan with its normal
/// within 1° and its offset within 0.2 m. The scans were taken standing still, and the
/// registration must say so. Their vertical planes are vegetation that the facade test
/// rejects (see `full_frames`), so today no wall reaches the check; every wall the
/// segmentation keeps there in future must repeat.
#[test]
fn shared_scans_registered_by_icp_repeat_their_walls() {
    use smc_lmb::cloud::odometry::{odometry_of_frames, OdometryConfig};
    let Some(dir) = common::shared_data(DRIVE) else {
        return;
    };
    let clouds: Vec<_> = (0..4)
        .map(|k| read_kitti_bin(dir.join(format!("{k:010}.bin"))).expect("readable frame"))
        .collect();
    let load = |k: usize| Ok(clouds[k].clone());
    let poses = odometry_of_frames(4, &load, &OdometryConfig::default()).unwrap();
    for (k, p) in poses.iter().enumerate() {
        let moved = p.translation.vector.norm();
        let turned = p.rotation.angle().to_degrees();
        println!("scan {k}: {moved:.4} m, {turned:.4}° from scan 0");
        assert!(
            moved < 0.05 && turned < 0.1,
            "scan {k}: {moved} m, {turned}°"
        );
    }
    let walls = walls_again(&clouds, &poses, 20.0);
    println!("{} walls of 20 m² or more", walls.len());
    for (area, best) in walls {
        let (angle, offset) = best.unwrap_or((f64::INFINITY, f64::INFINITY));
        println!("wall of {area:.1} m²: again within {angle:.2}°, {offset:.3} m");
        assert!(
            angle <= 1.0 && offset <= 0.2,
            "{area} m²: {angle}°, {offset} m"
        );
    }
}

/// The same criterion on seed 001's drive (frames 0–49, registered by lidar odometry): how
/// many walls of 20 m² or more are segmented again in the next scan with their normal within
/// 1° and their offset within 0.2 m. 138 of 205 are (67 %, measured 2026-11-30). Of the other
/// 67, 27 come out again 1–4° or 0.2–0.7 m apart (the upper tail of the pairs' errors), 15
/// fail the facade test in the next scan although a plane within about 1° is there (their RMS
/// near its 0.08 m limit), 9 are far facades behind the car whose next scan finds only a
/// parallel facade 6 m away, and 16 have no counterpart. The tracker keeps walls through the
/// scans that miss them. The floor of 60 % guards today's rate.
#[test]
fn seed_drive_walls_are_segmented_again() {
    use smc_lmb::cloud::odometry::{odometry_of_frames, OdometryConfig};
    use smc_lmb::kitti::RawDrive;
    let Some(dir) = common::shared_data(SEED_DRIVE) else {
        return;
    };
    let drive = RawDrive::open(&dir).expect("drive");
    let count = drive.velodyne_count();
    let clouds: Vec<_> = (0..count).map(|k| drive.scan(k).unwrap()).collect();
    let load = |k: usize| Ok(clouds[k].clone());
    let poses = odometry_of_frames(count, &load, &OdometryConfig::default()).unwrap();
    let walls = walls_again(&clouds, &poses, 20.0);
    let again = walls
        .iter()
        .filter(|(_, b)| b.is_some_and(|(a, o)| a <= 1.0 && o <= 0.2))
        .count();
    println!("{again} of {} walls of 20 m² or more again", walls.len());
    assert!(walls.len() >= 3 * (count - 1), "{} walls", walls.len());
    assert!(
        again as f64 >= 0.6 * walls.len() as f64,
        "{again} of {}",
        walls.len()
    );
}
