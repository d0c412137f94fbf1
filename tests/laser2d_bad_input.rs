//! Bad input to the 2D laser readers (CARMEN plain/.gz/.bz2, ROS bag, CSV) and to the people
//! run: odd ranges, beam counts that disagree with the header, short or damaged lines,
//! truncated and empty files, bags without a scan topic, time going backwards. Each case is
//! either a clear error naming the file (and line and field where there are lines) or a
//! documented skip — never a panic. Damaged real bags are made from
//! `../shared/data/laser2d/` (a missing file fails the test under `CI=true` and is skipped with a
//! note on the terminal otherwise).

use proptest::prelude::*;
use smc_lmb::laser2d::csv::{CSV_HEADER, CSV_MAGIC};
use smc_lmb::laser2d::{
    bag_topics, read_bag, read_carmen, read_scan_csv, BagOptions, CarmenOptions, CarmenReader,
    OnMalformed, Scan, TimeOrder,
};
use smc_lmb::pipeline::people_tracking::{config_for_scans, track_scans};
use smc_lmb::Error;
use std::path::Path;

mod common;
use common::{bz2, gz, shared_laser2d as shared, vendored_laser2d as vendored};

const ODOM: &str = "ODOM 0.0 0.0 0.1 0.0 0.0 0.0 100.0 nohost 0.0";
const FLASER: &str =
    "FLASER 6 1.50 1.52 0.00 3.10 3.12 81.83 0.0 0.0 0.1 0.0 0.0 0.1 100.05 nohost 0.05";

/// The error of reading `text` as a plain log with the default (strict) options, checking
/// that its message starts with the file's name; (line, field, message).
fn carmen_parse_error(dir: &Path, text: &str) -> (usize, String, String) {
    let path = dir.join("bad.clf");
    std::fs::write(&path, text).unwrap();
    match read_carmen(&path, CarmenOptions::default()) {
        Err(e @ Error::Parse { .. }) => {
            let msg = e.to_string();
            assert!(msg.starts_with(&path.display().to_string()), "{msg}");
            let Error::Parse { line, field, .. } = e else {
                unreachable!()
            };
            (line, field, msg)
        }
        other => panic!("{text:?}: expected a parse error, got {other:?}"),
    }
}

#[test]
fn carmen_odd_ranges_are_no_return_beams() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("odd.clf");
    // NaN, +inf, -inf, zero, the SICK "nothing reflected" value and a negative range: kept in
    // place (beam indices stay aligned with bearings) but none is a return.
    let line = "FLASER 8 nan inf -inf 0.0 81.83 -1.0 2.0 3.0 0 0 0 0 0 0 5.0 h 5.0\n";
    std::fs::write(&path, line).unwrap();
    let log = read_carmen(&path, CarmenOptions::default()).unwrap();
    let s = &log.flaser[0];
    assert_eq!(s.len(), 8);
    assert!(s.ranges[0].is_nan() && s.ranges[1] == f32::INFINITY);
    let valid: Vec<usize> = s.points().map(|(i, _)| i).collect();
    assert_eq!(valid, vec![6, 7]);
    // A scan with no return at all is still a scan (the tracker sees nobody).
    std::fs::write(&path, "FLASER 2 0 nan 0 0 0 0 0 0 5.0 h 5.0\n").unwrap();
    let log = read_carmen(&path, CarmenOptions::default()).unwrap();
    assert_eq!(log.flaser[0].valid_count(), 0);
}

