//! `kitti-tools planes --paper`: seed 001's tables for one frame pair, on a simulated drive
//! (our pairs only) and on the paper's own drive at k = 11 (the paper's values beside ours).

mod common;
use common::{ok, output as run};
use std::path::PathBuf;

#[test]
fn paper_tables_on_a_simulated_drive() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    ok(&run(&[
        "synth",
        "--out",
        out.to_str().unwrap(),
        "--frames",
        "3",
        "--seed",
        "2",
        "--quiet",
    ]));
    let drive = out.join("2020_01_01/2020_01_01_drive_0001_sync");
    let text = ok(&run(&[
        "planes",
        "--drive",
        drive.to_str().unwrap(),
        "--frame",
        "1",
        "--runs",
        "5",
        "--paper",
    ]));
    for needle in [
        "Table 1. Areas of the predicted and segmented planes for k = 2, mean of 5 runs",
        "Table 2. Distances between each pair of plane vertexes",
        "Table 3. Angles between each pair of normal vectors",
        "Plane Pair 1",
        "Vertex Pair 4",
        "Execution time of the prediction",
    ] {
        assert!(text.contains(needle), "missing `{needle}` in\n{text}");
    }
    assert!(
        !text.contains("paper"),
        "no reference on a simulated drive:\n{text}"
    );
    // --paper is one frame pair's report: not with --all or --json.
    let refused = run(&[
        "planes",
        "--drive",
        drive.to_str().unwrap(),
        "--all",
        "--paper",
    ]);
    assert!(!refused.status.success());
}

#[test]
fn paper_tables_on_the_papers_drive_find_its_three_walls() {
    let Some(drive) = common::shared_data("kitti_raw/2011_09_26/2011_09_26_drive_0005_sync") else {
        return;
    };
    let text = ok(&run(&[
        "planes",
        "--drive",
        drive.to_str().unwrap(),
        "--frame",
        "11",
        "--runs",
        "20",
        "--paper",
    ]));
    assert!(
        text.contains("Table 4. Areas of the predicted and segmented planes for k = 12"),
        "{text}"
    );
    assert!(text.contains("(ours | paper)"), "{text}");
    // The paper's values are printed beside ours: its third pair's segmented area and its
    // second pair's angle.
    assert!(text.contains("| 90.5685"), "{text}");
    assert!(text.contains("| 6.4916"), "{text}");
    assert!(
        text.contains("3 of the paper's 3 walls found and paired"),
        "{text}"
    );
    assert!(text.contains("walls 1, 2, 3 found"), "{text}");
    // Each of the paper's walls on a line of its own, judged against the targets.
    for n in 1..=3 {
        let line = text
            .lines()
            .find(|l| l.trim_start().starts_with(&format!("paper wall {n} (")))
            .unwrap_or_else(|| panic!("no line on paper wall {n} in\n{text}"));
        assert!(
            line.contains("normal angle") && line.contains("target"),
            "{line}"
        );
    }
}

/// A simulated street of `frames` frames (seed 4) written under `dir` as a raw drive.
fn street_drive(dir: &std::path::Path, frames: usize) -> PathBuf {
    let out = dir.join("out");
    let frames = frames.to_string();
    ok(&run(&[
        "synth",
        "--out",
        out.to_str().unwrap(),
        "--frames",
        &frames,
        "--seed",
        "4",
        "--quiet",
    ]));
    out.join("2020_01_01/2020_01_01_drive_0001_sync")
}

#[test]
fn ego_motion_source_is_chosen_and_said() {
    let dir = tempfile::tempdir().unwrap();
    let drive = street_drive(dir.path(), 3);
    let d = drive.to_str().unwrap();
    let text = ok(&run(&[
        "planes", "--drive", d, "--frame", "0", "--runs", "2",
    ]));
    assert!(text.starts_with("ego motion: vehicle model (ECT"), "{text}");
    let text = ok(&run(&[
        "planes",
        "--drive",
        d,
        "--frame",
        "0",
        "--measured",
    ]));
    assert!(text.starts_with("ego motion: recorded poses"), "{text}");
    let text = ok(&run(&[
        "planes", "--drive", d, "--frame", "0", "--ego", "lidar",
    ]));
    assert!(text.starts_with("ego motion: lidar odometry"), "{text}");
    // Without OXTS, `auto` falls back to lidar odometry and `recorded` is refused.
    std::fs::remove_dir_all(drive.join("oxts")).unwrap();
    let text = ok(&run(&[
        "planes", "--drive", d, "--frame", "0", "--runs", "2",
    ]));
    assert!(text.starts_with("ego motion: lidar odometry"), "{text}");
    assert!(text.contains("frame"), "{text}");
    let refused = run(&["planes", "--drive", d, "--frame", "0", "--ego", "recorded"]);
    assert!(!refused.status.success());
    assert!(String::from_utf8_lossy(&refused.stderr).contains("oxts"));
    // A frame number at the top of the integers is an error, not an overflow.
    let huge = run(&[
        "planes",
        "--drive",
        d,
        "--frame",
        "18446744073709551615",
        "--measured",
    ]);
    assert!(!huge.status.success());
    let stderr = String::from_utf8_lossy(&huge.stderr);
    assert!(stderr.contains("18446744073709551615"), "{stderr}");
}

