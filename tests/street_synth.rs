//! The simulated street drive as a KITTI raw drive: it opens with the ordinary reader, its
//! OXTS packets give back the simulated poses, its points lie on the surfaces the truth says
//! they hit, it repeats per seed, and the plane extraction finds its ground and walls.

use nalgebra::{Isometry3, Point3, Vector3};
use smc_lmb::cloud::planes::{extract_planes, PlaneConfig};
use smc_lmb::cloud::{read_kitti_bin, PointCloud};
use smc_lmb::kitti::RawDrive;
use smc_lmb::recording::Recording;
use smc_lmb::sim::street::{
    generate, write_drive, LegSpec, StreetConfig, StreetSimulator, StreetTruth, Surface,
    WrittenDrive,
};
use std::path::Path;
use std::time::Instant;

/// A street whose first turn (45° left over 2 s) starts after 0.5 s, with a coarse lidar.
fn quick_config(columns: usize) -> StreetConfig {
    let mut c = StreetConfig {
        route: vec![
            LegSpec {
                straight: 5.0,
                turn_deg: 45.0,
                turn_seconds: 2.0,
            },
            LegSpec {
                straight: 40.0,
                turn_deg: -60.0,
                turn_seconds: 3.0,
            },
        ],
        ..StreetConfig::default()
    };
    c.lidar.columns = columns;
    c
}

fn write(root: &Path, config: &StreetConfig, frames: usize, seed: u64) -> WrittenDrive {
    write_drive(root, config, frames, seed, |_| {}).unwrap()
}

fn world_points(cloud: &PointCloud, pose: &Isometry3<f64>) -> Vec<Point3<f64>> {
    cloud
        .iter()
        .map(|p| pose * Point3::new(p.x as f64, p.y as f64, p.z as f64))
        .collect()
}

#[test]
fn small_drive_opens_checks_clean_and_round_trips_the_poses() {
    let dir = tempfile::tempdir().unwrap();
    let frames = 30;
    let written = write(dir.path(), &quick_config(900), frames, 7);
    assert!(written
        .dir
        .ends_with("2020_01_01/2020_01_01_drive_0001_sync"));
    let drive = RawDrive::open(&written.dir).unwrap();
    assert_eq!(drive.check(), vec![], "issues");
    assert_eq!(drive.frame_count(), frames);
    assert_eq!(drive.oxts_count(), frames);
    let stamps = drive.timestamps().unwrap();
    assert!(stamps.intervals().iter().all(|d| (d - 0.1).abs() < 1e-9));
    for k in 0..frames {
        let cloud = drive.scan(k).unwrap(); // errors on any non-finite value
        assert!(cloud.len() > 1000, "frame {k}: {} points", cloud.len());
        assert!(cloud.intensities().iter().all(|r| (0.0..=1.0).contains(r)));
    }
    let truth = StreetTruth::read(written.dir.join("truth.json")).unwrap();
    assert_eq!(truth.frames.len(), frames);
    assert_eq!(truth.walls.len(), written.truth.walls.len());

    // OXTS → Velodyne poses through the written calibration equal the simulated ones.
    let poses = drive.poses().unwrap();
    let world_from_drive = truth.world_from_drive.to_isometry();
    let (mut worst_t, mut worst_r) = (0.0f64, 0.0f64);
    for (k, pose) in poses.iter().enumerate() {
        let expected = truth.frames[k].drive_pose.to_isometry();
        worst_t = worst_t.max((pose.translation.vector - expected.translation.vector).norm());
        worst_r = worst_r.max(pose.rotation.angle_to(&expected.rotation));
        // The drive frame placed in the world is the simulated Velodyne pose.
        let in_world = world_from_drive * pose;
        let sim = truth.frames[k].velodyne_pose.to_isometry();
        assert!((in_world.translation.vector - sim.translation.vector).norm() < 1e-3);
    }
    eprintln!("pose round trip: {worst_t:.2e} m, {worst_r:.2e} rad");
    assert!(worst_t < 1e-3, "{worst_t} m");
    assert!(worst_r < 1e-6, "{worst_r} rad");
    // The drive moved about 29 m and turned.
    let last = poses.last().unwrap();
    assert!(
        (last.translation.vector.norm() - 29.0).abs() < 1.5,
        "{last}"
    );

    // Planar vehicle states: 10 m/s, and the simulated yaw rate and heading change.
    let states = drive.vehicle_states().unwrap();
    let yaw0 = truth.frames[0].ego.yaw;
    let mut max_rate = 0.0f64;
    for (s, f) in states.iter().zip(&truth.frames) {
        assert!((s.speed() - 10.0).abs() < 1e-9, "{s:?}");
        assert!((s.yaw_rate - f.ego.yaw_rate).abs() < 1e-12);
        assert!((s.heading - (f.ego.yaw - yaw0)).abs() < 1e-9);
        // Velocity along the heading (no side slip).
        assert!((s.vy.atan2(s.vx) - s.heading).abs() < 1e-9);
        max_rate = max_rate.max(s.yaw_rate.abs());
    }
    // A 45° raised-cosine turn over 2 s peaks at 2·(π/4)/2 rad/s.
    assert!(
        (max_rate - std::f64::consts::FRAC_PI_4).abs() < 0.02,
        "{max_rate}"
    );
    // Positions: ego displacement between frames ≈ 1 m.
    for w in states.windows(2) {
        let d = (w[1].x - w[0].x).hypot(w[1].y - w[0].y);
        assert!((d - 1.0).abs() < 0.01, "{d}");
    }
    // Objects: every state is inside the truth's frames and moving cars move at 5–12 m/s.
    for o in &truth.objects {
        for s in &o.states {
            assert!(s.frame < frames);
            let v = s.velocity[0].hypot(s.velocity[1]);
            assert!(v <= 12.0 + 1e-9, "{o:?}");
        }
    }
}

