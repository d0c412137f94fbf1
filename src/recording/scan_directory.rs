//! [`ScanDirectory`]: a plain folder of lidar scans from any sensor, `.bin` (KITTI's float32
//! x, y, z, intensity) or `.pcd` files taken in file-name order, one frame each, with an
//! optional pose file (one row-major 3 × 4 sensor pose per line, KITTI's odometry layout) and
//! an optional time file (one time in seconds per line).
//!
//! Everything is checked when the folder is opened, so a run never starts on a recording that
//! cannot finish: no scan, `.bin` and `.pcd` mixed, a malformed pose or time line (file and
//! line named), fewer poses or times than scans.
//!
//! Not for: KITTI's own layouts (see [`crate::kitti`]), which number their files.

use super::Recording;
use crate::cloud::{read_scan_with, PointCloud};
use crate::error::{Error, Result};
use crate::kitti::odometry::{read_odometry_poses, read_times};
use nalgebra::Isometry3;
use std::path::{Path, PathBuf};

/// A folder of scans (module documentation).
#[derive(Clone, Debug)]
pub struct ScanDirectory {
    dir: PathBuf,
    scans: Vec<PathBuf>,
    poses: Option<(PathBuf, Vec<Isometry3<f64>>)>,
    times: Option<Vec<f64>>,
    sensor_height: Option<f64>,
}

impl ScanDirectory {
    /// The `.bin` or the `.pcd` files of `dir` in file-name order. Errors name the folder
    /// when it cannot be read, holds no scan, or holds both kinds.
    pub fn open(dir: impl AsRef<Path>) -> Result<ScanDirectory> {
        let dir = dir.as_ref();
        let io = |e: std::io::Error| Error::io(dir, e);
        let (mut bin, mut pcd) = (Vec::new(), Vec::new());
        for entry in std::fs::read_dir(dir).map_err(io)? {
            let path = entry.map_err(io)?.path();
            if !path.is_file() {
                continue;
            }
            let ext = path.extension().map(|e| e.to_string_lossy().to_lowercase());
            match ext.as_deref() {
                Some("bin") => bin.push(path),
                Some("pcd") => pcd.push(path),
                _ => {}
            }
        }
        let what = || format!("scan folder {}", dir.display());
        let mut scans = match (bin.is_empty(), pcd.is_empty()) {
            (true, true) => return Err(Error::invalid(what(), "holds no .bin or .pcd scans")),
            (false, false) => {
                return Err(Error::invalid(
                    what(),
                    format!(
                        "holds both .bin ({}) and .pcd ({}) scans; keep one kind",
                        bin.len(),
                        pcd.len()
                    ),
                ))
            }
            (false, true) => bin,
            (true, false) => pcd,
        };
        scans.sort();
        Ok(ScanDirectory {
            dir: dir.to_path_buf(),
            scans,
            poses: None,
            times: None,
            sensor_height: None,
        })
    }

    /// The same folder with the sensor poses of `path` (one row-major 3 × 4 matrix per line,
    /// sensor → world). Errors name the file and line of a malformed pose, or the file when it
    /// has fewer poses than there are scans.
    pub fn with_poses(mut self, path: impl AsRef<Path>) -> Result<ScanDirectory> {
        let path = path.as_ref();
        let poses = read_odometry_poses(path)?;
        if poses.len() < self.scans.len() {
            return Err(Error::invalid(
                format!("pose file {}", path.display()),
                format!("has {} poses for {} scans", poses.len(), self.scans.len()),
            ));
        }
        self.poses = Some((path.to_path_buf(), poses));
        Ok(self)
    }

    /// The same folder with the frame times of `path` (seconds, one per line, not
    /// decreasing). Errors name the file and line of a malformed or decreasing time, or the
    /// file when it has fewer times than there are scans.
    pub fn with_times(mut self, path: impl AsRef<Path>) -> Result<ScanDirectory> {
        let path = path.as_ref();
        let times = read_times(path)?;
        if times.len() < self.scans.len() {
            return Err(Error::invalid(
                format!("time file {}", path.display()),
                format!("has {} times for {} scans", times.len(), self.scans.len()),
            ));
        }
        if let Some(k) = times.windows(2).position(|w| w[1] < w[0]) {
            return Err(Error::parse(
                path,
                k + 2,
                "time",
                format!(
                    "{} is earlier than the line before ({})",
                    times[k + 1],
                    times[k]
                ),
            ));
        }
        self.times = Some(times);
        Ok(self)
    }

    /// The same folder with the sensor's height over the road (m), which the tracker uses
    /// where a frame has no ground plane ([`Recording::sensor_height`]); a height that is not
    /// finite and positive is an error.
    pub fn with_sensor_height(mut self, height: f64) -> Result<ScanDirectory> {
        if !(height.is_finite() && height > 0.0) {
            return Err(Error::invalid(
                format!("sensor height of {}", self.describe()),
                format!("must be finite and positive, got {height}"),
            ));
        }
        self.sensor_height = Some(height);
        Ok(self)
    }

    /// The folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The scan files, in frame order.
    pub fn scan_paths(&self) -> &[PathBuf] {
        &self.scans
    }
}