#[test]
fn carmen_short_long_and_miscounted_lines_name_line_and_field() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let with = |bad: &str| format!("{ODOM}\n{bad}\n{FLASER}\n");
    for (bad, field, says) in [
        ("FLASER", "num_readings", "missing"),
        ("FLASER 6", "num_readings", "declares 6 ranges"),
        ("ODOM", "x", "missing"),
        ("ODOM 1 2", "theta", "missing"),
        ("ROBOTLASER1 0", "start_angle", "missing"),
        // declares 6 beams, carries 7
        (
            "FLASER 6 1.5 1.5 0.0 3.1 3.1 81.8 1.0 0 0 0.1 0 0 0.1 100.1 h 0.1",
            "num_readings",
            "has 18",
        ),
        // declares 7 beams, carries 6
        (
            "FLASER 7 1.5 1.5 0.0 3.1 3.1 81.8 0 0 0.1 0 0 0.1 100.1 h 0.1",
            "num_readings",
            "declares 7 ranges",
        ),
        (
            "FLASER -6 1 2",
            "num_readings",
            "not a non-negative integer",
        ),
        (
            "FLASER 6.0 1 2",
            "num_readings",
            "not a non-negative integer",
        ),
        (
            "FLASER 2 1 2 0 0 nan 0 0 0 100.1 h 0.1",
            "theta",
            "not finite",
        ),
        ("ODOM 0 0 0 0 0 0 inf h 0", "ipc_timestamp", "not finite"),
    ] {
        let (line, f, msg) = carmen_parse_error(d, &with(bad));
        assert_eq!((line, f.as_str()), (2, field), "{bad}: {msg}");
        assert!(msg.contains(says), "{bad}: {msg}");
    }
}

#[test]
fn carmen_odometry_before_any_laser_line_and_lines_of_other_kinds() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("odom_first.clf");
    // Odometry stamped after the laser line that follows it: types are not compared, so this
    // is not "time going backwards".
    let text = format!(
        "ODOM 0 0 0 0 0 0 200.0 h 0\nODOM 0 0 0 0 0 0 201.0 h 0\nFOO 1 2\n\n   \n{FLASER}\n"
    );
    std::fs::write(&path, text).unwrap();
    let log = read_carmen(&path, CarmenOptions::default()).unwrap();
    assert_eq!((log.odometry.len(), log.flaser.len()), (2, 1));
    assert_eq!(log.stats.ignored, 3);
    // The FLASER line carries its own odometry; the ODOM records do not change it.
    assert_eq!(log.flaser[0].odometry.unwrap().theta, 0.1);
}

#[test]
fn carmen_time_going_backwards_is_an_error_or_a_counted_skip() {
    let dir = tempfile::tempdir().unwrap();
    // 180 beams of 1°, all 4 m away but for a person-sized bump, at time `t`
    let flaser = |t: f64| {
        let ranges: Vec<&str> = (0..180)
            .map(|i| if (88..93).contains(&i) { "2.0" } else { "4.0" })
            .collect();
        format!("FLASER 180 {} 0 0 0 0 0 0 {t} h {t}", ranges.join(" "))
    };
    let text = format!("{}\n{ODOM}\n{}\n", flaser(100.05), flaser(99.0));
    let (line, field, msg) = carmen_parse_error(dir.path(), &text);
    assert_eq!((line, field.as_str()), (3, "ipc_timestamp"));
    assert!(msg.contains("backwards") && msg.contains("line 1"), "{msg}");
    let path = dir.path().join("bad.clf");
    let skip = CarmenOptions {
        time_order: TimeOrder::Skip,
        ..CarmenOptions::default()
    };
    let log = read_carmen(&path, skip).unwrap();
    assert_eq!(log.flaser.len(), 1);
    assert_eq!(log.stats.backwards_skipped, 1);
    // Kept in file order, the scans reach the tracker out of order: a clear error naming
    // the scan, not a panic.
    let keep = CarmenOptions {
        time_order: TimeOrder::Keep,
        ..CarmenOptions::default()
    };
    let scans = read_carmen(&path, keep).unwrap().flaser;
    assert_eq!(scans.len(), 2);
    let cfg = config_for_scans(&scans, 0.03, 0.005, 30.0, [0.0, 0.0]).unwrap();
    let msg = track_scans(&scans, cfg).unwrap_err().to_string();
    assert!(msg.contains("scan 1") && msg.contains("backwards"), "{msg}");
}

