//! [`RecordingSource`]: which recording a tracking run reads — a KITTI raw drive, a tracking
//! sequence or an odometry sequence, by where it lives — opened and tracked the same way
//! whatever its layout, for the command line and the Python package alike.
//!
//! Not for: the tracking loop itself (see [`super::track_drive`] and its siblings).

use super::{
    track_drive, track_odometry_sequence, track_tracking_sequence, DriveTracks, FrameView,
    TrackingConfig,
};
use crate::error::Result;
use crate::kitti::{OdometrySequence, RawDrive, TrackingSequence};
use std::ops::Range;
use std::path::PathBuf;

/// One recording to track.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum RecordingSource {
    /// A raw drive folder (`.../2011_09_26/2011_09_26_drive_0001_sync`).
    Raw(PathBuf),
    /// A tracking split folder (`.../training`) and a sequence number.
    Tracking(PathBuf, u32),
    /// An odometry root (holding `sequences/` and `poses/`) and a sequence number.
    Odometry(PathBuf, u32),
}

impl RecordingSource {
    /// A short name: the drive folder's name, or `tracking_NNNN` / `odometry_NN`.
    pub fn name(&self) -> String {
        match self {
            RecordingSource::Raw(dir) => dir
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_else(|| dir.display().to_string()),
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
        match self {
            RecordingSource::Raw(dir) => {
                track_drive(&RawDrive::open(dir)?, frames, config, seed, on_frame)
            }
            RecordingSource::Tracking(root, n) => {
                let seq = TrackingSequence::open(root, *n)?;
                track_tracking_sequence(&seq, frames, config, seed, on_frame)
            }
            RecordingSource::Odometry(root, n) => {
                let seq = OdometrySequence::open(root, *n)?;
                track_odometry_sequence(&seq, frames, config, seed, on_frame)
            }
        }
    }
}
