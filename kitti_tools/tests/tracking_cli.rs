//! The KITTI tracking layout through the built binary, end to end without downloads: `synth
//! --layout tracking` writes a simulated street as a tracking sequence with `label_02` truth,
//! which `info`, `planes`, `track` and `eval` then read with `--tracking ROOT --sequence N`.
//! The same scans and poses, rewritten in the odometry layout, are tracked with `--odometry`.

mod common;
use common::{ok, run};
use smc_lmb::kitti::TrackingSequence;
use std::fmt::Write as _;
use std::path::Path;

fn synth(root: &Path, frames: usize, sequence: u32) -> String {
    ok(&common::output(&[
        "synth",
        "--out",
        root.to_str().unwrap(),
        "--layout",
        "tracking",
        "--sequence",
        &sequence.to_string(),
        "--frames",
        &frames.to_string(),
        "--seed",
        "2",
        "--quiet",
    ]))
}

#[test]
fn synth_info_planes_track_eval_on_a_tracking_sequence() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path().join("training");
    let text = synth(&root, 8, 5);
    assert!(text.contains("--sequence 0005"), "{text}");
    for f in [
        "velodyne/0005/000007.bin",
        "oxts/0005.txt",
        "calib/0005.txt",
    ] {
        assert!(root.join(f).is_file(), "{f}");
    }
    let labels = std::fs::read_to_string(root.join("label_02/0005.txt")).unwrap();
    assert!(labels.lines().all(|l| l.split_whitespace().count() == 17));
    assert!(labels.contains(" Car ") && labels.contains(" Pedestrian "));

    let r = root.to_str().unwrap();
    let info = ok(&common::output(&[
        "info",
        "--tracking",
        r,
        "--sequence",
        "5",
        "--json",
    ]));
    let report: serde_json::Value = serde_json::from_str(&info).unwrap();
    assert_eq!(report["velodyne_frames"], 8, "{info}");
    assert_eq!(report["oxts_packets"], 8, "{info}");
    assert_eq!(report["errors"], 0, "{info}");
    assert_eq!(report["pose_frame"], "velodyne", "{info}");
    assert!(report["labels"]["Car"].as_u64().unwrap() > 0, "{info}");
    // 7 intervals at the default 10 m/s and 10 Hz.
    let length = report["path_length_m"].as_f64().unwrap();
    assert!((length - 7.0).abs() < 0.05, "{length}");

    let planes = ok(&common::output(&[
        "planes",
        "--tracking",
        r,
        "--sequence",
        "5",
        "--all",
        "--runs",
        "2",
        "--json",
    ]));
    let planes: serde_json::Value = serde_json::from_str(&planes).unwrap();
    assert!(planes["summary"]["pairs"].as_u64().unwrap() > 0, "{planes}");
    assert!(
        planes["summary"]["median_normal_angle_deg"]
            .as_f64()
            .unwrap()
            < 2.0,
        "{planes}"
    );

    let tracks = dir.path().join("tracks.json");
    let t = tracks.to_str().unwrap();
    let text = ok(&common::output(&[
        "track",
        "--tracking",
        r,
        "--sequence",
        "5",
        "--particles",
        "100",
        "--out",
        t,
        "--quiet",
    ]));
    assert!(text.contains("tracking_0005: 8 frames (ego oxts"), "{text}");

    let eval = ok(&common::output(&[
        "eval",
        "--tracks",
        t,
        "--tracking",
        r,
        "--sequence",
        "5",
        "--planes",
        "--runs",
        "2",
        "--json",
    ]));
    let eval: serde_json::Value = serde_json::from_str(&eval).unwrap();
    let frames = eval["clusters"]["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 8, "{eval}");
    assert!(frames.iter().any(|f| f["truth"].as_u64().unwrap() > 0));
    let ospa = eval["clusters"]["mean_ospa"].as_f64().unwrap();
    assert!(ospa.is_finite() && ospa <= 3.0, "{ospa}");
    // After the filter has confirmed its tracks, most labelled objects are found.
    let late = &frames[7];
    let (truth, missed) = (
        late["truth"].as_u64().unwrap(),
        late["missed"].as_u64().unwrap(),
    );
    assert!(missed * 2 < truth, "{late}");
    assert!(
        eval["plane_prediction"]["pairs"].as_u64().unwrap() > 0,
        "{eval}"
    );

    // Only what camera 2 sees: fewer labelled objects and fewer tracks, none of them new.
    let front = ok(&common::output(&[
        "eval",
        "--tracks",
        t,
        "--tracking",
        r,
        "--sequence",
        "5",
        "--camera-view",
        "--json",
    ]));
    let front: serde_json::Value = serde_json::from_str(&front).unwrap();
    let sum = |v: &serde_json::Value, key: &str| -> u64 {
        v["clusters"]["frames"]
            .as_array()
            .unwrap()
            .iter()
            .map(|f| f[key].as_u64().unwrap())
            .sum()
    };
    for key in ["truth", "estimates"] {
        let (all, seen) = (sum(&eval, key), sum(&front, key));
        assert!(0 < seen && seen < all, "{key}: {seen} of {all}");
    }
}

