//! The KITTI tracking benchmark layout ([`TrackingSequence`]):
//!
//! ```text
//! ROOT/                       the split folder, `training` or `testing`
//!   velodyne/NNNN/000000.bin ...   Velodyne scans (.bin, see crate::cloud), six-digit names
//!   oxts/NNNN.txt                  one OXTS packet line per frame (30 values, see super::oxts)
//!   calib/NNNN.txt                 P0..P3, R_rect, Tr_velo_cam, Tr_imu_velo ([`TrackingCalib`])
//!   label_02/NNNN.txt              tracking labels (training only, see super::labels)
//! ```
//!
//! The sequences are cut out of the raw drives (sequence 0000 is raw drive 2011_09_26_0005
//! frame for frame), and poses, Velodyne poses and vehicle states are computed exactly as
//! [`super::drive::RawDrive`] computes them, from the OXTS packets and `Tr_imu_velo` with
//! [`super::poses`]. The layout keeps no time stamps: frame k is taken at k·[`FRAME_PERIOD`]
//! (the recordings' 10 Hz). A scan missing inside the numbering is a dropped scan (sequence
//! 0001 has none for frames 177–180, whose OXTS lines and labels are there): the sequence's
//! frames are those the scans span, and [`TrackingSequence::scans`] tells which have one.
//!
//! Opening lists the scans only; everything else is read when asked for. [`TrackingSequence::check`]
//! reports every inconsistency at once.
//!
//! Not for: camera images, the raw layout (see [`super::drive`]) or the odometry layout (see
//! [`super::odometry`]).

use super::calib::{rigid_from_parts, CalibEntry, CalibFile};
use super::frames::{numbering_gaps, ScanFolder};
use super::issue::Issue;
use super::labels::{read_tracking_labels, TrackingLabel};
use super::oxts::OxtsPacket;
use super::poses::{self, VehicleState};
use super::text::{numbered_lines, read_text};
use crate::error::{Error, Result};
use nalgebra::{Isometry3, Matrix3, Matrix3x4, Point3, Translation3, UnitQuaternion, Vector3};
use std::path::{Path, PathBuf};

/// Time between frames of the tracking layout, which keeps no time stamps (s).
pub const FRAME_PERIOD: f64 = 0.1;

/// The calibration of one tracking sequence (`calib/NNNN.txt`). Lines are `key values` or
/// `key: values`; the keys of the tracking benchmark and of the object benchmark are both
/// accepted (`R_rect`/`R0_rect`, `Tr_velo_cam`/`Tr_velo_to_cam`, `Tr_imu_velo`/`Tr_imu_to_velo`).
#[derive(Clone, Debug, PartialEq)]
pub struct TrackingCalib {
    /// The file read.
    pub path: PathBuf,
    /// Projections P0..P3 of rectified camera-0 coordinates to the images of cameras 0..3.
    pub projections: [Matrix3x4<f64>; 4],
    /// The rectifying rotation as printed (row-major in the file).
    pub r_rect: Matrix3<f64>,
    /// Velodyne → camera 0 (unrectified): p_cam = Tr_velo_cam·p_velo.
    pub velo_to_cam: Isometry3<f64>,
    /// IMU → Velodyne: p_velo = Tr_imu_velo·p_imu (the raw layout's `calib_imu_to_velo.txt`).
    pub imu_to_velo: Isometry3<f64>,
    /// `r_rect` snapped to the nearest rotation.
    rect: UnitQuaternion<f64>,
}

/// Width and height (pixels) of KITTI's rectified camera images; the sequences' images differ
/// from it by a few pixels at most.
pub const IMAGE_SIZE: [f64; 2] = [1242.0, 375.0];

/// The accepted spellings of each key, the first being the one in error messages.
const KEYS_R_RECT: [&str; 2] = ["R_rect", "R0_rect"];
const KEYS_VELO_CAM: [&str; 2] = ["Tr_velo_cam", "Tr_velo_to_cam"];
const KEYS_IMU_VELO: [&str; 2] = ["Tr_imu_velo", "Tr_imu_to_velo"];