impl Recording for ScanDirectory {
    fn name(&self) -> String {
        super::folder_name(&self.dir)
    }
    fn describe(&self) -> String {
        format!("scan folder {}", self.dir.display())
    }
    fn frame_count(&self) -> usize {
        self.scans.len()
    }
    /// The scan. A PCD file's points with a non-finite value are left out (organised clouds
    /// mark missing returns so); in a `.bin` file such a point is an error naming the file.
    fn scan(&self, k: usize) -> Result<PointCloud> {
        let path = self.scans.get(k).ok_or_else(|| {
            Error::invalid(
                self.describe(),
                format!("has no frame {k} ({} scans)", self.scans.len()),
            )
        })?;
        Ok(read_scan_with(path, super::non_finite_policy(path))?.cloud)
    }
    fn scan_name(&self, k: usize) -> String {
        match self.scans.get(k) {
            Some(p) => p.display().to_string(),
            None => format!("frame {k} of {}", self.describe()),
        }
    }
    fn scan_dir(&self) -> Option<PathBuf> {
        Some(self.dir.clone())
    }
    fn times(&self) -> Result<Option<Vec<f64>>> {
        Ok(self.times.clone())
    }
    fn has_poses(&self) -> bool {
        self.poses.is_some()
    }
    fn sensor_height(&self) -> Option<f64> {
        self.sensor_height
    }
    fn poses(&self) -> Result<Vec<Isometry3<f64>>> {
        match &self.poses {
            Some((_, p)) => Ok(p.clone()),
            None => Err(Error::invalid(
                self.describe(),
                "has no pose file (give one, or use lidar odometry)",
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cloud::write_kitti_bin;

    fn folder(name: &str) -> PathBuf {
        let d =
            std::env::temp_dir().join(format!("smc_lmb_scan_dir_{name}_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn cloud(x: f32) -> PointCloud {
        let mut c = PointCloud::default();
        c.push(x, 1.0, 0.5, 0.25);
        c.push(x + 1.0, 2.0, 0.5, 0.5);
        c
    }

    #[test]
    fn scans_in_name_order_with_poses_and_times() {
        let d = folder("ok");
        for (name, x) in [("b.bin", 2.0), ("a.bin", 1.0), ("c.bin", 3.0)] {
            write_kitti_bin(d.join(name), &cloud(x)).unwrap();
        }
        std::fs::write(d.join("notes.txt"), "ignored").unwrap();
        let pose = "1 0 0 0 0 1 0 0 0 0 1 0\n";
        std::fs::write(d.join("poses.txt"), pose.repeat(3)).unwrap();
        std::fs::write(d.join("times.txt"), "0.0\n0.1\n0.25\n").unwrap();
        let r = ScanDirectory::open(&d)
            .unwrap()
            .with_poses(d.join("poses.txt"))
            .unwrap()
            .with_times(d.join("times.txt"))
            .unwrap();
        assert_eq!(r.frame_count(), 3);
        assert!(r.has_scan(2) && !r.has_scan(3));
        assert_eq!(r.scan(0).unwrap().xs()[0], 1.0);
        assert_eq!(r.scan(2).unwrap().xs()[0], 3.0);
        assert_eq!(r.times().unwrap(), Some(vec![0.0, 0.1, 0.25]));
        assert_eq!(r.poses().unwrap().len(), 3);
        assert!(!r.has_vehicle() && r.vehicle().is_err());
        assert!(r.scan(3).unwrap_err().to_string().contains("no frame 3"));
    }

    #[test]
    fn bad_folders_and_files_are_named() {
        let empty = folder("empty");
        let e = ScanDirectory::open(&empty).unwrap_err().to_string();
        assert!(
            e.contains("no .bin or .pcd") && e.contains("smc_lmb_scan_dir_empty"),
            "{e}"
        );
        let mixed = folder("mixed");
        write_kitti_bin(mixed.join("0.bin"), &cloud(0.0)).unwrap();
        std::fs::write(mixed.join("1.pcd"), "").unwrap();
        let e = ScanDirectory::open(&mixed).unwrap_err().to_string();
        assert!(e.contains("both .bin (1) and .pcd (1)"), "{e}");
        let d = folder("short");
        for k in 0..3 {
            write_kitti_bin(d.join(format!("{k}.bin")), &cloud(k as f32)).unwrap();
        }
        let pose = "1 0 0 0 0 1 0 0 0 0 1 0\n";
        std::fs::write(d.join("two.txt"), pose.repeat(2)).unwrap();
        let e = ScanDirectory::open(&d)
            .unwrap()
            .with_poses(d.join("two.txt"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("two.txt") && e.contains("2 poses for 3 scans"),
            "{e}"
        );
        std::fs::write(d.join("bad.txt"), format!("{pose}1 0 0\n{pose}")).unwrap();
        let e = ScanDirectory::open(&d)
            .unwrap()
            .with_poses(d.join("bad.txt"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("bad.txt:2"), "{e}");
        std::fs::write(d.join("t.txt"), "0\n0.2\n0.1\n").unwrap();
        let e = ScanDirectory::open(&d)
            .unwrap()
            .with_times(d.join("t.txt"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("t.txt:3") && e.contains("earlier"), "{e}");
        let r = ScanDirectory::open(&d).unwrap();
        assert!(!r.has_poses());
        assert!(r.poses().unwrap_err().to_string().contains("no pose file"));
        assert_eq!(r.times().unwrap(), None);
        // a truncated scan is an error naming its file
        std::fs::write(d.join("1.bin"), [0u8; 7]).unwrap();
        let e = r.scan(1).unwrap_err().to_string();
        assert!(e.contains("1.bin"), "{e}");
    }
}