#[test]
fn track_reads_the_odometry_layout() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path().join("training");
    synth(&root, 4, 0);
    // The same scans and poses in the odometry layout: camera poses P_k = Tr·V_k·Tr⁻¹.
    let seq = TrackingSequence::open(&root, 0).unwrap();
    let tr = seq.calib().unwrap().velo_to_cam;
    let odo = dir.path().join("odometry");
    let sdir = odo.join("sequences/00");
    std::fs::create_dir_all(sdir.join("velodyne")).unwrap();
    std::fs::create_dir_all(odo.join("poses")).unwrap();
    let (mut poses, mut times) = (String::new(), String::new());
    for (k, v) in seq.poses().unwrap().iter().enumerate() {
        std::fs::copy(
            seq.scans().path(k),
            sdir.join(format!("velodyne/{k:06}.bin")),
        )
        .unwrap();
        let m = (tr * v * tr.inverse()).to_homogeneous();
        let row: Vec<String> = (0..3)
            .flat_map(|r| (0..4).map(move |c| (r, c)))
            .map(|(r, c)| format!("{:e}", m[(r, c)]))
            .collect();
        writeln!(poses, "{}", row.join(" ")).unwrap();
        writeln!(times, "{:e}", k as f64 * 0.1).unwrap();
    }
    std::fs::write(odo.join("poses/00.txt"), poses).unwrap();
    std::fs::write(sdir.join("times.txt"), times).unwrap();
    let m = tr.to_homogeneous();
    let tr_row: Vec<String> = (0..12)
        .map(|i| format!("{:e}", m[(i / 4, i % 4)]))
        .collect();
    std::fs::write(
        sdir.join("calib.txt"),
        format!("P0: 1 0 0 0 0 1 0 0 0 0 1 0\nTr: {}\n", tr_row.join(" ")),
    )
    .unwrap();
    let out = dir.path().join("odo.json");
    let text = ok(&common::output(&[
        "track",
        "--odometry",
        odo.to_str().unwrap(),
        "--sequence",
        "0",
        "--particles",
        "100",
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]));
    assert!(
        text.contains("odometry_00: 4 frames (ego odometry"),
        "{text}"
    );
    let tracks: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    assert_eq!(tracks["drive"], "odometry_00");
    assert_eq!(tracks["ego"], "odometry");
    assert_eq!(tracks["frames"].as_array().unwrap().len(), 4);
}

