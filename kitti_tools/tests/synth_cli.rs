//! `kitti-tools synth` through the built binary: a small drive that `info` then reads without
//! issues, a configuration file, and refused arguments.

mod common;
use common::{ok, output as run};

#[test]
fn synth_then_info() {
    let dir = tempfile::tempdir().unwrap();
    let config = dir.path().join("street.toml");
    std::fs::write(
        &config,
        "speed = 8.0\n[lidar]\ncolumns = 400\n[recording]\ndrive_number = 42\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let text = ok(&run(&[
        "synth",
        "--out",
        out.to_str().unwrap(),
        "--frames",
        "4",
        "--seed",
        "3",
        "--config",
        config.to_str().unwrap(),
        "--quiet",
    ]));
    let drive = out.join("2020_01_01/2020_01_01_drive_0042_sync");
    assert!(text.contains(drive.to_str().unwrap()), "{text}");
    assert!(text.contains("8.0 m/s"), "{text}");
    assert!(drive.join("truth.json").is_file());
    let info = ok(&run(&[
        "info",
        "--drive",
        drive.to_str().unwrap(),
        "--json",
    ]));
    let report: serde_json::Value = serde_json::from_str(&info).unwrap();
    assert_eq!(report["velodyne_frames"], 4, "{info}");
    assert_eq!(report["oxts_packets"], 4, "{info}");
    assert_eq!(report["errors"], 0, "{info}");
    assert_eq!(report["issues"].as_array().unwrap().len(), 0, "{info}");
    // 3 intervals at 8 m/s and 10 Hz.
    let length = report["path_length_m"].as_f64().unwrap();
    assert!((length - 2.4).abs() < 0.01, "{length}");
}

#[test]
fn bad_arguments_are_refused_clearly() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let zero = run(&["synth", "--out", out, "--frames", "0"]);
    assert!(!zero.status.success());
    let err = String::from_utf8_lossy(&zero.stderr);
    assert!(err.contains("--frames must be at least 1"), "{err}");

    let config = dir.path().join("bad.toml");
    std::fs::write(&config, "[lidar]\ncolums = 400\n").unwrap();
    let bad = run(&["synth", "--out", out, "--config", config.to_str().unwrap()]);
    assert!(!bad.status.success());
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(
        err.contains("bad.toml:2") && err.contains("colums"),
        "{err}"
    );

    std::fs::write(&config, "[lidar]\ndropout = 1.5\n").unwrap();
    let bad = run(&["synth", "--out", out, "--config", config.to_str().unwrap()]);
    assert!(!bad.status.success());
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(err.contains("lidar.dropout"), "{err}");
}

#[test]
fn the_tracking_layout_gets_the_urban_street_and_the_raw_layout_the_plain_one() {
    let dir = tempfile::tempdir().unwrap();
    let synth = |sub: &str, extra: &[&str]| {
        let out = dir.path().join(sub);
        let mut args = vec![
            "synth",
            "--out",
            out.to_str().unwrap(),
            "--frames",
            "3",
            "--seed",
            "3",
            "--quiet",
        ];
        args.extend_from_slice(extra);
        (ok(&run(&args)), out)
    };
    let (urban, root) = synth("trk", &["--layout", "tracking", "--sequence", "3"]);
    assert!(urban.contains("cyclists; clutter:"), "{urban}");
    let labels = std::fs::read_to_string(root.join("label_02/0003.txt")).unwrap();
    for l in labels.lines() {
        let kind = l.split_whitespace().nth(2).unwrap();
        // Road users only: poles, trunks, hedges and low walls are not labelled.
        assert!(
            ["Car", "Van", "Truck", "Pedestrian", "Cyclist"].contains(&kind),
            "{l}"
        );
    }
    assert!(
        labels.contains(" Van ") && labels.contains(" Cyclist "),
        "{labels}"
    );
    let (plain, _) = synth(
        "plain",
        &[
            "--layout",
            "tracking",
            "--sequence",
            "3",
            "--street",
            "plain",
        ],
    );
    assert!(!plain.contains("clutter:"), "{plain}");
    let (raw, _) = synth("raw", &[]);
    assert!(!raw.contains("clutter:"), "{raw}");
    // A configuration file lies over the built-in street: what it sets replaces the street's.
    let config = dir.path().join("street.toml");
    std::fs::write(
        &config,
        "[clutter]\npoles = 2\n[street]\nsidewalk_width = 4.5\n",
    )
    .unwrap();
    let (plain_poles, _) = synth("poles", &["--config", config.to_str().unwrap()]);
    assert!(
        plain_poles.contains("clutter: 2 poles, 0 tree trunks"),
        "{plain_poles}"
    );
    let (urban_poles, _) = synth(
        "urban_poles",
        &["--street", "urban", "--config", config.to_str().unwrap()],
    );
    assert!(
        urban_poles.contains("clutter: 2 poles, 10 tree trunks"),
        "{urban_poles}"
    );
    let out = dir.path().join("bad");
    // A clutter size that does not fit its row is refused, naming the field.
    std::fs::write(&config, "[clutter]\ntrunk_radius = [0.2, 0.9]\n").unwrap();
    let bad = run(&[
        "synth",
        "--out",
        out.to_str().unwrap(),
        "--config",
        config.to_str().unwrap(),
    ]);
    assert!(!bad.status.success());
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(err.contains("clutter.trunk_radius"), "{err}");
}