#[test]
fn full_resolution_frame_has_kitti_density_and_points_lie_on_their_surfaces() {
    let config = StreetConfig::default();
    let started = Instant::now();
    let run = generate(&config, 1, 3).unwrap();
    eprintln!(
        "one full-resolution frame: {:.0} ms (test profile)",
        started.elapsed().as_secs_f64() * 1e3
    );
    let scan = &run.scans[0];
    let n = scan.cloud.len();
    eprintln!("points per frame: {n}");
    assert!((100_000..=140_000).contains(&n), "{n} points");
    let truth = &run.truth;
    let pose = truth.frames[0].velodyne_pose.to_isometry();
    let pts = world_points(&scan.cloud, &pose);
    // Ground points on the ground's surface in the world, which is near z = 0.
    let sim = StreetSimulator::new(&config, 1, 3).unwrap();
    let surface = sim.ground();
    assert!(surface.bound() <= 0.1, "{}", surface.bound());
    let ground: Vec<f64> = pts
        .iter()
        .zip(&scan.surfaces)
        .filter(|(_, s)| **s == Surface::Ground)
        .map(|(p, _)| p.z - surface.height(p.x, p.y))
        .collect();
    let rms = |v: &[f64]| (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt();
    assert!(ground.len() > 20_000, "{}", ground.len());
    assert!(rms(&ground) < 0.03, "ground rms {}", rms(&ground));
    // Wall points on their wall's plane, within the rectangle.
    let mut walls_checked = 0;
    for w in &truth.walls {
        let n = Vector3::from(w.normal);
        let d: Vec<f64> = pts
            .iter()
            .zip(&scan.surfaces)
            .filter(|(_, s)| **s == Surface::Wall(w.id))
            .map(|(p, _)| n.dot(&p.coords) + w.offset)
            .collect();
        assert_eq!(d.len(), w.points[0]);
        if d.len() >= 100 {
            walls_checked += 1;
            assert!(rms(&d) < 0.03, "wall {}: rms {}", w.id, rms(&d));
        }
    }
    assert!(walls_checked >= 4, "{walls_checked} walls with points");
    let in_view = truth.walls.iter().filter(|w| w.points[0] >= 2000).count();
    eprintln!(
        "walls: {} in the street, {} with ≥ 100 points, {} with ≥ 2000",
        truth.walls.len(),
        walls_checked,
        in_view
    );
    // The file written for the same seed holds exactly these points.
    let dir = tempfile::tempdir().unwrap();
    let written = write(dir.path(), &config, 1, 3);
    let back = read_kitti_bin(written.dir.join("velodyne_points/data/0000000000.bin")).unwrap();
    assert_eq!(back, scan.cloud);
    assert_eq!(written.truth, run.truth);
}

fn files(root: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![root.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let rel = p.strip_prefix(root).unwrap().to_string_lossy().into_owned();
                out.push((rel, std::fs::read(&p).unwrap()));
            }
        }
    }
    out.sort();
    out
}