impl TrackingCalib {
    /// Reads a tracking calibration file; errors name the file, the line and the key (a
    /// wrong number of values, a value that is not a number, a matrix that is not a rotation),
    /// or line 0 and the key when a key is missing.
    pub fn read(path: impl AsRef<Path>) -> Result<TrackingCalib> {
        let path = path.as_ref();
        let text = read_text(path)?;
        TrackingCalib::parse(path, &text)
    }

    /// Parses calibration text; `path` is used in error messages.
    pub fn parse(path: &Path, text: &str) -> Result<TrackingCalib> {
        let entries = numbered_lines(text)
            .map(|(line, l)| {
                let l = l.trim_start();
                let (key, rest) = l.split_at(l.find(char::is_whitespace).unwrap_or(l.len()));
                // `P0:` and `P0` alike; a colon glued to the first value (`P0:7.2`) too.
                let (key, rest) = match key.split_once(':') {
                    Some((k, glued)) => (k, format!("{glued} {rest}")),
                    None => (key, rest.to_string()),
                };
                CalibEntry {
                    key: key.to_string(),
                    line,
                    text: rest.trim().to_string(),
                }
            })
            .collect();
        let file = CalibFile {
            path: path.to_path_buf(),
            entries,
        };
        let key = |names: [&'static str; 2]| -> Result<&'static str> {
            names
                .into_iter()
                .find(|k| file.get(k).is_some())
                .ok_or_else(|| {
                    Error::parse(
                        path,
                        0,
                        names[0],
                        format!("missing (nor is there a line `{}`)", names[1]),
                    )
                })
        };
        let mut projections = [Matrix3x4::zeros(); 4];
        for (i, p) in projections.iter_mut().enumerate() {
            let name = format!("P{i}");
            if file.get(&name).is_none() {
                return Err(Error::parse(path, 0, name, "missing"));
            }
            *p = file.matrix3x4(&name)?;
        }
        let r_key = key(KEYS_R_RECT)?;
        let r_rect = file.matrix3(r_key)?;
        let r_line = file.get(r_key).map_or(0, |e| e.line);
        let rect = rigid_from_parts(&r_rect, &Vector3::zeros())
            .map_err(|reason| Error::parse(path, r_line, r_key, reason))?
            .rotation;
        let velo_to_cam = file.rigid3x4(key(KEYS_VELO_CAM)?)?;
        let imu_to_velo = file.rigid3x4(key(KEYS_IMU_VELO)?)?;
        Ok(TrackingCalib {
            path: path.to_path_buf(),
            projections,
            r_rect,
            velo_to_cam,
            imu_to_velo,
            rect,
        })
    }

    /// Velodyne → rectified camera 0, the frame of the labels' boxes:
    /// p_rect = R_rect·Tr_velo_cam·p_velo.
    pub fn rect_from_velo(&self) -> Isometry3<f64> {
        Isometry3::from_parts(Translation3::identity(), self.rect) * self.velo_to_cam
    }

    /// Rectified camera 0 → Velodyne, the inverse of [`rect_from_velo`](Self::rect_from_velo).
    pub fn velo_from_rect(&self) -> Isometry3<f64> {
        self.rect_from_velo().inverse()
    }

    /// Velodyne → rectified camera 2: rectified camera 0 shifted by camera 2's offset read off
    /// `P2 = K·[I | t]` (t = (P2₀₃ − c_x·t_z, P2₁₃ − c_y·t_z)/f, t_z = P2₂₃ with K's focal
    /// lengths f and centre c), so that P2·p_rect = K·p_cam2.
    pub fn cam2_rect_from_velo(&self) -> Isometry3<f64> {
        let p = &self.projections[2];
        let tz = p[(2, 3)];
        let tx = (p[(0, 3)] - p[(0, 2)] * tz) / p[(0, 0)];
        let ty = (p[(1, 3)] - p[(1, 2)] * tz) / p[(1, 1)];
        Isometry3::from_parts(Translation3::new(tx, ty, tz), UnitQuaternion::identity())
            * self.rect_from_velo()
    }

    /// The pixel of camera 2 (the labels' image) at which a Velodyne point appears,
    /// P2·R_rect·Tr_velo_cam·p; `None` for a point not in front of the camera.
    pub fn project_to_image2(&self, p_velo: &Point3<f64>) -> Option<[f64; 2]> {
        let q = self.rect_from_velo() * p_velo;
        if q.z <= 0.0 {
            return None;
        }
        let u = self.projections[2] * q.to_homogeneous();
        (u.z > 0.0).then(|| [u.x / u.z, u.y / u.z])
    }

    /// Whether a Velodyne point appears inside camera 2's image of [`IMAGE_SIZE`] (in front of
    /// the camera).
    pub fn in_image2(&self, p_velo: &Point3<f64>) -> bool {
        self.project_to_image2(p_velo).is_some_and(|[u, v]| {
            (0.0..IMAGE_SIZE[0]).contains(&u) && (0.0..IMAGE_SIZE[1]).contains(&v)
        })
    }

    /// The calibration as a file in the tracking layout (keys without colons, 12 significant
    /// digits, as KITTI writes it).
    pub fn to_text(&self) -> String {
        let row = |v: &[f64]| {
            v.iter()
                .map(|x| format!("{x:.12e}"))
                .collect::<Vec<_>>()
                .join(" ")
        };
        let rigid = |t: &Isometry3<f64>| {
            let m = t.to_homogeneous();
            let mut v = Vec::with_capacity(12);
            for r in 0..3 {
                for c in 0..4 {
                    v.push(m[(r, c)]);
                }
            }
            row(&v)
        };
        let mut out = String::new();
        for (i, p) in self.projections.iter().enumerate() {
            let v: Vec<f64> = (0..3)
                .flat_map(|r| (0..4).map(move |c| p[(r, c)]))
                .collect();
            out.push_str(&format!("P{i}: {}\n", row(&v)));
        }
        let r: Vec<f64> = (0..3)
            .flat_map(|i| (0..3).map(move |j| (i, j)))
            .map(|(i, j)| self.r_rect[(i, j)])
            .collect();
        out.push_str(&format!("R_rect {}\n", row(&r)));
        out.push_str(&format!("Tr_velo_cam {}\n", rigid(&self.velo_to_cam)));
        out.push_str(&format!("Tr_imu_velo {}\n", rigid(&self.imu_to_velo)));
        out
    }
}

/// One sequence `NNNN` of a tracking split folder.
#[derive(Clone, Debug)]
pub struct TrackingSequence {
    root: PathBuf,
    name: String,
    /// `velodyne/NNNN`, as listed when opened.
    velodyne: ScanFolder,
}

impl TrackingSequence {
    /// Opens sequence `sequence` (formatted with four digits, e.g. `0000`) of the split folder
    /// `root` (`.../training` or `.../testing`) and lists its scans.
    ///
    /// Errors: `root` does not exist or is not a folder, or the scan folder cannot be listed.
    /// A missing scan folder is not an error here (see [`check`](Self::check)).
    pub fn open(root: impl AsRef<Path>, sequence: u32) -> Result<TrackingSequence> {
        let root = root.as_ref().to_path_buf();
        let meta = std::fs::metadata(&root).map_err(|e| Error::io(&root, e))?;
        if !meta.is_dir() {
            return Err(Error::invalid(
                format!("tracking folder {}", root.display()),
                "is not a folder",
            ));
        }
        let name = format!("{sequence:04}");
        let velodyne = ScanFolder::open(root.join("velodyne").join(&name), 6, "no scans")?;
        Ok(TrackingSequence {
            root,
            name,
            velodyne,
        })
    }

