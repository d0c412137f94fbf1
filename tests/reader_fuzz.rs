//! Hostile input to every file reader of the library: arbitrary bytes, valid files with a few
//! bytes changed, every truncation of a valid file, and hand-made files whose length or count
//! fields announce far more data than they hold. Each read must return (`Ok` or an `Err` that
//! names the file), never panic or abort, and never ask the allocator for a block much larger
//! than the input warrants.
//!
//! Memory is watched by this binary's global allocator: it records the largest single request
//! made on each thread (checked after every read against [`ALLOCATION_BUDGET`]) and refuses any
//! request above [`ALLOCATION_REFUSED`], which aborts the binary with "memory allocation of N
//! bytes failed" instead of letting one hostile header take the machine's memory.
//!
//! Readers: KITTI `.bin`, OXTS packet, calibration files (rigid, cam-to-cam, tracking),
//! timestamps, odometry poses, tracklets XML, tracking labels (`label_02`), LAS, PLY, PCD, CARMEN
//! logs (plain and gzip), ROS bags (scans, topics, pose arrays), laser2d CSV, detections JSON
//! and CSV. The TOML/JSON configuration reader lives in the command-line crate and is tested
//! there (`kitti_tools/src/config_file.rs`).

use proptest::prelude::*;
use proptest::sample::Index;
use smc_lmb::cloud::{
    encode_pcd, read_kitti_bin, read_las, read_pcd_with, read_ply, write_las, write_ply,
    NonFinite as CloudNonFinite, PcdEncoding, PointCloud,
};
use smc_lmb::detections::{read_frames, read_frames_with, NonFinite};
use smc_lmb::kitti::odometry::read_odometry_poses;
use smc_lmb::kitti::{
    read_cam_to_cam, read_oxts_file, read_rigid_calib, read_timestamps, read_tracking_labels,
    read_tracklets, TrackingCalib,
};
use smc_lmb::laser2d::rosbag::read_pose_arrays;
use smc_lmb::laser2d::{
    bag_topics, read_bag, read_carmen, read_scan_csv, write_scan_csv, BagOptions, CarmenOptions,
    Scan, TimeOrder,
};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

mod common;
use common::{bz2, gz};

// ---------------------------------------------------------------- allocation watch

/// The largest single allocation one read of these (small) inputs may ask for. The largest
/// legitimate one is the detections CSV reader's: up to `MAX_FRAME_GAP` (10^6) empty frames of
/// 88 bytes each, in a vector that may have doubled past that.
const ALLOCATION_BUDGET: usize = 256 << 20;

/// Requests above this are refused (the binary then aborts, naming the size).
const ALLOCATION_REFUSED: usize = 1 << 30;

/// How long one read of a small hostile input may take (generous: debug build, busy machine).
const TIME_BUDGET: Duration = Duration::from_secs(20);

struct Watch;

thread_local! {
    static LARGEST: Cell<usize> = const { Cell::new(0) };
}

fn note(size: usize) {
    // `Cell<usize>` has no destructor, so this never touches a torn-down thread local.
    let _ = LARGEST.try_with(|c| {
        if size > c.get() {
            c.set(size);
        }
    });
}

