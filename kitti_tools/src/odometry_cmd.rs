//! `kitti-tools odometry`: lidar odometry (KISS-ICP's recipe) over the scans of a raw drive,
//! an odometry sequence or a folder of `.bin` or `.pcd` files; writes KITTI pose lines and, given a
//! reference trajectory, prints its relative pose errors.

use anyhow::{bail, Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use nalgebra::Isometry3;
use smc_lmb::cloud::odometry::{odometry_of_scans_at, Fallback, OdometryConfig};
use smc_lmb::kitti::odometry::{read_odometry_poses, write_odometry_poses};
use smc_lmb::kitti::{OdometrySequence, RawDrive};
use smc_lmb::metrics::{
    path_length, relative_pose_errors, segment_errors, Spread, KITTI_SEGMENT_LENGTHS,
};
use smc_lmb::recording::Recording;
use smc_lmb::recording::ScanDirectory;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::Instant;

/// Flags of `odometry`.
#[derive(clap::Args)]
pub struct Args {
    /// A KITTI raw drive folder; its OXTS Velodyne poses, when present, are the reference.
    #[arg(long, conflicts_with_all = ["odometry", "scans"])]
    drive: Option<PathBuf>,
    /// A KITTI odometry root (holding `sequences/` and `poses/`); needs `--sequence`. Its
    /// `poses/NN.txt`, when present, is the reference.
    #[arg(long, requires = "sequence", conflicts_with = "scans")]
    odometry: Option<PathBuf>,
    /// Odometry sequence number.
    #[arg(long)]
    sequence: Option<u32>,
    /// A folder of `.bin` scans or of `.pcd` clouds (their NaN points left out), taken in
    /// file-name order.
    #[arg(long)]
    scans: Option<PathBuf>,
    /// Only the first N scans.
    #[arg(long)]
    frames: Option<usize>,
    /// Where to write the poses (one row-major 3×4 matrix a line, scan k → scan 0).
    #[arg(long, required_unless_present = "evaluate")]
    out: Option<PathBuf>,
    /// A KITTI pose file to compare with instead of the drive's or sequence's own reference
    /// (for instance another odometry's output).
    #[arg(long)]
    reference: Option<PathBuf>,
    /// Score this pose file against the reference instead of running the odometry.
    #[arg(long)]
    evaluate: Option<PathBuf>,
    /// Voxel edge in metres (default: max range / 100).
    #[arg(long)]
    voxel_size: Option<f64>,
    /// Maximum range in metres.
    #[arg(long, default_value_t = 100.0)]
    max_range: f64,
    /// KISS-ICP's recipe alone: no point-to-plane refinement after the point-to-point
    /// alignment.
    #[arg(long)]
    no_refine: bool,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
}

/// The recording, the frames of its scans and where the reference trajectory comes from.
struct Input {
    rec: Box<dyn Recording>,
    /// Frame number of each scan: `0, 1, 2, …` but where a drive dropped scans (the
    /// reference has a pose per frame).
    frames: Vec<usize>,
    reference: Option<Reference>,
}

enum Reference {
    /// The recording's own poses (OXTS, `poses/NN.txt`), named by where they are.
    Recorded(String),
    /// A pose file.
    PoseFile(PathBuf),
}

/// Runs the command.
pub fn run(args: Args) -> Result<()> {
    let mut input = input(&args)?;
    if let Some(n) = args.frames {
        input.frames.truncate(n);
    }
    if input.frames.is_empty() {
        bail!("no scans to register");
    }
    let estimate = match &args.evaluate {
        Some(file) => read_odometry_poses(file)
            .with_context(|| format!("reading the poses to score, {}", file.display()))?,
        None => estimate(&args, &*input.rec, &input.frames)?,
    };
    if let Some(file) = &args.reference {
        input.reference = Some(Reference::PoseFile(file.clone()));
    }
    if let Some(reference) = &input.reference {
        let (name, poses) = reference_poses(reference, &*input.rec)?;
        // The frame of each estimated pose: the scans' own numbers, and consecutive ones after
        // the last (a scored file may hold more poses than there are scans).
        let gap = input
            .frames
            .last()
            .map_or(0, |&l| l + 1 - input.frames.len());
        let frame = |i: usize| input.frames.get(i).copied().unwrap_or(i + gap);
        if estimate
            .len()
            .checked_sub(1)
            .is_some_and(|l| poses.len() <= frame(l))
        {
            bail!(
                "{name}: the reference has {} poses for {} scans",
                poses.len(),
                estimate.len()
            );
        }
        let at_scans: Vec<Isometry3<f64>> = (0..estimate.len()).map(|i| poses[frame(i)]).collect();
        report(&estimate, &at_scans, &name)?;
    }
    Ok(())
}

fn input(args: &Args) -> Result<Input> {
    let (rec, reference): (Box<dyn Recording>, Option<String>) =
        match (&args.drive, &args.odometry, &args.scans) {
            (Some(dir), _, _) => {
                let drive = RawDrive::open(dir)
                    .with_context(|| format!("opening drive {}", dir.display()))?;
                let oxts = drive
                    .has_oxts()
                    .then(|| format!("{} (OXTS)", drive.oxts_dir().display()));
                (Box::new(drive), oxts)
            }
            (None, Some(root), _) => {
                let Some(number) = args.sequence else {
                    bail!("--odometry needs --sequence");
                };
                let seq = OdometrySequence::open(root, number).with_context(|| {
                    format!(
                        "opening odometry sequence {number:02} of {}",
                        root.display()
                    )
                })?;
                let poses = seq
                    .has_poses()
                    .then(|| seq.poses_path().display().to_string());
                (Box::new(seq), poses)
            }
            (None, None, Some(dir)) => (Box::new(ScanDirectory::open(dir)?), None),
            (None, None, None) => {
                bail!("give --drive DIR, --odometry ROOT --sequence NN or --scans DIR")
            }
        };
    // Dropped scans are left out; the others keep their frame numbers.
    let frames = (0..rec.frame_count())
        .filter(|&k| rec.has_scan(k))
        .collect();
    Ok(Input {
        rec,
        frames,
        reference: reference.map(Reference::Recorded),
    })
}

fn estimate(args: &Args, rec: &dyn Recording, frames: &[usize]) -> Result<Vec<Isometry3<f64>>> {
    let config = OdometryConfig {
        max_range: args.max_range,
        voxel_size: args.voxel_size.unwrap_or(args.max_range / 100.0),
        refine_iterations: if args.no_refine {
            0
        } else {
            OdometryConfig::default().refine_iterations
        },
        ..OdometryConfig::default()
    };
    let bar = if args.quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(frames.len() as u64)
    };
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} scans {elapsed}")
            .expect("valid template"),
    );
    let start = Instant::now();
    let mut fallbacks: BTreeMap<Fallback, Vec<usize>> = BTreeMap::new();
    let mut least_information = f64::INFINITY;
    let poses = odometry_of_scans_at(
        frames,
        &|i| rec.scan(frames[i]),
        &|i| rec.scan_name(frames[i]),
        &config,
        |k, r| {
            bar.inc(1);
            if let Some(f) = r.fallback {
                fallbacks.entry(f).or_default().push(k);
            }
            if let Some(i) = r.information_ratio {
                least_information = least_information.min(i);
            }
        },
    )?;
    let elapsed = start.elapsed().as_secs_f64();
    bar.finish_and_clear();
    let out = args
        .out
        .as_ref()
        .expect("clap requires --out without --evaluate");
    write_odometry_poses(out, &poses)?;
    println!(
        "{} scans, {:.1} m path, {:.1} ms/scan (reading included); poses written to {}",
        poses.len(),
        path_length(&poses),
        1000.0 * elapsed / poses.len() as f64,
        out.display()
    );
    if least_information.is_finite() {
        println!(
            "least translational information ratio {least_information:.2e} (fallback below {:.0e})",
            config.min_information_ratio
        );
    }
    for (f, frames) in &fallbacks {
        let shown: Vec<String> = frames.iter().take(10).map(|k| k.to_string()).collect();
        let more = if frames.len() > 10 { ", …" } else { "" };
        eprintln!(
            "warning: {} scan(s) kept the constant-velocity pose ({}): {}{more}",
            frames.len(),
            f.name(),
            shown.join(", ")
        );
    }
    Ok(poses)
}