    /// The split folder handed to [`open`](Self::open).
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// The sequence name, e.g. `0000`.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// `ROOT/velodyne/NNNN`.
    pub fn velodyne_dir(&self) -> PathBuf {
        self.root.join("velodyne").join(&self.name)
    }

    /// `ROOT/oxts/NNNN.txt`.
    pub fn oxts_path(&self) -> PathBuf {
        self.root.join("oxts").join(format!("{}.txt", self.name))
    }

    /// `ROOT/calib/NNNN.txt`.
    pub fn calib_path(&self) -> PathBuf {
        self.root.join("calib").join(format!("{}.txt", self.name))
    }

    /// `ROOT/label_02/NNNN.txt`.
    pub fn labels_path(&self) -> PathBuf {
        self.root
            .join("label_02")
            .join(format!("{}.txt", self.name))
    }

    /// Whether `velodyne/NNNN` exists.
    pub fn has_velodyne(&self) -> bool {
        self.velodyne.exists()
    }

    /// Whether `oxts/NNNN.txt` exists.
    pub fn has_oxts(&self) -> bool {
        self.oxts_path().is_file()
    }

    /// Whether `label_02/NNNN.txt` exists (the testing split has none).
    pub fn has_labels(&self) -> bool {
        self.labels_path().is_file()
    }

