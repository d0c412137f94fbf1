//! Numbered frame files: KITTI stores one file per frame, named by the frame index padded to
//! ten digits (`0000000042.bin`, `0000000042.txt`). This module lists such files in a folder,
//! finds gaps in the numbering, builds the names, and keeps a recording's listed scan folder
//! (`ScanFolder`), whose scans it hands to the point-cloud readers.
//!
//! Not for: parsing the files' contents (see [`crate::cloud`] and the layout readers).

use crate::cloud::{read_scan_with, BinScan, NonFinite};
use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// The KITTI file name of frame `k` with extension `ext` (without the dot), e.g.
/// `frame_file_name(42, "bin") == "0000000042.bin"`.
pub fn frame_file_name(k: u64, ext: &str) -> String {
    format!("{k:010}.{ext}")
}

/// The files `<digits>.<ext>` of `dir`, as (frame number, path) sorted by number.
///
/// Other files are ignored. Errors: the folder cannot be read ([`Error::Io`] naming it), or two
/// files carry the same number (e.g. `5.bin` and `0000000005.bin`).
pub fn list_frame_files(dir: &Path, ext: &str) -> Result<Vec<(u64, PathBuf)>> {
    let entries = std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))?;
    let mut files = Vec::new();
    for entry in entries {
        let entry = entry.map_err(|e| Error::io(dir, e))?;
        let path = entry.path();
        if path.extension().and_then(|e| e.to_str()) != Some(ext) {
            continue;
        }
        let Some(stem) = path.file_stem().and_then(|s| s.to_str()) else {
            continue;
        };
        if stem.is_empty() || !stem.bytes().all(|b| b.is_ascii_digit()) {
            continue;
        }
        let Ok(k) = stem.parse::<u64>() else {
            continue;
        };
        files.push((k, path));
    }
    files.sort();
    for pair in files.windows(2) {
        if pair[0].0 == pair[1].0 {
            return Err(Error::parse(
                &pair[1].1,
                0,
                "file name",
                format!("frame {} also stored as {}", pair[0].0, pair[0].1.display()),
            ));
        }
    }
    Ok(files)
}

/// The scan files of a Velodyne folder: its numbered `.bin` files, or its numbered `.pcd`
/// files when it holds no `.bin` (a recording kept as PCD). A folder holding both kinds is an
/// error naming it.
pub fn list_scan_files(dir: &Path) -> Result<Vec<(u64, PathBuf)>> {
    let bin = list_frame_files(dir, "bin")?;
    let pcd = list_frame_files(dir, "pcd")?;
    match (bin.is_empty(), pcd.is_empty()) {
        (false, false) => Err(Error::invalid(
            format!("scan folder {}", dir.display()),
            format!(
                "holds both .bin ({}) and .pcd ({}) scans; keep one kind",
                bin.len(),
                pcd.len()
            ),
        )),
        (true, false) => Ok(pcd),
        _ => Ok(bin),
    }
}

/// A KITTI layout's scan folder as listed when the recording was opened: its numbered scan
/// files ([`list_scan_files`]), or none when the folder does not exist. Scan `k` is the listed
/// file numbered `k`, else the `.bin` name with `digits` digits (whether or not it exists).
/// The raw drive, tracking and odometry layouts each hand theirs out (`scans()`).
#[derive(Clone, Debug)]
pub struct ScanFolder {
    dir: PathBuf,
    files: Option<Vec<(u64, PathBuf)>>,
    digits: usize,
    /// What a missing folder means, for the error of a read.
    missing: &'static str,
}

impl ScanFolder {
    /// Lists `dir` when it is a folder; names scans with `digits` digits when not listed;
    /// `missing` says what a missing folder means in the error of a read.
    pub(crate) fn open(dir: PathBuf, digits: usize, missing: &'static str) -> Result<Self> {
        let files = if dir.is_dir() {
            Some(list_scan_files(&dir)?)
        } else {
            None
        };
        Ok(ScanFolder {
            dir,
            files,
            digits,
            missing,
        })
    }

    /// The folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Whether the folder exists.
    pub fn exists(&self) -> bool {
        self.files.is_some()
    }

    /// The listed scans, sorted by number; `None` without the folder.
    pub fn files(&self) -> Option<&[(u64, PathBuf)]> {
        self.files.as_deref()
    }

    /// Number of listed scans (0 without the folder).
    pub fn count(&self) -> usize {
        self.files.as_ref().map_or(0, Vec::len)
    }

    /// Number of frames the scans span: the last scan's number + 1 (0 without scans). It
    /// exceeds [`count`](Self::count) when scans were dropped inside the numbering.
    pub fn extent(&self) -> usize {
        self.files
            .as_deref()
            .and_then(<[_]>::last)
            .map_or(0, |(n, _)| *n as usize + 1)
    }

    /// The frames the scans span ([`extent`](Self::extent)) when the folder exists, else
    /// `otherwise()` (a layout's other count of frames, such as its OXTS packets).
    pub fn extent_or(&self, otherwise: impl FnOnce() -> usize) -> usize {
        if self.exists() {
            self.extent()
        } else {
            otherwise()
        }
    }

