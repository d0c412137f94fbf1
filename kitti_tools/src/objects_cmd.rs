//! `kitti-tools objects`: the tracker's road-user detector scored on single labelled frames of
//! KITTI's 3-D object benchmark layout (`training/` with `velodyne/`, `label_2/`, `calib/`):
//! recall of the labelled cars and vans by occlusion level and range, precision of the
//! detections reported as vehicles, and KITTI's bird's-eye average precision for Car.

use crate::config_file::tracking_config;
use crate::eval_cmd::{print_levels_and_ranges, ratio};
use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use smc_lmb::kitti::object::ObjectFrames;
use smc_lmb::pipeline::object_frame_eval::{
    evaluate_object_frames, ObjectEvalConfig, ObjectFrameReport, Tally, RANGE_BINS,
};
use std::path::PathBuf;

/// Flags of `objects`.
#[derive(clap::Args)]
pub struct Args {
    /// A KITTI object split folder (`.../training`, holding `velodyne/`, `label_2/`,
    /// `calib/`).
    #[arg(long)]
    root: PathBuf,
    /// Frames to score, `A..B` (B excluded); default every frame with a scan.
    #[arg(long)]
    frames: Option<String>,
    /// A tracking configuration (TOML or JSON) whose detector settings are used.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Labelled cars and vans count for recall within this range of the sensor (m).
    #[arg(long, default_value_t = 40.0)]
    within: f64,
    /// Random seed of the segmentation.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Print one JSON object.
    #[arg(long)]
    json: bool,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
}

fn print_report(r: &ObjectFrameReport, root: &std::path::Path, within: f64) {
    println!(
        "road-user detector on {} object frames of {}",
        r.frames,
        root.display()
    );
    println!(
        "cars and vans within {within} m found (box centres within 2 m): {}",
        ratio(&r.recall)
    );
    println!(
        "  by a cluster of any class (what the segmentation finds): {}",
        ratio(&r.cluster_recall)
    );
    print_levels_and_ranges(&r.recall_by_occlusion, &r.recall_by_range);
    println!(
        "detections reported as vehicles within {within} m that are cars or vans: {}",
        ratio(&r.precision)
    );
    println!("bird's-eye AP for Car (KITTI, 40 / 11 recall points):");
    println!("  IoU   difficulty   AP_R40   AP_R11   cars counted");
    for row in &r.bev_ap {
        println!(
            "  {:.1}   {:<10}   {:>6.2}   {:>6.2}   {}",
            row.min_iou,
            format!("{:?}", row.difficulty).to_lowercase(),
            100.0 * row.ap.ap_r40,
            100.0 * row.ap.ap_r11,
            row.ap.truth_count
        );
    }
}

fn json_report(r: &ObjectFrameReport) -> serde_json::Value {
    let tally =
        |t: &Tally| serde_json::json!({"hits": t.hits, "total": t.total, "ratio": t.ratio()});
    serde_json::json!({
        "frames": r.frames,
        "recall": tally(&r.recall),
        "cluster_recall": tally(&r.cluster_recall),
        "recall_by_occlusion": r.recall_by_occlusion.iter().map(tally).collect::<Vec<_>>(),
        "recall_by_range": r.recall_by_range.iter().map(tally).collect::<Vec<_>>(),
        "range_bins_m": RANGE_BINS,
        "precision": tally(&r.precision),
        "bev_ap_car": r.bev_ap.iter().map(|row| serde_json::json!({
            "min_iou": row.min_iou,
            "difficulty": format!("{:?}", row.difficulty).to_lowercase(),
            "ap_r40": row.ap.ap_r40,
            "ap_r11": row.ap.ap_r11,
            "cars_counted": row.ap.truth_count,
        })).collect::<Vec<_>>(),
        "misses": r.misses.iter().map(|m| serde_json::json!({
            "frame": m.frame,
            "type": format!("{:?}", m.object_type),
            "occluded": m.occluded,
            "range_m": m.range,
            "nearest": m.nearest.map(|(d, class, points)| serde_json::json!({
                "distance_m": d, "class": class.name(), "points": points,
            })),
        })).collect::<Vec<_>>(),
    })
}

/// Runs `objects`.
pub fn run(args: Args) -> Result<()> {
    let frames = ObjectFrames::open(&args.root)?;
    let ks = match &args.frames {
        Some(s) => crate::track_cmd::parse_range(s)?.collect(),
        None => frames
            .frames()
            .with_context(|| format!("listing the scans of {}", args.root.display()))?,
    };
    let config = ObjectEvalConfig {
        tracking: tracking_config(args.config.as_deref(), None)?,
        within: args.within,
        seed: args.seed,
        ..ObjectEvalConfig::default()
    };
    let bar = if args.quiet || args.json {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(ks.len() as u64)
    };
    bar.set_style(
        ProgressStyle::with_template("{bar:30} {pos}/{len} frames {msg}")
            .expect("a valid template"),
    );
    let report = evaluate_object_frames(&frames, Some(&ks), &config, |k| {
        bar.set_message(format!("{k:06}"));
        bar.inc(1);
    })
    .with_context(|| format!("scoring the detector on {}", args.root.display()))?;
    bar.finish_and_clear();
    if args.json {
        println!("{}", serde_json::to_string_pretty(&json_report(&report))?);
    } else {
        print_report(&report, &args.root, args.within);
    }
    Ok(())
}
