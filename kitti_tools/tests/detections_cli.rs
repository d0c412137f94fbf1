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

/// The worked example seen by two sensors, the second mounted 1 m ahead and 2 m left and
/// turned a quarter turn (it reports in its own frame, and only every other frame): every
/// fusion rule tracks the three objects as the single sensor does.
#[test]
fn two_sensors_from_one_file_track_the_worked_example() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(example("detections.csv")).unwrap();
    let mut csv = String::from("frame,time,sensor,z0,z1\n");
    for line in text.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        csv.push_str(&format!("{},{},a,{},{}\n", f[0], f[1], f[2], f[3]));
        let frame: usize = f[0].parse().unwrap();
        if frame.is_multiple_of(2) && !f[2].is_empty() {
            // p = R(π/2)·q + (1, 2), so q = R(−π/2)·(p − (1, 2)) = (y − 2, −(x − 1)).
            let (x, y): (f64, f64) = (f[2].parse().unwrap(), f[3].parse().unwrap());
            csv.push_str(&format!("{},{},b,{},{}\n", f[0], f[1], y - 2.0, 1.0 - x));
        }
    }
    let input = dir.path().join("two.csv");
    std::fs::write(&input, csv).unwrap();
    let single = std::fs::read_to_string(example("config.toml")).unwrap();
    let sensor = "measurement = { model = \"position\", sigma = 0.3 }\n\
                  detection = { model = \"constant\", probability = 0.9 }\n\
                  clutter = { rate = 2.0, volume = 3600.0 }\n";
    let base: String = single
        .split("\n[")
        .filter(|t| {
            !["measurement]", "detection]", "clutter]"]
                .iter()
                .any(|h| t.starts_with(h))
        })
        .collect::<Vec<_>>()
        .join("\n[");
    for method in ["ic", "pu", "ga", "aa"] {
        let config = dir.path().join(format!("{method}.toml"));
        std::fs::write(
            &config,
            format!(
                "{base}\n[[sensors]]\nname = \"a\"\n{sensor}\n[[sensors]]\nname = \"b\"\n\
                 {sensor}mounting = [1.0, 2.0, 1.5707963267948966]\n\n[fusion]\n\
                 method = \"{method}\"\n"
            ),
        )
        .unwrap();
        let out = dir.path().join(format!("{method}.json"));
        let (ok, stdout, stderr) = run(&[
            "detections",
            "--input",
            input.to_str().unwrap(),
            "--config",
            config.to_str().unwrap(),
            "--output",
            out.to_str().unwrap(),
            "--truth",
            example("truth.csv").to_str().unwrap(),
            "--cutoff",
            "2",
            "--quiet",
        ]);
        assert!(ok, "{method}: {stderr}");
        assert!(stdout.starts_with("40 frames"), "{method}: {stdout}");
        let ospa: f64 = stdout
            .lines()
            .find_map(|l| l.strip_prefix("mean OSPA (c = 2, p = 1): "))
            .expect("OSPA line")
            .parse()
            .unwrap();
        // The single sensor's bound of the worked example above.
        assert!(ospa < 1.0, "{method}: mean OSPA {ospa}");
    }

    // A sensor the configuration does not define: the file, the frame and the sensor named,
    // nothing written.
    let bad = dir.path().join("bad.csv");
    std::fs::write(&bad, "frame,time,sensor,z0,z1\n0,0.0,a,1,2\n1,0.5,c,1,2\n").unwrap();
    let out = dir.path().join("bad.json");
    let (ok, _, stderr) = run(&[
        "detections",
        "--input",
        bad.to_str().unwrap(),
        "--config",
        dir.path().join("pu.toml").to_str().unwrap(),
        "--output",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(!ok);
    assert!(
        stderr.contains("bad.csv") && stderr.contains("frame 1") && stderr.contains("\"c\""),
        "{stderr}"
    );
    assert!(!out.exists());
    // One sensor twice at one time: the line named.
    std::fs::write(&bad, "frame,time,sensor,z0,z1\n0,0.0,a,1,2\n1,0.0,a,1,2\n").unwrap();
    let (ok, _, stderr) = run(&[
        "detections",
        "--input",
        bad.to_str().unwrap(),
        "--config",
        dir.path().join("pu.toml").to_str().unwrap(),
        "--output",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(!ok);
    assert!(
        stderr.contains("bad.csv:3") && stderr.contains("\"a\""),
        "{stderr}"
    );
}
