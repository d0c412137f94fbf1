//! The KITTI tracking layout on real data: sequence 0000 of the shared data (labels, OXTS,
//! calibration) with the scans of raw drive 2011_09_26_0005, which is the same recording frame
//! for frame, assembled in a temporary folder by linking the scans. The sequence must give the
//! poses the raw drive gives, and its labels' boxes, moved into the Velodyne frame, must hold
//! lidar points. Broken copies must fail naming the file and line.

mod common;

use nalgebra::Point3;
use smc_lmb::kitti::labels::label_frame_count;
use smc_lmb::kitti::tracking::FRAME_PERIOD;
use smc_lmb::kitti::{Issue, ObjectType, RawDrive, TrackingSequence};
use smc_lmb::recording::Recording;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Frames of sequence 0000 in the shared data.
const FRAMES: usize = 100;

struct Shared {
    tracking: PathBuf,
    drive: PathBuf,
}

fn shared() -> Option<Shared> {
    Some(Shared {
        tracking: common::shared_data("kitti_tracking/training")?,
        drive: common::shared_data("kitti_raw/2011_09_26/2011_09_26_drive_0005_sync")?,
    })
}

/// Builds `ROOT/{velodyne/0000, oxts, calib, label_02}` under `root` from the shared data,
/// with the first `scans` scans of the raw drive linked in.
fn assemble(s: &Shared, root: &Path, scans: usize) {
    let vdir = root.join("velodyne/0000");
    std::fs::create_dir_all(&vdir).unwrap();
    for k in 0..scans {
        let src = s.drive.join(format!("velodyne_points/data/{k:010}.bin"));
        let dst = vdir.join(format!("{k:06}.bin"));
        #[cfg(unix)]
        std::os::unix::fs::symlink(&src, &dst).unwrap();
        #[cfg(not(unix))]
        std::fs::copy(&src, &dst).unwrap();
    }
    for sub in ["oxts", "calib", "label_02"] {
        std::fs::create_dir_all(root.join(sub)).unwrap();
        std::fs::copy(
            s.tracking.join(sub).join("0000.txt"),
            root.join(sub).join("0000.txt"),
        )
        .unwrap();
    }
}

#[test]
fn sequence_0000_gives_the_poses_of_raw_drive_0005() {
    let Some(s) = shared() else { return };
    let tmp = tempfile::tempdir().unwrap();
    assemble(&s, tmp.path(), FRAMES);
    let seq = TrackingSequence::open(tmp.path(), 0).unwrap();
    assert_eq!(seq.name(), "0000");
    assert_eq!(seq.frame_count(), FRAMES);
    assert_eq!(seq.check(), Vec::<Issue>::new());
    let drive = RawDrive::open(&s.drive).unwrap();
    assert_eq!(drive.frame_count(), FRAMES);
    assert_eq!(seq.oxts().unwrap(), drive.oxts().unwrap());
    let (a, b) = (seq.poses().unwrap(), drive.poses().unwrap());
    assert_eq!(a.len(), FRAMES);
    for (k, (p, q)) in a.iter().zip(&b).enumerate() {
        let d = (p.to_homogeneous() - q.to_homogeneous()).abs().max();
        assert!(d < 1e-9, "frame {k}: poses differ by {d}");
    }
    let (a, b) = (seq.imu_poses().unwrap(), drive.imu_poses().unwrap());
    assert_eq!(a, b);
    assert_eq!(
        seq.vehicle_states().unwrap(),
        drive.vehicle_states().unwrap()
    );
    // The sequence's Tr_velo_cam is the raw day's calib_velo_to_cam.txt.
    let calib = seq.calib().unwrap();
    let raw = drive.calib_velo_to_cam().unwrap().isometry;
    let d = (calib.velo_to_cam.to_homogeneous() - raw.to_homogeneous())
        .abs()
        .max();
    assert!(d < 1e-9, "{d}");
    let t = seq.times();
    assert_eq!(t.len(), FRAMES);
    assert!((t[49] - 49.0 * FRAME_PERIOD).abs() < 1e-12);
    // The drive moves ~3.5 m/s: about 17 m in 49 frames.
    let travelled = seq.poses().unwrap()[49].translation.vector.norm();
    assert!((10.0..25.0).contains(&travelled), "{travelled}");
    let a = seq.scan(11).unwrap();
    assert_eq!(a.len(), 123_334);
}