// SAFETY: every call is forwarded to the system allocator unchanged, except that oversized
// requests get a null pointer, which `GlobalAlloc` allows.
unsafe impl GlobalAlloc for Watch {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note(layout.size());
        if layout.size() > ALLOCATION_REFUSED {
            return std::ptr::null_mut();
        }
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        note(layout.size());
        if layout.size() > ALLOCATION_REFUSED {
            return std::ptr::null_mut();
        }
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note(new_size);
        if new_size > ALLOCATION_REFUSED {
            return std::ptr::null_mut();
        }
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static WATCH: Watch = Watch;

// ---------------------------------------------------------------- the checks

/// A reader under test: reads the file and counts what it found.
type Reader = fn(&Path) -> smc_lmb::Result<usize>;

/// Runs `read` on `path` and checks that it returned (no panic) within the time and allocation
/// budgets, and that an error names the file. Returns the result for further checks.
fn survive(what: &str, path: &Path, read: Reader) -> smc_lmb::Result<usize> {
    LARGEST.with(|c| c.set(0));
    let start = Instant::now();
    let result = catch_unwind(AssertUnwindSafe(|| read(path)));
    let elapsed = start.elapsed();
    let largest = LARGEST.with(Cell::get);
    let result = result.unwrap_or_else(|_| panic!("{what}: reading {} panicked", path.display()));
    assert!(
        largest <= ALLOCATION_BUDGET,
        "{what}: reading {} asked for {largest} bytes at once",
        path.display()
    );
    assert!(
        elapsed <= TIME_BUDGET,
        "{what}: reading {} took {elapsed:?}",
        path.display()
    );
    if let Err(e) = &result {
        let msg = e.to_string();
        assert!(
            msg.contains(&path.display().to_string()),
            "{what}: the error does not name the file: {msg}"
        );
    }
    result
}

/// Writes `bytes` to `dir/name` and reads it with [`survive`].
fn survive_bytes(
    what: &str,
    dir: &Path,
    name: &str,
    bytes: &[u8],
    read: Reader,
) -> smc_lmb::Result<usize> {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    survive(what, &path, read)
}

/// Every prefix length up to 512 bytes, then 128 evenly spaced longer ones, and the whole.
fn prefix_lengths(len: usize) -> Vec<usize> {
    let mut v: Vec<usize> = (0..=len.min(512)).collect();
    if len > 512 {
        v.extend((1..=128).map(|k| 512 + (len - 512) * k / 128));
    }
    v.dedup();
    v
}

/// Reads every truncation of `valid` (see [`prefix_lengths`]) and returns, per prefix length,
/// what the reader said. The whole file must read back as `Ok(expected)`.
fn truncations(
    what: &str,
    name: &str,
    valid: &[u8],
    expected: usize,
    read: Reader,
) -> Vec<(usize, smc_lmb::Result<usize>)> {
    let dir = tempfile::tempdir().unwrap();
    let out: Vec<_> = prefix_lengths(valid.len())
        .into_iter()
        .map(|n| {
            let r = survive_bytes(
                &format!("{what} cut at {n}"),
                dir.path(),
                name,
                &valid[..n],
                read,
            );
            (n, r)
        })
        .collect();
    let (n, whole) = out.last().unwrap();
    assert_eq!(*n, valid.len());
    match whole {
        Ok(count) => assert_eq!(*count, expected, "{what}: whole file"),
        Err(e) => panic!("{what}: the whole valid file fails: {e}"),
    }
    out
}

/// Small changes to a valid file: each `(position, byte, kind)` overwrites, inserts or deletes
/// one byte.
fn mutate(valid: &[u8], edits: &[(Index, u8, u8)]) -> Vec<u8> {
    let mut v = valid.to_vec();
    for (at, byte, kind) in edits {
        if v.is_empty() {
            v.push(*byte);
            continue;
        }
        let i = at.index(v.len());
        match kind % 3 {
            0 => v[i] = *byte,
            1 => v.insert(i, *byte),
            _ => {
                v.remove(i);
            }
        }
    }
    v
}

/// Arbitrary bytes, or a valid file with up to eight bytes changed.
fn hostile(valid: Vec<u8>) -> impl Strategy<Value = Vec<u8>> {
    let edits = proptest::collection::vec((any::<Index>(), any::<u8>(), any::<u8>()), 1..8);
    prop_oneof![
        proptest::collection::vec(any::<u8>(), 0..1024),
        edits.prop_map(move |e| mutate(&valid, &e)),
    ]
}

/// Generates one property test per reader: `$name` reads `$file` (a file name, whose extension
/// may matter) written from hostile bytes around the valid file `$valid`.
macro_rules! fuzz_reader {
    ($name:ident, $file:expr, $valid:expr, $read:expr) => {
        proptest! {
            #![proptest_config(ProptestConfig::with_cases(128))]
            #[test]
            fn $name(bytes in hostile($valid)) {
                let dir = tempfile::tempdir().unwrap();
                let _ = survive_bytes(stringify!($name), dir.path(), $file, &bytes, $read);
            }
        }
    };
}

// ---------------------------------------------------------------- valid files

fn data(relative: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(relative)
}

fn vendored(relative: &str) -> Vec<u8> {
    std::fs::read(data(relative)).unwrap()
}

const DAY: &str = "tests/data/kitti/2011_09_26";

fn velodyne_bin() -> Vec<u8> {
    vendored(&format!(
        "{DAY}/2011_09_26_drive_UNKNOWN_sync/velodyne_points/data/0000000000.bin"
    ))
}

fn oxts_line() -> Vec<u8> {
    vendored(&format!(
        "{DAY}/2011_09_26_drive_0001_sync/oxts/data/0000000000.txt"
    ))
}

fn oxts_timestamps() -> Vec<u8> {
    vendored(&format!(
        "{DAY}/2011_09_26_drive_0001_sync/oxts/timestamps.txt"
    ))
}

fn rigid_calib() -> Vec<u8> {
    vendored(&format!("{DAY}/calib_velo_to_cam.txt"))
}

fn cam_to_cam() -> Vec<u8> {
    vendored(&format!("{DAY}/calib_cam_to_cam.txt"))
}

fn odometry_poses() -> Vec<u8> {
    vendored("tests/data/kitti/odometry/poses/00.txt")
}

fn tracklets_xml() -> Vec<u8> {
    vendored("tests/data/kitti/tracklets/tracklet_labels.xml")
}

/// A tracking-benchmark calibration (the layout of `data_tracking_calib`).
fn tracking_calib() -> Vec<u8> {
    b"P0: 7.215377e+02 0.000000e+00 6.095593e+02 0.000000e+00 0.000000e+00 7.215377e+02 \
1.728540e+02 0.000000e+00 0.000000e+00 0.000000e+00 1.000000e+00 0.000000e+00
P1: 7.215377e+02 0.000000e+00 6.095593e+02 -3.875744e+02 0.000000e+00 7.215377e+02 \
1.728540e+02 0.000000e+00 0.000000e+00 0.000000e+00 1.000000e+00 0.000000e+00
P2: 7.215377e+02 0.000000e+00 6.095593e+02 4.485728e+01 0.000000e+00 7.215377e+02 \
1.728540e+02 2.163791e-01 0.000000e+00 0.000000e+00 1.000000e+00 2.745884e-03
P3: 7.215377e+02 0.000000e+00 6.095593e+02 -3.395242e+02 0.000000e+00 7.215377e+02 \
1.728540e+02 2.199936e+00 0.000000e+00 0.000000e+00 1.000000e+00 2.729905e-03
R_rect 9.999239e-01 9.837760e-03 -7.445048e-03 -9.869795e-03 9.999421e-01 -4.278459e-03 \
7.402527e-03 4.351614e-03 9.999631e-01
Tr_velo_cam 7.533745e-03 -9.999714e-01 -6.166020e-04 -4.069766e-03 1.480249e-02 \
7.280733e-04 -9.998902e-01 -7.631618e-02 9.998621e-01 7.523790e-03 1.480755e-02 -2.717806e-01
Tr_imu_velo 9.999976e-01 7.553071e-04 -2.035826e-03 -8.086759e-01 -7.854027e-04 \
9.998898e-01 -1.482298e-02 3.195559e-01 2.024406e-03 1.482454e-02 9.998881e-01 -7.997231e-01
"
    .to_vec()
}

/// Three `label_02` lines: a DontCare region and two objects in two frames.
fn tracking_labels() -> Vec<u8> {
    b"0 -1 DontCare -1 -1 -10.000000 219.310000 188.490000 245.500000 218.560000 -1000.000000 \
-1000.000000 -1000.000000 -10.000000 -1.000000 -1.000000 -1.000000
0 0 Van 0 0 -1.793451 296.744956 161.752147 455.226042 292.372804 2.000000 1.823255 4.433886 \
-4.552284 1.858523 13.410495 -2.115488
1 0 Van 0 0 -1.796862 294.898777 156.024256 452.199718 284.621269 2.000000 1.823255 \
4.433886 -4.650955 1.766774 13.581085 -2.121565 0.93
"
    .to_vec()
}

fn small_cloud() -> PointCloud {
    let mut c = PointCloud::new();
    for i in 0..12 {
        let f = i as f32;
        c.push(f * 0.5, -f, 0.25 * f, f / 12.0);
    }
    c
}

fn las_file() -> Vec<u8> {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("c.las");
    write_las(&p, &small_cloud()).unwrap();
    std::fs::read(p).unwrap()
}

fn ply_file() -> Vec<u8> {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("c.ply");
    write_ply(&p, &small_cloud()).unwrap();
    std::fs::read(p).unwrap()
}

fn pcd_file(encoding: PcdEncoding) -> Vec<u8> {
    let labels: Vec<u32> = (0..12).collect();
    encode_pcd(&small_cloud(), Some(&labels), encoding).unwrap()
}

fn ply_ascii() -> Vec<u8> {
    b"ply\nformat ascii 1.0\ncomment two points and a face\nelement vertex 3\n\
property float x\nproperty float y\nproperty float z\nproperty uchar intensity\n\
element face 1\nproperty list uchar int vertex_indices\nend_header\n\
0 0 0 10\n1 0 0 20\n0 1 0 30\n3 0 1 2\n"
        .to_vec()
}

fn carmen_log() -> Vec<u8> {
    vendored("tests/data/laser2d/intel_head.clf")
}

fn carmen_log_excerpt() -> Vec<u8> {
    // The first lines of the vendored log, so that every truncation can be tried.
    let all = carmen_log();
    let end = all
        .iter()
        .enumerate()
        .filter(|(_, &b)| b == b'\n')
        .map(|(i, _)| i + 1)
        .find(|&i| i > 3000)
        .unwrap_or(all.len());
    all[..end].to_vec()
}

fn scans() -> Vec<Scan> {
    (0..3)
        .map(|k| {
            let ranges = (0..7).map(|i| 1.0 + 0.25 * i as f32 + k as f32).collect();
            Scan::new(0.1 * k as f64, -1.5, 0.5, ranges, 0.05, 30.0).unwrap()
        })
        .collect()
}

fn laser_csv() -> Vec<u8> {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("s.csv");
    write_scan_csv(&p, &scans()).unwrap();
    std::fs::read(p).unwrap()
}

fn detections_json() -> Vec<u8> {
    br#"{"frames": [
  {"time": 0.0, "measurements": [[1.0, 2.0], [3.5, -4.0]]},
  {"time": 0.5, "measurements": [], "sensor_pose": [0.0, 1.0, 0.1]},
  {"time": 1.0, "measurements": [[1.5, 2.5]], "ids": [7]}
]}
"#
    .to_vec()
}

