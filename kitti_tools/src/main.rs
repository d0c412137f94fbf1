//! `kitti-tools`: the command-line face of smc-lmb. Each subcommand parses its flags, builds a
//! configuration and calls the library; no pipeline lives here.

mod batch_cmd;
mod config_file;
mod convert_cmd;
mod demo_cmd;
mod detections_cmd;
mod eval_cmd;
mod info_cmd;
mod objects_cmd;
mod odometry_cmd;
mod paper_tables;
mod planes_cmd;
mod recording;
mod synth_cmd;
mod track_cmd;
mod tracking_eval_cmd;

use anyhow::Result;
use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "kitti-tools",
    version,
    about = "Labelled multi-Bernoulli tracking tools"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// The whole 3-D pipeline on a simulated street (nothing to download): simulate a KITTI
    /// drive, predict its walls frame to frame, track walls and clusters, score the tracks.
    Demo(demo_cmd::Args),
    /// Run the filter on your own per-frame detections (JSON or CSV) with a model config
    /// (TOML or JSON); write per-frame estimates and, given truth, print OSPA/GOSPA.
    Detections(detections_cmd::Args),
    /// Convert a point cloud between KITTI .bin, .las, .ply and .pcd (by extension).
    Convert(convert_cmd::Args),
    /// Describe a KITTI raw drive or tracking sequence: frame counts, time span, calibration,
    /// poses, labels, issues.
    Info(info_cmd::Args),
    /// Lidar odometry (KISS-ICP's recipe) over the scans of a drive, an odometry sequence or
    /// a folder of .bin files; write KITTI poses and, given a reference, print the errors.
    Odometry(odometry_cmd::Args),
    /// Segment building walls in consecutive Velodyne frames of a drive, odometry or tracking
    /// sequence, predict them one frame ahead and print area, vertex and normal errors.
    Planes(planes_cmd::Args),
    /// Simulate a street drive (lidar, OXTS, walls, cars, pedestrians) in the KITTI raw
    /// layout with a ground-truth JSON, or in the tracking layout with `label_02` truth.
    Synth(synth_cmd::Args),
    /// Track building walls and point clusters of a KITTI raw drive, tracking sequence or
    /// odometry sequence with one labelled multi-Bernoulli filter; write per-frame tracks
    /// (JSON), labelled clouds and a plot.
    Track(Box<track_cmd::Args>),
    /// Track many recordings (a list file or a folder of raw drives), each into its own
    /// folder, resumably (recordings already tracked are skipped), with one summary table.
    Batch(batch_cmd::Args),
    /// Score the output of `track` against ground truth (a simulated street's truth.json,
    /// KITTI tracklets or a tracking sequence's label_02): OSPA, GOSPA and label switches of
    /// the clusters, wall accuracy, and optionally the recording's plane-prediction
    /// statistics.
    Eval(eval_cmd::Args),
    /// Score the tracker's road-user detector on single labelled frames of KITTI's 3-D object
    /// benchmark: recall of cars and vans by occlusion level and range, precision, and
    /// KITTI's bird's-eye average precision for Car (40 and 11 recall points, IoU 0.5 and 0.7).
    Objects(objects_cmd::Args),
}

/// Writing to a closed pipe (`kitti-tools planes --all … | head`) ends the process quietly, as
/// it does for other Unix tools, instead of a panic in `println!`: Rust ignores SIGPIPE and
/// turns the failed write into an error that `println!` cannot return. Outputs are written to
/// a temporary file and renamed, so an interrupted command leaves no half-written file.
fn restore_default_sigpipe() {
    #[cfg(unix)]
    // SAFETY: called first thing in `main`, before any thread exists; SIG_DFL is a valid
    // disposition for SIGPIPE.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

fn main() -> Result<()> {
    restore_default_sigpipe();
    match Cli::parse().command {
        Command::Demo(args) => demo_cmd::run(args),
        Command::Detections(args) => detections_cmd::run(args),
        Command::Convert(args) => convert_cmd::run(args),
        Command::Info(args) => info_cmd::run(args),
        Command::Odometry(args) => odometry_cmd::run(args),
        Command::Planes(args) => planes_cmd::run(args),
        Command::Synth(args) => synth_cmd::run(args),
        Command::Track(args) => track_cmd::run(*args),
        Command::Batch(args) => batch_cmd::run(args),
        Command::Eval(args) => eval_cmd::run(args),
        Command::Objects(args) => objects_cmd::run(args),
    }
}