#[test]
fn segmentation_settings_come_from_a_file_and_a_flag() {
    let dir = tempfile::tempdir().unwrap();
    let drive = street_drive(dir.path(), 2);
    let d = drive.to_str().unwrap();
    let pairs = |extra: &[&str]| -> u64 {
        let mut args = vec![
            "planes",
            "--drive",
            d,
            "--frame",
            "0",
            "--measured",
            "--json",
        ];
        args.extend_from_slice(extra);
        let text = ok(&run(&args));
        let json: serde_json::Value = serde_json::from_str(&text).unwrap();
        json["summary"]["pairs"].as_u64().unwrap()
    };
    // The simulated street's walls are found with the defaults, and none when a file allows
    // one round only (the ground's).
    assert!(pairs(&[]) >= 3);
    let one_round = dir.path().join("one_round.toml");
    std::fs::write(&one_round, "max_planes = 1\n").unwrap();
    assert_eq!(pairs(&["--planes-config", one_round.to_str().unwrap()]), 0);
    assert!(pairs(&["--wall-refits", "0"]) >= 3);
    // A misspelt field names the file; a refit count past the limit is refused.
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "max_plane = 1\n").unwrap();
    let refused = run(&[
        "planes",
        "--drive",
        d,
        "--planes-config",
        bad.to_str().unwrap(),
    ]);
    assert!(!refused.status.success());
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(
        stderr.contains("bad.toml") && stderr.contains("max_plane"),
        "{stderr}"
    );
    // So is one in a file, which the error names.
    std::fs::write(&bad, "wall_refits = 101\n").unwrap();
    let refused = run(&[
        "planes",
        "--drive",
        d,
        "--planes-config",
        bad.to_str().unwrap(),
    ]);
    assert!(!refused.status.success());
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(
        stderr.contains("bad.toml") && stderr.contains("wall_refits"),
        "{stderr}"
    );
    let refused = run(&["planes", "--drive", d, "--wall-refits", "101"]);
    assert!(!refused.status.success());
    assert!(String::from_utf8_lossy(&refused.stderr).contains("wall_refits"));
}

/// The four shared scans hold no facade: the default keeps no wall there, `--any-vertical`
/// keeps their vertical pieces (vegetation) and pairs them from scan to scan.
#[test]
fn any_vertical_keeps_what_the_facade_test_rejects() {
    let Some(drive) = common::shared_data("kitti_raw/2011_09_26/2011_09_26_drive_UNKNOWN_sync")
    else {
        return;
    };
    let d = drive.to_str().unwrap();
    let pairs = |extra: &[&str]| -> u64 {
        let mut args = vec!["planes", "--drive", d, "--all", "--runs", "1", "--json"];
        args.extend_from_slice(extra);
        let text = ok(&run(&args));
        let json: serde_json::Value = serde_json::from_str(&text).unwrap();
        json["summary"]["pairs"].as_u64().unwrap()
    };
    assert_eq!(pairs(&[]), 0);
    assert!(pairs(&["--any-vertical"]) >= 3);
}

/// `--vehicle-model` chooses the model Algorithm 1 draws from (and `track`'s walls follow);
/// an unknown name, an unknown parameter or a malformed `--vehicle-param` is an error naming
/// it, with nothing written.
#[test]
fn vehicle_models_by_name_in_planes_and_track() {
    let dir = tempfile::tempdir().unwrap();
    let drive = street_drive(dir.path(), 4);
    let d = drive.to_str().unwrap();
    let base = ["planes", "--drive", d, "--frame", "1", "--runs", "3"];
    for (name, label) in [("ect", "ECT"), ("ct", "ct"), ("bicycle", "bicycle")] {
        let mut a = base.to_vec();
        a.extend(["--vehicle-model", name]);
        let text = ok(&run(&a));
        assert!(
            text.starts_with(&format!(
                "ego motion: vehicle model ({label}, 3 Monte-Carlo runs)"
            )),
            "{text}"
        );
        assert!(text.contains("frame"), "{text}");
    }
    let mut a = base.to_vec();
    a.extend([
        "--vehicle-model",
        "bicycle",
        "--vehicle-param",
        "wheelbase=3.1",
    ]);
    ok(&run(&a));
    for (flags, needle) in [
        (vec!["--vehicle-model", "hovercraft"], "hovercraft"),
        (
            vec!["--vehicle-model", "ect", "--vehicle-param", "wheelbase=3"],
            "wheelbase",
        ),
        (
            vec!["--vehicle-model", "bicycle", "--vehicle-param", "wheelbase"],
            "NAME=VALUE",
        ),
        (
            vec![
                "--vehicle-model",
                "bicycle",
                "--vehicle-param",
                "wheelbase=long",
            ],
            "not a number",
        ),
    ] {
        let mut a = base.to_vec();
        a.extend(flags);
        let out = run(&a);
        assert!(!out.status.success());
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains(needle), "{needle}: {stderr}");
    }
    let tracks = dir.path().join("tracks.json");
    let t = tracks.to_str().unwrap();
    let text = ok(&run(&[
        "track",
        "--drive",
        d,
        "--out",
        t,
        "--quiet",
        "--vehicle-model",
        "ct",
    ]));
    assert!(text.contains("oxts+ct"), "{text}");
    let _ = std::fs::remove_file(&tracks);
    let out = run(&[
        "track",
        "--drive",
        d,
        "--out",
        t,
        "--quiet",
        "--vehicle-model",
        "hovercraft",
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("hovercraft"));
    assert!(!tracks.exists(), "a refused run wrote {t}");
}
