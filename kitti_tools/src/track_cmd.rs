//! `kitti-tools track`: one LMB run over a KITTI raw drive, tracking sequence, odometry
//! sequence or folder of scans in which building walls and point clusters are labelled
//! objects; writes the per-frame tracks as JSON and, on request,
//! labelled LAS/PLY clouds of chosen frames and a bird's-eye plot; prints a summary.

use crate::config_file::tracking_config;
use crate::recording::{track, Recording};
use anyhow::{bail, Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use smc_lmb::cloud::{write_las_labelled, write_ply_labelled};
use smc_lmb::kitti::tracking::TrackingCalib;
use smc_lmb::kitti::TrackingSequence;
use smc_lmb::pipeline::drive_tracking::kitti_out::{lmb_results, BaselineBoxes};
use smc_lmb::pipeline::drive_tracking::{
    drive_plot, frame_plot, point_labels, DriveTracks, EgoModel, FrameView, PoseSource,
};
use smc_lmb::pipeline::kitti_results::{results_path, write_tracking_results, ResultObject};
use smc_lmb::trackers::ab3dmot::Ab3dmotConfig;
use std::ops::Range;
use std::path::PathBuf;

/// Flags of `track`.
#[derive(clap::Args)]
pub struct Args {
    /// A KITTI raw drive folder (`.../2011_09_26/2011_09_26_drive_0001_sync`).
    #[arg(long, conflicts_with_all = ["odometry", "tracking", "scans"])]
    drive: Option<PathBuf>,
    /// A folder of `.bin` or `.pcd` scans from any lidar, one frame per file in file-name
    /// order; poses from `--poses` or lidar odometry, times from `--times` or the config's
    /// `dt`.
    #[arg(long, conflicts_with_all = ["odometry", "tracking"])]
    scans: Option<PathBuf>,
    /// With `--scans`: a pose file, one row-major 3 × 4 sensor pose per line (KITTI's
    /// odometry layout), at least one per scan.
    #[arg(long, requires = "scans")]
    poses: Option<PathBuf>,
    /// With `--scans`: a time file, one time in seconds per line, at least one per scan.
    #[arg(long, requires = "scans")]
    times: Option<PathBuf>,
    /// With `--scans`: the sensor's height over the road (m), used where a frame has no
    /// ground plane (overrides the config's `clusters.sensor_height`, KITTI's 1.73 m).
    #[arg(long, requires = "scans")]
    sensor_height: Option<f64>,
    /// A KITTI odometry root (holding `sequences/` and `poses/`); needs `--sequence`. Walls
    /// move by the ground-truth poses (sequences 00–10).
    #[arg(long, requires = "sequence", conflicts_with = "tracking")]
    odometry: Option<PathBuf>,
    /// A KITTI tracking split folder (`.../training`, holding `velodyne/`, `oxts/`,
    /// `calib/`); needs `--sequence`.
    #[arg(long, requires = "sequence")]
    tracking: Option<PathBuf>,
    /// Odometry or tracking sequence number.
    #[arg(long)]
    sequence: Option<u32>,
    /// Frames to track, `A..B` (B excluded); default all.
    #[arg(long)]
    frames: Option<String>,
    /// Particles per track (overrides the config).
    #[arg(long)]
    particles: Option<usize>,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Output JSON file.
    #[arg(long)]
    out: PathBuf,
    /// Write a labelled LAS cloud of every tracked frame (or of `--export-frames`) here.
    #[arg(long)]
    las: Option<PathBuf>,
    /// Write a labelled PLY cloud of every tracked frame (or of `--export-frames`) here.
    #[arg(long)]
    ply: Option<PathBuf>,
    /// Frames to export as LAS/PLY, comma-separated (default: all tracked frames).
    #[arg(long, value_delimiter = ',')]
    export_frames: Vec<usize>,
    /// Bird's-eye plot of the drive (.svg or .png).
    #[arg(long)]
    plot: Option<PathBuf>,
    /// Bird's-eye plot of one frame with its point cloud (.svg or .png; PNG is the lighter
    /// for a whole cloud): points coloured by ground, walls and tracked clusters by class,
    /// wall rectangles and cluster boxes, in the sensor frame. The frame is `--frame-plot-at`.
    #[arg(long)]
    frame_plot: Option<PathBuf>,
    /// The frame `--frame-plot` draws (default: the first tracked frame).
    #[arg(long, requires = "frame_plot")]
    frame_plot_at: Option<usize>,
    /// Models and tuning (.toml or .json); see `TrackingConfig` (its `planes` section is the
    /// plane segmentation's).
    #[arg(long)]
    config: Option<PathBuf>,
    /// Passes a wall round makes after its two, towards the fit that no longer depends on
    /// the drawn triple (overrides the config's `planes.wall_refits`; default 2, at most 100).
    #[arg(long, value_name = "N")]
    wall_refits: Option<usize>,
    /// Keep every building-scale vertical piece as a wall: the facade test (top above the
    /// sensor, RMS, plumb) is off, whatever the settings say. Shows what the test rejects:
    /// vegetation, hedges, car sides.
    #[arg(long)]
    any_vertical: bool,
    /// Move walls by a per-particle draw of the vehicle model instead of the measured poses
    /// (the extended constant turn; `--vehicle-model` names another).
    #[arg(long)]
    ect: bool,
    /// Move walls by a per-particle draw of this vehicle model: `ect`, `ct` or `bicycle`
    /// (implies a vehicle ego like `--ect`).
    #[arg(long, value_name = "NAME", conflicts_with = "ect")]
    vehicle_model: Option<String>,
    /// A parameter of the vehicle model, `NAME=VALUE` (repeatable; see `planes --help`).
    #[arg(long, value_name = "NAME=VALUE", requires = "vehicle_model")]
    vehicle_param: Vec<String>,
    /// Where the poses come from: the recording's own (OXTS, `poses/NN.txt`), lidar odometry
    /// on the scans, `auto` (recorded when the recording has them, lidar odometry otherwise)
    /// or `static` (a sensor that does not move). The output's `ego` says which was used.
    #[arg(long, value_enum, default_value_t = Ego::Auto)]
    ego: Ego,
    /// Report every confirmed cluster, also static ones of class `Other` (poles, trunks,
    /// hedges), which are left out of the road users by default.
    #[arg(long)]
    all_clusters: bool,
    /// Write the road users as KITTI tracking results, `DIR/NNNN.txt` in the label_02 format
    /// (tracking layout only: the 2-D boxes need the sequence's calibration).
    #[arg(long, requires = "tracking")]
    kitti_out: Option<PathBuf>,
    /// Also run the AB3DMOT-style baseline on the same detections and write its results to
    /// `DIR/NNNN.txt` (tracking layout only).
    #[arg(long, requires = "tracking")]
    baseline_out: Option<PathBuf>,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
}

/// Source of the poses, as `--ego` names it.
#[derive(Copy, Clone, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Ego {
    /// Recorded poses when there are any, lidar odometry otherwise.
    Auto,
    /// The recording's poses (fails without them).
    Recorded,
    /// Lidar odometry (KISS-ICP's recipe) on the recording's scans.
    Lidar,
    /// Every frame at the origin.
    Static,
}

