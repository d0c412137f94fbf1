//! `--scans DIR` in `track` and `planes`: a plain folder of scans is the same recording as the
//! drive it was copied from (same tracks, same plane pairs), takes a pose file and a time
//! file, and a broken folder or file is refused naming it, with nothing written.

use std::path::{Path, PathBuf};
mod common;
use common::run;

/// The vendored real Velodyne frame.
fn frame() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(
        "../tests/data/kitti/2011_09_26/2011_09_26_drive_UNKNOWN_sync/velodyne_points/data/0000000000.bin",
    )
}

/// A raw drive of `copies` copies of the frame (no OXTS, no time stamps: a static sensor)
/// and its scan folder.
fn static_drive(root: &Path, copies: usize) -> (PathBuf, PathBuf) {
    let drive = root.join("2011_09_26/2011_09_26_drive_0000_sync");
    let data = drive.join("velodyne_points/data");
    std::fs::create_dir_all(&data).unwrap();
    for k in 0..copies {
        std::fs::copy(frame(), data.join(format!("{k:010}.bin"))).unwrap();
    }
    (drive, data)
}

/// The JSON in `path` without its timings (`*_ms` keys), which differ from run to run.
fn untimed(path: &Path) -> serde_json::Value {
    fn strip(v: &mut serde_json::Value) {
        match v {
            serde_json::Value::Object(m) => {
                m.retain(|k, _| !k.ends_with("_ms") && k != "times");
                m.values_mut().for_each(strip);
            }
            serde_json::Value::Array(a) => a.iter_mut().for_each(strip),
            _ => {}
        }
    }
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    strip(&mut v);
    v
}

#[test]
fn a_scan_folder_tracks_as_the_drive_it_came_from() {
    let tmp = tempfile::tempdir().unwrap();
    let (drive, data) = static_drive(tmp.path(), 3);
    let track = |flag: &str, path: &Path, out: &Path, extra: &[&str]| {
        let mut args = vec![
            "track",
            flag,
            path.to_str().unwrap(),
            "--particles",
            "200",
            "--seed",
            "3",
            "--out",
            out.to_str().unwrap(),
            "--quiet",
        ];
        args.extend_from_slice(extra);
        let (ok, stdout, stderr) = run(&args);
        assert!(ok, "{stdout}\n{stderr}");
        untimed(out)
    };
    let from_drive = track("--drive", &drive, &tmp.path().join("d.json"), &[]);
    let from_scans = track("--scans", &data, &tmp.path().join("s.json"), &[]);
    assert_eq!(from_scans["drive"], "data");
    assert_eq!(from_scans["ego"], "lidar");
    assert_eq!(from_drive["ego"], "lidar");
    assert_eq!(from_scans["frames"], from_drive["frames"]);
    assert_eq!(from_scans["frames"].as_array().unwrap().len(), 3);
    // A pose file and a time file are the recording's poses and times.
    let poses = tmp.path().join("poses.txt");
    std::fs::write(&poses, "1 0 0 0 0 1 0 0 0 0 1 0\n".repeat(3)).unwrap();
    let times = tmp.path().join("times.txt");
    std::fs::write(&times, "10.0\n10.1\n10.2\n").unwrap();
    let posed = track(
        "--scans",
        &data,
        &tmp.path().join("p.json"),
        &[
            "--poses",
            poses.to_str().unwrap(),
            "--times",
            times.to_str().unwrap(),
        ],
    );
    assert_eq!(posed["ego"], "poses");
    // A sensor height is taken; one that is no height is refused naming it.
    let high = track(
        "--scans",
        &data,
        &tmp.path().join("h.json"),
        &["--sensor-height", "1.9"],
    );
    assert_eq!(high["frames"].as_array().unwrap().len(), 3);
    let (ok, _, stderr) = run(&[
        "track",
        "--scans",
        data.to_str().unwrap(),
        "--sensor-height=0",
        "--out",
        tmp.path().join("bad.json").to_str().unwrap(),
    ]);
    assert!(!ok && stderr.contains("sensor height"), "{stderr}");
    assert!(!tmp.path().join("bad.json").exists());
    let frames = posed["frames"].as_array().unwrap();
    assert_eq!(frames[2]["time"], 10.2);
    assert_eq!(
        frames[1]["ego_position"],
        serde_json::json!([0.0, 0.0, 0.0])
    );
}

