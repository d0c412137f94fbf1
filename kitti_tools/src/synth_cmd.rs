//! `kitti-tools synth`: simulate a street drive (HDL-64E-like lidar, OXTS, walls, cars,
//! pedestrians) and write it in the KITTI raw layout with `truth.json`.

use anyhow::{bail, Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use smc_lmb::sim::street::{write_drive, ObjectKind, StreetConfig};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Flags of `synth`.
#[derive(clap::Args)]
pub struct Args {
    /// Output root; the drive goes to OUT/DATE/DATE_drive_NNNN_sync.
    #[arg(long)]
    out: PathBuf,
    /// Number of frames (10 per second by default).
    #[arg(long, default_value_t = 50)]
    frames: usize,
    /// Random seed (scene and lidar noise).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Street configuration (.toml or .json); defaults for everything not given.
    #[arg(long)]
    config: Option<PathBuf>,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
}

/// Reads a TOML or JSON street configuration, naming the file and line of any problem.
fn read_config(path: &Path) -> Result<StreetConfig> {
    let config: StreetConfig = crate::config_file::read_config(path)?;
    config
        .validate()
        .with_context(|| format!("checking {}", path.display()))?;
    Ok(config)
}

/// Runs the command.
pub fn run(args: Args) -> Result<()> {
    if args.frames == 0 {
        bail!("--frames must be at least 1");
    }
    let config = match &args.config {
        Some(path) => read_config(path)?,
        None => StreetConfig::default(),
    };
    let bar = if args.quiet {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(args.frames as u64)
    };
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} frames {elapsed}")
            .expect("valid template"),
    );
    let started = Instant::now();
    let drive = write_drive(&args.out, &config, args.frames, args.seed, |_| bar.inc(1))
        .with_context(|| format!("writing a simulated drive under {}", args.out.display()))?;
    bar.finish_and_clear();
    let seconds = started.elapsed().as_secs_f64();
    let truth = &drive.truth;
    let points: usize = truth.frames.iter().map(|f| f.points).sum();
    let count = |kind: ObjectKind| truth.objects.iter().filter(|o| o.kind == kind).count();
    let last = truth.frames.last().map(|f| f.ego).unwrap_or_default();
    let first = truth.frames[0].ego;
    println!("drive    {}", drive.dir.display());
    println!("truth    {}", drive.dir.join("truth.json").display());
    println!(
        "frames   {} ({:.1} s), {:.0} points per frame on average",
        truth.frames.len(),
        last.time,
        points as f64 / truth.frames.len() as f64
    );
    println!(
        "scene    {} walls, {} parked cars, {} moving cars, {} pedestrians",
        truth.walls.len(),
        count(ObjectKind::ParkedCar),
        count(ObjectKind::Car),
        count(ObjectKind::Pedestrian)
    );
    println!(
        "ego      {:.1} m/s, heading {:.1}° → {:.1}°",
        config.speed,
        first.yaw.to_degrees(),
        last.yaw.to_degrees()
    );
    println!(
        "time     {seconds:.2} s ({:.0} ms per frame)",
        1e3 * seconds / truth.frames.len() as f64
    );
    Ok(())
}