impl From<Ego> for PoseSource {
    fn from(e: Ego) -> PoseSource {
        match e {
            Ego::Auto => PoseSource::Auto,
            Ego::Recorded => PoseSource::Recorded,
            Ego::Lidar => PoseSource::Lidar,
            Ego::Static => PoseSource::Static,
        }
    }
}

/// `--frames A..B` (B excluded, after A); errors quote the flag.
pub(crate) fn parse_range(text: &str) -> Result<Range<usize>> {
    let Some((a, b)) = text.split_once("..") else {
        bail!("--frames `{text}`: expected A..B");
    };
    let a: usize = a
        .trim()
        .parse()
        .with_context(|| format!("--frames `{text}`: start"))?;
    let b: usize = b
        .trim()
        .parse()
        .with_context(|| format!("--frames `{text}`: end"))?;
    if b <= a {
        bail!("--frames `{text}`: the end must be after the start");
    }
    Ok(a..b)
}

/// Runs the command.
pub fn run(args: Args) -> Result<()> {
    let mut config = tracking_config(args.config.as_deref(), args.particles)?;
    if args.ect {
        config.ego = EgoModel::Ect {
            sigma_accel: 0.5,
            sigma_turn_accel: 0.1,
        };
    }
    if let Some(model) = &args.vehicle_model {
        config.ego = EgoModel::Vehicle {
            model: model.clone(),
            parameters: crate::config_file::vehicle_params(&args.vehicle_param)?
                .into_iter()
                .collect(),
        };
        config.validate().context("--vehicle-model")?;
    }
    config.poses = args.ego.into();
    config.all_clusters = args.all_clusters;
    if let Some(n) = args.wall_refits {
        config.planes.wall_refits = n;
    }
    if args.any_vertical {
        config.planes.wall_quality = None;
    }
    let baseline = std::cell::RefCell::new(BaselineBoxes::new());
    let frames = args.frames.as_deref().map(parse_range).transpose()?;
    for dir in [&args.las, &args.ply].into_iter().flatten() {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let bar = if args.quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(0)
    };
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} frames {elapsed} {msg}")
            .expect("valid template"),
    );
    if args.scans.is_none()
        && (args.poses.is_some() || args.times.is_some() || args.sensor_height.is_some())
    {
        bail!(
            "--poses, --times and --sensor-height go with --scans DIR (the KITTI layouts bring \
             their own)"
        );
    }
    let recording = match (&args.drive, &args.odometry, &args.tracking, args.sequence) {
        (Some(dir), _, _, _) => Recording::Raw(dir.clone()),
        (None, Some(root), _, Some(n)) => Recording::Odometry(root.clone(), n),
        (None, None, Some(root), Some(n)) => Recording::Tracking(root.clone(), n),
        _ => match &args.scans {
            Some(dir) => Recording::Scans {
                dir: dir.clone(),
                poses: args.poses.clone(),
                times: args.times.clone(),
                sensor_height: args.sensor_height,
            },
            None => bail!(
                "give --drive DIR, --odometry ROOT --sequence NN, --tracking ROOT --sequence NNNN \
                 or --scans DIR"
            ),
        },
    };
    let frame_plotted = std::cell::RefCell::new(false);
    let plot_at = args
        .frame_plot_at
        .or(frames.as_ref().map(|r| r.start))
        .unwrap_or(0);
    let on_frame = |view: &FrameView<'_>| -> smc_lmb::Result<()> {
        let (done, total) = view.progress;
        bar.set_length(total as u64);
        bar.set_position(done as u64);
        bar.set_message(format!(
            "{} walls, {} clusters",
            view.tracked.planes.len(),
            view.tracked.clusters.len()
        ));
        if args.baseline_out.is_some() {
            baseline.borrow_mut().add(view);
        }
        let k = view.tracked.frame;
        if let Some(path) = &args.frame_plot {
            if k == plot_at {
                let name = recording.name();
                frame_plot(view, &name, config.clusters.max_range).write(path, 1000)?;
                *frame_plotted.borrow_mut() = true;
            }
        }
        if args.export_frames.is_empty() || args.export_frames.contains(&k) {
            let labels = point_labels(view.cloud.len(), view.detections, view.tracked);
            let name = format!("{k:010}");
            if let Some(dir) = &args.las {
                write_las_labelled(dir.join(format!("{name}.las")), view.cloud, &labels)?;
            }
            if let Some(dir) = &args.ply {
                write_ply_labelled(dir.join(format!("{name}.ply")), view.cloud, &labels)?;
            }
        }
        Ok(())
    };
    let tracks = track(&recording, frames.clone(), &config, args.seed, on_frame)?;
    bar.finish_and_clear();
    tracks.write_json(&args.out)?;
    if let Some(p) = &args.plot {
        drive_plot(&tracks).write(p, 1000)?;
    }
    if let Some(p) = &args.frame_plot {
        if !frame_plotted.into_inner() {
            bail!(
                "--frame-plot {}: frame {plot_at} was not tracked (see --frames)",
                p.display()
            );
        }
    }
    print_summary(&tracks);
    println!("wrote {}", args.out.display());
    if let (Some(root), Some(n)) = (&args.tracking, args.sequence) {
        let calib = TrackingSequence::open(root, n)?.calib()?;
        if let Some(dir) = &args.kitti_out {
            let path = write_results(dir, n, &lmb_results(&tracks), &calib)?;
            println!("wrote {path}");
        }
        if let Some(dir) = &args.baseline_out {
            let objects = baseline.borrow().results(&Ab3dmotConfig::default())?;
            let path = write_results(dir, n, &objects, &calib)?;
            println!("wrote {path} (AB3DMOT-style baseline on the same detections)");
        }
    }
    Ok(())
}