    /// Number of scans in `velodyne/NNNN` (0 when the folder is missing).
    pub fn velodyne_count(&self) -> usize {
        self.velodyne.count()
    }

    /// Number of packets in `oxts/NNNN.txt`, whatever the number of scans (0 when the file is
    /// missing or does not parse).
    pub fn oxts_count(&self) -> usize {
        self.read_packets().map_or(0, |p| p.len())
    }

    /// Number of frames: the frames the scans span when `velodyne/NNNN` exists (the last
    /// scan's number + 1, dropped scans inside the numbering included; see
    /// [`ScanFolder::has_scan`]), otherwise the OXTS packets (0 when neither can be read).
    pub fn frame_count(&self) -> usize {
        self.velodyne.extent_or(|| self.oxts_count())
    }

    /// The scans (`velodyne/NNNN`, `NNNNNN.bin`): which frames have one
    /// ([`ScanFolder::has_scan`]; KITTI's sequence 0001 has none for frames 177–180, its raw
    /// drive dropped them, while their OXTS lines and labels are there), their paths, reading
    /// them.
    pub fn scans(&self) -> &ScanFolder {
        &self.velodyne
    }

    /// Every packet of the OXTS file, whatever the number of scans.
    fn read_packets(&self) -> Result<Vec<OxtsPacket>> {
        let path = self.oxts_path();
        let text = read_text(&path)?;
        numbered_lines(&text)
            .map(|(line, l)| OxtsPacket::parse_line(l, &path, line))
            .collect()
    }

    /// Reads the OXTS packets, one per frame.
    ///
    /// Errors: the file is missing ([`Error::Io`] naming it), a line is malformed (naming
    /// file, line and field), or the number of packets differs from the number of scans
    /// (naming the file and the line of the first missing or first extra packet).
    pub fn oxts(&self) -> Result<Vec<OxtsPacket>> {
        let packets = self.read_packets()?;
        if self.has_velodyne() {
            let n = self.frame_count();
            let path = self.oxts_path();
            if packets.len() < n {
                return Err(Error::parse(
                    path,
                    packets.len() + 1,
                    "packet",
                    format!(
                        "missing: {} packets for the {n} frames the scans in {} span",
                        packets.len(),
                        self.velodyne_dir().display()
                    ),
                ));
            }
            if packets.len() > n {
                let text = read_text(&path)?;
                let line = numbered_lines(&text).nth(n).map_or(0, |(line, _)| line);
                return Err(Error::parse(
                    path,
                    line,
                    "packet",
                    format!(
                        "{} packets for the {n} frames the scans in {} span",
                        packets.len(),
                        self.velodyne_dir().display()
                    ),
                ));
            }
        }
        Ok(packets)
    }

    /// The frame times, s: k·[`FRAME_PERIOD`] for every frame (the layout keeps no stamps).
    pub fn times(&self) -> Vec<f64> {
        (0..self.frame_count())
            .map(|k| k as f64 * FRAME_PERIOD)
            .collect()
    }

