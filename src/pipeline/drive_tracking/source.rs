//! [`RecordingSource`]: which recording a tracking run reads — a KITTI raw drive, a tracking
//! sequence, an odometry sequence or a folder of scans, by where it lives — opened and
//! tracked the same way whatever its layout, for the command line and the Python package
//! alike.
//!
//! Not for: the tracking loop itself (see [`super::track_recording`]).

use super::{track_recording, DriveTracks, FrameView, TrackingConfig};
use crate::error::Result;
use crate::kitti::{OdometrySequence, RawDrive, TrackingSequence};
use crate::recording::{folder_name, Recording, ScanDirectory};
use std::ops::Range;
use std::path::PathBuf;

/// One recording to track.
#[derive(Clone, Debug, PartialEq)]
pub enum RecordingSource {
    /// A raw drive folder (`.../2011_09_26/2011_09_26_drive_0001_sync`).
    Raw(PathBuf),
    /// A tracking split folder (`.../training`) and a sequence number.
    Tracking(PathBuf, u32),
    /// An odometry root (holding `sequences/` and `poses/`) and a sequence number.
    Odometry(PathBuf, u32),
    /// A folder of `.bin` or `.pcd` scans ([`ScanDirectory`]) with an optional pose file and
    /// an optional time file.
    Scans {
        /// The folder.
        dir: PathBuf,
        /// One row-major 3 × 4 sensor pose per line (KITTI's odometry layout).
        poses: Option<PathBuf>,
        /// One time (s) per line.
        times: Option<PathBuf>,
        /// The sensor's height over the road (m), when known.
        sensor_height: Option<f64>,
    },
}

impl RecordingSource {
    /// A short name: the drive's or scan folder's name, or `tracking_NNNN` / `odometry_NN`.
    pub fn name(&self) -> String {
        match self {
            RecordingSource::Raw(dir) | RecordingSource::Scans { dir, .. } => folder_name(dir),
            RecordingSource::Tracking(_, n) => format!("tracking_{n:04}"),
            RecordingSource::Odometry(_, n) => format!("odometry_{n:02}"),
        }
    }

    /// What the recording is, for messages.
    pub fn describe(&self) -> String {
        match self {
            RecordingSource::Raw(dir) => format!("drive {}", dir.display()),
            RecordingSource::Tracking(root, n) => {
                format!("tracking sequence {n:04} of {}", root.display())
            }
            RecordingSource::Odometry(root, n) => {
                format!("odometry sequence {n:02} of {}", root.display())
            }
            RecordingSource::Scans { dir, .. } => format!("scan folder {}", dir.display()),
        }
    }

    /// Opens the recording and runs one tracking pass over `frames` (all when `None`).
    pub fn track(
        &self,
        frames: Option<Range<usize>>,
        config: &TrackingConfig,
        seed: u64,
        on_frame: impl FnMut(&FrameView<'_>) -> Result<()>,
    ) -> Result<DriveTracks> {
        track_recording(&*self.open()?, frames, config, seed, on_frame)
    }

    /// Opens the recording.
    pub fn open(&self) -> Result<Box<dyn Recording>> {
        Ok(match self {
            RecordingSource::Raw(dir) => Box::new(RawDrive::open(dir)?),
            RecordingSource::Tracking(root, n) => Box::new(TrackingSequence::open(root, *n)?),
            RecordingSource::Odometry(root, n) => Box::new(OdometrySequence::open(root, *n)?),
            RecordingSource::Scans {
                dir,
                poses,
                times,
                sensor_height,
            } => {
                let mut scans = ScanDirectory::open(dir)?;
                if let Some(h) = sensor_height {
                    scans = scans.with_sensor_height(*h)?;
                }
                if let Some(p) = poses {
                    scans = scans.with_poses(p)?;
                }
                if let Some(t) = times {
                    scans = scans.with_times(t)?;
                }
                Box::new(scans)
            }
        })
    }
}
