//! `kitti-tools planes`: segment building walls in consecutive Velodyne frames, predict them
//! one frame ahead and print the errors the way seed 001 reports them (areas, vertex
//! distances, normal angle, prediction time).

use crate::paper_tables;
use anyhow::{bail, Context, Result};
use smc_lmb::kitti::{OdometrySequence, RawDrive, TrackingSequence};
use smc_lmb::metrics::{PlanePairError, PlanePredictionSummary};
use smc_lmb::pipeline::{
    predict_drive_pairs, predict_odometry_pairs, predict_tracking_pairs, PairPrediction,
    PlanePredictionConfig,
};
use std::path::PathBuf;

/// Flags of `planes`.
#[derive(clap::Args)]
pub struct Args {
    /// A KITTI raw drive folder (`.../2011_09_26/2011_09_26_drive_0001_sync`).
    #[arg(long, conflicts_with_all = ["odometry", "tracking"])]
    drive: Option<PathBuf>,
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
    /// Use the measured poses instead of the vehicle motion model (raw drives and tracking
    /// sequences).
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
}

/// Runs the command.
pub fn run(args: Args) -> Result<()> {
    let config = PlanePredictionConfig {
        use_vehicle_model: !args.measured,
        ..PlanePredictionConfig::default()
    };
    let frames = if args.all {
        None
    } else {
        Some(args.frame..args.frame + 1)
    };
    let mut rng = smc_lmb::rng::seeded(args.seed);
    let source = match (&args.drive, &args.odometry, &args.tracking, args.sequence) {
        (Some(dir), _, _, _) => dir.display().to_string(),
        (None, Some(root), _, Some(n)) => format!("{} odometry sequence {n:02}", root.display()),
        (None, None, Some(root), Some(n)) => {
            format!("{} tracking sequence {n:04}", root.display())
        }
        _ => String::new(),
    };
    let results: Vec<PairPrediction> = match (&args.drive, &args.odometry, &args.tracking) {
        (Some(dir), _, _) => {
            let drive =
                RawDrive::open(dir).with_context(|| format!("opening drive {}", dir.display()))?;
            predict_drive_pairs(&drive, frames, &config, args.runs, &mut rng)
                .with_context(|| format!("predicting planes of drive {}", dir.display()))?
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
            predict_odometry_pairs(&seq, frames, &config, args.runs, &mut rng).with_context(
                || {
                    format!(
                        "predicting planes of odometry sequence {number:02} of {}",
                        root.display()
                    )
                },
            )?
        }
        (None, None, Some(root)) => {
            let Some(number) = args.sequence else {
                bail!("--tracking needs --sequence");
            };
            let what = format!("tracking sequence {number:04} of {}", root.display());
            let seq =
                TrackingSequence::open(root, number).with_context(|| format!("opening {what}"))?;
            predict_tracking_pairs(&seq, frames, &config, args.runs, &mut rng)
                .with_context(|| format!("predicting planes of {what}"))?
        }
        (None, None, None) => bail!(
            "give --drive DIR, --odometry ROOT --sequence NN or --tracking ROOT --sequence NNNN"
        ),
    };
    if args.paper {
        for r in &results {
            paper_tables::print(r, args.runs, paper_tables::reference_for(&source, r.frame));
        }
        return Ok(());
    }
    let (pairs, summary) = pairs_and_summary(&results);
    if args.json {
        let out = serde_json::json!({
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