#[test]
fn carmen_empty_and_truncated_compressed_files() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let text = std::fs::read(vendored("intel_head.clf")).unwrap();
    let keep = CarmenOptions {
        time_order: TimeOrder::Keep,
        ..CarmenOptions::default()
    };
    let whole = read_carmen(vendored("intel_head.clf"), keep).unwrap();
    // Empty files hold no records, whatever the compression.
    for (name, bytes) in [
        ("empty.clf", Vec::new()),
        ("empty.clf.gz", gz(b"")),
        ("empty.clf.bz2", bz2(b"")),
    ] {
        let p = d.join(name);
        std::fs::write(&p, bytes).unwrap();
        let log = read_carmen(&p, CarmenOptions::default()).unwrap();
        assert!(log.flaser.is_empty() && log.odometry.is_empty(), "{name}");
        assert_eq!(log.stats.lines, 0);
    }
    // Zero-byte compressed files: an error naming the file, or no records.
    for name in ["zero.clf.gz", "zero.clf.bz2"] {
        let p = d.join(name);
        std::fs::write(&p, b"").unwrap();
        match read_carmen(&p, CarmenOptions::default()) {
            Ok(log) => assert!(log.flaser.is_empty() && log.odometry.is_empty()),
            Err(e) => assert!(e.to_string().contains(name), "{e}"),
        }
    }
    // A compressed log cut short: an I/O error naming the file and the last whole line read,
    // in strict and lenient mode alike (a damaged stream cannot be skipped over).
    for (ext, packed) in [("gz", gz(&text)), ("bz2", bz2(&text))] {
        for cut in [10, packed.len() / 3, packed.len() / 2, packed.len() - 4] {
            let p = d.join(format!("cut{cut}.clf.{ext}"));
            std::fs::write(&p, &packed[..cut]).unwrap();
            for options in [keep, CarmenOptions::lenient()] {
                match read_carmen(&p, options) {
                    Err(e @ Error::Io { .. }) => {
                        let msg = e.to_string();
                        assert!(msg.contains(&format!("cut{cut}.clf.{ext}")), "{msg}");
                        assert!(msg.contains("after line"), "{msg}");
                    }
                    other => panic!("{ext} cut at {cut}: expected an I/O error, got {other:?}"),
                }
            }
        }
    }
    // A plain log cut inside a line: the last, partial line is a malformed record.
    let cut = &text[..text.len() - 40];
    let p = d.join("cut.clf");
    std::fs::write(&p, cut).unwrap();
    let lines = cut.iter().filter(|&&b| b == b'\n').count() + 1;
    match read_carmen(&p, keep) {
        Err(Error::Parse { line, .. }) => assert_eq!(line, lines),
        other => panic!("{other:?}"),
    }
    let lenient = CarmenOptions {
        on_malformed: OnMalformed::Skip,
        ..keep
    };
    let log = read_carmen(&p, lenient).unwrap();
    assert_eq!(log.stats.malformed_skipped, 1);
    assert_eq!(
        log.flaser.len() + log.odometry.len() + 1,
        whole.flaser.len() + whole.odometry.len()
    );
}

#[test]
fn csv_odd_ranges_truncation_and_bytes_that_are_not_text() {
    let dir = tempfile::tempdir().unwrap();
    let head = format!("{CSV_MAGIC}\n{CSV_HEADER}\n");
    let p = dir.path().join("odd.csv");
    std::fs::write(&p, format!("{head}0,0,0.1,0,10,,,,5,nan,inf,0,10,2\n")).unwrap();
    let scans = read_scan_csv(&p).unwrap();
    assert_eq!(scans[0].len(), 5);
    assert_eq!(scans[0].valid_count(), 1);
    // The last line cut short.
    std::fs::write(
        &p,
        format!("{head}0,0,0.1,0,10,,,,2,1,2\n1,0,0.1,0,10,,,,2,1"),
    )
    .unwrap();
    match read_scan_csv(&p) {
        Err(Error::Parse { line, field, .. }) => {
            assert_eq!((line, field.as_str()), (4, "num_ranges"))
        }
        other => panic!("{other:?}"),
    }
    // Bytes that are not UTF-8: an error naming the file and the line.
    let mut bytes = format!("{head}0,0,0.1,0,10,,,,1,1\n").into_bytes();
    bytes.extend_from_slice(b"1,0,0.1,0,10,,,,1,\xff\n");
    std::fs::write(&p, bytes).unwrap();
    let msg = read_scan_csv(&p).unwrap_err().to_string();
    assert!(msg.contains("odd.csv") && msg.contains("line 4"), "{msg}");
}

fn bag_error(path: &Path, options: &BagOptions) -> String {
    match read_bag(path, options) {
        Err(e) => {
            let msg = e.to_string();
            assert!(msg.contains(&path.display().to_string()), "{msg}");
            msg
        }
        Ok(b) => panic!("{}: read {} scans", path.display(), b.scans.len()),
    }
}