fn detections_csv() -> Vec<u8> {
    vendored("examples/data/detections.csv")
}

/// A ROS bag 2.0 written field by field: one connection (`/scan`, `sensor_msgs/LaserScan`),
/// one chunk (uncompressed, or bzip2 when `bzip2` is set) of `scans` scan messages, and the
/// index section (the connection again and one chunk info record).
mod bag {
    pub const LASER_SCAN_MD5: &[u8] = b"90c7ef2dc6895d81024acba2ac42f369";

    pub fn field(name: &str, value: &[u8]) -> Vec<u8> {
        let mut f = ((name.len() + 1 + value.len()) as u32)
            .to_le_bytes()
            .to_vec();
        f.extend_from_slice(name.as_bytes());
        f.push(b'=');
        f.extend_from_slice(value);
        f
    }

    pub fn record(fields: &[Vec<u8>], data: &[u8]) -> Vec<u8> {
        let header: Vec<u8> = fields.concat();
        let mut r = (header.len() as u32).to_le_bytes().to_vec();
        r.extend_from_slice(&header);
        r.extend_from_slice(&(data.len() as u32).to_le_bytes());
        r.extend_from_slice(data);
        r
    }

    pub fn time(secs: u32, nsecs: u32) -> Vec<u8> {
        [secs.to_le_bytes(), nsecs.to_le_bytes()].concat()
    }

    /// A serialised `sensor_msgs/LaserScan` of five beams over [-1, 1] rad.
    pub fn laser_scan(seq: u32, secs: u32, ranges_count: u32) -> Vec<u8> {
        let mut m = Vec::new();
        m.extend_from_slice(&seq.to_le_bytes());
        m.extend_from_slice(&time(secs, 0));
        m.extend_from_slice(&5u32.to_le_bytes());
        m.extend_from_slice(b"laser");
        for v in [-1.0f32, 1.0, 0.5, 0.0, 0.1, 0.1, 10.0] {
            m.extend_from_slice(&v.to_le_bytes());
        }
        m.extend_from_slice(&ranges_count.to_le_bytes());
        for i in 0..5 {
            m.extend_from_slice(&(1.0f32 + i as f32).to_le_bytes());
        }
        m.extend_from_slice(&0u32.to_le_bytes()); // no intensities
        m
    }

    pub fn connection() -> Vec<u8> {
        let data = [
            field("topic", b"/scan"),
            field("type", b"sensor_msgs/LaserScan"),
            field("md5sum", LASER_SCAN_MD5),
            field("message_definition", b"float32[] ranges\n"),
        ]
        .concat();
        record(
            &[
                field("op", &[0x07]),
                field("conn", &0u32.to_le_bytes()),
                field("topic", b"/scan"),
            ],
            &data,
        )
    }

    pub fn message(secs: u32, data: &[u8]) -> Vec<u8> {
        message_on(0, secs, data)
    }

    /// A message on connection `conn`.
    pub fn message_on(conn: u32, secs: u32, data: &[u8]) -> Vec<u8> {
        record(
            &[
                field("op", &[0x02]),
                field("conn", &conn.to_le_bytes()),
                field("time", &time(secs, 0)),
            ],
            data,
        )
    }

