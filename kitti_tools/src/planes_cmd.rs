//! `kitti-tools planes`: segment building walls in consecutive Velodyne frames, predict them
//! one frame ahead and print the errors the way seed 001 reports them (areas, vertex
//! distances, normal angle, prediction time).

use crate::paper_tables;
use anyhow::{bail, Context, Result};
use smc_lmb::cloud::planes::PlaneConfig;
use smc_lmb::kitti::{OdometrySequence, RawDrive, TrackingSequence};
use smc_lmb::metrics::{PlanePairError, PlanePredictionSummary};
use smc_lmb::pipeline::drive_tracking::RecordingSource;
use smc_lmb::pipeline::{predict_pairs, PairPrediction, PlanePredictionConfig};
use smc_lmb::recording::Recording;
use std::path::PathBuf;

/// Flags of `planes`.
#[derive(clap::Args)]
pub struct Args {
    /// A KITTI raw drive folder (`.../2011_09_26/2011_09_26_drive_0001_sync`).
    #[arg(long, conflicts_with_all = ["odometry", "tracking", "scans"])]
    drive: Option<PathBuf>,
    /// A folder of `.bin` or `.pcd` scans from any lidar, one frame per file in file-name
    /// order; the ego motion from `--poses` or lidar odometry (measured motion: a folder has
    /// no vehicle states).
    #[arg(long, conflicts_with_all = ["odometry", "tracking"])]
    scans: Option<PathBuf>,
    /// With `--scans`: a pose file, one row-major 3 × 4 sensor pose per line, at least one per
    /// scan.
    #[arg(long, requires = "scans")]
    poses: Option<PathBuf>,
    /// A KITTI odometry root (holding `sequences/` and `poses/`); needs `--sequence`.
    #[arg(long, requires = "sequence", conflicts_with = "tracking")]
    odometry: Option<PathBuf>,
    /// A KITTI tracking split folder (`.../training`, holding `velodyne/`, `oxts/`,
    /// `calib/`); needs `--sequence`.
    #[arg(long, requires = "sequence")]
    tracking: Option<PathBuf>,
    /// Odometry or tracking sequence number.
    #[arg(long)]
    sequence: Option<u32>,
    /// Predict frame K into frame K + 1.
    #[arg(long, default_value_t = 0)]
    frame: usize,
    /// Monte-Carlo runs per frame pair.
    #[arg(long, default_value_t = 100)]
    runs: usize,
    /// Every consecutive frame pair instead of one, with the error distribution.
    #[arg(long)]
    all: bool,
    /// Use the measured poses instead of the vehicle motion model (the model needs the
    /// vehicle's measured motion: raw drives and tracking sequences; other recordings are
    /// predicted with the measured poses anyway).
    #[arg(long)]
    measured: bool,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Print one JSON object instead of a table.
    #[arg(long)]
    json: bool,
    /// Print frame K's pairs as seed 001's Tables 1–3 / 4–6, with the paper's values beside
    /// ours on its drive (2011_09_26 drive 0005) at K = 11 and K = 124.
    #[arg(long, conflicts_with_all = ["all", "json"])]
    paper: bool,
    /// Where the ego motion comes from: the recording's own poses (OXTS, `poses/NN.txt`),
    /// lidar odometry on the scans, or `auto` (recorded poses when the recording has them,
    /// lidar odometry otherwise). Lidar odometry predicts with the measured motion.
    #[arg(long, value_enum, default_value_t = Ego::Auto)]
    ego: Ego,
    /// Plane segmentation settings, a TOML or JSON file with any subset of the library's
    /// `PlaneConfig` fields (the others keep their defaults).
    #[arg(long, value_name = "FILE")]
    planes_config: Option<PathBuf>,
    /// Passes a wall round makes after its two, towards the fit that no longer depends on
    /// the drawn triple (overrides the settings; default 2, at most 100).
    #[arg(long, value_name = "N")]
    wall_refits: Option<usize>,
    /// Keep every building-scale vertical piece as a wall: the facade test (top above the
    /// sensor, RMS, plumb) is off, whatever the settings say. Shows what the test rejects:
    /// vegetation, hedges, car sides.
    #[arg(long)]
    any_vertical: bool,
    /// The vehicle model that Algorithm 1 draws the ego motion from: `ect` (the paper's
    /// extended constant turn), `ct` (constant turn rate and velocity) or `bicycle`
    /// (kinematic bicycle).
    #[arg(long, value_name = "NAME", default_value = "ect")]
    vehicle_model: String,
    /// A parameter of the vehicle model, `NAME=VALUE` (repeatable): `sigma_accel`,
    /// `sigma_turn_accel` (ect, ct); `wheelbase`, `sigma_accel`, `sigma_steer_rate` (bicycle).
    #[arg(long, value_name = "NAME=VALUE")]
    vehicle_param: Vec<String>,
}