#[test]
fn bag_empty_and_not_a_bag() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("empty.bag");
    std::fs::write(&p, b"").unwrap();
    let msg = bag_error(&p, &BagOptions::default());
    assert!(msg.contains("ends inside"), "{msg}");
    std::fs::write(&p, b"#ROSBAG V2.0\n").unwrap();
    bag_error(&p, &BagOptions::default());
    std::fs::write(&p, format!("{FLASER}\n")).unwrap();
    let msg = bag_error(&p, &BagOptions::default());
    assert!(msg.contains("ROSBAG V2.0"), "{msg}");
}

#[test]
fn bag_truncated_or_damaged_is_an_error_never_a_panic() {
    let Some(src) = shared("demo_stationary_simple_environment.bag") else {
        return;
    };
    let bytes = std::fs::read(&src).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("cut.bag");
    // Cut anywhere: the index lies at the end, so every cut loses it.
    for cut in [
        13,
        17,
        100,
        4_200,
        bytes.len() / 2,
        bytes.len() - 100,
        bytes.len() - 1,
    ] {
        std::fs::write(&p, &bytes[..cut]).unwrap();
        bag_error(&p, &BagOptions::default());
    }
    // Damaged bytes inside the data: an error or, where the damage only touches range values,
    // a result — but never a panic. The positions are fixed, so the test is repeatable.
    let p = dir.path().join("damaged.bag");
    let mut state = 0x2545_f491_4f6c_dd1du64;
    for _ in 0..24 {
        let mut b = bytes.clone();
        for _ in 0..8 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let at = 13 + (state as usize) % (b.len() - 13);
            b[at] ^= (state >> 40) as u8 | 1;
        }
        std::fs::write(&p, &b).unwrap();
        let r = std::panic::catch_unwind(|| read_bag(&p, &BagOptions::default()));
        assert!(r.is_ok(), "reading a damaged bag panicked");
    }
}

#[test]
fn bag_without_a_laser_scan_topic_lists_what_it_has() {
    let Some(src) = shared("demo_stationary_simple_environment.bag") else {
        return;
    };
    // The same bag with its scan type renamed (same length, so the file stays well formed).
    let mut bytes = std::fs::read(&src).unwrap();
    let from = b"sensor_msgs/LaserScan";
    let to = b"sensor_msgs/LaserScam";
    let mut renamed = 0;
    let mut i = 0;
    while i + from.len() <= bytes.len() {
        if &bytes[i..i + from.len()] == from {
            bytes[i..i + from.len()].copy_from_slice(to);
            renamed += 1;
            i += from.len();
        } else {
            i += 1;
        }
    }
    assert!(renamed > 0);
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("no_scan.bag");
    std::fs::write(&p, &bytes).unwrap();
    let topics = bag_topics(&p).unwrap();
    assert!(topics
        .iter()
        .any(|t| t.message_type == "sensor_msgs/LaserScam"));
    let msg = bag_error(&p, &BagOptions::default());
    assert!(
        msg.contains("no sensor_msgs/LaserScan topic")
            && msg.contains("/scan (sensor_msgs/LaserScam)"),
        "{msg}"
    );
    let msg = bag_error(&p, &BagOptions::topic("/scan"));
    assert!(
        msg.contains("does not carry sensor_msgs/LaserScan"),
        "{msg}"
    );
}

#[test]
fn scans_with_bad_headers_are_refused_by_validate() {
    let ok = Scan::new(0.0, -1.0, 0.1, vec![1.0; 3], 0.0, 10.0).unwrap();
    let mut bad = Vec::new();
    for f in [f64::NAN, f64::INFINITY] {
        bad.push(Scan {
            time: f,
            ..ok.clone()
        });
        bad.push(Scan {
            angle_min: f,
            ..ok.clone()
        });
        bad.push(Scan {
            angle_increment: f,
            ..ok.clone()
        });
        bad.push(Scan {
            range_min: f,
            ..ok.clone()
        });
    }
    bad.push(Scan {
        range_max: f64::NAN,
        ..ok.clone()
    });
    bad.push(Scan {
        range_max: -1.0,
        ..ok.clone()
    });
    bad.push(Scan {
        odometry: Some(smc_lmb::geometry::Pose2::new(0.0, f64::NAN, 0.0)),
        ..ok.clone()
    });
    bad.push(Scan {
        laser_pose: Some(smc_lmb::geometry::Pose2::new(f64::INFINITY, 0.0, 0.0)),
        ..ok.clone()
    });
    for s in &bad {
        let e = s.validate().unwrap_err();
        assert!(matches!(e, Error::InvalidInput { .. }), "{e:?}");
        assert!(e.to_string().contains("laser scan"), "{e}");
    }
    // Odd ranges are never a header error.
    let odd = Scan {
        ranges: vec![f32::NAN, f32::INFINITY, 0.0, 10.0, -3.0],
        ..ok
    };
    assert!(odd.validate().is_ok());
    assert_eq!(odd.valid_count(), 0);
}

