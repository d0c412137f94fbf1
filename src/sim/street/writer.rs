//! Writes a simulated street drive to disk in the KITTI raw layout:
//!
//! ```text
//! ROOT/DATE/calib_imu_to_velo.txt  calib_velo_to_cam.txt  calib_cam_to_cam.txt
//! ROOT/DATE/DATE_drive_NNNN_sync/
//!   velodyne_points/data/0000000000.bin ...  timestamps.txt  timestamps_start.txt  timestamps_end.txt
//!   oxts/data/0000000000.txt ...             timestamps.txt
//!   truth.json
//! ```
//!
//! The drive folder is filled under a hidden temporary name in the date folder and renamed
//! into place only when every file is written, so a drive that exists under its real name is
//! complete; on failure the temporary folder is removed. An existing drive folder is never
//! overwritten, nor a calibration file whose content differs from the one this module writes.
//!
//! Not for: simulating (see [`super::StreetSimulator`]) or reading drives (see
//! [`crate::kitti::RawDrive`]).

use super::{calib_files, StreetConfig, StreetSimulator, StreetTruth};
use crate::atomic::write_bytes;
use crate::cloud::write_kitti_bin;
use crate::error::{Error, Result};
use crate::kitti::drive::{CALIB_CAM_TO_CAM, CALIB_IMU_TO_VELO, CALIB_VELO_TO_CAM};
use crate::kitti::{frame_file_name, write_oxts_dir, write_timestamps};
use std::fs;
use std::path::{Path, PathBuf};

/// A drive written by [`write_drive`].
#[derive(Clone, Debug)]
pub struct WrittenDrive {
    /// The drive folder (`ROOT/DATE/DATE_drive_NNNN_sync`), to hand to `RawDrive::open`.
    pub dir: PathBuf,
    /// The truth also written to `dir/truth.json`.
    pub truth: StreetTruth,
}

/// File name of the ground truth inside the drive folder.
pub const TRUTH_FILE: &str = "truth.json";

fn mkdir(path: &Path) -> Result<()> {
    fs::create_dir_all(path).map_err(|e| Error::io(path, e))
}

/// Writes a calibration file, or checks that an existing one has the same content.
fn ensure_calib(path: &Path, text: &str) -> Result<()> {
    match fs::read_to_string(path) {
        Ok(existing) if existing == text => Ok(()),
        Ok(_) => Err(Error::invalid(
            format!("calibration file {}", path.display()),
            "exists with other values; refusing to overwrite it (write the drive elsewhere)",
        )),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => write_bytes(path, text.as_bytes()),
        Err(e) => Err(Error::io(path, e)),
    }
}

/// Simulates `frames` frames with `seed` and writes the drive under `root`; `progress(k)` is
/// called after frame k is written. Returns the drive folder and the truth.
///
/// Errors: an invalid configuration or frame count (see [`StreetSimulator::new`]), a drive
/// folder that already exists, a calibration file in the date folder with other values, or
/// any write failure (naming the file).
pub fn write_drive(
    root: impl AsRef<Path>,
    config: &StreetConfig,
    frames: usize,
    seed: u64,
    mut progress: impl FnMut(usize),
) -> Result<WrittenDrive> {
    let sim = StreetSimulator::new(config, frames, seed)?;
    let date_dir = root.as_ref().join(&config.recording.date);
    let name = config.drive_name();
    let dir = date_dir.join(&name);
    if dir.exists() {
        return Err(Error::invalid(
            format!("drive folder {}", dir.display()),
            "already exists; remove it or choose another output folder or drive number",
        ));
    }
    mkdir(&date_dir)?;
    for (file, text) in [
        (CALIB_IMU_TO_VELO, calib_files::IMU_TO_VELO),
        (CALIB_VELO_TO_CAM, calib_files::VELO_TO_CAM),
        (CALIB_CAM_TO_CAM, calib_files::CAM_TO_CAM),
    ] {
        ensure_calib(&date_dir.join(file), text)?;
    }
    let tmp = date_dir.join(format!(".{name}.partial.{}", std::process::id()));
    if tmp.exists() {
        fs::remove_dir_all(&tmp).map_err(|e| Error::io(&tmp, e))?;
    }
    let written = fill(&tmp, &sim, &mut progress).and_then(|truth| {
        fs::rename(&tmp, &dir).map_err(|e| Error::io(&dir, e))?;
        Ok(truth)
    });
    match written {
        Ok(truth) => Ok(WrittenDrive { dir, truth }),
        Err(e) => {
            let _ = fs::remove_dir_all(&tmp);
            Err(e)
        }
    }
}

/// Writes every file of the drive into `dir` (a fresh folder).
fn fill(
    dir: &Path,
    sim: &StreetSimulator,
    progress: &mut impl FnMut(usize),
) -> Result<StreetTruth> {
    let velodyne = dir.join("velodyne_points");
    let oxts = dir.join("oxts");
    mkdir(&velodyne.join("data"))?;
    mkdir(&oxts.join("data"))?;
    let mut truth = sim.truth();
    for k in 0..sim.frames() {
        let scan = sim.scan(k);
        write_kitti_bin(
            velodyne.join("data").join(frame_file_name(k as u64, "bin")),
            &scan.cloud,
        )?;
        sim.record_scan(&mut truth, k, &scan);
        progress(k);
    }
    let n = sim.frames();
    let half = 0.5 * sim.config().frame_period;
    let stamps: Vec<_> = (0..n).map(|k| sim.timestamp(k)).collect();
    let shifted = |dt: f64| -> Vec<_> {
        stamps
            .iter()
            .map(|t| t.plus_seconds(dt).unwrap_or(*t))
            .collect()
    };
    write_timestamps(velodyne.join("timestamps.txt"), &stamps)?;
    write_timestamps(velodyne.join("timestamps_start.txt"), &shifted(-half))?;
    write_timestamps(velodyne.join("timestamps_end.txt"), &shifted(half))?;
    write_timestamps(oxts.join("timestamps.txt"), &stamps)?;
    let packets: Vec<_> = (0..n).map(|k| sim.packet(k)).collect();
    write_oxts_dir(oxts.join("data"), &packets)?;
    write_bytes(&dir.join(TRUTH_FILE), truth.to_json()?.as_bytes())?;
    Ok(truth)
}
