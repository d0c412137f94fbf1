//! [`Issue`]: one inconsistency found while checking a KITTI recording on disk (a missing
//! folder, a gap in the frame numbering, counts that disagree, an unreadable file). A check
//! collects all of them instead of stopping at the first, so a user sees the whole picture.
//!
//! Not for: the checks themselves (see [`super::drive::RawDrive::check`],
//! [`super::odometry::OdometrySequence::check`] and
//! [`super::tracking::TrackingSequence::check`]).

use crate::error::Error;
use std::fmt;
use std::path::{Path, PathBuf};

/// One inconsistency of a recording on disk.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum Issue {
    /// A folder that the layout expects does not exist.
    MissingFolder {
        /// The folder.
        path: PathBuf,
        /// What cannot be done without it.
        consequence: String,
    },
    /// A file that the layout expects does not exist.
    MissingFile {
        /// The file.
        path: PathBuf,
        /// What cannot be done without it.
        consequence: String,
    },
    /// Frame files are not numbered 0, 1, 2, ... without gaps.
    NumberingGap {
        /// The folder.
        folder: PathBuf,
        /// First missing frame number.
        first_missing: u64,
        /// Last missing frame number of this gap.
        last_missing: u64,
    },
    /// Frames inside a scan folder's numbering without a scan: KITTI drops a scan now and then
    /// and keeps the other files' numbers. Tracking leaves such frames out and predicts over
    /// them; frame pairs with one of them are not compared. Not an inconsistency of the
    /// recording, but what it lacks.
    DroppedScans {
        /// The scan folder.
        folder: PathBuf,
        /// First frame without a scan.
        first: u64,
        /// Last frame without a scan of this run.
        last: u64,
    },
    /// Two sources that should have one entry per frame disagree.
    CountMismatch {
        /// First source (folder or file).
        a: PathBuf,
        /// Entries in `a`.
        a_count: usize,
        /// Second source.
        b: PathBuf,
        /// Entries in `b`.
        b_count: usize,
    },
    /// Time stamps that do not increase.
    NonIncreasingTime {
        /// The timestamp file.
        path: PathBuf,
        /// One-based line (entry) number of the first stamp not later than its predecessor.
        line: usize,
    },
    /// A file exists but cannot be read or parsed.
    Unreadable {
        /// The file.
        path: PathBuf,
        /// The error, as text.
        error: String,
    },
}

impl Issue {
    /// The file or folder the issue is about.
    pub fn path(&self) -> &Path {
        match self {
            Issue::MissingFolder { path, .. }
            | Issue::MissingFile { path, .. }
            | Issue::NonIncreasingTime { path, .. }
            | Issue::Unreadable { path, .. } => path,
            Issue::NumberingGap { folder, .. } | Issue::DroppedScans { folder, .. } => folder,
            Issue::CountMismatch { a, .. } => a,
        }
    }

    /// Ok when there is no issue, else the first one as an error.
    pub fn first_as_error(issues: &[Issue]) -> crate::error::Result<()> {
        match issues.first() {
            None => Ok(()),
            Some(issue) => Err(issue.to_error()),
        }
    }

    /// The issue as an [`Error`] (for callers that want to stop at the first one).
    pub fn to_error(&self) -> Error {
        let line = match self {
            Issue::NonIncreasingTime { line, .. } => *line,
            _ => 0,
        };
        let field = match self {
            Issue::MissingFolder { .. } => "folder",
            Issue::MissingFile { .. } => "file",
            Issue::NumberingGap { .. } => "frame numbering",
            Issue::DroppedScans { .. } => "scans",
            Issue::CountMismatch { .. } => "frame count",
            Issue::NonIncreasingTime { .. } => "timestamp",
            Issue::Unreadable { .. } => "content",
        };
        Error::parse(self.path(), line, field, self.describe())
    }

    fn describe(&self) -> String {
        match self {
            Issue::MissingFolder { consequence, .. } => format!("folder missing; {consequence}"),
            Issue::MissingFile { consequence, .. } => format!("file missing; {consequence}"),
            Issue::NumberingGap {
                first_missing,
                last_missing,
                ..
            } if first_missing == last_missing => format!("frame {first_missing} is missing"),
            Issue::NumberingGap {
                first_missing,
                last_missing,
                ..
            } => format!("frames {first_missing}..={last_missing} are missing"),
            Issue::DroppedScans { first, last, .. } if first == last => {
                format!("frame {first} has no scan (dropped); tracking predicts over it")
            }
            Issue::DroppedScans { first, last, .. } => {
                format!(
                    "frames {first}..={last} have no scan (dropped); tracking predicts over them"
                )
            }
            Issue::CountMismatch {
                a_count,
                b,
                b_count,
                ..
            } => format!("{a_count} frames here but {b_count} in {}", b.display()),
            Issue::NonIncreasingTime { .. } => "not later than the previous stamp".to_string(),
            Issue::Unreadable { error, .. } => error.clone(),
        }
    }
}

impl fmt::Display for Issue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.to_error())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_name_both_sources() {
        let i = Issue::CountMismatch {
            a: "d/velodyne_points/data".into(),
            a_count: 5,
            b: "d/oxts/data".into(),
            b_count: 4,
        };
        assert_eq!(
            i.to_string(),
            "d/velodyne_points/data:0: frame count: 5 frames here but 4 in d/oxts/data"
        );
        let g = Issue::NumberingGap {
            folder: "x".into(),
            first_missing: 3,
            last_missing: 3,
        };
        assert!(g.to_string().contains("frame 3 is missing"));
    }
}
