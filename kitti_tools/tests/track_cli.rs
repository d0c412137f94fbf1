//! `kitti-tools track` end to end on a drive made of copies of the vendored real Velodyne
//! frame (a static sensor without OXTS), and on broken inputs.

use std::path::{Path, PathBuf};
mod common;
use common::run;

fn static_drive(root: &Path, copies: usize) -> PathBuf {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join(
        "../tests/data/kitti/2011_09_26/2011_09_26_drive_UNKNOWN_sync/velodyne_points/data/0000000000.bin",
    );
    let drive = root.join("2011_09_26/2011_09_26_drive_0000_sync");
    let data = drive.join("velodyne_points/data");
    std::fs::create_dir_all(&data).unwrap();
    for k in 0..copies {
        std::fs::copy(&src, data.join(format!("{k:010}.bin"))).unwrap();
    }
    drive
}

#[test]
fn tracks_a_drive_and_writes_every_output() {
    let tmp = tempfile::tempdir().unwrap();
    let drive = static_drive(tmp.path(), 3);
    let out = tmp.path().join("tracks.json");
    let (las, ply, plot) = (
        tmp.path().join("las"),
        tmp.path().join("ply"),
        tmp.path().join("drive.png"),
    );
    let (ok, stdout, stderr) = run(&[
        "track",
        "--drive",
        drive.to_str().unwrap(),
        "--frames",
        "0..3",
        "--particles",
        "200",
        "--seed",
        "4",
        "--out",
        out.to_str().unwrap(),
        "--las",
        las.to_str().unwrap(),
        "--ply",
        ply.to_str().unwrap(),
        "--export-frames",
        "2",
        "--plot",
        plot.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(ok, "{stdout}\n{stderr}");
    assert!(
        stdout.contains("3 frames") && stdout.contains("ms/frame"),
        "{stdout}"
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    assert_eq!(json["frames"].as_array().unwrap().len(), 3);
    assert_eq!(json["particles"], 200);
    // No OXTS: the poses come from lidar odometry on the scans (copies of one scan, so the
    // sensor stands still).
    assert_eq!(json["ego"], "lidar");
    assert!(las.join("0000000002.las").is_file());
    assert!(!las.join("0000000001.las").exists());
    assert!(ply.join("0000000002.ply").is_file());
    assert_eq!(&std::fs::read(&plot).unwrap()[1..4], b"PNG");
}

#[test]
fn bad_inputs_fail_with_clear_messages() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("t.json");
    let missing = tmp.path().join("no_such_drive");
    let (ok, _, stderr) = run(&[
        "track",
        "--drive",
        missing.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!ok && stderr.contains("no_such_drive"), "{stderr}");

    let drive = static_drive(tmp.path(), 2);
    let (ok, _, stderr) = run(&[
        "track",
        "--drive",
        drive.to_str().unwrap(),
        "--frames",
        "3..1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!ok && stderr.contains("--frames"), "{stderr}");

    // A config file that fails is named with the field at fault.
    let config = tmp.path().join("bad.toml");
    let with_config = |text: &str, field: &str| {
        std::fs::write(&config, text).unwrap();
        let (ok, _, stderr) = run(&[
            "track",
            "--drive",
            drive.to_str().unwrap(),
            "--config",
            config.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(
            !ok && stderr.contains("bad.toml") && stderr.contains(field),
            "{stderr}"
        );
    };
    with_config("[plane]\nsigma_angel = 0.1\n", "sigma_angel");
    // The plane segmentation's section is checked as well.
    with_config("[planes]\nwall_refits = 101\n", "wall_refits");
    let (ok, _, stderr) = run(&[
        "track",
        "--drive",
        drive.to_str().unwrap(),
        "--wall-refits",
        "101",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!ok && stderr.contains("wall_refits"), "{stderr}");

    let bin = drive.join("velodyne_points/data/0000000001.bin");
    let bytes = std::fs::read(&bin).unwrap();
    std::fs::write(&bin, &bytes[..bytes.len() - 3]).unwrap();
    let (ok, _, stderr) = run(&[
        "track",
        "--drive",
        drive.to_str().unwrap(),
        "--particles",
        "50",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!ok && stderr.contains("0000000001.bin"), "{stderr}");
    assert!(!out.exists());
}

#[test]
fn the_ego_flag_picks_the_pose_source_and_refuses_what_is_not_there() {
    let tmp = tempfile::tempdir().unwrap();
    let drive = static_drive(tmp.path(), 2);
    let out = tmp.path().join("t.json");
    let args = |ego: &'static str| {
        vec![
            "track".to_string(),
            "--drive".into(),
            drive.to_str().unwrap().into(),
            "--particles".into(),
            "50".into(),
            "--ego".into(),
            ego.into(),
            "--quiet".into(),
            "--out".into(),
            out.to_str().unwrap().into(),
        ]
    };
    let run_with = |ego| {
        let a = args(ego);
        let a: Vec<&str> = a.iter().map(String::as_str).collect();
        run(&a)
    };
    let (ok, _, stderr) = run_with("recorded");
    assert!(
        !ok && stderr.contains("no recorded poses") && stderr.contains("2011_09_26_drive_0000"),
        "{stderr}"
    );
    assert!(!out.exists());
    let (ok, stdout, stderr) = run_with("static");
    assert!(ok, "{stderr}");
    assert!(stdout.contains("ego none"), "{stdout}");
    let (ok, stdout, stderr) = run_with("lidar");
    assert!(ok, "{stderr}");
    assert!(
        stdout.contains("ego lidar") && stdout.contains("lidar odometry"),
        "{stdout}"
    );
}

#[test]
fn draws_one_frame_with_its_cloud_and_names_a_frame_not_tracked() {
    let tmp = tempfile::tempdir().unwrap();
    let drive = static_drive(tmp.path(), 2);
    let out = tmp.path().join("tracks.json");
    let plot = tmp.path().join("frame.png");
    let args = |at: &str| {
        vec![
            "track".to_string(),
            "--drive".into(),
            drive.to_str().unwrap().into(),
            "--particles".into(),
            "200".into(),
            "--out".into(),
            out.to_str().unwrap().into(),
            "--frame-plot".into(),
            plot.to_str().unwrap().into(),
            "--frame-plot-at".into(),
            at.into(),
            "--quiet".into(),
        ]
    };
    fn strs(v: &[String]) -> Vec<&str> {
        v.iter().map(String::as_str).collect()
    }
    let (ok, stdout, stderr) = run(&strs(&args("1")));
    assert!(ok, "{stdout}\n{stderr}");
    let png = std::fs::read(&plot).unwrap();
    assert_eq!(&png[1..4], b"PNG");
    // A whole cloud's points make the picture much heavier than an empty plot's frame.
    assert!(png.len() > 20_000, "{} bytes", png.len());
    std::fs::remove_file(&plot).unwrap();
    let (ok, _, stderr) = run(&strs(&args("7")));
    assert!(!ok);
    assert!(
        stderr.contains("frame 7 was not tracked") && stderr.contains("frame.png"),
        "{stderr}"
    );
    assert!(!plot.exists());
}