fn reference_poses(
    reference: &Reference,
    rec: &dyn Recording,
) -> Result<(String, Vec<Isometry3<f64>>)> {
    match reference {
        Reference::Recorded(name) => {
            let poses = rec
                .poses()
                .with_context(|| format!("reading the reference {name}"))?;
            Ok((name.clone(), poses))
        }
        Reference::PoseFile(file) => {
            let poses = read_odometry_poses(file)
                .with_context(|| format!("reading the reference {}", file.display()))?;
            Ok((file.display().to_string(), poses))
        }
    }
}

fn report(estimate: &[Isometry3<f64>], reference: &[Isometry3<f64>], name: &str) -> Result<()> {
    let rpe = relative_pose_errors(estimate, reference)?;
    println!(
        "against {name}: reference path {:.1} m, estimated {:.1} m",
        path_length(reference),
        path_length(estimate)
    );
    let t: Vec<f64> = rpe.iter().map(|e| e.translation).collect();
    let r: Vec<f64> = rpe.iter().map(|e| e.rotation_deg).collect();
    if let (Some(t), Some(r)) = (Spread::of(&t), Spread::of(&r)) {
        println!(
            "per-frame relative pose error over {} pairs: translation mean {:.4} m, median {:.4} m, \
             max {:.4} m; rotation mean {:.4}°, median {:.4}°, max {:.4}°",
            rpe.len(),
            t.mean,
            t.median,
            t.max,
            r.mean,
            r.median,
            r.max
        );
    }
    let last = estimate.len() - 1;
    let end = (reference[last].inverse() * estimate[last])
        .translation
        .vector
        .norm();
    let path = path_length(reference);
    if path >= 1.0 {
        println!(
            "end-point drift {end:.3} m ({:.2} % of the reference path)",
            100.0 * end / path
        );
    } else {
        println!("end-point drift {end:.3} m");
    }
    match segment_errors(estimate, reference, &KITTI_SEGMENT_LENGTHS)? {
        Some(s) => println!(
            "KITTI segments (100..800 m, {} segments): translation {:.3} %, rotation {:.4} °/100 m",
            s.segments, s.translation_percent, s.rotation_deg_per_100m
        ),
        None => println!("KITTI segment errors: the path is shorter than 100 m"),
    }
    Ok(())
}
