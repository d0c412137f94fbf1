//! The KITTI odometry benchmark layout:
//!
//! ```text
//! ROOT/sequences/NN/velodyne/000000.bin ...   Velodyne scans (.bin, see crate::cloud)
//! ROOT/sequences/NN/calib.txt                  P0..P3 (3×4 projections), Tr (3×4, velo→cam0)
//! ROOT/sequences/NN/times.txt                  one time in seconds per line
//! ROOT/poses/NN.txt                            one 3×4 pose per line (12 values, row-major)
//! ```
//!
//! Ground-truth poses P_k are given for the left camera (cam0): P_k maps cam0 coordinates of
//! frame k to cam0 coordinates of frame 0. `Tr` maps Velodyne coordinates to cam0 coordinates
//! (p_cam = Tr·p_velo), so the Velodyne poses are V_k = Tr⁻¹·P_k·Tr (Velodyne frame k → Velodyne
//! frame 0).
//!
//! Not for: the raw-drive layout (see [`super::drive`]).

use super::calib::{rigid_from_parts, CalibFile};
use super::frames::{numbering_gaps, ScanFolder};
use super::issue::Issue;
use super::text::{numbered_lines, parse_f64, read_text};
use crate::atomic::write_atomically;
use crate::error::{Error, Result};
use nalgebra::{Isometry3, Matrix3, Vector3};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Reads a pose file: one row-major 3×4 matrix `[R | t]` (12 values) per non-blank line.
/// Errors name the file, the line and the value (`value 7 of 12`), or the rotation when it is not
/// one.
pub fn read_odometry_poses(path: impl AsRef<Path>) -> Result<Vec<Isometry3<f64>>> {
    let path = path.as_ref();
    let text = read_text(path)?;
    let mut poses = Vec::new();
    for (line, l) in numbered_lines(&text) {
        let tokens: Vec<&str> = l.split_whitespace().collect();
        if tokens.len() != 12 {
            return Err(Error::parse(
                path,
                line,
                "pose",
                format!(
                    "{} values, expected 12 (a row-major 3×4 matrix)",
                    tokens.len()
                ),
            ));
        }
        let mut v = [0.0; 12];
        for (i, tok) in tokens.iter().enumerate() {
            v[i] = parse_f64(path, line, &format!("value {} of 12", i + 1), tok)?;
        }
        let r = Matrix3::new(v[0], v[1], v[2], v[4], v[5], v[6], v[8], v[9], v[10]);
        let t = Vector3::new(v[3], v[7], v[11]);
        let pose = rigid_from_parts(&r, &t)
            .map_err(|reason| Error::parse(path, line, "rotation", reason))?;
        poses.push(pose);
    }
    Ok(poses)
}

/// Writes a pose file in the layout [`read_odometry_poses`] reads: one row-major 3×4 matrix
/// `[R | t]` per line, twelve values in scientific notation, atomically.
pub fn write_odometry_poses(path: impl AsRef<Path>, poses: &[Isometry3<f64>]) -> Result<()> {
    write_atomically(path.as_ref(), |w| {
        for pose in poses {
            let m = pose.to_homogeneous();
            let mut row = Vec::with_capacity(12);
            for r in 0..3 {
                for c in 0..4 {
                    row.push(format!("{:.9e}", m[(r, c)]));
                }
            }
            writeln!(w, "{}", row.join(" "))?;
        }
        Ok(())
    })
}

/// Reads `times.txt`: one time in seconds per non-blank line.
pub fn read_times(path: impl AsRef<Path>) -> Result<Vec<f64>> {
    let path = path.as_ref();
    let text = read_text(path)?;
    numbered_lines(&text)
        .map(|(line, l)| parse_f64(path, line, "time", l.trim()))
        .collect()
}

/// Velodyne poses from camera poses: V_k = Tr⁻¹·P_k·Tr, with `tr` mapping Velodyne to cam0
/// coordinates.
pub fn camera_to_velodyne_poses(
    camera_poses: &[Isometry3<f64>],
    tr: &Isometry3<f64>,
) -> Vec<Isometry3<f64>> {
    let tr_inv = tr.inverse();
    camera_poses.iter().map(|p| tr_inv * p * tr).collect()
}

