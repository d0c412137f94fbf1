//! Shared helpers of the integration tests: synthetic KITTI raw drives written to disk, and
//! the paths of the vendored and shared 2-D laser recordings.
//!
//! A drive is laid out exactly as KITTI's (`DATE/DATE_drive_NNNN_sync/...`), with the real
//! 2011_09_26 calibration copied from the vendored excerpt, OXTS packets built from planar
//! vehicle states, and Velodyne clouds seen from the resulting Velodyne poses.

#![allow(dead_code)] // each test binary uses a subset

#[cfg(feature = "kitti")]
use nalgebra::{Isometry3, Point3};
#[cfg(feature = "kitti")]
use rand::RngExt;
#[cfg(feature = "kitti")]
use rand_distr::{Distribution, Normal};
#[cfg(feature = "kitti")]
use smc_lmb::cloud::{write_kitti_bin, PointCloud};
#[cfg(feature = "kitti")]
use smc_lmb::kitti::poses::Mercator;
#[cfg(feature = "kitti")]
use smc_lmb::kitti::{
    frame_file_name, write_oxts_dir, write_timestamps, OxtsPacket, RawDrive, Timestamp,
};
#[cfg(feature = "kitti")]
use smc_lmb::rng::{seeded, FilterRng};
use std::path::{Path, PathBuf};

#[cfg(feature = "kitti")]
/// The vendored real KITTI excerpt.
pub fn vendored_kitti() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/kitti")
}

#[cfg(feature = "kitti")]
/// `world` (world = Velodyne frame of the first frame) seen from a sensor at `pose`
/// (sensor → world), with Gaussian noise of `noise` metres per coordinate.
pub fn scan(
    world: &[Point3<f64>],
    pose: &Isometry3<f64>,
    noise: f64,
    rng: &mut FilterRng,
) -> PointCloud {
    let normal = Normal::new(0.0, noise.max(0.0)).unwrap();
    let inv = pose.inverse();
    let mut cloud = PointCloud::with_capacity(world.len());
    for p in world {
        let q = inv * p;
        let i: f32 = rng.random_range(0.0..1.0);
        cloud.push(
            (q.x + normal.sample(rng)) as f32,
            (q.y + normal.sample(rng)) as f32,
            (q.z + normal.sample(rng)) as f32,
            i,
        );
    }
    cloud
}

#[cfg(feature = "kitti")]
/// Writes a drive `2011_09_26_drive_NNNN_sync` under `root` with one frame per vehicle state
/// `[X, Ẋ, Y, Ẏ, φ, φ̇]` (frames `dt` apart); frame k shows `world(k)` (world points in the
/// Velodyne frame of frame 0) with 1 cm noise. Returns the drive folder.
pub fn write_drive(
    root: &Path,
    number: u32,
    states: &[[f64; 6]],
    dt: f64,
    world: impl Fn(usize) -> Vec<Point3<f64>>,
) -> PathBuf {
    let day = root.join("2011_09_26");
    let dir = day.join(format!("2011_09_26_drive_{number:04}_sync"));
    std::fs::create_dir_all(dir.join("oxts/data")).unwrap();
    let src = vendored_kitti().join("2011_09_26");
    for name in [
        "calib_imu_to_velo.txt",
        "calib_velo_to_cam.txt",
        "calib_cam_to_cam.txt",
    ] {
        std::fs::copy(src.join(name), day.join(name)).unwrap();
    }
    let merc = Mercator::from_reference_latitude(49.0).unwrap();
    let (x0, y0) = merc.project(49.0, 8.4);
    let packets: Vec<OxtsPacket> = states
        .iter()
        .map(|s| {
            let (lat, lon) = merc.unproject(x0 + s[0], y0 + s[2]);
            OxtsPacket {
                lat,
                lon,
                alt: 110.0,
                yaw: s[4],
                ve: s[1],
                vn: s[3],
                vf: s[1].hypot(s[3]),
                wu: s[5],
                wz: s[5],
                ..Default::default()
            }
        })
        .collect();
    write_oxts_dir(dir.join("oxts/data"), &packets).unwrap();
    let t0 = Timestamp::parse("2011-09-26 13:02:25.964389445").unwrap();
    let stamps: Vec<Timestamp> = (0..states.len())
        .map(|k| t0.plus_seconds(k as f64 * dt).unwrap())
        .collect();
    write_timestamps(dir.join("oxts/timestamps.txt"), &stamps).unwrap();
    let poses = RawDrive::open(&dir).unwrap().poses().unwrap();
    std::fs::create_dir_all(dir.join("velodyne_points/data")).unwrap();
    write_timestamps(dir.join("velodyne_points/timestamps.txt"), &stamps).unwrap();
    let mut rng = seeded(u64::from(number));
    for (k, pose) in poses.iter().enumerate() {
        write_kitti_bin(
            dir.join("velodyne_points/data")
                .join(frame_file_name(k as u64, "bin")),
            &scan(&world(k), pose, 0.01, &mut rng),
        )
        .unwrap();
    }
    dir
}