    /// The calibration (`calib/NNNN.txt`).
    pub fn calib(&self) -> Result<TrackingCalib> {
        TrackingCalib::read(self.calib_path())
    }

    /// IMU poses relative to the first packet (first = identity), one per frame; see
    /// [`poses::imu_poses`].
    pub fn imu_poses(&self) -> Result<Vec<Isometry3<f64>>> {
        poses::imu_poses(&self.oxts()?)
    }

    /// Velodyne poses relative to the first Velodyne frame (first = identity), one per frame:
    /// pose k maps Velodyne coordinates of frame k to those of frame 0 (as
    /// [`RawDrive::poses`](super::RawDrive::poses), with `Tr_imu_velo`).
    pub fn poses(&self) -> Result<Vec<Isometry3<f64>>> {
        let imu = self.imu_poses()?;
        let calib = self.calib()?;
        Ok(poses::velodyne_poses(&imu, &calib.imu_to_velo))
    }

    /// Planar vehicle states [X, Ẋ, Y, Ẏ, φ, φ̇], one per frame; see [`VehicleState`].
    pub fn vehicle_states(&self) -> Result<Vec<VehicleState>> {
        poses::vehicle_states(&self.oxts()?)
    }

    /// The labels (`label_02/NNNN.txt`).
    ///
    /// Errors: the file is missing or malformed (naming file, line and field), or a label
    /// lies in a frame beyond the scans (naming the file and the first such line).
    pub fn labels(&self) -> Result<Vec<TrackingLabel>> {
        let path = self.labels_path();
        let labels = read_tracking_labels(&path)?;
        if self.has_velodyne() {
            let n = self.frame_count();
            if let Some(l) = labels.iter().find(|l| l.frame >= n) {
                let text = read_text(&path)?;
                let line = numbered_lines(&text)
                    .find(|(_, t)| {
                        t.split_whitespace()
                            .next()
                            .and_then(|f| f.parse::<usize>().ok())
                            .is_some_and(|f| f >= n)
                    })
                    .map_or(0, |(line, _)| line);
                return Err(Error::parse(
                    path,
                    line,
                    "frame",
                    format!(
                        "label of frame {} but the scans in {} span {n} frames",
                        l.frame,
                        self.velodyne_dir().display()
                    ),
                ));
            }
        }
        Ok(labels)
    }

    /// Every inconsistency of the sequence on disk: missing scan folder, OXTS or calibration
    /// file; dropped scans inside the numbering ([`Issue::DroppedScans`]); an OXTS file, calibration or label file that does not
    /// parse; OXTS packets or label frames that disagree with the scans; `.bin` files whose
    /// size is not a multiple of 16 bytes. A missing label file is not an issue (the testing
    /// split has none). An empty list means the sequence is consistent.
    pub fn check(&self) -> Vec<Issue> {
        let mut issues = Vec::new();
        match self.velodyne.files() {
            None => issues.push(Issue::MissingFolder {
                path: self.velodyne_dir(),
                consequence: "no point clouds".into(),
            }),
            Some(files) => {
                for (first, last) in numbering_gaps(files.iter().map(|f| f.0)) {
                    issues.push(Issue::DroppedScans {
                        folder: self.velodyne_dir(),
                        first,
                        last,
                    });
                }
                self.velodyne.check_sizes(&mut issues);
            }
        }
        if !self.has_oxts() {
            issues.push(Issue::MissingFile {
                path: self.oxts_path(),
                consequence: "no OXTS packets, so no poses (point clouds only)".into(),
            });
        } else {
            match self.read_packets() {
                Err(e) => issues.push(Issue::Unreadable {
                    path: self.oxts_path(),
                    error: e.to_string(),
                }),
                Ok(p) if self.has_velodyne() && p.len() != self.frame_count() => {
                    issues.push(Issue::CountMismatch {
                        a: self.velodyne_dir(),
                        a_count: self.frame_count(),
                        b: self.oxts_path(),
                        b_count: p.len(),
                    })
                }
                Ok(_) => {}
            }
        }
        if !self.calib_path().exists() {
            issues.push(Issue::MissingFile {
                path: self.calib_path(),
                consequence: "no Velodyne poses and no camera transform".into(),
            });
        } else if let Err(e) = self.calib() {
            issues.push(Issue::Unreadable {
                path: self.calib_path(),
                error: e.to_string(),
            });
        }
        if self.has_labels() {
            match read_tracking_labels(self.labels_path()) {
                Err(e) => issues.push(Issue::Unreadable {
                    path: self.labels_path(),
                    error: e.to_string(),
                }),
                Ok(labels) => {
                    let frames = super::labels::label_frame_count(&labels);
                    if self.has_velodyne() && frames > self.frame_count() {
                        issues.push(Issue::CountMismatch {
                            a: self.labels_path(),
                            a_count: frames,
                            b: self.velodyne_dir(),
                            b_count: self.frame_count(),
                        });
                    }
                }
            }
        }
        issues
    }