/// Source of the ego motion.
#[derive(Copy, Clone, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Ego {
    /// Recorded poses when there are any, lidar odometry otherwise.
    Auto,
    /// The recording's poses (fails without them).
    Recorded,
    /// Lidar odometry (KISS-ICP's recipe) on the recording's scans.
    Lidar,
}

/// Runs the command.
pub fn run(args: Args) -> Result<()> {
    let mut planes: PlaneConfig = match &args.planes_config {
        Some(path) => crate::config_file::read_checked(path, |c: &PlaneConfig| c.validate())?,
        None => Default::default(),
    };
    if let Some(n) = args.wall_refits {
        planes.wall_refits = n;
    }
    if args.any_vertical {
        planes.wall_quality = None;
    }
    let params = crate::config_file::vehicle_params(&args.vehicle_param)?;
    let vehicle = smc_lmb::models::vehicle_model_by_name(&args.vehicle_model, &params)
        .context("--vehicle-model")?;
    let mut config = PlanePredictionConfig {
        planes,
        use_vehicle_model: !args.measured,
        vehicle: smc_lmb::models::SharedVehicleModel(vehicle),
        ..PlanePredictionConfig::default()
    };
    config.validate().context("plane segmentation settings")?;
    let frames = if args.all {
        None
    } else {
        let end = args
            .frame
            .checked_add(1)
            .with_context(|| format!("--frame {} is past any recording", args.frame))?;
        Some(args.frame..end)
    };
    let mut rng = smc_lmb::rng::seeded(args.seed);
    let source = match (&args.drive, &args.odometry, &args.tracking, args.sequence) {
        (Some(dir), _, _, _) => dir.display().to_string(),
        (None, Some(root), _, Some(n)) => format!("{} odometry sequence {n:02}", root.display()),
        (None, None, Some(root), Some(n)) => {
            format!("{} tracking sequence {n:04}", root.display())
        }
        _ => args
            .scans
            .as_ref()
            .map_or_else(String::new, |d| d.display().to_string()),
    };
    if args.scans.is_none() && args.poses.is_some() {
        bail!("--poses goes with --scans DIR (the KITTI layouts bring their own)");
    }
    let input: Box<dyn Recording> = match (&args.drive, &args.odometry, &args.tracking) {
        (Some(dir), _, _) => Box::new(
            RawDrive::open(dir).with_context(|| format!("opening drive {}", dir.display()))?,
        ),
        (None, Some(root), _) => {
            let Some(number) = args.sequence else {
                bail!("--odometry needs --sequence");
            };
            Box::new(OdometrySequence::open(root, number).with_context(|| {
                format!(
                    "opening odometry sequence {number:02} of {}",
                    root.display()
                )
            })?)
        }
        (None, None, Some(root)) => {
            let Some(number) = args.sequence else {
                bail!("--tracking needs --sequence");
            };
            Box::new(TrackingSequence::open(root, number).with_context(|| {
                format!(
                    "opening tracking sequence {number:04} of {}",
                    root.display()
                )
            })?)
        }
        (None, None, None) => match &args.scans {
            Some(dir) => RecordingSource::Scans {
                dir: dir.clone(),
                poses: args.poses.clone(),
                times: None,
                sensor_height: None,
            }
            .open()?,
            None => bail!(
                "give --drive DIR, --odometry ROOT --sequence NN, --tracking ROOT --sequence \
                 NNNN or --scans DIR"
            ),
        },
    };
    // Algorithm 1 needs the vehicle's measured motion; other recordings use the poses.
    config.use_vehicle_model &= input.has_vehicle();
    let lidar = match args.ego {
        Ego::Lidar => true,
        Ego::Recorded => false,
        Ego::Auto => !input.has_poses(),
    };
    let ego_line = if lidar {
        "ego motion: lidar odometry on the scans (measured motion)".to_string()
    } else if !config.use_vehicle_model {
        "ego motion: recorded poses (measured motion)".to_string()
    } else {
        let model = match args.vehicle_model.as_str() {
            "ect" => "ECT".to_string(),
            other => other.to_string(),
        };
        format!(
            "ego motion: vehicle model ({model}, {} Monte-Carlo runs) from the recorded OXTS states",
            args.runs
        )
    };
    let results: Vec<PairPrediction> = if lidar {
        let count = input.frame_count();
        let end = frames
            .as_ref()
            .map_or(count, |r| r.end.saturating_add(1).min(count));
        let poses = smc_lmb::cloud::odometry::odometry_of_frames_with(
            end,
            &|k| input.has_scan(k),
            &|k| input.scan(k),
            &smc_lmb::cloud::odometry::OdometryConfig::default(),
        )
        .with_context(|| format!("lidar odometry on {source}"))?;
        let frames = frames.unwrap_or(0..end.saturating_sub(1));
        smc_lmb::pipeline::plane_prediction::predict_pairs_with_poses(
            frames,
            &|k| input.has_scan(k),
            &|k| input.scan(k),
            &poses,
            &source,
            &config,
            args.runs,
            &mut rng,
        )
        .with_context(|| format!("predicting planes of {source}"))?
    } else {
        predict_pairs(&*input, frames, &config, args.runs, &mut rng)
            .with_context(|| format!("predicting planes of {}", input.describe()))?
    };
    if args.paper {
        println!("{ego_line}");
        for r in &results {
            paper_tables::print(r, args.runs, paper_tables::reference_for(&source, r.frame));
        }
        return Ok(());
    }
    let (pairs, summary) = pairs_and_summary(&results);
    if args.json {
        let out = serde_json::json!({
            "ego": ego_line,
            "pairs": pairs,
            "summary": {
                "median_normal_angle_deg": summary.median_normal_angle_deg,
                "p90_normal_angle_deg": summary.p90_normal_angle_deg,
                "median_vertex_distance_m": summary.median_vertex_distance_m,
                "p90_vertex_distance_m": summary.p90_vertex_distance_m,
                "mean_prediction_ms": summary.mean_prediction_ms,
                "pairs": summary.pairs,
            },
        });
        println!("{}", serde_json::to_string_pretty(&out)?);
        return Ok(());
    }
    println!("{ego_line}");
    print_pairs(&results);
    if args.all {
        print_summary(&summary, results.len());
    }
    Ok(())
}