    /// Whether frame `k` has a listed scan. KITTI drops a scan now and then (raw drive 0009,
    /// tracking sequence 0001: frames 177–180) and keeps the other files' numbers.
    pub fn has_scan(&self, k: usize) -> bool {
        self.files
            .as_deref()
            .is_some_and(|f| listed_path(f, k as u64).is_some())
    }

    /// The frames below [`extent`](Self::extent) without a scan (dropped scans), as inclusive
    /// ranges.
    pub fn dropped(&self) -> Vec<(u64, u64)> {
        numbering_gaps(self.files.iter().flatten().map(|f| f.0))
    }

    /// Path of scan `k`: the listed `.bin` or `.pcd` file, else (whether or not it exists) the
    /// `.bin` name.
    pub fn path(&self, k: usize) -> PathBuf {
        self.files
            .as_deref()
            .and_then(|v| listed_path(v, k as u64))
            .map(Path::to_path_buf)
            .unwrap_or_else(|| {
                self.dir
                    .join(format!("{k:0width$}.bin", width = self.digits))
            })
    }

    /// Adds an [`Issue::Unreadable`](super::Issue::Unreadable) for every listed `.bin` scan
    /// that cannot be read or whose size is not a whole number of points (16 bytes each).
    pub(crate) fn check_sizes(&self, issues: &mut Vec<super::Issue>) {
        for (_, path) in self.files().into_iter().flatten() {
            if crate::cloud::is_pcd(path) {
                continue;
            }
            match std::fs::metadata(path) {
                Err(e) => issues.push(super::Issue::Unreadable {
                    path: path.clone(),
                    error: e.to_string(),
                }),
                Ok(m) if m.len() % 16 != 0 => issues.push(super::Issue::Unreadable {
                    path: path.clone(),
                    error: format!("{} bytes is not a multiple of 16", m.len()),
                }),
                Ok(_) => {}
            }
        }
    }

    /// Reads scan `k` with a choice for non-finite points. Errors name the file, or the
    /// folder when it does not exist.
    pub fn read(&self, k: usize, policy: NonFinite) -> Result<BinScan> {
        if !self.exists() {
            return Err(missing_folder(&self.dir, self.missing));
        }
        read_scan_with(self.path(k), policy)
    }
}

/// The error for a folder `path` that does not exist, saying what that means.
pub(crate) fn missing_folder(path: &Path, consequence: &str) -> Error {
    Error::io(
        path,
        std::io::Error::new(
            std::io::ErrorKind::NotFound,
            format!("folder missing; {consequence}"),
        ),
    )
}

/// The path of frame `k` in a sorted frame list, when listed.
pub(crate) fn listed_path(files: &[(u64, PathBuf)], k: u64) -> Option<&Path> {
    match files.get(k as usize) {
        Some((n, p)) if *n == k => Some(p),
        _ => files
            .binary_search_by_key(&k, |f| f.0)
            .ok()
            .map(|i| files[i].1.as_path()),
    }
}

/// Frame numbers missing from `0..=max` in a sorted list of frame numbers, as inclusive ranges.
pub fn numbering_gaps(numbers: impl IntoIterator<Item = u64>) -> Vec<(u64, u64)> {
    let mut gaps = Vec::new();
    let mut next = 0u64;
    for k in numbers {
        if k > next {
            gaps.push((next, k - 1));
        }
        next = next.max(k + 1);
    }
    gaps
}

/// Fails naming the first missing file when the numbering of `files` is not `0, 1, 2, ...`.
pub(crate) fn require_contiguous(dir: &Path, files: &[(u64, PathBuf)], ext: &str) -> Result<()> {
    if let Some(&(first, last)) = numbering_gaps(files.iter().map(|f| f.0)).first() {
        let missing = dir.join(frame_file_name(first, ext));
        let reason = if first == last {
            "missing (frame numbering has a gap)".to_string()
        } else {
            format!("missing, up to frame {last} (frame numbering has a gap)")
        };
        return Err(Error::parse(missing, 0, "file", reason));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_ten_digits() {
        assert_eq!(frame_file_name(42, "bin"), "0000000042.bin");
    }

    #[test]
    fn gaps_are_ranges() {
        assert!(numbering_gaps([0, 1, 2]).is_empty());
        assert_eq!(numbering_gaps([0, 3, 4, 6]), vec![(1, 2), (5, 5)]);
        assert_eq!(numbering_gaps([2]), vec![(0, 1)]);
    }

    #[test]
    fn listing_sorts_ignores_and_detects_duplicates() {
        let dir = tempfile::tempdir().unwrap();
        for n in [
            "0000000002.txt",
            "0000000000.txt",
            "notes.txt",
            "0000000001.bin",
        ] {
            std::fs::write(dir.path().join(n), "").unwrap();
        }
        let files = list_frame_files(dir.path(), "txt").unwrap();
        assert_eq!(files.iter().map(|f| f.0).collect::<Vec<_>>(), vec![0, 2]);
        let msg = require_contiguous(dir.path(), &files, "txt")
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("0000000001.txt") && msg.contains("missing"),
            "{msg}"
        );
        std::fs::write(dir.path().join("2.txt"), "").unwrap();
        assert!(list_frame_files(dir.path(), "txt").is_err());
    }
}
