//! `kitti-tools batch` end to end: a simulated raw drive, a simulated tracking sequence and a
//! broken drive in one list; the table, the outputs, resuming and `--force`.

use std::path::Path;
mod common;
use common::run;

fn synth(args: &[&str]) {
    let (ok, out, err) = run(&[&["synth", "--quiet"], args].concat());
    assert!(ok, "{out}\n{err}");
}

fn frames_of(path: &Path) -> serde_json::Value {
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    json["frames"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| {
            let mut f = f.clone();
            f.as_object_mut().unwrap().remove("times");
            f
        })
        .collect()
}

#[test]
fn tracks_a_list_resumes_and_reports_failures() {
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path();
    let s = |p: &Path| p.to_str().unwrap().to_owned();
    synth(&[
        "--out",
        &s(&root.join("raw")),
        "--frames",
        "3",
        "--seed",
        "2",
    ]);
    synth(&[
        "--out",
        &s(&root.join("trk/training")),
        "--layout",
        "tracking",
        "--sequence",
        "3",
        "--frames",
        "3",
        "--seed",
        "4",
    ]);
    // A drive whose only scan is cut short.
    let bad = root.join("bad/2011_09_26_drive_0099_sync/velodyne_points/data");
    std::fs::create_dir_all(&bad).unwrap();
    std::fs::write(bad.join("0000000000.bin"), [0u8; 100]).unwrap();
    let list = root.join("list.txt");
    std::fs::write(
        &list,
        "raw/2020_01_01/2020_01_01_drive_0001_sync\n\
         tracking trk/training 3   # simulated, tracking layout\n\
         bad/2011_09_26_drive_0099_sync\n",
    )
    .unwrap();
    let out = root.join("out");
    let batch = |extra: &[&str]| {
        run(&[
            &["batch", "--drives", &s(&list), "--out", &s(&out), "--quiet"],
            extra,
        ]
        .concat())
    };

    let (ok, stdout, stderr) = batch(&["--particles", "200"]);
    assert!(!ok, "a failed recording must fail the batch:\n{stdout}");
    assert!(stderr.contains("1 of 3 recordings failed"), "{stderr}");
    let table = std::fs::read_to_string(out.join("summary.tsv")).unwrap();
    assert_eq!(
        table,
        stdout
            .lines()
            .take(4)
            .map(|l| format!("{l}\n"))
            .collect::<String>()
    );
    let rows: Vec<Vec<&str>> = table.lines().map(|l| l.split('\t').collect()).collect();
    assert_eq!(rows.len(), 4, "{table}");
    assert_eq!(
        rows[1][..4],
        ["2020_01_01_drive_0001_sync", "tracked", "3", "oxts"]
    );
    assert_eq!(rows[2][..4], ["tracking_0003", "tracked", "3", "oxts"]);
    assert_eq!(rows[3][..2], ["2011_09_26_drive_0099_sync", "failed"]);
    let note = rows[3].last().unwrap();
    assert!(
        note.contains("0000000000.bin") && note.contains("multiple of 16"),
        "{note}"
    );
    let walls: f64 = rows[1][4].parse().unwrap();
    assert!(walls > 0.0, "the simulated street has walls: {table}");
    // Outputs of the tracked recordings, nothing for the broken one.
    let raw_out = out.join("2020_01_01_drive_0001_sync/tracks.json");
    let trk_out = out.join("tracking_0003/tracks.json");
    let first = frames_of(&raw_out);
    assert_eq!(first.as_array().unwrap().len(), 3);
    assert_eq!(frames_of(&trk_out).as_array().unwrap().len(), 3);
    assert!(!out.join("2011_09_26_drive_0099_sync/tracks.json").exists());

    // Run again: the finished recordings are skipped, their files untouched.
    let before = std::fs::read(&raw_out).unwrap();
    let (ok, stdout, _) = batch(&["--particles", "200"]);
    assert!(!ok);
    assert_eq!(stdout.matches("\tskipped\t").count(), 2, "{stdout}");
    assert_eq!(std::fs::read(&raw_out).unwrap(), before);

    // `--force` tracks them again with the same seed: the same tracks.
    let (_, stdout, _) = batch(&["--particles", "200", "--force"]);
    assert_eq!(stdout.matches("\ttracked\t").count(), 2, "{stdout}");
    assert_eq!(frames_of(&raw_out), first);

    // Asking for plots makes recordings without one unfinished; they are tracked again.
    let (_, stdout, _) = batch(&["--particles", "200", "--plot"]);
    assert_eq!(stdout.matches("\ttracked\t").count(), 2, "{stdout}");
    let png = std::fs::read(out.join("tracking_0003/tracks.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
}

#[test]
fn a_bad_list_is_named() {
    let tmp = tempfile::tempdir().unwrap();
    let list = tmp.path().join("drives.txt");
    std::fs::write(&list, "tracking only_a_root\n").unwrap();
    let (ok, _, stderr) = run(&[
        "batch",
        "--drives",
        list.to_str().unwrap(),
        "--out",
        tmp.path().join("out").to_str().unwrap(),
    ]);
    assert!(!ok);
    assert!(
        stderr.contains("drives.txt line 1") && stderr.contains("tracking ROOT NUMBER"),
        "{stderr}"
    );
    assert!(
        !tmp.path().join("out").exists(),
        "nothing written for a bad list"
    );
}