/// Prints one row per associated wall pair, like seed 001's Tables 1–6.
pub fn print_pairs(results: &[PairPrediction]) {
    println!(
        "{:>6} {:>10} {:>10} {:>8} {:>8} {:>8} {:>8} {:>9} {:>8} {:>9}",
        "frame",
        "pred m²",
        "seg m²",
        "v1 m",
        "v2 m",
        "v3 m",
        "v4 m",
        "angle rad",
        "angle °",
        "pred ms"
    );
    for r in results {
        if r.pairs.is_empty() {
            println!(
                "{:>6} (no associated walls: {} predicted, {} segmented)",
                r.frame, r.predicted, r.segmented
            );
        }
        for p in &r.pairs {
            let [a, b, c, d] = p.vertex_distances;
            println!(
                "{:>6} {:>10.2} {:>10.2} {:>8.4} {:>8.4} {:>8.4} {:>8.4} {:>9.5} {:>8.3} {:>9.4}",
                p.frame,
                p.predicted_area,
                p.segmented_area,
                a,
                b,
                c,
                d,
                p.normal_angle_rad,
                p.normal_angle_deg,
                r.mean_prediction_ms()
            );
        }
    }
}

/// Prints the distribution over all pairs.
pub fn print_summary(summary: &PlanePredictionSummary, frame_pairs: usize) {
    println!(
        "{} pairs over {frame_pairs} frame pairs: normal angle median {:.3}° p90 {:.3}°, vertex \
         distance median {:.3} m p90 {:.3} m, prediction {:.4} ms",
        summary.pairs,
        summary.median_normal_angle_deg,
        summary.p90_normal_angle_deg,
        summary.median_vertex_distance_m,
        summary.p90_vertex_distance_m,
        summary.mean_prediction_ms
    );
}

/// Every associated wall pair of `results` and their distribution.
pub fn pairs_and_summary(
    results: &[PairPrediction],
) -> (Vec<PlanePairError>, PlanePredictionSummary) {
    let pairs: Vec<PlanePairError> = results.iter().flat_map(|r| r.pairs.clone()).collect();
    let timings: Vec<f64> = results
        .iter()
        .flat_map(|r| r.prediction_ms.iter().copied())
        .collect();
    let summary = PlanePredictionSummary::from_pairs(&pairs, &timings);
    (pairs, summary)
}
