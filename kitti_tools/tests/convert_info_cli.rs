//! `kitti-tools convert` and `kitti-tools info` through the built binary, on the vendored KITTI
//! data: format round trips (`.bin`, `.las`, `.ply`, `.pcd`), refused inputs and the drive
//! summary.

use smc_lmb::cloud::{read_kitti_bin, read_pcd, read_ply, write_ply_labelled, PointCloud};
use std::path::{Path, PathBuf};
mod common;
use common::{ok, output as run};
use std::process::Output;

fn data(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/data/kitti/2011_09_26")
        .join(rel)
}

fn frame() -> PathBuf {
    data("2011_09_26_drive_UNKNOWN_sync/velodyne_points/data/0000000000.bin")
}

fn convert(input: &Path, output: &Path) -> Output {
    run(&[
        "convert",
        "--input",
        input.to_str().unwrap(),
        "--output",
        output.to_str().unwrap(),
    ])
}

fn max_abs_diff(a: &PointCloud, b: &PointCloud) -> f32 {
    a.iter()
        .zip(b.iter())
        .map(|(p, q)| {
            (p.x - q.x)
                .abs()
                .max((p.y - q.y).abs())
                .max((p.z - q.z).abs())
        })
        .fold(0.0, f32::max)
}

#[test]
fn bin_las_bin_round_trip_within_a_millimetre() {
    let dir = tempfile::tempdir().unwrap();
    let las = dir.path().join("f.las");
    let back = dir.path().join("back.bin");
    let stdout = ok(&convert(&frame(), &las));
    assert!(stdout.contains("14714"), "{stdout}");
    ok(&convert(&las, &back));
    let original = read_kitti_bin(frame()).unwrap();
    let round = read_kitti_bin(&back).unwrap();
    assert_eq!(original.len(), 14_714);
    assert_eq!(round.len(), original.len());
    assert!(max_abs_diff(&original, &round) <= 1e-3);
}

#[test]
fn bin_ply_bin_round_trip_is_exact() {
    let dir = tempfile::tempdir().unwrap();
    let ply = dir.path().join("f.ply");
    let back = dir.path().join("back.bin");
    ok(&convert(&frame(), &ply));
    let stdout = ok(&convert(&ply, &back));
    assert!(stdout.contains("14714"), "{stdout}");
    assert_eq!(
        read_kitti_bin(&back).unwrap(),
        read_kitti_bin(frame()).unwrap()
    );
}

#[test]
fn bin_pcd_las_keeps_the_points_in_every_pcd_encoding() {
    let dir = tempfile::tempdir().unwrap();
    let original = read_kitti_bin(frame()).unwrap();
    for data in ["ascii", "binary", "binary_compressed"] {
        let pcd = dir.path().join(format!("f_{data}.pcd"));
        let las = dir.path().join(format!("f_{data}.las"));
        let back = dir.path().join(format!("back_{data}.bin"));
        let stdout = ok(&run(&[
            "convert",
            "--input",
            frame().to_str().unwrap(),
            "--output",
            pcd.to_str().unwrap(),
            "--pcd-data",
            data,
        ]));
        assert!(stdout.contains("14714"), "{stdout}");
        let head = std::fs::read(&pcd).unwrap();
        let marker = format!("DATA {data}\n");
        assert!(
            head.windows(marker.len()).any(|w| w == marker.as_bytes()),
            "{data}"
        );
        // Every encoding keeps the f32 values exactly.
        assert_eq!(read_pcd(&pcd).unwrap(), original, "{data}");
        let stdout = ok(&convert(&pcd, &las));
        assert!(stdout.contains("14714"), "{stdout}");
        ok(&convert(&las, &back));
        let round = read_kitti_bin(&back).unwrap();
        assert_eq!(round.len(), original.len());
        assert!(max_abs_diff(&original, &round) <= 1e-3, "{data}");
        let reflectance = original
            .intensities()
            .iter()
            .zip(round.intensities())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f32::max);
        assert!(reflectance <= 1e-4, "{data}: {reflectance}");
    }
}

#[test]
fn organised_pcd_with_nan_points_is_refused_unless_skipped() {
    let dir = tempfile::tempdir().unwrap();
    let pcd = dir.path().join("organised.pcd");
    std::fs::write(
        &pcd,
        "VERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\n\
         WIDTH 2\nHEIGHT 2\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 4\nDATA ascii\n\
         1 2 3 255\nnan nan nan 0\n4 5 6 0\nnan nan nan 0\n",
    )
    .unwrap();
    let bin = dir.path().join("out.bin");
    assert_fails_naming(&convert(&pcd, &bin), "organised.pcd", &bin);
    let stdout = ok(&run(&[
        "convert",
        "--input",
        pcd.to_str().unwrap(),
        "--output",
        bin.to_str().unwrap(),
        "--skip-invalid",
    ]));
    assert!(stdout.contains("2 points (2 non-finite"), "{stdout}");
    let cloud = read_kitti_bin(&bin).unwrap();
    assert_eq!(cloud.xs(), &[1.0, 4.0]);
    assert_eq!(cloud.intensities(), &[0.0, 0.0]);
}