#[cfg(feature = "kitti")]
/// Points on a regular grid over the rectangle `origin + u·[0, a] + v·[0, b]`, `spacing` apart.
pub fn grid(origin: [f64; 3], a: [f64; 3], b: [f64; 3], spacing: f64) -> Vec<Point3<f64>> {
    let la = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    let lb = (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]).sqrt();
    let (na, nb) = (
        (la / spacing).round() as usize,
        (lb / spacing).round() as usize,
    );
    let mut pts = Vec::with_capacity((na + 1) * (nb + 1));
    for i in 0..=na {
        for j in 0..=nb {
            let (s, t) = (i as f64 / na.max(1) as f64, j as f64 / nb.max(1) as f64);
            pts.push(Point3::new(
                origin[0] + s * a[0] + t * b[0],
                origin[1] + s * a[1] + t * b[1],
                origin[2] + s * a[2] + t * b[2],
            ));
        }
    }
    pts
}

#[cfg(feature = "kitti")]
/// The surface of an axis-aligned box with centre `c` and size `size`, `spacing` apart.
pub fn box_surface(c: [f64; 3], size: [f64; 3], spacing: f64) -> Vec<Point3<f64>> {
    let h = [0.5 * size[0], 0.5 * size[1], 0.5 * size[2]];
    let lo = [c[0] - h[0], c[1] - h[1], c[2] - h[2]];
    let mut pts = Vec::new();
    for (axis, (u, v)) in [(0usize, (1usize, 2usize)), (1, (0, 2)), (2, (0, 1))] {
        for side in [0.0, size[axis]] {
            let mut origin = lo;
            origin[axis] += side;
            let mut a = [0.0; 3];
            a[u] = size[u];
            let mut b = [0.0; 3];
            b[v] = size[v];
            pts.extend(grid(origin, a, b, spacing));
        }
    }
    pts
}

/// A vendored 2-D laser excerpt (`tests/data/laser2d/`).
pub fn vendored_laser2d(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/laser2d")
        .join(name)
}

/// A path under `../shared/data`, the real recordings beside the checkout. When it is absent
/// a test that needs it cannot run: under `CI=true` it fails, naming what is missing (CI must
/// exercise the real data); elsewhere it returns `None` after a line on the terminal saying the
/// test is skipped (written to the process's stderr directly, past the test harness's capture,
/// so that a person sees it).
pub fn shared_data(relative: &str) -> Option<PathBuf> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data")
        .join(relative);
    if p.exists() {
        return Some(p);
    }
    if std::env::var("CI").is_ok_and(|v| v == "true") {
        panic!(
            "CI=true but the shared data {} is missing: the tests on real recordings must run",
            p.display()
        );
    }
    use std::io::Write;
    let _ = writeln!(
        std::io::stderr(),
        "SKIPPED: {} is absent, a test on real data did not run",
        p.display()
    );
    None
}

/// A file of the shared 2-D laser data folder (see [`shared_data`]).
pub fn shared_laser2d(name: &str) -> Option<PathBuf> {
    shared_data(&format!("laser2d/{name}"))
}

/// `bytes` gzip-compressed, as a `.gz` log would hold them.
#[cfg(feature = "laser2d")]
pub fn gz(bytes: &[u8]) -> Vec<u8> {
    use std::io::Write;
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    e.write_all(bytes).unwrap();
    e.finish().unwrap()
}

/// `bytes` bzip2-compressed, as a `.bz2` log would hold them.
#[cfg(feature = "laser2d")]
pub fn bz2(bytes: &[u8]) -> Vec<u8> {
    use std::io::Write;
    let mut e = bzip2::write::BzEncoder::new(Vec::new(), bzip2::Compression::default());
    e.write_all(bytes).unwrap();
    e.finish().unwrap()
}