/// The vendored Intel excerpt's lines.
fn excerpt_lines() -> Vec<String> {
    std::fs::read_to_string(vendored("intel_head.clf"))
        .unwrap()
        .lines()
        .map(str::to_string)
        .collect()
}

/// Reads `bytes` as a CARMEN log in strict and lenient mode; must return, never panic.
fn read_all_modes(bytes: &[u8]) {
    for options in [CarmenOptions::default(), CarmenOptions::lenient()] {
        let reader = CarmenReader::new(bytes, "fuzz.clf", options).unwrap();
        for record in reader {
            if let Err(e) = record {
                assert!(e.to_string().contains("fuzz.clf"), "{e}");
            }
        }
    }
}

/// One edit of one line: replace, delete or insert a token, or cut the line.
#[derive(Clone, Debug)]
enum Mutation {
    Replace(usize, String),
    Delete(usize),
    Insert(usize, String),
    Cut(usize),
}

fn token() -> impl Strategy<Value = String> {
    prop_oneof![
        Just("nan".to_string()),
        Just("inf".to_string()),
        Just("-inf".to_string()),
        Just("1e999".to_string()),
        Just("18446744073709551616".to_string()),
        Just("4294967295".to_string()),
        Just("-1".to_string()),
        Just("0".to_string()),
        Just("FLASER".to_string()),
        Just("ROBOTLASER1".to_string()),
        Just("ODOM".to_string()),
        "[ -~]{0,6}",
        any::<f64>().prop_map(|v| v.to_string()),
        any::<u32>().prop_map(|v| v.to_string()),
    ]
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<usize>(), token()).prop_map(|(i, t)| Mutation::Replace(i, t)),
        any::<usize>().prop_map(Mutation::Delete),
        (any::<usize>(), token()).prop_map(|(i, t)| Mutation::Insert(i, t)),
        any::<usize>().prop_map(Mutation::Cut),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..2048)) {
        read_all_modes(&bytes);
    }

    #[test]
    fn arbitrary_laser_like_lines_never_panic(
        kind in prop_oneof![Just("FLASER"), Just("ROBOTLASER1"), Just("ODOM")],
        tokens in proptest::collection::vec(token(), 0..40),
    ) {
        let line = format!("{kind} {}\n", tokens.join(" "));
        read_all_modes(line.as_bytes());
    }

    #[test]
    fn mutated_real_log_lines_never_panic(
        edits in proptest::collection::vec((any::<usize>(), mutation()), 1..6),
    ) {
        let mut lines = excerpt_lines();
        for (which, m) in edits {
            let k = which % lines.len();
            let mut tokens: Vec<String> =
                lines[k].split_whitespace().map(str::to_string).collect();
            let n = tokens.len();
            match m {
                Mutation::Replace(i, t) if n > 0 => tokens[i % n] = t,
                Mutation::Delete(i) if n > 0 => {
                    tokens.remove(i % n);
                }
                Mutation::Insert(i, t) => tokens.insert(i % (n + 1), t),
                Mutation::Cut(i) => tokens.truncate(i % (n + 1)),
                _ => {}
            }
            lines[k] = tokens.join(" ");
        }
        let text = lines.join("\n") + "\n";
        read_all_modes(text.as_bytes());
        // A changed line is either parsed, ignored or reported, and reading goes on in
        // lenient mode to the end of the excerpt.
        let mut reader =
            CarmenReader::new(text.as_bytes(), "fuzz.clf", CarmenOptions::lenient()).unwrap();
        prop_assert!(reader.by_ref().all(|r| r.is_ok()));
        prop_assert_eq!(reader.stats().lines, lines.len());
    }
}
