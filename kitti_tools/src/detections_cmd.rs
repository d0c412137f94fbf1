//! `kitti-tools detections`: the filter on a user's detections file.

use anyhow::{bail, Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use nalgebra::{Isometry3, Vector3};
use smc_lmb::config::{RunConfig, TransitionConfig};
use smc_lmb::detections::{
    filter_frames, read_frames, read_frames_with, write_estimates, DetectionFrame, EstimateFrame,
    NonFinite,
};
use smc_lmb::filter::{Frame, Measurements};
use smc_lmb::metrics::{gospa, ospa, LabelConsistency};
use std::path::{Path, PathBuf};

/// Flags of `detections`.
#[derive(clap::Args)]
pub struct Args {
    /// Per-frame detections (.json or .csv; format in the README).
    #[arg(long)]
    input: PathBuf,
    /// Models and tuning (.toml or .json).
    #[arg(long)]
    config: PathBuf,
    /// Where to write the per-frame estimates (.json or .csv); written atomically.
    #[arg(long)]
    output: PathBuf,
    /// Optional truth file of the same shape as the input (positions, optional ids).
    #[arg(long)]
    truth: Option<PathBuf>,
    /// OSPA/GOSPA cut-off c (m).
    #[arg(long, default_value_t = 10.0)]
    cutoff: f64,
    /// OSPA/GOSPA order p.
    #[arg(long, default_value_t = 1.0)]
    order: f64,
    /// Leave out measurement rows holding NaN or infinities (CSV) instead of refusing the file.
    #[arg(long)]
    skip_invalid: bool,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
}

/// Reads a TOML or JSON run configuration, naming the file and line of any problem.
pub fn read_config(path: &Path) -> Result<RunConfig> {
    crate::config_file::read_config(path)
}

fn positions(config: &RunConfig) -> Vec<usize> {
    match config.transition {
        TransitionConfig::ConstantVelocity { dims: 3, .. } => vec![0, 2, 4],
        _ => vec![0, 2],
    }
}

/// Runs the command.
pub fn run(args: Args) -> Result<()> {
    let config = read_config(&args.config)?;
    let mut filter = config
        .build()
        .with_context(|| format!("config {}", args.config.display()))?;
    let policy = if args.skip_invalid {
        NonFinite::Skip
    } else {
        NonFinite::Error
    };
    let (entries, skipped) = read_frames_with(&args.input, policy)?;
    if skipped > 0 {
        eprintln!("skipped {skipped} measurement row(s) with NaN or infinite values");
    }
    let groups = filter_frames(&entries);
    let frames: Vec<&[DetectionFrame]> = groups.iter().map(|r| &entries[r.clone()]).collect();
    let truth = match &args.truth {
        Some(p) => {
            let t = read_frames(p)?;
            if t.len() != frames.len() {
                bail!(
                    "{}: {} frames, the input has {}",
                    p.display(),
                    t.len(),
                    frames.len()
                );
            }
            Some(t)
        }
        None => None,
    };
    let bar = if args.quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(frames.len() as u64)
    };
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} frames {elapsed}")
            .expect("valid template"),
    );
    let mut rng = smc_lmb::rng::seeded(config.seed);
    let pos = positions(&config);
    let mut out = Vec::with_capacity(frames.len());
    let (mut ospa_sum, mut gospa_sum) = (0.0, 0.0);
    let mut labels = LabelConsistency::new(args.cutoff)?;
    let multi = !config.sensors.is_empty();
    for (k, group) in frames.iter().enumerate() {
        let f = &group[0];
        let mut frame = Frame::at_time(f.time);
        for entry in group.iter() {
            let dim = entry.measurements.first().map_or(0, |m| m.len());
            let z = Measurements::from_rows(dim, &entry.measurements)
                .with_context(|| format!("{} frame {k}", args.input.display()))?;
            let sensor = match (&entry.sensor, multi) {
                (None, false) => 0,
                // A frame no sensor reported in (a gap in the frame numbers).
                (None, true) if z.is_empty() => continue,
                (None, true) => bail!(
                    "{}: frame {k} (time {}) names no sensor, but the config has {} sensors; \
                     give each line (entry) its sensor",
                    args.input.display(),
                    entry.time,
                    config.sensors.len()
                ),
                (Some(name), _) => filter.sensor_index(name).with_context(|| {
                    format!(
                        "{}: frame {k} (time {}) names sensor {name:?}, which the config {} \
                         does not define (its sensors: {})",
                        args.input.display(),
                        entry.time,
                        args.config.display(),
                        filter
                            .sensors()
                            .iter()
                            .map(|s| format!("{:?}", s.name()))
                            .collect::<Vec<_>>()
                            .join(", ")
                    )
                })?,
            };
            frame = frame.with_sensor(sensor, z);
        }
        frame.platform = group
            .iter()
            .find_map(|e| e.sensor_pose)
            .map(|[x, y, h]| Isometry3::new(Vector3::new(x, y, 0.0), Vector3::new(0.0, 0.0, h)));
        let estimates = filter
            .step(&frame, &mut rng)
            .with_context(|| format!("{} frame {k}", args.input.display()))?;
        if let Some(t) = &truth {
            let x: Vec<Vec<f64>> = estimates
                .iter()
                .map(|e| pos.iter().map(|&c| e.state[c]).collect())
                .collect();
            let y = &t[k].measurements;
            ospa_sum += ospa(y, &x, args.cutoff, args.order)?.distance;
            gospa_sum += gospa(y, &x, args.cutoff, args.order)?.distance;
            if let Some(ids) = &t[k].ids {
                let tr: Vec<(u64, Vec<f64>)> = ids.iter().copied().zip(y.iter().cloned()).collect();
                let es: Vec<_> = estimates
                    .iter()
                    .zip(&x)
                    .map(|(e, p)| (e.label, p.clone()))
                    .collect();
                labels.add_step(&tr, &es)?;
            }
        }
        out.push(EstimateFrame {
            frame: k,
            time: f.time,
            estimates,
        });
        bar.inc(1);
    }
    bar.finish_and_clear();
    write_estimates(&args.output, &out)?;
    let n_est: usize = out.iter().map(|f| f.estimates.len()).sum();
    println!(
        "{} frames, {} estimates written to {}",
        out.len(),
        n_est,
        args.output.display()
    );
    if truth.is_some() {
        let n = frames.len().max(1) as f64;
        println!(
            "mean OSPA (c = {}, p = {}): {:.3}",
            args.cutoff,
            args.order,
            ospa_sum / n
        );
        println!(
            "mean GOSPA (c = {}, p = {}): {:.3}",
            args.cutoff,
            args.order,
            gospa_sum / n
        );
        let stats = labels.finish();
        if stats.steps > 0 {
            println!(
                "label switches: {}, every object kept one label: {}",
                stats.switches, stats.all_kept
            );
        }
    }
    Ok(())
}
