//! [`RawDrive`]: one synchronised KITTI raw drive on disk, laid out as
//!
//! ```text
//! DATE/                                  e.g. 2011_09_26/
//!   calib_imu_to_velo.txt  calib_velo_to_cam.txt  calib_cam_to_cam.txt
//!   DATE_drive_NNNN_sync/                the drive folder handed to RawDrive::open
//!     velodyne_points/data/0000000000.bin ...   velodyne_points/timestamps.txt
//!     oxts/data/0000000000.txt ...              oxts/timestamps.txt
//! ```
//!
//! The scans may also be numbered `.pcd` files (a recording kept as PCD) in place of `.bin`.
//!
//! Opening lists the frame files only; clouds, packets, stamps and calibration are read when
//! asked for. Either sensor folder may be absent: a drive without OXTS still gives point clouds,
//! and asking it for poses is an error naming the missing folder. [`RawDrive::check`] reports
//! every inconsistency at once. A scan missing inside the numbering is a dropped scan (drive
//! 0009 lacks 177–180; their OXTS packets are there and their stamp lines blank): the drive's
//! frames are those the scans span, and [`RawDrive::scans`] tells which have one.
//!
//! Not for: camera images, the odometry benchmark layout (see [`super::odometry`]) or the
//! tracking benchmark layout (see [`super::tracking`]).

use super::calib::{read_cam_to_cam, read_rigid_calib, CamToCamCalib, RigidCalib};
use super::frames::{
    list_frame_files, listed_path, missing_folder, numbering_gaps, require_contiguous, ScanFolder,
};
use super::issue::Issue;
use super::oxts::{read_oxts_file, OxtsPacket};
use super::poses::{self, VehicleState};
use super::timestamps::{read_timestamps, Timestamps};
use crate::error::{Error, Result};
use nalgebra::Isometry3;
use std::path::{Path, PathBuf};

/// File name of the IMU→Velodyne calibration in the date folder.
pub const CALIB_IMU_TO_VELO: &str = "calib_imu_to_velo.txt";
/// File name of the Velodyne→camera calibration in the date folder.
pub const CALIB_VELO_TO_CAM: &str = "calib_velo_to_cam.txt";
/// File name of the camera-to-camera calibration in the date folder.
pub const CALIB_CAM_TO_CAM: &str = "calib_cam_to_cam.txt";

/// Frame files of one data folder: (frame number, path), sorted by number.
type FrameFiles = Vec<(u64, PathBuf)>;

/// One synchronised raw drive (`DATE/DATE_drive_NNNN_sync`).
#[derive(Clone, Debug)]
pub struct RawDrive {
    dir: PathBuf,
    date_dir: PathBuf,
    /// `velodyne_points/data`, as listed when opened.
    velodyne: ScanFolder,
    /// `None` when `oxts/data` does not exist.
    oxts: Option<FrameFiles>,
}

fn list_if_present(dir: &Path, ext: &str) -> Result<Option<FrameFiles>> {
    if dir.is_dir() {
        list_frame_files(dir, ext).map(Some)
    } else {
        Ok(None)
    }
}

