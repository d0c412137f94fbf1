//! `kitti-tools info`: what a KITTI raw drive or tracking sequence holds (frame counts, time
//! span, calibration, first and last pose, OXTS path length, label counts) and its consistency
//! issues.
//!
//! Severity of issues: a missing sensor folder or missing file only limits what can be done
//! with the drive and is a warning, and so are scans dropped inside the numbering (KITTI's
//! drive 0009 = tracking sequence 0001 lacks four); everything else (other numbering gaps,
//! counts that disagree, time that does not increase, unreadable files) is an error and makes
//! the command exit non-zero.

use anyhow::{bail, Result};
use nalgebra::Isometry3;
use serde::Serialize;
use smc_lmb::kitti::drive::{CALIB_CAM_TO_CAM, CALIB_IMU_TO_VELO, CALIB_VELO_TO_CAM};
use smc_lmb::kitti::tracking::FRAME_PERIOD;
use smc_lmb::kitti::{Issue, RawDrive, Timestamps, TrackingSequence};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// Flags of `info`.
#[derive(clap::Args)]
pub struct Args {
    /// The drive folder (`.../2011_09_26/2011_09_26_drive_0001_sync`).
    #[arg(long, conflicts_with = "tracking")]
    drive: Option<PathBuf>,
    /// A KITTI tracking split folder (`.../training`); needs `--sequence`.
    #[arg(long, requires = "sequence")]
    tracking: Option<PathBuf>,
    /// Tracking sequence number.
    #[arg(long)]
    sequence: Option<u32>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

/// Time covered by a sensor's stamps.
#[derive(Serialize)]
struct TimeSpan {
    /// Which stamps (`velodyne` or `oxts`).
    source: &'static str,
    first: String,
    last: String,
    seconds: f64,
}

/// A pose as translation (m) and roll, pitch, yaw (rad).
#[derive(Serialize)]
struct PoseSummary {
    translation: [f64; 3],
    roll_pitch_yaw: [f64; 3],
}

#[derive(Serialize)]
struct IssueReport {
    severity: &'static str,
    path: String,
    message: String,
}

#[derive(Serialize)]
struct Report {
    drive: String,
    name: String,
    velodyne_frames: usize,
    oxts_packets: usize,
    time_span: Option<TimeSpan>,
    /// Calibration file name → present.
    calibration: BTreeMap<String, bool>,
    /// `velodyne` (poses of the Velodyne frame, needs the IMU→Velodyne calibration) or `imu`.
    pose_frame: Option<&'static str>,
    first_pose: Option<PoseSummary>,
    last_pose: Option<PoseSummary>,
    path_length_m: Option<f64>,
    /// Tracking sequences: label lines per object type (`label_02`).
    #[serde(skip_serializing_if = "Option::is_none")]
    labels: Option<BTreeMap<String, usize>>,
    issues: Vec<IssueReport>,
    errors: usize,
}

fn is_error(issue: &Issue) -> bool {
    !matches!(
        issue,
        Issue::MissingFolder { .. } | Issue::MissingFile { .. } | Issue::DroppedScans { .. }
    )
}

fn span(source: &'static str, stamps: &Timestamps) -> Option<TimeSpan> {
    let (first, last) = (stamps.absolute.first()?, stamps.absolute.last()?);
    Some(TimeSpan {
        source,
        first: first.to_string(),
        last: last.to_string(),
        seconds: last.seconds_since(first),
    })
}

fn summary(pose: &Isometry3<f64>) -> PoseSummary {
    let t = pose.translation.vector;
    let (r, p, y) = pose.rotation.euler_angles();
    PoseSummary {
        translation: [t.x, t.y, t.z],
        roll_pitch_yaw: [r, p, y],
    }
}

fn path_length(poses: &[Isometry3<f64>]) -> f64 {
    poses
        .windows(2)
        .map(|w| (w[1].translation.vector - w[0].translation.vector).norm())
        .sum()
}

fn issue_reports(issues: &[Issue]) -> (Vec<IssueReport>, usize) {
    let reports: Vec<IssueReport> = issues
        .iter()
        .map(|i| IssueReport {
            severity: if is_error(i) { "error" } else { "warning" },
            path: i.path().display().to_string(),
            message: i.to_string(),
        })
        .collect();
    let errors = reports.iter().filter(|i| i.severity == "error").count();
    (reports, errors)
}

fn tracking_report(seq: &TrackingSequence) -> Report {
    let frames = seq.frame_count();
    let time_span = (frames > 0).then(|| TimeSpan {
        source: "assumed 0.1 s-per-frame",
        first: "0.000 s".to_string(),
        last: format!("{:.3} s", (frames - 1) as f64 * FRAME_PERIOD),
        seconds: (frames - 1) as f64 * FRAME_PERIOD,
    });
    let calib_name = format!("calib/{}.txt", seq.name());
    let calibration = BTreeMap::from([(calib_name, seq.calib_path().is_file())]);
    let imu = seq.imu_poses().ok();
    let path_length_m = imu.as_deref().map(path_length);
    let (pose_frame, poses) = match seq.poses() {
        Ok(p) => (Some("velodyne"), Some(p)),
        Err(_) => (imu.as_ref().map(|_| "imu"), imu.clone()),
    };
    let poses = poses.unwrap_or_default();
    let labels = seq.labels().ok().map(|labels| {
        let mut counts = BTreeMap::new();
        for l in &labels {
            *counts.entry(l.object_type.name().to_string()).or_insert(0) += 1;
        }
        counts
    });
    let (issues, errors) = issue_reports(&seq.check());
    Report {
        drive: seq.root().display().to_string(),
        name: format!("tracking sequence {}", seq.name()),
        velodyne_frames: seq.velodyne_count(),
        oxts_packets: seq.oxts_count(),
        time_span,
        calibration,
        pose_frame,
        first_pose: poses.first().map(summary),
        last_pose: poses.last().map(summary),
        path_length_m,
        labels,
        issues,
        errors,
    }
}

fn report(drive: &RawDrive) -> Report {
    let velodyne_stamps = if drive.has_velodyne() {
        drive.timestamps().ok()
    } else {
        None
    };
    let time_span = velodyne_stamps
        .and_then(|s| span("velodyne", &s))
        .or_else(|| drive.oxts_timestamps().ok().and_then(|s| span("oxts", &s)));
    let calibration = [CALIB_IMU_TO_VELO, CALIB_VELO_TO_CAM, CALIB_CAM_TO_CAM]
        .iter()
        .map(|name| (name.to_string(), drive.date_dir().join(name).is_file()))
        .collect();
    let imu = if drive.has_oxts() {
        drive.imu_poses().ok()
    } else {
        None
    };
    let path_length_m = imu.as_deref().map(path_length);
    let (pose_frame, poses) = match drive.poses() {
        Ok(p) => (Some("velodyne"), Some(p)),
        Err(_) => (imu.as_ref().map(|_| "imu"), imu.clone()),
    };
    let poses = poses.unwrap_or_default();
    let (issues, errors) = issue_reports(&drive.check());
    Report {
        drive: drive.dir().display().to_string(),
        name: drive.name(),
        velodyne_frames: if drive.has_velodyne() {
            drive.velodyne_count()
        } else {
            0
        },
        oxts_packets: if drive.has_oxts() {
            drive.oxts_count()
        } else {
            0
        },
        time_span,
        calibration,
        pose_frame,
        first_pose: poses.first().map(summary),
        last_pose: poses.last().map(summary),
        path_length_m,
        labels: None,
        issues,
        errors,
    }
}

fn print_text(r: &Report) {
    println!("drive           {} ({})", r.name, r.drive);
    println!("velodyne frames {}", r.velodyne_frames);
    println!("oxts packets    {}", r.oxts_packets);
    match &r.time_span {
        Some(t) => println!(
            "time span       {} .. {} ({:.3} s, {} stamps)",
            t.first, t.last, t.seconds, t.source
        ),
        None => println!("time span       unknown (no readable timestamps)"),
    }
    for (name, present) in &r.calibration {
        let state = if *present { "present" } else { "missing" };
        println!("calibration     {name}: {state}");
    }
    let pose = |label: &str, p: &Option<PoseSummary>| match p {
        Some(p) => println!(
            "{label} ({}) xyz [{:.3}, {:.3}, {:.3}] m, rpy [{:.4}, {:.4}, {:.4}] rad",
            r.pose_frame.unwrap_or("?"),
            p.translation[0],
            p.translation[1],
            p.translation[2],
            p.roll_pitch_yaw[0],
            p.roll_pitch_yaw[1],
            p.roll_pitch_yaw[2]
        ),
        None => println!("{label} none"),
    };
    pose("first pose     ", &r.first_pose);
    pose("last pose      ", &r.last_pose);
    match r.path_length_m {
        Some(l) => println!("path length     {l:.3} m (OXTS)"),
        None => println!("path length     unknown (no readable OXTS)"),
    }
    if let Some(labels) = &r.labels {
        let counts: Vec<String> = labels.iter().map(|(t, n)| format!("{n} {t}")).collect();
        println!("labels          {}", counts.join(", "));
    }
    if r.issues.is_empty() {
        println!("issues          none");
    }
    for i in &r.issues {
        println!("{:<7} {}", i.severity, i.message);
    }
}

/// Runs the command; fails (non-zero exit) when the drive has an error-level issue.
pub fn run(args: Args) -> Result<()> {
    let (r, source) = match (&args.drive, &args.tracking, args.sequence) {
        (Some(dir), _, _) => (report(&RawDrive::open(dir)?), dir.display().to_string()),
        (None, Some(root), Some(n)) => {
            let seq = TrackingSequence::open(root, n)?;
            let source = format!("tracking sequence {n:04} of {}", root.display());
            (tracking_report(&seq), source)
        }
        _ => bail!("give --drive DIR or --tracking ROOT --sequence NNNN"),
    };
    if args.json {
        println!("{}", serde_json::to_string_pretty(&r)?);
    } else {
        print_text(&r);
    }
    if r.errors > 0 {
        bail!("{source}: {} consistency error(s) (see above)", r.errors);
    }
    Ok(())
}