#[test]
fn labels_of_sequence_0000_hold_lidar_points() {
    let Some(s) = shared() else { return };
    let tmp = tempfile::tempdir().unwrap();
    assemble(&s, tmp.path(), FRAMES);
    let seq = TrackingSequence::open(tmp.path(), 0).unwrap();
    let labels = seq.labels().unwrap();
    assert_eq!(labels.len(), 525);
    assert_eq!(label_frame_count(&labels), FRAMES);
    let mut per_frame = BTreeMap::new();
    for l in &labels {
        *per_frame.entry(l.frame).or_insert(0usize) += 1;
    }
    assert_eq!(per_frame.len(), FRAMES);
    assert_eq!((per_frame[&0], per_frame[&5], per_frame[&10]), (5, 6, 4));
    let types: BTreeSet<ObjectType> = labels.iter().map(|l| l.object_type).collect();
    assert_eq!(
        types,
        BTreeSet::from([
            ObjectType::Van,
            ObjectType::Pedestrian,
            ObjectType::Cyclist,
            ObjectType::DontCare
        ])
    );
    let count = |t: ObjectType| labels.iter().filter(|l| l.object_type == t).count();
    assert_eq!(count(ObjectType::Cyclist), 100);
    assert_eq!(count(ObjectType::DontCare), 224);

    let calib = seq.calib().unwrap();
    let rect_from_velo = calib.rect_from_velo();
    let mut checked = BTreeMap::<ObjectType, usize>::new();
    for k in [0, 12, 25, 37, 49] {
        let cloud = seq.scan(k).unwrap();
        let points: Vec<Point3<f64>> = cloud
            .positions()
            .map(|p| Point3::new(p.x as f64, p.y as f64, p.z as f64))
            .collect();
        for l in labels.iter().filter(|l| l.frame == k && l.is_object()) {
            let mut b = l.to_velodyne(&rect_from_velo);
            // Lifted off the road: the lowest 0.3 m of the box holds ground points.
            b.center.z += 0.15;
            b.size[2] -= 0.3;
            let range = b.center.coords.xy().norm();
            let in_view = calib.in_image2(&b.center);
            if range > 30.0 || !in_view {
                continue;
            }
            // The yaw about the Velodyne z axis is −rotation_y − π/2 up to the rig's tilt.
            let expected = -l.rotation_y - std::f64::consts::FRAC_PI_2;
            let off = smc_lmb::geometry::wrap_angle(b.yaw - expected).abs();
            assert!(
                off < 1e-3,
                "frame {k} track {}: yaw off by {off}",
                l.track_id
            );
            let inside = points.iter().filter(|p| b.contains(p, 0.1)).count();
            assert!(
                inside >= 20,
                "frame {k}: {} {} at {range:.1} m holds {inside} points",
                l.object_type,
                l.track_id
            );
            // A box shifted sideways by two of its widths holds far fewer (the points are
            // the object's, not the street's everywhere).
            let mut shifted = b;
            let (sn, cs) = b.yaw.sin_cos();
            let step = 2.0 * b.size[1].max(1.0);
            shifted.center += nalgebra::Vector3::new(-sn * step, cs * step, 0.0);
            let beside = points.iter().filter(|p| shifted.contains(p, 0.1)).count();
            assert!(
                beside * 2 < inside,
                "frame {k}: {} {} holds {inside} points, {beside} beside it",
                l.object_type,
                l.track_id
            );
            *checked.entry(l.object_type).or_default() += 1;
        }
    }
    assert!(
        checked.get(&ObjectType::Cyclist).copied().unwrap_or(0) >= 3,
        "{checked:?}"
    );
    assert!(checked.contains_key(&ObjectType::Pedestrian), "{checked:?}");
}

fn assert_error(err: impl std::fmt::Display, parts: &[&str]) {
    let msg = err.to_string();
    for p in parts {
        assert!(msg.contains(p), "`{msg}` does not contain `{p}`");
    }
}