#[test]
fn layout_flags_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().to_str().unwrap();
    let (ok_, _, err) = run(&[
        "track",
        "--drive",
        d,
        "--tracking",
        d,
        "--sequence",
        "0",
        "--out",
        "x.json",
    ]);
    assert!(!ok_ && err.contains("cannot be used with"), "{err}");
    let (ok_, _, err) = run(&["info", "--tracking", d]);
    assert!(!ok_ && err.contains("--sequence"), "{err}");
    let (ok_, _, err) = run(&["eval", "--tracks", "t.json", "--tracking", d, "--drive", d]);
    assert!(!ok_ && err.contains("cannot be used with"), "{err}");
    // A sequence that is not there: the error names the missing scans or files.
    let (ok_, _, err) = run(&[
        "track",
        "--tracking",
        d,
        "--sequence",
        "3",
        "--out",
        "x.json",
    ]);
    assert!(!ok_ && err.contains("0003"), "{err}");
    // `info` reports missing parts as warnings, as for raw drives.
    let (ok_, out, _) = run(&["info", "--tracking", d, "--sequence", "3"]);
    assert!(
        ok_ && out.contains("warning") && out.contains("velodyne/0003"),
        "{out}"
    );
}

#[test]
fn track_writes_kitti_results_of_the_lmb_and_the_baseline_which_eval_scores() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path().join("training");
    synth(&root, 12, 0);
    let r = root.to_str().unwrap();
    let (lmb, ab3) = (dir.path().join("lmb"), dir.path().join("ab3"));
    let text = ok(&common::output(&[
        "track",
        "--tracking",
        r,
        "--sequence",
        "0",
        "--particles",
        "200",
        "--out",
        dir.path().join("t.json").to_str().unwrap(),
        "--kitti-out",
        lmb.to_str().unwrap(),
        "--baseline-out",
        ab3.to_str().unwrap(),
        "--quiet",
    ]));
    assert!(
        text.contains("result lines") && text.contains("AB3DMOT"),
        "{text}"
    );
    for d in [&lmb, &ab3] {
        let lines = std::fs::read_to_string(d.join("0000.txt")).unwrap();
        assert!(!lines.is_empty(), "{}", d.display());
        for l in lines.lines() {
            let f: Vec<&str> = l.split_whitespace().collect();
            assert_eq!(f.len(), 18, "{l}");
            assert!(
                ["Car", "Van", "Truck", "Pedestrian", "Cyclist"].contains(&f[2]),
                "{l}"
            );
        }
        let scores = ok(&common::output(&[
            "eval",
            "--tracking",
            r,
            "--sequence",
            "0",
            "--results",
            d.to_str().unwrap(),
            "--camera-view",
            "--within",
            "40",
        ]));
        assert!(
            scores.contains("HOTA") && scores.contains("Car"),
            "{scores}"
        );
        // The groups: these frames' van, cyclist and pedestrians are road users to score
        // (KITTI's Car class has none of them), and something of them is found.
        let row = |name: &str| -> Vec<f64> {
            let line = scores.lines().find(|l| l.starts_with(name)).expect(name);
            line[name.len()..]
                .split_whitespace()
                .map(|v| v.parse().unwrap())
                .collect()
        };
        let (road, car_van) = (row("Road users"), row("Car+Van"));
        assert!(road[13] > 0.0 && car_van[13] > 0.0, "{scores}");
        assert!(road[12] > 0.0, "no road user found: {scores}");
    }
    // Results need the tracking layout's calibration.
    let out = common::output(&[
        "track",
        "--drive",
        r,
        "--out",
        dir.path().join("x.json").to_str().unwrap(),
        "--kitti-out",
        lmb.to_str().unwrap(),
    ]);
    assert!(!out.status.success());
}

