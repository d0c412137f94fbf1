//! `kitti-tools detections` end to end on the worked example of the README, and on broken
//! inputs.

use std::path::{Path, PathBuf};
mod common;
use common::run;

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/data")
        .join(name)
}

#[test]
fn worked_example_tracks_three_objects() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("estimates.json");
    let (ok, stdout, stderr) = run(&[
        "detections",
        "--input",
        example("detections.csv").to_str().unwrap(),
        "--config",
        example("config.toml").to_str().unwrap(),
        "--output",
        out.to_str().unwrap(),
        "--truth",
        example("truth.csv").to_str().unwrap(),
        "--cutoff",
        "2",
        "--quiet",
    ]);
    assert!(ok, "{stderr}");
    let ospa: f64 = stdout
        .lines()
        .find_map(|l| l.strip_prefix("mean OSPA (c = 2, p = 1): "))
        .expect("OSPA line")
        .parse()
        .unwrap();
    // Three objects with 0.3 m noise: after a two-frame confirmation delay per birth (3 births
    // in 40 frames, each costing at most c/n for ~2 frames) the localisation error dominates;
    // anything above 1 m means the tracker is not following them.
    assert!(ospa < 1.0, "mean OSPA {ospa}");
    assert!(
        stdout.contains("every object kept one label: true"),
        "{stdout}"
    );
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    assert_eq!(v["frames"].as_array().unwrap().len(), 40);
    // The CSV writer gives the same estimates.
    let csv = dir.path().join("estimates.csv");
    let (ok, _, _) = run(&[
        "detections",
        "--input",
        example("detections.csv").to_str().unwrap(),
        "--config",
        example("config.toml").to_str().unwrap(),
        "--output",
        csv.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(ok);
    let rows = std::fs::read_to_string(&csv).unwrap().lines().count() - 1;
    let n: usize = v["frames"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["estimates"].as_array().unwrap().len())
        .sum();
    assert_eq!(rows, n);
}

#[test]
fn broken_inputs_name_file_and_line_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.json");
    let bad_config = dir.path().join("bad.toml");
    std::fs::write(
        &bad_config,
        std::fs::read_to_string(example("config.toml"))
            .unwrap()
            .replace("sigma = 0.3", "sigma = nan"),
    )
    .unwrap();
    let (ok, _, stderr) = run(&[
        "detections",
        "--input",
        example("detections.csv").to_str().unwrap(),
        "--config",
        bad_config.to_str().unwrap(),
        "--output",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(!ok);
    assert!(
        stderr.contains("bad.toml") && stderr.contains("sigma"),
        "{stderr}"
    );

    let bad_input = dir.path().join("bad.csv");
    std::fs::write(&bad_input, "frame,time,z0,z1\n0,0,1,2\n1,1,3,oops\n").unwrap();
    let (ok, _, stderr) = run(&[
        "detections",
        "--input",
        bad_input.to_str().unwrap(),
        "--config",
        example("config.toml").to_str().unwrap(),
        "--output",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(!ok);
    assert!(
        stderr.contains("bad.csv:3") && stderr.contains("z1"),
        "{stderr}"
    );
    assert!(!out.exists(), "nothing may be written on failure");
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        2,
        "no temporary files left behind"
    );

    // NaN rows are refused by default and skipped on request.
    std::fs::write(&bad_input, "frame,time,z0,z1\n0,0,1,2\n1,1,nan,2\n").unwrap();
    let args = |extra: &'static str| {
        let mut a = vec![
            "detections".to_string(),
            "--input".into(),
            bad_input.to_str().unwrap().into(),
            "--config".into(),
            example("config.toml").to_str().unwrap().into(),
            "--output".into(),
            out.to_str().unwrap().into(),
            "--quiet".into(),
        ];
        if !extra.is_empty() {
            a.push(extra.into());
        }
        a
    };
    let a = args("");
    let (ok, _, stderr) = run(&a.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(!ok && stderr.contains("not finite"), "{stderr}");
    let a = args("--skip-invalid");
    let (ok, _, stderr) = run(&a.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(ok, "{stderr}");
    assert!(stderr.contains("skipped 1"), "{stderr}");
}