    /// A chunk record holding `records`, declaring `size` as its uncompressed length
    /// (`None`: the true one).
    pub fn chunk(records: &[u8], bzip2: bool, size: Option<u32>) -> Vec<u8> {
        let (compression, stored): (&[u8], Vec<u8>) = if bzip2 {
            (b"bz2", super::bz2(records))
        } else {
            (b"none", records.to_vec())
        };
        let size = size.unwrap_or(records.len() as u32);
        record(
            &[
                field("op", &[0x05]),
                field("compression", compression),
                field("size", &size.to_le_bytes()),
            ],
            &stored,
        )
    }

    /// The whole bag around the chunk section `chunks` (one chunk, starting right after the
    /// bag header record).
    pub fn assemble(chunks: &[u8], scans: u32) -> Vec<u8> {
        const MAGIC: &[u8] = b"#ROSBAG V2.0\n";
        let header = |index_pos: u64| {
            record(
                &[
                    field("op", &[0x03]),
                    field("index_pos", &index_pos.to_le_bytes()),
                    field("conn_count", &1u32.to_le_bytes()),
                    field("chunk_count", &1u32.to_le_bytes()),
                ],
                &[],
            )
        };
        let chunk_pos = (MAGIC.len() + header(0).len()) as u64;
        let index_pos = chunk_pos + chunks.len() as u64;
        let chunk_info = record(
            &[
                field("op", &[0x06]),
                field("ver", &1u32.to_le_bytes()),
                field("chunk_pos", &chunk_pos.to_le_bytes()),
                field("start_time", &time(100, 0)),
                field("end_time", &time(100 + scans, 0)),
                field("count", &1u32.to_le_bytes()),
            ],
            &[0u32.to_le_bytes(), scans.to_le_bytes()].concat(),
        );
        [
            MAGIC.to_vec(),
            header(index_pos),
            chunks.to_vec(),
            connection(),
            chunk_info,
        ]
        .concat()
    }

    /// The records of a chunk: the connection, then `scans` scan messages.
    pub fn chunk_records(scans: u32) -> Vec<u8> {
        let mut r = connection();
        for k in 0..scans {
            r.extend(message(100 + k, &laser_scan(k, 100 + k, 5)));
        }
        r
    }

    pub fn valid(scans: u32, bzip2: bool) -> Vec<u8> {
        assemble(&chunk(&chunk_records(scans), bzip2, None), scans)
    }
}

// ---------------------------------------------------------------- the readers

fn read_bin(p: &Path) -> smc_lmb::Result<usize> {
    read_kitti_bin(p).map(|c| c.len())
}

fn read_oxts(p: &Path) -> smc_lmb::Result<usize> {
    read_oxts_file(p).map(|_| 1)
}

fn read_rigid(p: &Path) -> smc_lmb::Result<usize> {
    read_rigid_calib(p).map(|_| 1)
}

fn read_c2c(p: &Path) -> smc_lmb::Result<usize> {
    read_cam_to_cam(p).map(|_| 1)
}

fn read_tracking_calib(p: &Path) -> smc_lmb::Result<usize> {
    TrackingCalib::read(p).map(|_| 1)
}

fn read_stamps(p: &Path) -> smc_lmb::Result<usize> {
    read_timestamps(p).map(|t| t.len())
}

fn read_poses(p: &Path) -> smc_lmb::Result<usize> {
    read_odometry_poses(p).map(|v| v.len())
}

fn read_xml(p: &Path) -> smc_lmb::Result<usize> {
    read_tracklets(p).map(|t| t.items.len())
}

fn read_labels(p: &Path) -> smc_lmb::Result<usize> {
    read_tracking_labels(p).map(|l| l.len())
}

fn read_las_points(p: &Path) -> smc_lmb::Result<usize> {
    read_las(p).map(|c| c.len())
}

fn read_ply_points(p: &Path) -> smc_lmb::Result<usize> {
    read_ply(p).map(|c| c.len())
}

/// NaN points are left out (counted) so that more of the reader is reached.
fn read_pcd_points(p: &Path) -> smc_lmb::Result<usize> {
    read_pcd_with(p, CloudNonFinite::Skip).map(|s| s.cloud.len())
}

/// Strict about lines; time going backwards is kept (the vendored log has such records).
fn read_carmen_strict(p: &Path) -> smc_lmb::Result<usize> {
    let options = CarmenOptions {
        time_order: TimeOrder::Keep,
        ..CarmenOptions::strict()
    };
    read_carmen(p, options).map(|l| l.flaser.len() + l.robot_laser.len() + l.odometry.len())
}

fn read_carmen_lenient(p: &Path) -> smc_lmb::Result<usize> {
    read_carmen(p, CarmenOptions::lenient())
        .map(|l| l.flaser.len() + l.robot_laser.len() + l.odometry.len())
}

/// Every way into a bag: its topics, pose arrays of `/scan` (an error unless a mutation made
/// a pose array topic of it), and the scans, which are counted. Each error must name the file.
fn read_bag_all(p: &Path) -> smc_lmb::Result<usize> {
    let topics = bag_topics(p);
    let poses = read_pose_arrays(p, "/scan");
    let bag = read_bag(p, &BagOptions::default());
    let errors = [
        topics.as_ref().err(),
        poses.as_ref().err(),
        bag.as_ref().err(),
    ];
    for e in errors.into_iter().flatten() {
        let msg = e.to_string();
        assert!(msg.contains(&p.display().to_string()), "{msg}");
    }
    if let (Ok(topics), Ok(bag)) = (&topics, &bag) {
        assert!(
            topics
                .iter()
                .any(|t| t.topic == bag.scan_topic && t.message_type == "sensor_msgs/LaserScan"),
            "{topics:?} lacks {}",
            bag.scan_topic
        );
    }
    bag.map(|b| b.scans.len())
}