impl RawDrive {
    /// Opens a drive folder and lists its Velodyne and OXTS frame files.
    ///
    /// Errors: `dir` does not exist or is not a folder, or a data folder cannot be listed.
    /// Missing sensor folders are not errors here (see [`check`](Self::check)).
    pub fn open(dir: impl AsRef<Path>) -> Result<RawDrive> {
        let dir = dir.as_ref().to_path_buf();
        let meta = std::fs::metadata(&dir).map_err(|e| Error::io(&dir, e))?;
        if !meta.is_dir() {
            return Err(Error::invalid(
                format!("drive folder {}", dir.display()),
                "is not a folder",
            ));
        }
        let date_dir = match dir.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            Some(_) => PathBuf::from("."),
            None => dir.clone(),
        };
        let velodyne = ScanFolder::open(
            dir.join("velodyne_points").join("data"),
            10,
            "this drive has no Velodyne point clouds",
        )?;
        let oxts = list_if_present(&dir.join("oxts").join("data"), "txt")?;
        Ok(RawDrive {
            dir,
            date_dir,
            velodyne,
            oxts,
        })
    }

    /// The drive folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The folder holding the calibration files (the drive folder's parent).
    pub fn date_dir(&self) -> &Path {
        &self.date_dir
    }

    /// The drive folder's name, e.g. `2011_09_26_drive_0001_sync`.
    pub fn name(&self) -> String {
        self.dir
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default()
    }

    /// `velodyne_points/data`.
    pub fn velodyne_dir(&self) -> PathBuf {
        self.dir.join("velodyne_points").join("data")
    }

    /// `oxts/data`.
    pub fn oxts_dir(&self) -> PathBuf {
        self.dir.join("oxts").join("data")
    }

    /// `velodyne_points/timestamps.txt`.
    pub fn velodyne_timestamps_path(&self) -> PathBuf {
        self.dir.join("velodyne_points").join("timestamps.txt")
    }

    /// `oxts/timestamps.txt`.
    pub fn oxts_timestamps_path(&self) -> PathBuf {
        self.dir.join("oxts").join("timestamps.txt")
    }

    /// Whether `velodyne_points/data` exists.
    pub fn has_velodyne(&self) -> bool {
        self.velodyne.exists()
    }

    /// Whether `oxts/data` exists.
    pub fn has_oxts(&self) -> bool {
        self.oxts.is_some()
    }

    /// Number of scan files (`.bin`, or `.pcd` when there is no `.bin`) in
    /// `velodyne_points/data` (0 when the folder is missing).
    pub fn velodyne_count(&self) -> usize {
        self.velodyne.count()
    }

    /// Number of `.txt` files in `oxts/data` (0 when the folder is missing).
    pub fn oxts_count(&self) -> usize {
        self.oxts.as_ref().map_or(0, Vec::len)
    }

    /// Number of frames: the frames the Velodyne scans span when `velodyne_points/data` exists
    /// (the last scan's number + 1, dropped scans inside the numbering included; see
    /// [`ScanFolder::has_scan`]), otherwise the OXTS packets.
    pub fn frame_count(&self) -> usize {
        self.velodyne.extent_or(|| self.oxts_count())
    }

    /// The Velodyne scans (`velodyne_points/data`): which frames have one
    /// ([`ScanFolder::has_scan`]; KITTI drops a scan now and then, drive 0009 has none for
    /// frames 177–180, and keeps the other files' numbers, its OXTS packet and a blank line in
    /// `velodyne_points/timestamps.txt`), their paths, reading them.
    pub fn scans(&self) -> &ScanFolder {
        &self.velodyne
    }

    /// Reads every OXTS packet, in frame order.
    ///
    /// Errors: `oxts/data` is missing (naming it), a file in the numbering is missing (naming
    /// it), or a file is malformed (naming file, line and field).
    pub fn oxts(&self) -> Result<Vec<OxtsPacket>> {
        let files = self.oxts.as_ref().ok_or_else(|| {
            missing_folder(
                &self.oxts_dir(),
                "this drive has no OXTS packets, so no poses (point clouds only)",
            )
        })?;
        require_contiguous(&self.oxts_dir(), files, "txt")?;
        files.iter().map(|(_, p)| read_oxts_file(p)).collect()
    }

    /// Velodyne time stamps (`velodyne_points/timestamps.txt`).
    pub fn timestamps(&self) -> Result<Timestamps> {
        read_timestamps(self.velodyne_timestamps_path())
    }

    /// The Velodyne frames' times, seconds since the first stamp, one per frame (a dropped
    /// scan's interpolated from its blank line).
    ///
    /// Errors (naming the file): it cannot be read, its stamps are not one per frame, or a
    /// frame with a scan has a blank line (naming that line).
    pub fn scan_times(&self) -> Result<Vec<f64>> {
        let path = self.velodyne_timestamps_path();
        let t = self.timestamps()?;
        let n = self.frame_count();
        if t.len() != n {
            return Err(Error::invalid(
                format!("{}", path.display()),
                format!("has {} stamps for {n} Velodyne frames", t.len()),
            ));
        }
        if let Some(&k) = t.blank.iter().find(|&&k| self.velodyne.has_scan(k)) {
            return Err(Error::parse(
                path,
                k + 1,
                "timestamp",
                format!("blank, but frame {k} has a scan"),
            ));
        }
        Ok(t.seconds)
    }

    /// OXTS time stamps (`oxts/timestamps.txt`).
    pub fn oxts_timestamps(&self) -> Result<Timestamps> {
        read_timestamps(self.oxts_timestamps_path())
    }

    /// The IMU→Velodyne calibration T_velo_imu (p_velo = T_velo_imu·p_imu).
    pub fn calib_imu_to_velo(&self) -> Result<RigidCalib> {
        read_rigid_calib(self.date_dir.join(CALIB_IMU_TO_VELO))
    }

    /// The Velodyne→camera-0 calibration T_cam0_velo (p_cam0 = T_cam0_velo·p_velo).
    pub fn calib_velo_to_cam(&self) -> Result<RigidCalib> {
        read_rigid_calib(self.date_dir.join(CALIB_VELO_TO_CAM))
    }

    /// `R_rect_00` and `P_rect_02` of the camera-to-camera calibration.
    pub fn calib_cam_to_cam(&self) -> Result<CamToCamCalib> {
        read_cam_to_cam(self.date_dir.join(CALIB_CAM_TO_CAM))
    }

    /// Fails when the drive has Velodyne frames and the frames they span differ from the OXTS
    /// count (a dropped scan inside the numbering still has its packet).
    fn ensure_counts_agree(&self, n_oxts: usize) -> Result<()> {
        if self.has_velodyne() && self.frame_count() != n_oxts {
            return Err(Issue::CountMismatch {
                a: self.oxts_dir(),
                a_count: n_oxts,
                b: self.velodyne_dir(),
                b_count: self.frame_count(),
            }
            .to_error());
        }
        Ok(())
    }

    /// IMU poses relative to the first packet (first = identity), one per frame; see
    /// [`poses::imu_poses`].
    pub fn imu_poses(&self) -> Result<Vec<Isometry3<f64>>> {
        let packets = self.oxts()?;
        self.ensure_counts_agree(packets.len())?;
        poses::imu_poses(&packets)
    }

    /// Velodyne poses relative to the first Velodyne frame (first = identity), one per frame:
    /// pose k maps Velodyne coordinates of frame k to those of frame 0.
    ///
    /// Errors: no OXTS folder (naming it), Velodyne and OXTS counts that disagree, a missing or
    /// malformed `calib_imu_to_velo.txt`, or any OXTS reading error.
    pub fn poses(&self) -> Result<Vec<Isometry3<f64>>> {
        let imu = self.imu_poses()?;
        let calib = self.calib_imu_to_velo()?;
        Ok(poses::velodyne_poses(&imu, &calib.isometry))
    }

    /// Planar vehicle states [X, Ẋ, Y, Ẏ, φ, φ̇], one per frame; see [`VehicleState`].
    pub fn vehicle_states(&self) -> Result<Vec<VehicleState>> {
        let packets = self.oxts()?;
        self.ensure_counts_agree(packets.len())?;
        poses::vehicle_states(&packets)
    }

    /// Every inconsistency of the drive on disk: missing sensor folders, timestamp files or
    /// calibration files; gaps in the OXTS numbering and dropped scans
    /// ([`Issue::DroppedScans`]); frame counts that disagree between the data folders and their
    /// timestamp files; OXTS files or timestamp files that do not parse; stamps that do not
    /// increase; `.bin` files whose size is not a multiple of 16 bytes.
    /// An empty list means the drive is consistent.
    pub fn check(&self) -> Vec<Issue> {
        let mut issues = Vec::new();
        let sensors = [
            (
                "no point clouds",
                self.velodyne.files().map(|f| (f, self.velodyne.extent())),
                self.velodyne_dir(),
                self.velodyne_timestamps_path(),
                "Velodyne frames have no time stamps",
            ),
            (
                "no OXTS packets, so no poses (point clouds only)",
                self.oxts.as_deref().map(|f| (f, f.len())),
                self.oxts_dir(),
                self.oxts_timestamps_path(),
                "OXTS packets have no time stamps",
            ),
        ];
        for (missing_consequence, files, dir, stamps_path, stamps_consequence) in sensors {
            let Some((files, frames)) = files else {
                issues.push(Issue::MissingFolder {
                    path: dir,
                    consequence: missing_consequence.to_string(),
                });
                continue;
            };
            for (first, last) in numbering_gaps(files.iter().map(|f| f.0)) {
                issues.push(if dir == self.velodyne_dir() {
                    Issue::DroppedScans {
                        folder: dir.clone(),
                        first,
                        last,
                    }
                } else {
                    Issue::NumberingGap {
                        folder: dir.clone(),
                        first_missing: first,
                        last_missing: last,
                    }
                });
            }
            if !stamps_path.exists() {
                issues.push(Issue::MissingFile {
                    path: stamps_path,
                    consequence: stamps_consequence.to_string(),
                });
                continue;
            }
            match read_timestamps(&stamps_path) {
                Err(e) => issues.push(Issue::Unreadable {
                    path: stamps_path,
                    error: e.to_string(),
                }),
                Ok(stamps) => {
                    if stamps.len() != frames {
                        issues.push(Issue::CountMismatch {
                            a: dir.clone(),
                            a_count: frames,
                            b: stamps_path.clone(),
                            b_count: stamps.len(),
                        });
                    }
                    if let Some(&i) = stamps
                        .blank
                        .iter()
                        .find(|&&i| listed_path(files, i as u64).is_some())
                    {
                        issues.push(Issue::Unreadable {
                            path: stamps_path.clone(),
                            error: format!("line {} is blank, but frame {i} has a file", i + 1),
                        });
                    }
                    if let Some(i) = stamps.first_non_increasing() {
                        issues.push(Issue::NonIncreasingTime {
                            path: stamps_path,
                            line: i + 1,
                        });
                    }
                }
            }
        }
        if let (true, Some(o)) = (self.has_velodyne(), &self.oxts) {
            if self.frame_count() != o.len() {
                issues.push(Issue::CountMismatch {
                    a: self.velodyne_dir(),
                    a_count: self.frame_count(),
                    b: self.oxts_dir(),
                    b_count: o.len(),
                });
            }
        }
        for (_, path) in self.oxts.iter().flatten() {
            if let Err(e) = read_oxts_file(path) {
                issues.push(Issue::Unreadable {
                    path: path.clone(),
                    error: e.to_string(),
                });
            }
        }
        self.velodyne.check_sizes(&mut issues);
        let calib = [
            (CALIB_IMU_TO_VELO, "no Velodyne poses"),
            (CALIB_VELO_TO_CAM, "no Velodyne→camera transform"),
            (CALIB_CAM_TO_CAM, "no camera rectification"),
        ];
        for (name, consequence) in calib {
            let path = self.date_dir.join(name);
            if !path.exists() {
                issues.push(Issue::MissingFile {
                    path,
                    consequence: consequence.to_string(),
                });
            }
        }
        issues
    }

    /// [`check`](Self::check), stopping with the first issue as an error.
    pub fn ensure_consistent(&self) -> Result<()> {
        Issue::first_as_error(&self.check())
    }
}
