//! The recordings `track` and `batch` run on (the library's `RecordingSource`), tracked with
//! errors that say which; and the list file of `batch` that names many of them.
//!
//! Not for: what a run writes (see `track_cmd` and `batch_cmd`).

use anyhow::{bail, Context, Result};
pub use smc_lmb::pipeline::drive_tracking::RecordingSource as Recording;
use smc_lmb::pipeline::drive_tracking::{DriveTracks, FrameView, TrackingConfig};
use std::ops::Range;
use std::path::Path;

/// Opens `rec` and runs one tracking pass over `frames` (all when `None`); errors say which
/// recording.
pub fn track(
    rec: &Recording,
    frames: Option<Range<usize>>,
    config: &TrackingConfig,
    seed: u64,
    on_frame: impl FnMut(&FrameView<'_>) -> smc_lmb::Result<()>,
) -> Result<DriveTracks> {
    rec.track(frames, config, seed, on_frame)
        .with_context(|| format!("tracking {}", rec.describe()))
}

/// The recordings `path` names: every raw drive in it when it is a folder (its subfolders
/// holding `velodyne_points/`, by name), else its lines. A line is a raw drive folder,
/// `tracking ROOT NNNN`, `odometry ROOT NN` or `scans DIR [POSES [TIMES]]`; relative paths
/// are taken from the list's own folder, blank lines and text after `#` are ignored. Errors
/// name the file and line. Two recordings with the same [`Recording::name`] are an error
/// (their outputs would collide).
pub fn read_list(path: &Path) -> Result<Vec<Recording>> {
    let list = if path.is_dir() {
        drives_in(path)?
    } else {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("reading the recording list {}", path.display()))?;
        let base = path.parent().unwrap_or(Path::new("."));
        let mut list = Vec::new();
        for (k, line) in text.lines().enumerate() {
            let line = line.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let rec = parse_line(line, base)
                .with_context(|| format!("{} line {}: `{line}`", path.display(), k + 1))?;
            list.push(rec);
        }
        list
    };
    if list.is_empty() {
        bail!("{} names no recording", path.display());
    }
    let mut seen = std::collections::BTreeMap::new();
    for rec in &list {
        if let Some(first) = seen.insert(rec.name(), rec.describe()) {
            bail!(
                "{}: {} and {} would both write to `{}`",
                path.display(),
                first,
                rec.describe(),
                rec.name()
            );
        }
    }
    Ok(list)
}

/// The raw drives directly inside `dir`, by name.
fn drives_in(dir: &Path) -> Result<Vec<Recording>> {
    let entries =
        std::fs::read_dir(dir).with_context(|| format!("listing the folder {}", dir.display()))?;
    let mut drives = Vec::new();
    for e in entries {
        let p = e
            .with_context(|| format!("listing the folder {}", dir.display()))?
            .path();
        if p.join("velodyne_points").is_dir() {
            drives.push(p);
        }
    }
    drives.sort();
    Ok(drives.into_iter().map(Recording::Raw).collect())
}

/// One list line (comment and blanks removed).
fn parse_line(line: &str, base: &Path) -> Result<Recording> {
    let words: Vec<&str> = line.split_whitespace().collect();
    let at = |p: &str| base.join(p);
    let number = |w: &str| -> Result<u32> {
        w.parse()
            .with_context(|| format!("`{w}` is not a sequence number"))
    };
    match words.as_slice() {
        ["tracking", root, n] => Ok(Recording::Tracking(at(root), number(n)?)),
        ["odometry", root, n] => Ok(Recording::Odometry(at(root), number(n)?)),
        [kind @ ("tracking" | "odometry"), ..] => {
            bail!("expected `{kind} ROOT NUMBER`")
        }
        ["scans", dir, rest @ ..] if rest.len() <= 2 => Ok(Recording::Scans {
            dir: at(dir),
            poses: rest.first().map(|p| at(p)),
            times: rest.get(1).map(|t| at(t)),
            sensor_height: None,
        }),
        ["scans", ..] => bail!("expected `scans DIR [POSES [TIMES]]`"),
        [dir] => Ok(Recording::Raw(at(dir))),
        _ => bail!(
            "expected a drive folder, `tracking ROOT NNNN`, `odometry ROOT NN` or `scans DIR \
             [POSES [TIMES]]`"
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    #[test]
    fn list_lines_and_their_errors() {
        let tmp = tempfile::tempdir().unwrap();
        let list = tmp.path().join("drives.txt");
        std::fs::write(
            &list,
            "# two drives and a sequence\n\
             a/2011_09_26_drive_0001_sync\n\n\
             /abs/2011_09_26_drive_0002_sync   # absolute\n\
             tracking kitti/training 7\n\
             odometry odo 3\n\
             scans lidar/run1 lidar/run1_poses.txt\n",
        )
        .unwrap();
        let got = read_list(&list).unwrap();
        assert_eq!(
            got,
            vec![
                Recording::Raw(tmp.path().join("a/2011_09_26_drive_0001_sync")),
                Recording::Raw(PathBuf::from("/abs/2011_09_26_drive_0002_sync")),
                Recording::Tracking(tmp.path().join("kitti/training"), 7),
                Recording::Odometry(tmp.path().join("odo"), 3),
                Recording::Scans {
                    dir: tmp.path().join("lidar/run1"),
                    poses: Some(tmp.path().join("lidar/run1_poses.txt")),
                    times: None,
                    sensor_height: None,
                },
            ]
        );
        assert_eq!(got[4].name(), "run1");
        assert_eq!(got[2].name(), "tracking_0007");
        assert_eq!(got[3].name(), "odometry_03");
        for (text, needle) in [
            ("x\ntracking root\n", "line 2"),
            ("tracking root seven\n", "not a sequence number"),
            ("a b\n", "expected a drive folder"),
            ("scans a b c d\n", "expected `scans DIR [POSES [TIMES]]`"),
            ("# nothing\n", "names no recording"),
            ("x/d_sync\ny/d_sync\n", "would both write"),
        ] {
            std::fs::write(&list, text).unwrap();
            let e = format!("{:#}", read_list(&list).unwrap_err());
            assert!(
                e.contains(needle) && e.contains("drives.txt"),
                "{text:?}: {e}"
            );
        }
        let e = format!(
            "{:#}",
            read_list(&tmp.path().join("missing.txt")).unwrap_err()
        );
        assert!(e.contains("missing.txt"), "{e}");
    }

    #[test]
    fn a_folder_gives_its_raw_drives_by_name() {
        let tmp = tempfile::tempdir().unwrap();
        for d in ["d_0002_sync", "d_0001_sync", "not_a_drive"] {
            std::fs::create_dir_all(tmp.path().join(d)).unwrap();
        }
        for d in ["d_0002_sync", "d_0001_sync"] {
            std::fs::create_dir_all(tmp.path().join(d).join("velodyne_points")).unwrap();
        }
        let got = read_list(tmp.path()).unwrap();
        assert_eq!(
            got,
            vec![
                Recording::Raw(tmp.path().join("d_0001_sync")),
                Recording::Raw(tmp.path().join("d_0002_sync")),
            ]
        );
        let empty = tempfile::tempdir().unwrap();
        let e = format!("{:#}", read_list(empty.path()).unwrap_err());
        assert!(e.contains("names no recording"), "{e}");
    }
}