/// Writes `objects` as `DIR/NNNN.txt`; returns the path and line count as text.
fn write_results(
    dir: &std::path::Path,
    sequence: u32,
    objects: &[ResultObject],
    calib: &TrackingCalib,
) -> Result<String> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let path = results_path(dir, sequence);
    let lines = write_tracking_results(&path, objects, calib)
        .with_context(|| format!("writing {}", path.display()))?;
    Ok(format!("{} ({lines} result lines)", path.display()))
}

/// Prints what a tracking run confirmed and how long its stages took.
pub fn print_summary(tracks: &DriveTracks) {
    let s = &tracks.summary;
    let t = &s.mean_times;
    println!(
        "{}: {} frames (ego {}, up to {} particles/track, seed {})",
        tracks.drive, s.frames, tracks.ego, tracks.particles, tracks.seed
    );
    println!(
        "confirmed per frame: {:.2} walls, {:.2} clusters; labels: {} walls, {} clusters",
        s.mean_planes, s.mean_clusters, s.plane_labels, s.cluster_labels
    );
    println!(
        "ms/frame: read {:.1}, planes {:.1}, clusters {:.1}, filter {:.1}{}, total {:.1}{}",
        t.read_ms,
        t.planes_ms,
        t.clusters_ms,
        t.filter_ms,
        if t.overlap_ms > 0.0 {
            format!(" (side by side: {:.1})", t.overlap_ms)
        } else {
            String::new()
        },
        t.total_ms(),
        if t.ego_ms > 0.0 {
            format!(" (+ lidar odometry {:.1})", t.ego_ms)
        } else {
            String::new()
        }
    );
    if s.ego_fallbacks > 0 {
        eprintln!(
            "warning: lidar odometry kept the constant-velocity pose in {} frame(s) (too few \
             points, a degenerate scene or a jump; see `kitti-tools odometry` for which)",
            s.ego_fallbacks
        );
    }
    let pairs = smc_lmb::pipeline::drive_tracking::tracked_wall_pairs(tracks);
    if !pairs.is_empty() {
        let w = smc_lmb::metrics::PlanePredictionSummary::from_pairs(&pairs, &[]);
        println!(
            "tracked walls frame to frame: {} pairs, normal angle median {:.3}° p90 {:.3}°, \
             vertex distance median {:.3} m p90 {:.3} m",
            w.pairs,
            w.median_normal_angle_deg,
            w.p90_normal_angle_deg,
            w.median_vertex_distance_m,
            w.p90_vertex_distance_m
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_ranges() {
        assert_eq!(parse_range("2..5").unwrap(), 2..5);
        assert!(parse_range("5..2").is_err());
        assert!(parse_range("5").is_err());
        assert!(parse_range("a..3").is_err());
    }
}