#[test]
fn a_scan_folder_predicts_planes_as_the_drive_it_came_from() {
    let Some(real) = common::shared_data("kitti_raw/2011_09_26/2011_09_26_drive_0005_sync") else {
        return;
    };
    // frames 10–12 of drive 0005 (facades on both sides) as a drive without OXTS and as a
    // folder of scans
    let tmp = tempfile::tempdir().unwrap();
    let drive = tmp.path().join("2011_09_26/2011_09_26_drive_0001_sync");
    let data = drive.join("velodyne_points/data");
    std::fs::create_dir_all(&data).unwrap();
    for k in 0..3 {
        let from = real.join(format!("velodyne_points/data/{:010}.bin", k + 10));
        std::fs::copy(from, data.join(format!("{k:010}.bin"))).unwrap();
    }
    let planes = |flag: &str, path: &Path, extra: &[&str]| {
        let mut args = vec![
            "planes",
            flag,
            path.to_str().unwrap(),
            "--all",
            "--runs",
            "3",
            "--json",
        ];
        args.extend_from_slice(extra);
        let (ok, stdout, stderr) = run(&args);
        assert!(ok, "{stdout}\n{stderr}");
        serde_json::from_str::<serde_json::Value>(&stdout).unwrap()
    };
    let a = planes("--drive", &drive, &[]);
    let b = planes("--scans", &data, &[]);
    assert_eq!(a["pairs"], b["pairs"]);
    assert!(!b["pairs"].as_array().unwrap().is_empty(), "{b}");
    assert!(
        b["ego"].as_str().unwrap().contains("lidar odometry"),
        "{}",
        b["ego"]
    );
    // a pose file: a sensor standing still, the measured motion
    let poses = tmp.path().join("poses.txt");
    std::fs::write(&poses, "1 0 0 0 0 1 0 0 0 0 1 0\n".repeat(3)).unwrap();
    let c = planes("--scans", &data, &["--poses", poses.to_str().unwrap()]);
    assert!(
        c["ego"].as_str().unwrap().contains("recorded poses"),
        "{}",
        c["ego"]
    );
    assert!(!c["pairs"].as_array().unwrap().is_empty(), "{c}");
}

#[test]
fn broken_scan_folders_and_files_are_named_and_nothing_is_written() {
    let tmp = tempfile::tempdir().unwrap();
    let (_, data) = static_drive(tmp.path(), 3);
    let out = tmp.path().join("out.json");
    let empty = tmp.path().join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let mixed = tmp.path().join("mixed");
    std::fs::create_dir_all(&mixed).unwrap();
    std::fs::copy(frame(), mixed.join("a.bin")).unwrap();
    std::fs::write(mixed.join("b.pcd"), "").unwrap();
    let short = tmp.path().join("short.txt");
    std::fs::write(&short, "1 0 0 0 0 1 0 0 0 0 1 0\n".repeat(2)).unwrap();
    let malformed = tmp.path().join("malformed.txt");
    std::fs::write(
        &malformed,
        "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 x 0 1 0 0 0 0 1 0\n",
    )
    .unwrap();
    let truncated = tmp.path().join("truncated");
    std::fs::create_dir_all(&truncated).unwrap();
    std::fs::copy(frame(), truncated.join("0.bin")).unwrap();
    std::fs::write(truncated.join("1.bin"), [0u8; 10]).unwrap();
    let cases: Vec<(PathBuf, Vec<&str>, Vec<&str>)> = vec![
        (empty.clone(), vec![], vec!["empty", "no .bin or .pcd"]),
        (
            mixed.clone(),
            vec![],
            vec!["mixed", "both .bin (1) and .pcd (1)"],
        ),
        (
            data.clone(),
            vec!["--poses", short.to_str().unwrap()],
            vec!["short.txt", "2 poses for 3 scans"],
        ),
        (
            data.clone(),
            vec!["--poses", malformed.to_str().unwrap()],
            vec!["malformed.txt:2"],
        ),
        (truncated.clone(), vec![], vec!["1.bin"]),
    ];
    for (dir, extra, needles) in &cases {
        for command in ["track", "planes"] {
            let mut args = vec![command, "--scans", dir.to_str().unwrap()];
            args.extend_from_slice(extra);
            if command == "track" {
                args.extend_from_slice(&["--out", out.to_str().unwrap(), "--quiet"]);
            } else {
                args.extend_from_slice(&["--all", "--runs", "2"]);
            }
            let (ok, stdout, stderr) = run(&args);
            assert!(!ok, "{command} {args:?} succeeded: {stdout}");
            for n in needles {
                assert!(
                    stderr.contains(n),
                    "{command} {args:?}: no `{n}` in\n{stderr}"
                );
            }
            assert!(!out.exists(), "{command} {args:?} wrote {}", out.display());
        }
    }
    // --poses and --times belong to --scans
    let (ok, _, stderr) = run(&[
        "track",
        "--drive",
        data.to_str().unwrap(),
        "--poses",
        short.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!ok && stderr.contains("--scans"), "{stderr}");
    let (ok, _, stderr) = run(&[
        "track",
        "--drive",
        data.to_str().unwrap(),
        "--sensor-height",
        "1.9",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!ok && stderr.contains("--scans"), "{stderr}");
    let (ok, _, stderr) = run(&[
        "planes",
        "--drive",
        data.to_str().unwrap(),
        "--poses",
        short.to_str().unwrap(),
    ]);
    assert!(!ok && stderr.contains("--scans"), "{stderr}");
}
