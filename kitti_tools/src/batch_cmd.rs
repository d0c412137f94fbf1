//! `kitti-tools batch`: one tracking run per recording of a list (raw drives, tracking or
//! odometry sequences), each into its own folder `OUT/NAME/`, and one summary table.
//!
//! Resumable: a recording whose `tracks.json` is already there (and reads as a tracking
//! output) is skipped, so a batch that was stopped is run again with the same command. Every
//! file is written atomically and `tracks.json` last, so a stopped run leaves no output that
//! looks finished. A recording that fails is reported in the table with its error and the
//! others go on; the command then exits with an error. Every recording is tracked with the same
//! seed, so its output does not depend on its place in the list.
//!
//! Not for: running recordings on several machines (each `batch` is one process; split the
//! list to spread it).

use crate::config_file::tracking_config;
use crate::recording::{read_list, track, Recording};
use anyhow::{bail, Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use smc_lmb::pipeline::drive_tracking::{drive_plot, DriveTracks, FrameView, TrackingConfig};
use std::path::{Path, PathBuf};

/// Flags of `batch`.
#[derive(clap::Args)]
pub struct Args {
    /// The recordings: a text file with one per line (a raw drive folder, `tracking ROOT NNNN`,
    /// `odometry ROOT NN` or `scans DIR [POSES [TIMES]]`; relative paths from the file's
    /// folder; `#` comments), or a
    /// folder whose raw drives (subfolders with `velodyne_points/`) are all taken.
    #[arg(long)]
    drives: PathBuf,
    /// Output folder: `OUT/NAME/tracks.json` (and `tracks.png` with `--plot`) per recording,
    /// `OUT/summary.tsv` for the whole batch.
    #[arg(long)]
    out: PathBuf,
    /// Models and tuning (.toml or .json), the same for every recording; see `TrackingConfig`.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Particles per track (overrides the config).
    #[arg(long)]
    particles: Option<usize>,
    /// Random seed of every run.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Also draw each recording's bird's-eye plot (`tracks.png`).
    #[arg(long)]
    plot: bool,
    /// Track every recording again, even those whose output is there.
    #[arg(long)]
    force: bool,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
}

/// What became of one recording.
enum Outcome {
    /// Tracked in this run.
    Tracked(DriveTracks),
    /// Its output was already there.
    Skipped(DriveTracks),
    /// Tracking or writing failed.
    Failed(String),
}

/// Runs the command.
pub fn run(args: Args) -> Result<()> {
    let config = tracking_config(args.config.as_deref(), args.particles)?;
    config
        .validate()
        .context("the tracking configuration is not valid")?;
    let recordings = read_list(&args.drives)?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let bar = if args.quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(recordings.len() as u64)
    };
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} recordings {elapsed} {msg}")
            .expect("valid template"),
    );
    let mut rows = Vec::with_capacity(recordings.len());
    for rec in &recordings {
        let dir = args.out.join(rec.name());
        let outcome = match done_before(&dir, args.plot).filter(|_| !args.force) {
            Some(tracks) => Outcome::Skipped(tracks),
            None => match track_one(rec, &dir, &config, &args, &bar) {
                Ok(tracks) => Outcome::Tracked(tracks),
                Err(e) => Outcome::Failed(format!("{e:#}")),
            },
        };
        bar.inc(1);
        rows.push((rec.name(), outcome));
    }
    bar.finish_and_clear();
    let table = summary_table(&rows);
    print!("{table}");
    let summary = args.out.join("summary.tsv");
    smc_lmb::atomic::write_bytes(&summary, table.as_bytes())
        .with_context(|| format!("writing {}", summary.display()))?;
    println!("wrote {}", summary.display());
    let failed = rows
        .iter()
        .filter(|(_, o)| matches!(o, Outcome::Failed(_)))
        .count();
    if failed > 0 {
        bail!(
            "{failed} of {} recordings failed (see the table above)",
            rows.len()
        );
    }
    Ok(())
}

/// The output of an earlier run in `dir`, when there is a readable one (and its plot, when
/// one is asked for).
fn done_before(dir: &Path, plot: bool) -> Option<DriveTracks> {
    let path = dir.join("tracks.json");
    let complete = path.is_file() && (!plot || dir.join("tracks.png").is_file());
    complete
        .then(|| DriveTracks::read_json(&path).ok())
        .flatten()
}

/// Tracks one recording into `dir`: the plot first, `tracks.json` last.
fn track_one(
    rec: &Recording,
    dir: &Path,
    config: &TrackingConfig,
    args: &Args,
    bar: &ProgressBar,
) -> Result<DriveTracks> {
    let name = rec.name();
    bar.set_message(name.clone());
    let on_frame = |view: &FrameView<'_>| -> smc_lmb::Result<()> {
        let (done, total) = view.progress;
        bar.set_message(format!("{name}: frame {done}/{total}"));
        Ok(())
    };
    let tracks = track(rec, None, config, args.seed, on_frame)?;
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    if args.plot {
        drive_plot(&tracks).write(&dir.join("tracks.png"), 1000)?;
    }
    tracks.write_json(&dir.join("tracks.json"))?;
    Ok(tracks)
}

/// The batch as a tab-separated table with a header line.
fn summary_table(rows: &[(String, Outcome)]) -> String {
    let mut out = String::from(
        "recording\tstatus\tframes\tego\twalls/frame\tclusters/frame\tms/frame\todometry ms/frame\tnote\n",
    );
    for (name, outcome) in rows {
        let line = match outcome {
            Outcome::Tracked(t) | Outcome::Skipped(t) => {
                let (status, note) = match outcome {
                    Outcome::Skipped(_) => ("skipped", "output already there"),
                    _ => ("tracked", ""),
                };
                let s = &t.summary;
                format!(
                    "{name}\t{status}\t{}\t{}\t{:.2}\t{:.2}\t{:.1}\t{:.1}\t{note}",
                    s.frames,
                    t.ego,
                    s.mean_planes,
                    s.mean_clusters,
                    s.mean_times.total_ms(),
                    s.mean_times.ego_ms
                )
            }
            Outcome::Failed(e) => {
                let e = e.replace(['\t', '\n'], " ");
                format!("{name}\tfailed\t\t\t\t\t\t\t{e}")
            }
        };
        out.push_str(&line);
        out.push('\n');
    }
    out
}
