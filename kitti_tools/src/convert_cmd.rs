//! `kitti-tools convert`: a point cloud from one file format to another (`.bin`, `.las`,
//! `.ply`, `.pcd`, chosen by extension).

use anyhow::{bail, Result};
use smc_lmb::cloud::{
    read_kitti_bin_with, read_las, read_pcd_with, read_ply, write_kitti_bin, write_las, write_pcd,
    write_ply, NonFinite, PcdEncoding, PointCloud,
};
use std::path::{Path, PathBuf};

/// Flags of `convert`.
#[derive(clap::Args)]
pub struct Args {
    /// The cloud to read (.bin KITTI Velodyne scan, .las, .ply or .pcd).
    #[arg(long)]
    input: PathBuf,
    /// Where to write the cloud (.bin, .las, .ply or .pcd); written atomically.
    #[arg(long)]
    output: PathBuf,
    /// The DATA encoding of a .pcd output.
    #[arg(long, value_enum, default_value_t = PcdData::Binary)]
    pcd_data: PcdData,
    /// Leave out points holding NaN or infinities instead of refusing the input.
    #[arg(long)]
    skip_invalid: bool,
}

/// The DATA encodings of a .pcd output.
#[derive(Copy, Clone, Debug, PartialEq, Eq, clap::ValueEnum)]
enum PcdData {
    Ascii,
    Binary,
    /// LZF-compressed, column by column.
    #[value(name = "binary_compressed", alias = "binary-compressed")]
    BinaryCompressed,
}

impl From<PcdData> for PcdEncoding {
    fn from(d: PcdData) -> Self {
        match d {
            PcdData::Ascii => PcdEncoding::Ascii,
            PcdData::Binary => PcdEncoding::Binary,
            PcdData::BinaryCompressed => PcdEncoding::BinaryCompressed,
        }
    }
}

/// The formats `convert` knows.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
enum Format {
    Bin,
    Las,
    Ply,
    Pcd,
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
        "pcd" => Format::Pcd,
        other => bail!(
            "{}: unknown point-cloud extension `{other}` (expected .bin, .las, .ply or .pcd)",
            path.display()
        ),
    })
}

/// Reads `path`, dropping (with `skip_invalid`) or refusing non-finite points; returns the
/// cloud and how many points were dropped.
fn read(path: &Path, skip_invalid: bool) -> Result<(PointCloud, usize)> {
    let policy = if skip_invalid {
        NonFinite::Skip
    } else {
        NonFinite::Error
    };
    let mut cloud = match format_of(path)? {
        Format::Bin => {
            let scan = read_kitti_bin_with(path, policy)?;
            return Ok((scan.cloud, scan.skipped));
        }
        Format::Pcd => {
            let scan = read_pcd_with(path, policy)?;
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
        Format::Pcd => write_pcd(&args.output, &cloud, args.pcd_data.into())?,
    }
    print!("{} points", cloud.len());
    if skipped > 0 {
        print!(" ({skipped} non-finite points left out)");
    }
    println!(" written to {}", args.output.display());
    Ok(())
}