/// One sequence `NN` of an odometry root folder.
#[derive(Clone, Debug)]
pub struct OdometrySequence {
    root: PathBuf,
    name: String,
    velodyne: ScanFolder,
}

impl OdometrySequence {
    /// Opens sequence `sequence` (formatted with two digits, e.g. `00`) of `root`.
    ///
    /// Errors: `ROOT/sequences/NN` does not exist (naming it). A missing `velodyne` folder is
    /// not an error here (poses and times can still be read).
    pub fn open(root: impl AsRef<Path>, sequence: u32) -> Result<OdometrySequence> {
        let root = root.as_ref().to_path_buf();
        let name = format!("{sequence:02}");
        let dir = root.join("sequences").join(&name);
        let meta = std::fs::metadata(&dir).map_err(|e| Error::io(&dir, e))?;
        if !meta.is_dir() {
            return Err(Error::invalid(
                format!("sequence folder {}", dir.display()),
                "is not a folder",
            ));
        }
        let velodyne = ScanFolder::open(dir.join("velodyne"), 6, "no scans")?;
        Ok(OdometrySequence {
            root,
            name,
            velodyne,
        })
    }

    /// The sequence name, e.g. `00`.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// `ROOT/sequences/NN`.
    pub fn dir(&self) -> PathBuf {
        self.root.join("sequences").join(&self.name)
    }

    /// `ROOT/sequences/NN/velodyne`.
    pub fn velodyne_dir(&self) -> PathBuf {
        self.dir().join("velodyne")
    }

    /// `ROOT/sequences/NN/calib.txt`.
    pub fn calib_path(&self) -> PathBuf {
        self.dir().join("calib.txt")
    }

    /// `ROOT/sequences/NN/times.txt`.
    pub fn times_path(&self) -> PathBuf {
        self.dir().join("times.txt")
    }

    /// `ROOT/poses/NN.txt`.
    pub fn poses_path(&self) -> PathBuf {
        self.root.join("poses").join(format!("{}.txt", self.name))
    }

    /// Number of Velodyne scans (0 without a `velodyne` folder).
    pub fn frame_count(&self) -> usize {
        self.velodyne.count()
    }

    /// The scans (`velodyne/`, `NNNNNN.bin`): their paths, reading them.
    pub fn scans(&self) -> &ScanFolder {
        &self.velodyne
    }

    /// The frame times, seconds.
    pub fn times(&self) -> Result<Vec<f64>> {
        read_times(self.times_path())
    }

    /// `Tr` of `calib.txt`: Velodyne → cam0 (p_cam = Tr·p_velo).
    pub fn velo_to_cam(&self) -> Result<Isometry3<f64>> {
        CalibFile::read(self.calib_path())?.rigid3x4("Tr")
    }

    /// The ground-truth cam0 poses of `poses/NN.txt`.
    pub fn camera_poses(&self) -> Result<Vec<Isometry3<f64>>> {
        read_odometry_poses(self.poses_path())
    }

    /// Velodyne poses V_k = Tr⁻¹·P_k·Tr (Velodyne frame k → Velodyne frame 0).
    pub fn velodyne_poses(&self) -> Result<Vec<Isometry3<f64>>> {
        let cams = self.camera_poses()?;
        let tr = self.velo_to_cam()?;
        Ok(camera_to_velodyne_poses(&cams, &tr))
    }

