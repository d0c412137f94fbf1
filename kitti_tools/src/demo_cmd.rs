//! `kitti-tools demo`: the whole 3-D pipeline on a simulated street, with nothing to download.
//! Writes the street as a KITTI raw drive (once; later runs reuse it), predicts every frame's
//! walls to the next frame and prints the plane-prediction table of the first frame pair and
//! the distribution over all pairs, tracks walls and clusters through the drive with one LMB
//! filter, and scores the tracks against the street's truth.

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use smc_lmb::kitti::RawDrive;
use smc_lmb::pipeline::drive_evaluation::{evaluate_recording, Evaluation, EvaluationOptions};
use smc_lmb::pipeline::drive_tracking::drive_plot;
use smc_lmb::pipeline::{predict_pairs, track_recording, PlanePredictionConfig, TrackingConfig};
use smc_lmb::sim::street::{write_drive, StreetConfig, TRUTH_FILE};
use std::path::PathBuf;
use std::time::Instant;

/// Flags of `demo`.
#[derive(clap::Args)]
pub struct Args {
    /// Where the simulated drive is written (reused when it is already there).
    #[arg(long, default_value = "target/demo-drive")]
    dir: PathBuf,
    /// Frames of the drive (10 Hz).
    #[arg(long, default_value_t = 40)]
    frames: usize,
    /// Seed of the street and of the filter.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Monte-Carlo runs of the ECT plane prediction.
    #[arg(long, default_value_t = 10)]
    runs: usize,
    /// No progress bars.
    #[arg(long)]
    quiet: bool,
}

fn bar(quiet: bool, len: usize, what: &str) -> ProgressBar {
    let bar = if quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(len as u64)
    };
    bar.set_style(
        ProgressStyle::with_template(&format!("{{bar:40}} {{pos}}/{{len}} {what} {{elapsed}}"))
            .expect("valid template"),
    );
    bar
}

/// FNV-1a hash of `text`: the same on every run and machine.
fn fingerprint(text: &str) -> u64 {
    text.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ b as u64).wrapping_mul(0x0100_0000_01b3)
    })
}

/// Runs the command.
pub fn run(args: Args) -> Result<()> {
    anyhow::ensure!(args.frames >= 2, "--frames must be at least 2");
    let config = StreetConfig::default();
    // The folder is keyed by the street's configuration too, so that a drive simulated by an
    // older street model is not reused for a newer one.
    let root = args.dir.join(format!(
        "seed{}-frames{}-{:016x}",
        args.seed,
        args.frames,
        fingerprint(&serde_json::to_string(&config)?)
    ));
    let dir = root.join(&config.recording.date).join(config.drive_name());
    if !dir.join(TRUTH_FILE).is_file() {
        let b = bar(args.quiet, args.frames, "frames simulated");
        let t = Instant::now();
        write_drive(&root, &config, args.frames, args.seed, |k| {
            b.set_position(k as u64 + 1)
        })
        .with_context(|| format!("writing the simulated drive under {}", root.display()))?;
        b.finish_and_clear();
        println!(
            "simulated street written to {} ({} frames, {:.1} s)",
            dir.display(),
            args.frames,
            t.elapsed().as_secs_f64()
        );
    } else {
        println!("reusing the simulated street in {}", dir.display());
    }
    let drive = RawDrive::open(&dir).with_context(|| format!("opening {}", dir.display()))?;

    // Plane prediction, seed 001 Sec. 5: frame k's walls moved to k + 1 by ECT Monte Carlo.
    println!(
        "\nplane prediction k → k+1 (ECT vehicle model, {} Monte-Carlo runs); first frame pair:",
        args.runs
    );
    let mut rng = smc_lmb::rng::seeded(args.seed);
    let results = predict_pairs(
        &drive,
        None,
        &PlanePredictionConfig::default(),
        args.runs,
        &mut rng,
    )?;
    crate::planes_cmd::print_pairs(&results[..1]);
    print!("all frame pairs: ");
    crate::planes_cmd::print_summary(
        &crate::planes_cmd::pairs_and_summary(&results).1,
        results.len(),
    );

    // Tracking: walls and clusters as labelled objects of one filter run.
    println!("\ntracking walls and clusters (one LMB filter, up to 1000 particles per track):");
    let b = bar(args.quiet, drive.frame_count(), "frames tracked");
    let tracks = track_recording(
        &drive,
        None,
        &TrackingConfig::default(),
        args.seed,
        |view| {
            b.set_position(view.progress.0 as u64);
            Ok(())
        },
    )?;
    b.finish_and_clear();
    crate::track_cmd::print_summary(&tracks);
    let out = root.join("tracks.json");
    tracks.write_json(&out)?;
    let plot = root.join("tracks.svg");
    drive_plot(&tracks).write(&plot, 1000)?;
    println!("wrote {} and {}", out.display(), plot.display());

    // Scores against the street's truth.
    println!();
    let Evaluation {
        clusters, walls, ..
    } = evaluate_recording(&tracks, &drive, &EvaluationOptions::default())?;
    crate::eval_cmd::print_evaluation(&tracks.drive, &clusters, walls.as_ref());
    Ok(())
}
