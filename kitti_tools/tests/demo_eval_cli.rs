//! `kitti-tools demo` (simulate, predict planes, track, score) and `kitti-tools eval` on its
//! output, end to end, and `eval` on broken inputs.

mod common;
use common::run;

#[test]
fn demo_runs_the_whole_pipeline_and_eval_scores_its_tracks() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().to_str().unwrap();
    let (ok, out, err) = run(&[
        "demo", "--dir", dir, "--frames", "8", "--runs", "2", "--quiet",
    ]);
    assert!(ok, "{err}");
    for needle in [
        "simulated street written",
        "all frame pairs",
        "confirmed per frame",
        "mean OSPA",
        "wall tracks",
    ] {
        assert!(out.contains(needle), "missing `{needle}` in\n{out}");
    }
    // A second run reuses the drive.
    let (ok, out, err) = run(&[
        "demo", "--dir", dir, "--frames", "8", "--runs", "2", "--quiet",
    ]);
    assert!(ok, "{err}");
    assert!(out.contains("reusing the simulated street"), "{out}");

    // The drive's folder is named by the seed, the frames and the street configuration.
    let roots: Vec<_> = std::fs::read_dir(tmp.path())
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(roots.len(), 1, "{roots:?}");
    let root = roots[0].clone();
    let name = root.file_name().unwrap().to_string_lossy().into_owned();
    assert!(name.starts_with("seed1-frames8-"), "{name}");
    let drive = root.join("2020_01_01/2020_01_01_drive_0001_sync");
    let tracks = root.join("tracks.json");
    assert!(root.join("tracks.svg").is_file());
    let (ok, out, err) = run(&[
        "eval",
        "--tracks",
        tracks.to_str().unwrap(),
        "--drive",
        drive.to_str().unwrap(),
        "--planes",
        "--runs",
        "2",
        "--json",
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let ospa = v["clusters"]["mean_ospa"].as_f64().unwrap();
    // c = 3 m. The first two of the eight frames come before any birth is confirmed (OSPA = c
    // each); the other six must average within a quarter of c (a missed or false object in a
    // frame of ~15 costs c/15, a box-centre error its own size).
    let c = 3.0;
    let bound = (2.0 * c + 6.0 * c / 4.0) / 8.0;
    assert!(ospa >= 0.0 && ospa <= bound, "{ospa} > {bound}");
    assert_eq!(v["clusters"]["frames"].as_array().unwrap().len(), 8);
    assert!(v["walls"]["matched"].as_u64().unwrap() > 0);
    let angle = v["plane_prediction"]["median_normal_angle_deg"]
        .as_f64()
        .unwrap();
    assert!(angle < 0.5, "{angle}");
}

#[test]
fn eval_names_what_is_wrong() {
    let tmp = tempfile::tempdir().unwrap();
    let missing = tmp.path().join("nope.json");
    let (ok, _, err) = run(&[
        "eval",
        "--tracks",
        missing.to_str().unwrap(),
        "--truth",
        "x.json",
    ]);
    assert!(!ok);
    assert!(err.contains("nope.json"), "{err}");

    let bad = tmp.path().join("bad.json");
    std::fs::write(&bad, "{\"drive\": 3}").unwrap();
    let (ok, _, err) = run(&[
        "eval",
        "--tracks",
        bad.to_str().unwrap(),
        "--truth",
        "x.json",
    ]);
    assert!(!ok);
    assert!(err.contains("bad.json"), "{err}");

    let (ok, _, err) = run(&["eval", "--tracks", bad.to_str().unwrap()]);
    assert!(!ok);
    assert!(err.contains("bad.json") || err.contains("--drive"), "{err}");

    let (ok, _, err) = run(&[
        "demo",
        "--frames",
        "1",
        "--dir",
        tmp.path().to_str().unwrap(),
    ]);
    assert!(!ok);
    assert!(err.contains("--frames"), "{err}");
}
