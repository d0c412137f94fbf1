//! `kitti-tools convert`: a point cloud from one file format to another (`.bin`, `.las`,
//! `.ply`, chosen by extension).

use anyhow::{bail, Result};
use smc_lmb::cloud::{
    read_kitti_bin_with, read_las, read_ply, write_kitti_bin, write_las, write_ply, NonFinite,
    PointCloud,
};
use std::path::{Path, PathBuf};

/// Flags of `convert`.
#[derive(clap::Args)]
pub struct Args {
    /// The cloud to read (.bin KITTI Velodyne scan, .las or .ply).
    #[arg(long)]
    input: PathBuf,
    /// Where to write the cloud (.bin, .las or .ply); written atomically.
    #[arg(long)]
    output: PathBuf,
    /// Leave out points holding NaN or infinities instead of refusing the input.
    #[arg(long)]
    skip_invalid: bool,
}

/// The formats `convert` knows.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
enum Format {
    Bin,
    Las,
    Ply,
}

fn format_of(path: &Path) -> Result<Format> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    Ok(match ext.as_str() {
        "bin" => Format::Bin,
        "las" => Format::Las,
        "ply" => Format::Ply,
        other => bail!(
            "{}: unknown point-cloud extension `{other}` (expected .bin, .las or .ply)",
            path.display()
        ),
    })
}

/// Reads `path`, dropping (with `skip_invalid`) or refusing non-finite points; returns the
/// cloud and how many points were dropped.
fn read(path: &Path, skip_invalid: bool) -> Result<(PointCloud, usize)> {
    let mut cloud = match format_of(path)? {
        Format::Bin => {
            let policy = if skip_invalid {
                NonFinite::Skip
            } else {
                NonFinite::Error
            };
            let scan = read_kitti_bin_with(path, policy)?;
            return Ok((scan.cloud, scan.skipped));
        }
        Format::Las => read_las(path)?,
        Format::Ply => read_ply(path)?,
    };
    let before = cloud.len();
    if let Some(i) = cloud.first_non_finite() {
        if !skip_invalid {
            bail!(
                "{}: point {i} has a NaN or infinite value (use --skip-invalid to leave such \
                 points out)",
                path.display()
            );
        }
        cloud.retain(|p| {
            p.x.is_finite() && p.y.is_finite() && p.z.is_finite() && p.intensity.is_finite()
        });
    }
    let skipped = before - cloud.len();
    Ok((cloud, skipped))
}

/// Runs the command.
pub fn run(args: Args) -> Result<()> {
    let out_format = format_of(&args.output)?;
    let (cloud, skipped) = read(&args.input, args.skip_invalid)?;
    match out_format {
        Format::Bin => write_kitti_bin(&args.output, &cloud)?,
        Format::Las => write_las(&args.output, &cloud)?,
        Format::Ply => write_ply(&args.output, &cloud)?,
    }
    print!("{} points", cloud.len());
    if skipped > 0 {
        print!(" ({skipped} non-finite points left out)");
    }
    println!(" written to {}", args.output.display());
    Ok(())
}