#[test]
fn broken_sequences_fail_naming_file_and_line() {
    let Some(s) = shared() else { return };
    // Missing OXTS file.
    let tmp = tempfile::tempdir().unwrap();
    assemble(&s, tmp.path(), 3);
    let oxts = tmp.path().join("oxts/0000.txt");
    let full = std::fs::read_to_string(&oxts).unwrap();
    std::fs::remove_file(&oxts).unwrap();
    let seq = TrackingSequence::open(tmp.path(), 0).unwrap();
    assert_error(seq.poses().unwrap_err(), &["oxts/0000.txt"]);
    assert!(seq
        .check()
        .iter()
        .any(|i| matches!(i, Issue::MissingFile { path, .. } if path.ends_with("oxts/0000.txt"))));

    // Fewer packets than scans: the first missing packet's line.
    let two: String = full.lines().take(2).map(|l| format!("{l}\n")).collect();
    std::fs::write(&oxts, two).unwrap();
    assert_error(
        seq.imu_poses().unwrap_err(),
        &["oxts/0000.txt:3: packet: missing: 2 packets for the 3 frames the scans in"],
    );
    assert_eq!(seq.oxts_count(), 2);
    assert!(seq.check().iter().any(
        |i| matches!(i, Issue::CountMismatch { a_count: 3, b_count: 2, b, .. } if b.ends_with("oxts/0000.txt"))
    ));
    // More packets than scans: the first extra one's line.
    std::fs::write(&oxts, &full).unwrap();
    assert_error(
        seq.poses().unwrap_err(),
        &["oxts/0000.txt:4: packet: 100 packets for the 3 frames the scans in"],
    );

    // Calibration without Tr_imu_velo.
    let calib = tmp.path().join("calib/0000.txt");
    let text = std::fs::read_to_string(&calib).unwrap();
    let without: String = text
        .lines()
        .filter(|l| !l.starts_with("Tr_imu_velo"))
        .map(|l| format!("{l}\n"))
        .collect();
    std::fs::write(&calib, without).unwrap();
    let three: String = full.lines().take(3).map(|l| format!("{l}\n")).collect();
    std::fs::write(&oxts, three).unwrap();
    assert_error(
        seq.poses().unwrap_err(),
        &["calib/0000.txt:0: Tr_imu_velo: missing"],
    );
    // A calibration line with a value too few.
    let short = text.replace(" 9.999631000000e-01", "");
    std::fs::write(&calib, short).unwrap();
    assert_error(
        seq.calib().unwrap_err(),
        &["calib/0000.txt:5: R_rect: 8 values, expected 9"],
    );
    std::fs::remove_file(&calib).unwrap();
    assert_error(seq.poses().unwrap_err(), &["calib/0000.txt"]);

    // Labels of 100 frames for 3 scans: the first label line beyond the scans.
    assert_error(
        seq.labels().unwrap_err(),
        &[
            "label_02/0000.txt:",
            "frame: label of frame 3 but",
            "span 3 frames",
        ],
    );
    let first_beyond = std::fs::read_to_string(seq.labels_path())
        .unwrap()
        .lines()
        .position(|l| l.starts_with("3 "))
        .unwrap()
        + 1;
    assert_error(
        seq.labels().unwrap_err(),
        &[&format!("label_02/0000.txt:{first_beyond}: frame")],
    );
    assert!(seq.check().iter().any(
        |i| matches!(i, Issue::CountMismatch { a, a_count: 100, b_count: 3, .. } if a.ends_with("label_02/0000.txt"))
    ));

    // A label line with 16 fields.
    let labels = tmp.path().join("label_02/0000.txt");
    let text = std::fs::read_to_string(&labels).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let mut fields: Vec<&str> = lines[3].split_whitespace().collect();
    fields.pop();
    lines[3] = fields.join(" ");
    std::fs::write(&labels, lines.join("\n")).unwrap();
    assert_error(
        seq.labels().unwrap_err(),
        &["label_02/0000.txt:4: line: 16 values, expected 17"],
    );
}