fn read_laser_csv(p: &Path) -> smc_lmb::Result<usize> {
    read_scan_csv(p).map(|s| s.len())
}

fn read_detections(p: &Path) -> smc_lmb::Result<usize> {
    read_frames(p).map(|f| f.len())
}

fn read_detections_skipping(p: &Path) -> smc_lmb::Result<usize> {
    read_frames_with(p, NonFinite::Skip).map(|(f, _)| f.len())
}

// ---------------------------------------------------------------- arbitrary and mutated bytes

fuzz_reader!(
    kitti_bin_hostile_bytes,
    "0000000000.bin",
    velodyne_bin()[..4096].to_vec(),
    read_bin
);
fuzz_reader!(oxts_hostile_bytes, "0000000000.txt", oxts_line(), read_oxts);
fuzz_reader!(
    rigid_calib_hostile_bytes,
    "calib_velo_to_cam.txt",
    rigid_calib(),
    read_rigid
);
fuzz_reader!(
    cam_to_cam_hostile_bytes,
    "calib_cam_to_cam.txt",
    cam_to_cam(),
    read_c2c
);
fuzz_reader!(
    tracking_calib_hostile_bytes,
    "0000.txt",
    tracking_calib(),
    read_tracking_calib
);
fuzz_reader!(
    timestamps_hostile_bytes,
    "timestamps.txt",
    oxts_timestamps(),
    read_stamps
);
fuzz_reader!(
    odometry_poses_hostile_bytes,
    "00.txt",
    odometry_poses(),
    read_poses
);
fuzz_reader!(
    tracklets_hostile_bytes,
    "tracklet_labels.xml",
    tracklets_xml(),
    read_xml
);
fuzz_reader!(
    labels_hostile_bytes,
    "0000.txt",
    tracking_labels(),
    read_labels
);
fuzz_reader!(las_hostile_bytes, "c.las", las_file(), read_las_points);
fuzz_reader!(
    ply_binary_hostile_bytes,
    "c.ply",
    ply_file(),
    read_ply_points
);
fuzz_reader!(
    ply_ascii_hostile_bytes,
    "c.ply",
    ply_ascii(),
    read_ply_points
);
fuzz_reader!(
    pcd_ascii_hostile_bytes,
    "c.pcd",
    pcd_file(PcdEncoding::Ascii),
    read_pcd_points
);
fuzz_reader!(
    pcd_binary_hostile_bytes,
    "c.pcd",
    pcd_file(PcdEncoding::Binary),
    read_pcd_points
);
fuzz_reader!(
    pcd_compressed_hostile_bytes,
    "c.pcd",
    pcd_file(PcdEncoding::BinaryCompressed),
    read_pcd_points
);
fuzz_reader!(
    carmen_hostile_bytes,
    "log.clf",
    carmen_log_excerpt(),
    read_carmen_strict
);
fuzz_reader!(
    carmen_lenient_hostile_bytes,
    "log.clf",
    carmen_log_excerpt(),
    read_carmen_lenient
);
fuzz_reader!(
    carmen_gz_hostile_bytes,
    "log.clf.gz",
    gz(&carmen_log_excerpt()),
    read_carmen_lenient
);
fuzz_reader!(
    bag_hostile_bytes,
    "s.bag",
    bag::valid(2, false),
    read_bag_all
);
fuzz_reader!(
    real_bag_excerpt_hostile_bytes,
    "positive_1_excerpt.bag",
    vendored(REAL_BAG),
    read_bag_all
);
fuzz_reader!(
    bag_bz2_hostile_bytes,
    "s.bag",
    bag::valid(2, true),
    read_bag_all
);
fuzz_reader!(
    laser_csv_hostile_bytes,
    "s.csv",
    laser_csv(),
    read_laser_csv
);
fuzz_reader!(
    detections_json_hostile_bytes,
    "d.json",
    detections_json(),
    read_detections
);
fuzz_reader!(
    detections_csv_hostile_bytes,
    "d.csv",
    detections_csv(),
    read_detections_skipping
);

// ---------------------------------------------------------------- every truncation

#[test]
fn kitti_bin_truncations_keep_whole_points_or_fail() {
    let valid = velodyne_bin();
    let n = valid.len() / 16;
    for (len, r) in truncations("kitti .bin", "0000000000.bin", &valid, n, read_bin) {
        match r {
            Ok(points) => assert!(len % 16 == 0 && points == len / 16, "{len}: {points}"),
            Err(_) => assert!(len % 16 != 0, "{len} bytes hold whole points"),
        }
    }
}

#[test]
fn oxts_truncations() {
    let r = truncations("oxts", "0000000000.txt", &oxts_line(), 1, read_oxts);
    // A packet cut anywhere before its last value is missing fields.
    let last_space = oxts_line().iter().rposition(|&b| b == b' ').unwrap();
    assert!(r
        .iter()
        .filter(|(n, _)| *n <= last_space)
        .all(|(_, r)| r.is_err()));
}

#[test]
fn calibration_truncations() {
    truncations(
        "rigid calib",
        "calib_velo_to_cam.txt",
        &rigid_calib(),
        1,
        read_rigid,
    );
    truncations(
        "cam to cam",
        "calib_cam_to_cam.txt",
        &cam_to_cam(),
        1,
        read_c2c,
    );
    truncations(
        "tracking calib",
        "0000.txt",
        &tracking_calib(),
        1,
        read_tracking_calib,
    );
}

#[test]
fn timestamps_and_poses_truncations() {
    let stamps = oxts_timestamps();
    let lines = stamps.iter().filter(|&&b| b == b'\n').count();
    truncations("timestamps", "timestamps.txt", &stamps, lines, read_stamps);
    let poses = odometry_poses();
    let lines = poses.iter().filter(|&&b| b == b'\n').count();
    truncations("odometry poses", "00.txt", &poses, lines, read_poses);
}

