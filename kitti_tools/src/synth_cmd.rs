//! `kitti-tools synth`: simulate a street drive (HDL-64E-like lidar, OXTS, walls, cars,
//! pedestrians; on the urban street also vans, trucks, cyclists and street clutter) and write
//! it in the KITTI raw layout with `truth.json`, or in the KITTI tracking layout with the road
//! users as `label_02` labels.

use anyhow::{bail, Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use smc_lmb::sim::street::{
    write_drive, write_tracking_sequence, ClutterKind, ObjectKind, StreetConfig, StreetTruth,
};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The folder layouts `synth` writes.
#[derive(Copy, Clone, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Layout {
    /// KITTI raw: OUT/DATE/DATE_drive_NNNN_sync with `truth.json`.
    Raw,
    /// KITTI tracking: OUT/{velodyne/NNNN, oxts, calib, label_02} (OUT is the split folder).
    Tracking,
}

/// The built-in streets.
#[derive(Copy, Clone, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Street {
    /// Cars and pedestrians between building walls (`StreetConfig::default`).
    Plain,
    /// A city street: cars, vans, a truck, cyclists and pedestrians, with poles, tree trunks,
    /// hedges and low walls (`StreetConfig::urban`).
    Urban,
    /// The city street with both kerbs lined by parked cars and vans nose to tail, 0.5–2 m
    /// apart, so that the farther ones along a row are largely hidden
    /// (`StreetConfig::parked_rows`).
    ParkedRows,
}

/// Flags of `synth`.
#[derive(clap::Args)]
pub struct Args {
    /// Output root; the raw layout's drive goes to OUT/DATE/DATE_drive_NNNN_sync, the tracking
    /// layout's sequence to OUT/velodyne/NNNN, OUT/oxts/NNNN.txt, ...
    #[arg(long)]
    out: PathBuf,
    /// Folder layout to write.
    #[arg(long, value_enum, default_value_t = Layout::Raw)]
    layout: Layout,
    /// Sequence number of the tracking layout.
    #[arg(long, default_value_t = 0)]
    sequence: u32,
    /// Number of frames (10 per second by default).
    #[arg(long, default_value_t = 50)]
    frames: usize,
    /// Random seed (scene and lidar noise).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Built-in street [default: `urban` for the tracking layout, which exists to score road
    /// users, `plain` for the raw layout].
    #[arg(long, value_enum)]
    street: Option<Street>,
    /// Street configuration (.toml or .json) over the built-in street: the fields it sets
    /// replace the street's, the others keep them.
    #[arg(long)]
    config: Option<PathBuf>,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
}

/// Reads a TOML or JSON street configuration over `base`, naming the file and line of any
/// problem.
fn read_config(path: &Path, base: &StreetConfig) -> Result<StreetConfig> {
    let config = crate::config_file::read_config_over(path, base)?;
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
    let street = args.street.unwrap_or(match args.layout {
        Layout::Raw => Street::Plain,
        Layout::Tracking => Street::Urban,
    });
    let base = match street {
        Street::Plain => StreetConfig::default(),
        Street::Urban => StreetConfig::urban(),
        Street::ParkedRows => StreetConfig::parked_rows(),
    };
    let config = match &args.config {
        Some(path) => read_config(path, &base)?,
        None => base,
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
    let truth: StreetTruth = match args.layout {
        Layout::Raw => {
            let drive = write_drive(&args.out, &config, args.frames, args.seed, |_| bar.inc(1))
                .with_context(|| {
                    format!("writing a simulated drive under {}", args.out.display())
                })?;
            bar.finish_and_clear();
            println!("drive    {}", drive.dir.display());
            println!("truth    {}", drive.dir.join("truth.json").display());
            drive.truth
        }
        Layout::Tracking => {
            let seq = write_tracking_sequence(
                &args.out,
                &config,
                args.frames,
                args.seed,
                args.sequence,
                |_| bar.inc(1),
            )
            .with_context(|| {
                format!(
                    "writing simulated tracking sequence {:04} under {}",
                    args.sequence,
                    args.out.display()
                )
            })?;
            bar.finish_and_clear();
            let name = format!("{:04}", seq.sequence);
            println!(
                "sequence {name} of {} (--tracking {} --sequence {name})",
                seq.root.display(),
                seq.root.display()
            );
            println!(
                "labels   {} ({} labels)",
                seq.root
                    .join("label_02")
                    .join(format!("{name}.txt"))
                    .display(),
                seq.labels.len()
            );
            seq.truth
        }
    };
    let seconds = started.elapsed().as_secs_f64();
    let truth = &truth;
    let points: usize = truth.frames.iter().map(|f| f.points).sum();
    let count = |kind: ObjectKind| truth.objects.iter().filter(|o| o.kind == kind).count();
    let last = truth.frames.last().map(|f| f.ego).unwrap_or_default();
    let first = truth.frames[0].ego;
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
    let more = count(ObjectKind::ParkedVan)
        + count(ObjectKind::Van)
        + count(ObjectKind::Truck)
        + count(ObjectKind::Cyclist)
        + truth.clutter.len();
    if more > 0 {
        let clutter = |kind: ClutterKind| truth.clutter.iter().filter(|c| c.kind == kind).count();
        println!(
            "         {} parked vans, {} moving vans, {} trucks, {} cyclists; clutter: {} poles, \
             {} tree trunks, {} hedges, {} low walls",
            count(ObjectKind::ParkedVan),
            count(ObjectKind::Van),
            count(ObjectKind::Truck),
            count(ObjectKind::Cyclist),
            clutter(ClutterKind::Pole),
            clutter(ClutterKind::Trunk),
            clutter(ClutterKind::Hedge),
            clutter(ClutterKind::LowWall)
        );
    }
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