    /// [`check`](Self::check), stopping with the first issue as an error.
    pub fn ensure_consistent(&self) -> Result<()> {
        Issue::first_as_error(&self.check())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first seven lines of the real `calib/0000.txt` (P lines with colons, the others
    /// without, as KITTI ships it).
    const CALIB_0000: &str = "\
P0: 7.215377000000e+02 0.000000000000e+00 6.095593000000e+02 0.000000000000e+00 0.000000000000e+00 7.215377000000e+02 1.728540000000e+02 0.000000000000e+00 0.000000000000e+00 0.000000000000e+00 1.000000000000e+00 0.000000000000e+00
P1: 7.215377000000e+02 0.000000000000e+00 6.095593000000e+02 -3.875744000000e+02 0.000000000000e+00 7.215377000000e+02 1.728540000000e+02 0.000000000000e+00 0.000000000000e+00 0.000000000000e+00 1.000000000000e+00 0.000000000000e+00
P2: 7.215377000000e+02 0.000000000000e+00 6.095593000000e+02 4.485728000000e+01 0.000000000000e+00 7.215377000000e+02 1.728540000000e+02 2.163791000000e-01 0.000000000000e+00 0.000000000000e+00 1.000000000000e+00 2.745884000000e-03
P3: 7.215377000000e+02 0.000000000000e+00 6.095593000000e+02 -3.395242000000e+02 0.000000000000e+00 7.215377000000e+02 1.728540000000e+02 2.199936000000e+00 0.000000000000e+00 0.000000000000e+00 1.000000000000e+00 2.729905000000e-03
R_rect 9.999239000000e-01 9.837760000000e-03 -7.445048000000e-03 -9.869795000000e-03 9.999421000000e-01 -4.278459000000e-03 7.402527000000e-03 4.351614000000e-03 9.999631000000e-01
Tr_velo_cam 7.533745000000e-03 -9.999714000000e-01 -6.166020000000e-04 -4.069766000000e-03 1.480249000000e-02 7.280733000000e-04 -9.998902000000e-01 -7.631618000000e-02 9.998621000000e-01 7.523790000000e-03 1.480755000000e-02 -2.717806000000e-01
Tr_imu_velo 9.999976000000e-01 7.553071000000e-04 -2.035826000000e-03 -8.086759000000e-01 -7.854027000000e-04 9.998898000000e-01 -1.482298000000e-02 3.195559000000e-01 2.024406000000e-03 1.482454000000e-02 9.998881000000e-01 -7.997231000000e-01
";

    #[test]
    fn parses_the_real_calibration() {
        let c = TrackingCalib::parse(Path::new("calib/0000.txt"), CALIB_0000).unwrap();
        assert_eq!(c.projections[2][(0, 3)], 4.485728e+01);
        assert_eq!(c.r_rect[(0, 1)], 9.83776e-03);
        assert!((c.velo_to_cam.translation.vector.z + 0.2717806).abs() < 1e-12);
        assert!((c.imu_to_velo.translation.vector.x + 0.8086759).abs() < 1e-12);
        // A point 10 m ahead of the Velodyne is about 9.73 m ahead of the camera (Tr puts the camera 0.27 m ahead) and near the
        // image centre column.
        let q = c.rect_from_velo() * Point3::new(10.0, 0.0, 0.0);
        assert!((q.z - 9.73).abs() < 0.02, "{q}");
        let uv = c.project_to_image2(&Point3::new(10.0, 0.0, 0.0)).unwrap();
        assert!((uv[0] - 620.0).abs() < 30.0, "{uv:?}");
        assert!(c.project_to_image2(&Point3::new(-10.0, 0.0, 0.0)).is_none());
        assert!(c.in_image2(&Point3::new(10.0, 0.0, 0.0)));
        assert!(!c.in_image2(&Point3::new(10.0, 30.0, 0.0)));
        assert!(!c.in_image2(&Point3::new(-10.0, 0.0, 0.0)));
        // Camera 2 sits about 6 cm left of camera 0 (t_x ≈ +0.06 m in its coordinates), and
        // its intrinsics applied to cam2 coordinates give P2's pixel.
        let c2 = c.cam2_rect_from_velo() * Point3::new(10.0, 0.0, 0.0);
        assert!((c2.x - q.x - 0.06).abs() < 0.005, "{c2} {q}");
        let (f, cx, cy) = (
            c.projections[2][(0, 0)],
            c.projections[2][(0, 2)],
            c.projections[2][(1, 2)],
        );
        assert!((f * c2.x / c2.z + cx - uv[0]).abs() < 1e-9);
        assert!((f * c2.y / c2.z + cy - uv[1]).abs() < 1e-9);
        let back = c.velo_from_rect() * q;
        assert!((back - Point3::new(10.0, 0.0, 0.0)).norm() < 1e-12);
        // Written and read back: the same transforms.
        let again = TrackingCalib::parse(Path::new("x"), &c.to_text()).unwrap();
        assert!(
            (again.rect_from_velo().to_homogeneous() - c.rect_from_velo().to_homogeneous())
                .abs()
                .max()
                < 1e-11
        );
    }

    #[test]
    fn object_benchmark_keys_and_colons_are_accepted() {
        let text = CALIB_0000
            .replace("R_rect ", "R0_rect: ")
            .replace("Tr_velo_cam ", "Tr_velo_to_cam: ")
            .replace("Tr_imu_velo ", "Tr_imu_to_velo: ");
        let a = TrackingCalib::parse(Path::new("a"), CALIB_0000).unwrap();
        let b = TrackingCalib::parse(Path::new("b"), &text).unwrap();
        assert_eq!(a.rect_from_velo(), b.rect_from_velo());
        assert_eq!(a.imu_to_velo, b.imu_to_velo);
    }

    #[test]
    fn calibration_errors_name_line_and_key() {
        let p = Path::new("calib/0000.txt");
        let short = CALIB_0000.replace(" 9.999631000000e-01", "");
        let msg = TrackingCalib::parse(p, &short).unwrap_err().to_string();
        assert_eq!(msg, "calib/0000.txt:5: R_rect: 8 values, expected 9");
        let missing: String = CALIB_0000
            .lines()
            .filter(|l| !l.starts_with("Tr_imu_velo"))
            .map(|l| format!("{l}\n"))
            .collect();
        let msg = TrackingCalib::parse(p, &missing).unwrap_err().to_string();
        assert!(
            msg.starts_with("calib/0000.txt:0: Tr_imu_velo: missing"),
            "{msg}"
        );
        let bad = CALIB_0000.replace("-8.086759000000e-01", "x");
        let msg = TrackingCalib::parse(p, &bad).unwrap_err().to_string();
        assert!(msg.starts_with("calib/0000.txt:7: Tr_imu_velo[3]"), "{msg}");
        let no_p = CALIB_0000.replace("P3:", "Q3:");
        let msg = TrackingCalib::parse(p, &no_p).unwrap_err().to_string();
        assert!(msg.contains(":0: P3: missing"), "{msg}");
    }
}