#[test]
fn tracklets_truncations_fail_until_the_root_closes() {
    let xml = tracklets_xml();
    let close = xml.iter().rposition(|&b| b == b'>').unwrap() + 1;
    for (n, r) in truncations("tracklets", "tracklet_labels.xml", &xml, 2, read_xml) {
        assert_eq!(r.is_ok(), n >= close, "cut at {n}: {r:?}");
    }
}

#[test]
fn labels_truncations() {
    truncations("labels", "0000.txt", &tracking_labels(), 3, read_labels);
}

#[test]
fn las_truncations_fail() {
    let las = las_file();
    for (n, r) in truncations("las", "c.las", &las, 12, read_las_points) {
        assert_eq!(r.is_ok(), n == las.len(), "cut at {n}: {r:?}");
    }
}

#[test]
fn ply_truncations() {
    let ply = ply_file();
    for (n, r) in truncations("binary ply", "c.ply", &ply, 12, read_ply_points) {
        assert_eq!(r.is_ok(), n == ply.len(), "cut at {n}: {r:?}");
    }
    truncations("ascii ply", "c.ply", &ply_ascii(), 3, read_ply_points);
}

#[test]
fn pcd_truncations() {
    for encoding in [PcdEncoding::Binary, PcdEncoding::BinaryCompressed] {
        let pcd = pcd_file(encoding);
        for (n, r) in truncations("pcd", "c.pcd", &pcd, 12, read_pcd_points) {
            assert_eq!(r.is_ok(), n == pcd.len(), "{encoding:?} cut at {n}: {r:?}");
        }
    }
    // Ascii cut inside its last line may still read (a shorter last label); before it, never.
    let pcd = pcd_file(PcdEncoding::Ascii);
    let last_line = pcd[..pcd.len() - 1]
        .iter()
        .rposition(|&b| b == b'\n')
        .unwrap();
    for (n, r) in truncations("ascii pcd", "c.pcd", &pcd, 12, read_pcd_points) {
        assert!(r.is_err() || n > last_line + 1, "cut at {n}: {r:?}");
    }
}

#[test]
fn carmen_truncations() {
    let log = carmen_log();
    let vendored = data("tests/data/laser2d/intel_head.clf");
    let whole = read_carmen_strict(&vendored).unwrap();
    truncations("carmen", "log.clf", &log, whole, read_carmen_strict);
    let whole = read_carmen_lenient(&vendored).unwrap();
    truncations(
        "carmen lenient",
        "log.clf",
        &log,
        whole,
        read_carmen_lenient,
    );
    let packed = gz(&carmen_log_excerpt());
    let excerpt = {
        let dir = tempfile::tempdir().unwrap();
        survive_bytes(
            "excerpt",
            dir.path(),
            "e.clf",
            &carmen_log_excerpt(),
            read_carmen_lenient,
        )
        .unwrap()
    };
    truncations(
        "carmen gz",
        "log.clf.gz",
        &packed,
        excerpt,
        read_carmen_lenient,
    );
    let packed = bz2(&carmen_log_excerpt());
    truncations(
        "carmen bz2",
        "log.clf.bz2",
        &packed,
        excerpt,
        read_carmen_lenient,
    );
}

#[test]
fn bag_truncations() {
    for bzip2 in [false, true] {
        let valid = bag::valid(3, bzip2);
        for (n, r) in truncations("bag", "s.bag", &valid, 3, read_bag_all) {
            assert_eq!(r.is_ok(), n == valid.len(), "cut at {n}: {r:?}");
        }
    }
}

/// The vendored excerpt of a real recording (three topics, three uncompressed chunks).
const REAL_BAG: &str = "tests/data/laser2d/positive_1_excerpt.bag";

#[test]
fn real_bag_excerpt_truncations() {
    let valid = vendored(REAL_BAG);
    for (n, r) in truncations("real bag", "r.bag", &valid, 39, read_bag_all) {
        if let Ok(scans) = r {
            assert!(scans <= 39, "cut at {n}: {scans} scans");
        }
    }
}

#[test]
fn laser_csv_truncations() {
    truncations("laser2d csv", "s.csv", &laser_csv(), 3, read_laser_csv);
}

#[test]
fn detections_truncations() {
    let json = detections_json();
    let close = json.iter().rposition(|&b| b == b'}').unwrap() + 1;
    for (n, r) in truncations("detections json", "d.json", &json, 3, read_detections) {
        assert_eq!(r.is_ok(), n >= close, "cut at {n}: {r:?}");
    }
    let csv = detections_csv();
    let text = String::from_utf8(csv.clone()).unwrap();
    let last = text.lines().last().unwrap();
    let frames = last.split(',').next().unwrap().parse::<usize>().unwrap() + 1;
    truncations("detections csv", "d.csv", &csv, frames, read_detections);
}

fn find(haystack: &[u8], needle: &[u8]) -> Option<usize> {
    haystack.windows(needle.len()).position(|w| w == needle)
}

// ---------------------------------------------------------------- lengths and counts that lie

/// `bytes` with `value` written little-endian at `at`.
fn patched(bytes: &[u8], at: usize, value: &[u8]) -> Vec<u8> {
    let mut v = bytes.to_vec();
    v[at..at + value.len()].copy_from_slice(value);
    v
}