#[test]
fn same_seed_same_bytes_other_seed_other_drive() {
    let config = quick_config(500);
    let (a, b, c) = (
        tempfile::tempdir().unwrap(),
        tempfile::tempdir().unwrap(),
        tempfile::tempdir().unwrap(),
    );
    write(a.path(), &config, 3, 11);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    pool.install(|| write(b.path(), &config, 3, 11));
    write(c.path(), &config, 3, 12);
    let (fa, fb, fc) = (files(a.path()), files(b.path()), files(c.path()));
    assert!(fa.len() >= 3 + 3 + 3 + 5, "{}", fa.len());
    assert_eq!(fa, fb);
    let bin = "2020_01_01/2020_01_01_drive_0001_sync/velodyne_points/data/0000000000.bin";
    let get = |f: &[(String, Vec<u8>)]| f.iter().find(|(n, _)| n == bin).unwrap().1.clone();
    assert_ne!(get(&fa), get(&fc));
    // No temporary folder is left behind, and an existing drive is not overwritten.
    assert!(fa.iter().all(|(n, _)| !n.contains(".partial")));
    let err = write_drive(a.path(), &config, 3, 11, |_| {}).unwrap_err();
    assert!(err.to_string().contains("already exists"), "{err}");
}

#[test]
fn bad_inputs_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let err = write_drive(dir.path(), &StreetConfig::default(), 0, 1, |_| {}).unwrap_err();
    assert!(err.to_string().contains("frame count"), "{err}");
    let mut c = StreetConfig::default();
    c.lidar.beams = 63;
    let err = write_drive(dir.path(), &c, 2, 1, |_| {}).unwrap_err();
    assert!(err.to_string().contains("lidar.beams"), "{err}");
    // Legs too short for the street: the corners overlap.
    let mut c = quick_config(100);
    c.route[1].straight = 0.0;
    c.route[1].turn_deg = 120.0;
    c.route[1].turn_seconds = 0.5;
    c.route[0].turn_deg = 120.0;
    c.route[0].turn_seconds = 0.5;
    let err = write_drive(dir.path(), &c, 2, 1, |_| {}).unwrap_err();
    assert!(err.to_string().contains("route leg"), "{err}");
    assert!(!dir
        .path()
        .join("2020_01_01/2020_01_01_drive_0001_sync")
        .exists());
}

#[test]
fn plane_extraction_finds_the_ground_and_the_big_walls() {
    let run = generate(&StreetConfig::default(), 1, 5).unwrap();
    let truth = &run.truth;
    let scan = &run.scans[0];
    let pose = truth.frames[0].velodyne_pose.to_isometry();
    let mut rng = smc_lmb::rng::seeded(1);
    let seg = extract_planes(&scan.cloud, &PlaneConfig::default(), &mut rng).unwrap();
    // Ground: normal within 2° of the world's vertical.
    let ground = seg.ground.as_ref().expect("ground found");
    let up = pose * ground.patch.plane.normal;
    assert!(up.z.abs() > 2f64.to_radians().cos(), "ground normal {up}");
    // Walls: match each detected wall with the truth wall holding most of its inliers.
    let big: Vec<_> = truth.walls.iter().filter(|w| w.points[0] >= 2000).collect();
    let mut matched = std::collections::BTreeSet::new();
    let mut report = Vec::new();
    for det in &seg.walls {
        let mut votes = std::collections::HashMap::new();
        for &i in &det.inliers {
            if let Surface::Wall(id) = scan.surfaces[i as usize] {
                *votes.entry(id).or_insert(0usize) += 1;
            }
        }
        let Some((&id, &n)) = votes
            .iter()
            .max_by_key(|(id, n)| (**n, std::cmp::Reverse(**id)))
        else {
            report.push(format!(
                "detection with no wall inliers ({})",
                det.inliers.len()
            ));
            continue;
        };
        let w = &truth.walls[id as usize];
        let normal = (pose * det.patch.plane.normal).normalize();
        let angle = normal
            .dot(&Vector3::from(w.normal))
            .abs()
            .min(1.0)
            .acos()
            .to_degrees();
        report.push(format!(
            "wall {id}: {n}/{} inliers from it (truth {} points), normal off by {angle:.2}°",
            det.inliers.len(),
            w.points[0]
        ));
        if angle < 2.0 {
            matched.insert(id);
        }
    }
    let big_found = big.iter().filter(|w| matched.contains(&w.id)).count();
    eprintln!(
        "plane extraction: {} walls detected, {} truth walls matched within 2°, {big_found} of \
         {} walls with ≥ 2000 points\n  {}",
        seg.walls.len(),
        matched.len(),
        big.len(),
        report.join("\n  ")
    );
    assert!(matched.len() >= 2, "{report:?}");
}