/// KITTI drops a scan now and then (tracking sequence 0001 has none for frames 177–180, its
/// raw drive 0009 keeps their OXTS packets and a blank time stamp line): such frames are left
/// out, the filter predicts over them, and their labels count as missed.
#[test]
fn dropped_scans_are_predicted_over_and_their_labels_missed() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path().join("training");
    synth(&root, 12, 1);
    for k in [5, 6] {
        std::fs::remove_file(root.join(format!("velodyne/0001/{k:06}.bin"))).unwrap();
    }
    let r = root.to_str().unwrap();
    let info = ok(&common::output(&[
        "info",
        "--tracking",
        r,
        "--sequence",
        "1",
        "--json",
    ]));
    let report: serde_json::Value = serde_json::from_str(&info).unwrap();
    assert_eq!(report["velodyne_frames"], 10, "{info}");
    assert_eq!(report["oxts_packets"], 12, "{info}");
    assert_eq!(report["errors"], 0, "{info}");
    let issues = report["issues"].as_array().unwrap();
    assert_eq!(issues.len(), 1, "{info}");
    assert_eq!(issues[0]["severity"], "warning", "{info}");
    assert!(
        issues[0]["message"]
            .as_str()
            .unwrap()
            .contains("frames 5..=6 have no scan"),
        "{info}"
    );

    let (json, results) = (dir.path().join("t.json"), dir.path().join("lmb"));
    let text = ok(&common::output(&[
        "track",
        "--tracking",
        r,
        "--sequence",
        "1",
        "--particles",
        "200",
        "--out",
        json.to_str().unwrap(),
        "--kitti-out",
        results.to_str().unwrap(),
        "--quiet",
    ]));
    assert!(text.contains("tracking_0001: 10 frames"), "{text}");
    let tracks: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let frames = tracks["frames"].as_array().unwrap();
    let numbers: Vec<u64> = frames
        .iter()
        .map(|f| f["frame"].as_u64().unwrap())
        .collect();
    assert_eq!(numbers, [0, 1, 2, 3, 4, 7, 8, 9, 10, 11]);
    // The clusters confirmed before the gap are still there after it, under their labels:
    // the filter predicted over the 0.3 s from frame 4 to frame 7.
    let labels = |f: &serde_json::Value| -> std::collections::BTreeSet<String> {
        f["clusters"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c["label"].to_string())
            .collect()
    };
    let (before, after) = (labels(&frames[4]), labels(&frames[5]));
    let kept = before.intersection(&after).count();
    assert!(
        !before.is_empty() && kept * 4 >= before.len() * 3,
        "{kept} of {} labels of frame 4 in frame 7",
        before.len()
    );
    let lines = std::fs::read_to_string(results.join("0001.txt")).unwrap();
    let result_frames: std::collections::BTreeSet<u64> = lines
        .lines()
        .map(|l| l.split_whitespace().next().unwrap().parse().unwrap())
        .collect();
    assert!(!result_frames.contains(&5) && !result_frames.contains(&6));
    assert!(result_frames.contains(&4) && result_frames.contains(&7));
    let scores = ok(&common::output(&[
        "eval",
        "--tracking",
        r,
        "--sequence",
        "1",
        "--results",
        results.to_str().unwrap(),
    ]));
    assert!(scores.contains("HOTA"), "{scores}");

    // Wall pairs need both scans: 11 consecutive pairs, 3 of them touch the gap.
    let planes = ok(&common::output(&[
        "planes",
        "--tracking",
        r,
        "--sequence",
        "1",
        "--all",
        "--runs",
        "1",
        "--json",
    ]));
    let planes: serde_json::Value = serde_json::from_str(&planes).unwrap();
    let pair_frames: std::collections::BTreeSet<u64> = planes["pairs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["frame"].as_u64().unwrap())
        .collect();
    assert!(
        !pair_frames.is_empty() && pair_frames.iter().all(|f| ![5, 6, 7].contains(f)),
        "{pair_frames:?}"
    );
    let lone = common::output(&[
        "planes",
        "--tracking",
        r,
        "--sequence",
        "1",
        "--frame",
        "5",
        "--runs",
        "1",
    ]);
    assert!(!lone.status.success());
    let err = String::from_utf8_lossy(&lone.stderr);
    assert!(err.contains("dropped scans"), "{err}");

    // Scans that end before the OXTS packets do are no dropped scans: an error naming the
    // OXTS file's line.
    std::fs::remove_file(root.join("velodyne/0001/000011.bin")).unwrap();
    let out = common::output(&[
        "track",
        "--tracking",
        r,
        "--sequence",
        "1",
        "--out",
        json.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("oxts/0001.txt:12"), "{err}");
}