fn expect_err(what: &str, name: &str, bytes: &[u8], read: Reader) -> String {
    let dir = tempfile::tempdir().unwrap();
    match survive_bytes(what, dir.path(), name, bytes, read) {
        Ok(n) => panic!("{what}: read {n} items"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn las_point_count_beyond_the_file_is_refused_without_allocating_it() {
    let las = las_file();
    // Legacy point count (LAS 1.2): u32 at byte 107.
    let msg = expect_err(
        "las 4e9 points",
        "c.las",
        &patched(&las, 107, &u32::MAX.to_le_bytes()),
        read_las_points,
    );
    assert!(msg.contains("point"), "{msg}");
    // Record length × count beyond the file.
    let msg = expect_err(
        "las long records",
        "c.las",
        &patched(&las, 105, &u16::MAX.to_le_bytes()),
        read_las_points,
    );
    assert!(!msg.is_empty());
}

#[test]
fn pcd_counts_beyond_the_file_are_refused_without_allocating_them() {
    let binary = String::from_utf8_lossy(&pcd_file(PcdEncoding::Binary)).into_owned();
    for n in ["214748364", "4000000000", "18446744073709551615"] {
        let text = binary
            .replace("WIDTH 12", &format!("WIDTH {n}"))
            .replace("POINTS 12", &format!("POINTS {n}"));
        let msg = expect_err("pcd huge count", "c.pcd", text.as_bytes(), read_pcd_points);
        assert!(msg.contains("POINTS"), "{msg}");
    }
    // binary_compressed: a POINTS count matching an uncompressed size of almost 4 GiB, or a
    // compressed size beyond the file.
    let compressed = pcd_file(PcdEncoding::BinaryCompressed);
    let data = find(&compressed, b"DATA binary_compressed\n").unwrap() + 23;
    let header = String::from_utf8_lossy(&compressed[..data])
        .replace("WIDTH 12", "WIDTH 214748364")
        .replace("POINTS 12", "POINTS 214748364");
    let mut bytes = header.into_bytes();
    bytes.extend_from_slice(&compressed[data..]);
    let at = bytes.len() - (compressed.len() - data) + 4;
    let big = patched(&bytes, at, &(214_748_364u32 * 20).to_le_bytes());
    let msg = expect_err("pcd huge unpacked", "c.pcd", &big, read_pcd_points);
    assert!(msg.contains("cannot hold"), "{msg}");
    let msg = expect_err(
        "pcd huge packed",
        "c.pcd",
        &patched(&compressed, data, &u32::MAX.to_le_bytes()),
        read_pcd_points,
    );
    assert!(msg.contains("truncated"), "{msg}");
}

/// A LAS 1.4 file of the small cloud (written with the `las` crate itself).
fn las14(cloud: &PointCloud) -> Vec<u8> {
    let mut builder = las::Builder::from((1, 4));
    builder.point_format = las::point::Format::new(0).unwrap();
    let header = builder.into_header().unwrap();
    let mut writer = las::Writer::new(std::io::Cursor::new(Vec::new()), header).unwrap();
    let (x, y, z, _) = cloud.columns();
    for i in 0..cloud.len() {
        writer
            .write_point(las::Point {
                x: f64::from(x[i]),
                y: f64::from(y[i]),
                z: f64::from(z[i]),
                ..Default::default()
            })
            .unwrap();
    }
    writer.into_inner().unwrap().into_inner()
}

#[test]
fn las14_counts_and_evlr_lengths_beyond_the_file_are_refused() {
    let cloud = small_cloud();
    let las = las14(&cloud);
    let dir = tempfile::tempdir().unwrap();
    assert_eq!(
        survive_bytes("las 1.4", dir.path(), "c.las", &las, read_las_points).unwrap(),
        cloud.len()
    );
    // 64-bit point count (LAS 1.4): u64 at byte 247; 10^12 points, and one that overflows
    // count × record length.
    for count in [1_000_000_000_000u64, u64::MAX / 4] {
        let bad = patched(&las, 247, &count.to_le_bytes());
        let bad = patched(&bad, 107, &0u32.to_le_bytes());
        expect_err("las 1.4 count", "c.las", &bad, read_las_points);
    }
    // One extended VLR after the points whose length says 10^12 bytes.
    let end = las.len() as u64;
    let mut evlr = Vec::new();
    evlr.extend_from_slice(&0u16.to_le_bytes());
    evlr.extend_from_slice(&[0u8; 16]);
    evlr.extend_from_slice(&1u16.to_le_bytes());
    evlr.extend_from_slice(&1_000_000_000_000u64.to_le_bytes());
    evlr.extend_from_slice(&[0u8; 32]);
    let mut bad = patched(&las, 235, &end.to_le_bytes());
    bad = patched(&bad, 243, &1u32.to_le_bytes());
    bad.extend_from_slice(&evlr);
    expect_err("las evlr length", "c.las", &bad, read_las_points);
    // The same with the EVLR's start beyond the file.
    let bad = patched(
        &patched(&las, 235, &u64::MAX.to_le_bytes()),
        243,
        &1u32.to_le_bytes(),
    );
    expect_err("las evlr start", "c.las", &bad, read_las_points);
}

#[test]
fn ply_counts_beyond_the_file_are_refused_without_allocating_them() {
    let header = |format: &str, count: &str| {
        format!(
            "ply\nformat {format} 1.0\nelement vertex {count}\nproperty float x\n\
             property float y\nproperty float z\nend_header\n"
        )
    };
    for format in ["ascii", "binary_little_endian", "binary_big_endian"] {
        for count in [
            "1000000000000",
            "18446744073709551615",
            "18446744073709551616",
        ] {
            let mut bytes = header(format, count).into_bytes();
            bytes.extend_from_slice(if format == "ascii" {
                b"1 2 3\n"
            } else {
                &[0u8; 12]
            });
            expect_err("ply vertex count", "c.ply", &bytes, read_ply_points);
        }
    }
    // A list whose length prefix is 4e9.
    let mut bytes = b"ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\n\
        property float y\nproperty float z\nelement face 1\n\
        property list uint int vertex_indices\nend_header\n"
        .to_vec();
    bytes.extend_from_slice(&[0u8; 12]);
    bytes.extend_from_slice(&u32::MAX.to_le_bytes());
    bytes.extend_from_slice(&[0u8; 8]);
    expect_err("ply list length", "c.ply", &bytes, read_ply_points);
}

#[test]
fn bag_lengths_beyond_the_file_are_refused_without_allocating_them() {
    let records = bag::chunk_records(2);
    // A compressed chunk declaring 4 GiB uncompressed.
    let bad = bag::assemble(&bag::chunk(&records, true, Some(u32::MAX)), 2);
    expect_err("bag chunk size", "s.bag", &bad, read_bag_all);
    // An uncompressed chunk declaring more than it holds.
    let bad = bag::assemble(&bag::chunk(&records, false, Some(u32::MAX)), 2);
    expect_err("bag chunk size", "s.bag", &bad, read_bag_all);
    // A message whose data length runs past its chunk.
    let mut msg = bag::message(100, &bag::laser_scan(0, 100, 5));
    let data_len_at = msg.len() - bag::laser_scan(0, 100, 5).len() - 4;
    msg = patched(&msg, data_len_at, &u32::MAX.to_le_bytes());
    let bad = bag::assemble(
        &bag::chunk(&[bag::connection(), msg].concat(), false, None),
        1,
    );
    expect_err("bag message length", "s.bag", &bad, read_bag_all);
    // A scan whose range count is 4e9.
    let scan = bag::laser_scan(0, 100, u32::MAX);
    let records = [bag::connection(), bag::message(100, &scan)].concat();
    let bad = bag::assemble(&bag::chunk(&records, false, None), 1);
    let msg = expect_err("bag range count", "s.bag", &bad, read_bag_all);
    assert!(msg.contains("ranges"), "{msg}");
    // The bag header record's length is 4e9.
    let valid = bag::valid(1, false);
    let bad = patched(&valid, 13, &(u32::MAX - 3).to_le_bytes());
    expect_err("bag header length", "s.bag", &bad, read_bag_all);
    // The index section's first record header says 4e9 bytes.
    let at = find(&valid, b"index_pos=").unwrap() + b"index_pos=".len();
    let index_pos = u64::from_le_bytes(valid[at..at + 8].try_into().unwrap()) as usize;
    let bad = patched(&valid, index_pos, &(u32::MAX - 3).to_le_bytes());
    expect_err("bag index record length", "s.bag", &bad, read_bag_all);
}

#[test]
fn bag_with_a_large_compressed_chunk_still_reads() {
    // A chunk declaring more than the size trusted without checking (64 MiB): its bzip2 data
    // really holds it (a 65 MiB message on a topic the reader skips), so the bag reads.
    let mut records = bag::chunk_records(2);
    records.extend(bag::message_on(1, 101, &vec![0u8; 65 << 20]));
    let valid = bag::assemble(&bag::chunk(&records, true, None), 2);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("big.bag");
    std::fs::write(&path, &valid).unwrap();
    let bag = read_bag(&path, &BagOptions::default()).unwrap();
    assert_eq!(bag.scans.len(), 2);
    // The same chunk declaring one byte more is refused by name.
    let bad = bag::assemble(
        &bag::chunk(&records, true, Some(records.len() as u32 + 1)),
        2,
    );
    std::fs::write(&path, &bad).unwrap();
    let msg = read_bag(&path, &BagOptions::default())
        .unwrap_err()
        .to_string();
    assert!(msg.contains("big.bag") && msg.contains("chunk 1"), "{msg}");
}

#[test]
fn carmen_and_csv_counts_beyond_the_line_are_refused() {
    for line in [
        "FLASER 1000000000000 1 2 3 0 0 0 0 0 0 1.0 h 1.0\n",
        "FLASER 18446744073709551615 1 0 0 0 0 0 0 1.0 h 1.0\n",
        "ROBOTLASER1 0 -1.5 3.1 0.01 81.9 0.01 0 18446744073709551610 1 2 \
         18446744073709551610 0 0 0 0 0 0 0 0 0 0 0 1.0 h 1.0\n",
        "ROBOTLASER1 0 -1.5 3.1 0.01 81.9 0.01 0 2 1 2 1000000000000 0 0 0 0 0 0 0 0 0 0 0 \
         1.0 h 1.0\n",
    ] {
        expect_err(
            "carmen count",
            "log.clf",
            line.as_bytes(),
            read_carmen_strict,
        );
    }
    let csv = String::from_utf8(laser_csv()).unwrap();
    let mut lines: Vec<&str> = csv.lines().collect();
    let row = lines[2].replacen(",7,", ",1000000000000,", 1);
    lines[2] = &row;
    let bad = lines.join("\n");
    let msg = expect_err("laser csv count", "s.csv", bad.as_bytes(), read_laser_csv);
    assert!(msg.contains("num_ranges"), "{msg}");
}

#[test]
fn detections_gaps_and_nesting_are_bounded() {
    // One huge gap.
    let csv = "frame,time,z0,z1\n0,0.0,1,2\n1000000000000,1.0,1,2\n";
    expect_err("detections gap", "d.csv", csv.as_bytes(), read_detections);
    // Many gaps each just under the limit: a few hundred bytes must not fill gigabytes.
    let mut csv = String::from("frame,time,z0,z1\n");
    for k in 0..64u64 {
        csv.push_str(&format!("{},{}.0,1,2\n", k * 999_999, k));
    }
    expect_err(
        "detections many gaps",
        "d.csv",
        csv.as_bytes(),
        read_detections,
    );
    // Deeply nested JSON.
    let json = format!(
        "{{\"frames\": {}{}}}",
        "[".repeat(100_000),
        "]".repeat(100_000)
    );
    expect_err(
        "detections nesting",
        "d.json",
        json.as_bytes(),
        read_detections,
    );
}

#[test]
fn tracklets_counts_and_nesting_are_bounded() {
    let xml = String::from_utf8(tracklets_xml()).unwrap();
    let huge = xml.replacen("<count>2</count>", "<count>18446744073709551615</count>", 1);
    expect_err("tracklets count", "t.xml", huge.as_bytes(), read_xml);
    let huge = xml.replacen("<count>3</count>", "<count>1000000000000</count>", 1);
    expect_err("tracklets pose count", "t.xml", huge.as_bytes(), read_xml);
    let deep = format!(
        "<tracklets>{}{}</tracklets>",
        "<a>".repeat(50_000),
        "</a>".repeat(50_000)
    );
    let dir = tempfile::tempdir().unwrap();
    let _ = survive_bytes(
        "tracklets nesting",
        dir.path(),
        "t.xml",
        deep.as_bytes(),
        read_xml,
    );
}