#[test]
fn labelled_ply_has_two_colours_for_two_labels() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("l.ply");
    let cloud = read_kitti_bin(frame()).unwrap();
    let labels: Vec<u32> = (0..cloud.len()).map(|i| 1 + (i % 2) as u32).collect();
    write_ply_labelled(&path, &cloud, &labels).unwrap();
    assert_eq!(read_ply(&path).unwrap(), cloud);
    // Colours sit after the 16-byte float block of each 19-byte record.
    let bytes = std::fs::read(&path).unwrap();
    let marker = b"end_header\n";
    let start = bytes
        .windows(marker.len())
        .position(|w| w == marker)
        .unwrap()
        + marker.len();
    let body = &bytes[start..];
    assert_eq!(body.len(), cloud.len() * 19);
    let colour = |k: usize| &body[k * 19 + 16..k * 19 + 19];
    let mut seen: Vec<&[u8]> = body.chunks(19).map(|r| &r[16..]).collect();
    seen.sort();
    seen.dedup();
    assert_eq!(seen.len(), 2);
    assert_ne!(colour(0), colour(1));
    assert_eq!(colour(0), smc_lmb::cloud::label_colour(1));
    assert_eq!(colour(1), smc_lmb::cloud::label_colour(2));
}

fn assert_fails_naming(out: &Output, name: &str, output: &Path) {
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains(name), "{stderr}");
    assert!(!output.exists(), "{} was written", output.display());
}

#[test]
fn bad_inputs_are_errors_naming_the_file_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out_ply = dir.path().join("out.ply");
    let out_bin = dir.path().join("out.bin");

    let las = dir.path().join("cut.las");
    ok(&convert(&frame(), &las));
    let bytes = std::fs::read(&las).unwrap();
    std::fs::write(&las, &bytes[..bytes.len() / 2]).unwrap();
    assert_fails_naming(&convert(&las, &out_ply), "cut.las", &out_ply);

    let ply = dir.path().join("wrong.ply");
    std::fs::write(
        &ply,
        "ply\nformat nonsense 9.9\nelement vertex 1\nend_header\n",
    )
    .unwrap();
    assert_fails_naming(&convert(&ply, &out_bin), "wrong.ply", &out_bin);

    let bin = dir.path().join("short.bin");
    std::fs::write(&bin, [0u8; 17]).unwrap();
    assert_fails_naming(&convert(&bin, &out_ply), "short.bin", &out_ply);

    let pcd = dir.path().join("cut.pcd");
    ok(&convert(&frame(), &pcd));
    let bytes = std::fs::read(&pcd).unwrap();
    std::fs::write(&pcd, &bytes[..bytes.len() / 2]).unwrap();
    assert_fails_naming(&convert(&pcd, &out_bin), "cut.pcd", &out_bin);

    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 4);
}

#[test]
fn nan_points_are_refused_unless_skipped() {
    let dir = tempfile::tempdir().unwrap();
    let bin = dir.path().join("nan.bin");
    let mut bytes = Vec::new();
    for v in [1.0f32, 2.0, 3.0, 0.5, f32::NAN, 0.0, 0.0, 0.0] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    std::fs::write(&bin, &bytes).unwrap();
    let las = dir.path().join("out.las");
    assert_fails_naming(&convert(&bin, &las), "nan.bin", &las);
    let out = run(&[
        "convert",
        "--input",
        bin.to_str().unwrap(),
        "--output",
        las.to_str().unwrap(),
        "--skip-invalid",
    ]);
    let stdout = ok(&out);
    assert!(stdout.contains("1 points"), "{stdout}");
    assert_eq!(smc_lmb::cloud::read_las(&las).unwrap().len(), 1);
}

#[test]
fn info_on_oxts_only_drive() {
    let drive = data("2011_09_26_drive_0001_sync");
    let text = ok(&run(&["info", "--drive", drive.to_str().unwrap()]));
    assert!(text.contains("oxts packets    10"), "{text}");
    assert!(text.contains("velodyne frames 0"), "{text}");

    let json = ok(&run(&[
        "info",
        "--drive",
        drive.to_str().unwrap(),
        "--json",
    ]));
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v["oxts_packets"], 10);
    assert_eq!(v["velodyne_frames"], 0);
    assert!(v["path_length_m"].as_f64().unwrap() >= 0.0);
    assert!(v["issues"].is_array());
}

/// Output into a pipe whose reader has gone (`kitti-tools info … | head -0`) ends the process
/// quietly, by SIGPIPE as for other Unix tools, not with a panic from `println!`.
#[cfg(unix)]
#[test]
fn a_closed_output_pipe_ends_the_command_without_a_panic() {
    use std::os::unix::process::ExitStatusExt;
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let drive = data("2011_09_26_drive_UNKNOWN_sync");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_kitti-tools"))
        .args(["info", "--drive", drive.to_str().unwrap()])
        .stdout(writer)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    // SIGPIPE is signal 13 on Linux, macOS and the BSDs.
    assert_eq!(out.status.signal(), Some(13), "{:?}", out.status);
}