    /// Inconsistencies: missing folder or files, gaps in scan numbering, and counts of scans,
    /// times and poses that disagree (poses are optional: only sequences 00–10 have them).
    pub fn check(&self) -> Vec<Issue> {
        let mut issues = Vec::new();
        match self.velodyne.files() {
            None => issues.push(Issue::MissingFolder {
                path: self.velodyne_dir(),
                consequence: "no scans".into(),
            }),
            Some(files) => {
                for (first, last) in numbering_gaps(files.iter().map(|f| f.0)) {
                    issues.push(Issue::NumberingGap {
                        folder: self.velodyne_dir(),
                        first_missing: first,
                        last_missing: last,
                    });
                }
            }
        }
        if !self.calib_path().exists() {
            issues.push(Issue::MissingFile {
                path: self.calib_path(),
                consequence: "no Velodyne poses".into(),
            });
        } else if let Err(e) = self.velo_to_cam() {
            issues.push(Issue::Unreadable {
                path: self.calib_path(),
                error: e.to_string(),
            });
        }
        let mut counted = Vec::new();
        if let Some(files) = self.velodyne.files() {
            counted.push((self.velodyne_dir(), files.len()));
        }
        if !self.times_path().exists() {
            issues.push(Issue::MissingFile {
                path: self.times_path(),
                consequence: "no frame times".into(),
            });
        } else {
            match self.times() {
                Ok(t) => counted.push((self.times_path(), t.len())),
                Err(e) => issues.push(Issue::Unreadable {
                    path: self.times_path(),
                    error: e.to_string(),
                }),
            }
        }
        if self.poses_path().exists() {
            match self.camera_poses() {
                Ok(p) => counted.push((self.poses_path(), p.len())),
                Err(e) => issues.push(Issue::Unreadable {
                    path: self.poses_path(),
                    error: e.to_string(),
                }),
            }
        }
        for w in counted.windows(2) {
            if w[0].1 != w[1].1 {
                issues.push(Issue::CountMismatch {
                    a: w[0].0.clone(),
                    a_count: w[0].1,
                    b: w[1].0.clone(),
                    b_count: w[1].1,
                });
            }
        }
        issues
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn written_poses_read_back() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("00.txt");
        let poses = vec![
            Isometry3::identity(),
            Isometry3::new(
                Vector3::new(0.35, -0.01, 0.002),
                Vector3::new(0.001, 0.0, 0.01),
            ),
        ];
        write_odometry_poses(&p, &poses).unwrap();
        let back = read_odometry_poses(&p).unwrap();
        assert_eq!(back.len(), 2);
        assert_eq!(back[0], Isometry3::identity());
        let d = poses[1].inverse() * back[1];
        assert!(d.translation.vector.norm() < 1e-9 && d.rotation.angle() < 1e-9);
    }

    #[test]
    fn pose_line_errors() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("00.txt");
        std::fs::write(&p, "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1\n").unwrap();
        let msg = read_odometry_poses(&p).unwrap_err().to_string();
        assert!(msg.contains("00.txt:2: pose: 11 values"), "{msg}");
        std::fs::write(&p, "1 0 0 0 0 1 0 q 0 0 1 0\n").unwrap();
        let msg = read_odometry_poses(&p).unwrap_err().to_string();
        assert!(msg.contains("00.txt:1: value 8 of 12"), "{msg}");
        std::fs::write(&p, "1 0 0 0 0 1 0 0 0 0 3 0\n").unwrap();
        let msg = read_odometry_poses(&p).unwrap_err().to_string();
        assert!(msg.contains("00.txt:1: rotation"), "{msg}");
    }

    #[test]
    fn conjugation_by_tr() {
        // Tr: velo x → cam z, velo y → cam −x, velo z → cam −y; plus an offset.
        let r = Matrix3::new(0.0, -1.0, 0.0, 0.0, 0.0, -1.0, 1.0, 0.0, 0.0);
        let tr = rigid_from_parts(&r, &Vector3::new(0.1, -0.2, 0.3)).unwrap();
        let p = Isometry3::translation(0.0, 0.0, 2.0); // 2 m along the camera's optical axis
        let v = camera_to_velodyne_poses(&[p], &tr);
        assert!((v[0].translation.vector - Vector3::new(2.0, 0.0, 0.0)).norm() < 1e-12);
        assert!(v[0].rotation.angle() < 1e-12);
    }
}