#[test]
fn pipelines_run_on_the_tracking_layout_as_on_the_raw_drive() {
    use smc_lmb::pipeline::{
        predict_pairs, track_recording, PlanePredictionConfig, TrackingConfig,
    };
    let Some(s) = shared() else { return };
    let tmp = tempfile::tempdir().unwrap();
    assemble(&s, tmp.path(), FRAMES);
    let seq = TrackingSequence::open(tmp.path(), 0).unwrap();
    let drive = RawDrive::open(&s.drive).unwrap();
    // Measured poses: the same poses and scans give the same plane-prediction errors.
    let config = PlanePredictionConfig {
        use_vehicle_model: false,
        ..PlanePredictionConfig::default()
    };
    let mut rng = smc_lmb::rng::seeded(3);
    let a = predict_pairs(&seq, Some(11..12), &config, 2, &mut rng).unwrap();
    let mut rng = smc_lmb::rng::seeded(3);
    let b = predict_pairs(&drive, Some(11..12), &config, 2, &mut rng).unwrap();
    assert_eq!(a.len(), 1);
    assert_eq!(a[0].pairs, b[0].pairs);
    assert_eq!(
        (a[0].predicted, a[0].segmented),
        (b[0].predicted, b[0].segmented)
    );
    let mut c = TrackingConfig::default();
    c.filter.particles = 100;
    let tracks = track_recording(&seq, Some(0..3), &c, 1, |_| Ok(())).unwrap();
    assert_eq!(tracks.drive, "tracking_0000");
    assert_eq!(tracks.ego, "oxts");
    assert_eq!(tracks.frames.len(), 3);
    let err = track_recording(&seq, Some(90..110), &c, 1, |_| Ok(()))
        .unwrap_err()
        .to_string();
    assert!(err.contains("beyond its 100 frames"), "{err}");
}

#[test]
fn the_sequence_scores_tracks_against_its_own_labels() {
    use smc_lmb::pipeline::drive_evaluation::{
        evaluate_clusters, evaluate_recording, label_truth, retain_clusters, EvaluationOptions,
    };
    use smc_lmb::pipeline::{track_recording, TrackingConfig};
    use smc_lmb::recording::RecordingLabels;
    let Some(s) = shared() else { return };
    let tmp = tempfile::tempdir().unwrap();
    assemble(&s, tmp.path(), FRAMES);
    let seq = TrackingSequence::open(tmp.path(), 0).unwrap();
    // The labels are the file's lines; the raw drive of the shared data has none.
    let lines = std::fs::read_to_string(s.tracking.join("label_02/0000.txt"))
        .unwrap()
        .lines()
        .filter(|l| !l.trim().is_empty())
        .count();
    match Recording::labels(&seq).unwrap() {
        Some(RecordingLabels::Camera { labels, .. }) => assert_eq!(labels.len(), lines),
        other => panic!("{other:?}"),
    }
    assert!(Recording::labels(&RawDrive::open(&s.drive).unwrap())
        .unwrap()
        .is_none());
    let mut c = TrackingConfig::default();
    c.filter.particles = 100;
    let tracks = track_recording(&seq, Some(0..10), &c, 1, |_| Ok(())).unwrap();
    let options = EvaluationOptions {
        camera_view: true,
        ..EvaluationOptions::default()
    };
    let scored = evaluate_recording(&tracks, &seq, &options).unwrap();
    assert!(scored.walls.is_none());
    // The same as the pieces put together by hand: labels within 40 m in camera 2's view,
    // tracks in its view.
    let calib = seq.calib().unwrap();
    let truth = label_truth(
        &seq.labels().unwrap(),
        &calib.rect_from_velo(),
        &seq.poses().unwrap(),
        |b| b.center.x.hypot(b.center.y) <= 40.0 && calib.in_image2(&b.center),
    );
    let mut in_view = tracks.clone();
    retain_clusters(&mut in_view, |p| {
        calib.in_image2(&Point3::new(p[0], p[1], p[2]))
    });
    let by_hand = evaluate_clusters(&in_view, &truth, &options.clusters).unwrap();
    assert_eq!(scored.clusters, by_hand);
    assert_eq!(scored.clusters.frames.len(), 10);
    assert!(scored.clusters.frames.iter().any(|f| f.truth > 0));
}
