//! KITTI calibration files: lines `key: v1 v2 ...` ([`CalibFile`]), and the typed readers built
//! on them — rigid transforms with a 3×3 rotation `R:` and a translation `T:`
//! (`calib_imu_to_velo.txt`, `calib_velo_to_cam.txt`, see [`RigidCalib`]) and the two simplest
//! entries of `calib_cam_to_cam.txt` (`R_rect_00`, `P_rect_02`, see [`CamToCamCalib`]).
//!
//! A file `calib_A_to_B.txt` holds T_B_A, the transform that maps coordinates in frame A to
//! coordinates in frame B: p_B = R·p_A + T.
//!
//! Not for: camera intrinsics beyond the rectified projection, or distortion models.

use super::text::{numbered_lines, parse_f64, read_text};
use crate::error::{Error, Result};
use nalgebra::{
    Isometry3, Matrix3, Matrix3x4, Matrix4, Rotation3, Translation3, UnitQuaternion, Vector3,
};
use std::path::{Path, PathBuf};

/// Largest deviation |RᵀR − I| accepted for a calibration rotation (KITTI prints 7 significant
/// digits, which leaves errors around 1e-6).
pub const ROTATION_TOLERANCE: f64 = 1e-3;

/// One `key: values` line of a calibration file.
#[derive(Clone, Debug, PartialEq)]
pub struct CalibEntry {
    /// The key, without the colon.
    pub key: String,
    /// One-based line number.
    pub line: usize,
    /// Everything after the colon, trimmed.
    pub text: String,
}

/// A KITTI calibration file as a list of `key: values` entries.
#[derive(Clone, Debug, PartialEq)]
pub struct CalibFile {
    /// The file read.
    pub path: PathBuf,
    /// Its entries in file order.
    pub entries: Vec<CalibEntry>,
}

impl CalibFile {
    /// Reads and splits a calibration file. A non-blank line without a colon is an error naming
    /// the line.
    pub fn read(path: impl AsRef<Path>) -> Result<CalibFile> {
        let path = path.as_ref();
        let text = read_text(path)?;
        CalibFile::parse(path, &text)
    }

    /// Splits calibration text; `path` is used in error messages.
    pub fn parse(path: &Path, text: &str) -> Result<CalibFile> {
        let mut entries = Vec::new();
        for (line, l) in numbered_lines(text) {
            let Some((key, rest)) = l.split_once(':') else {
                return Err(Error::parse(path, line, "line", "expected `key: values`"));
            };
            let key = key.trim();
            if key.is_empty() {
                return Err(Error::parse(path, line, "key", "empty key before `:`"));
            }
            entries.push(CalibEntry {
                key: key.to_string(),
                line,
                text: rest.trim().to_string(),
            });
        }
        Ok(CalibFile {
            path: path.to_path_buf(),
            entries,
        })
    }

    /// The entry for `key` (the first one if repeated).
    pub fn get(&self, key: &str) -> Option<&CalibEntry> {
        self.entries.iter().find(|e| e.key == key)
    }

    /// The numbers of entry `key`; errors name the file, the line and `key[i]` for a bad value,
    /// or line 0 when the key is missing.
    pub fn values(&self, key: &str) -> Result<Vec<f64>> {
        let entry = self
            .get(key)
            .ok_or_else(|| Error::parse(&self.path, 0, key, "missing"))?;
        entry
            .text
            .split_whitespace()
            .enumerate()
            .map(|(i, tok)| parse_f64(&self.path, entry.line, &format!("{key}[{i}]"), tok))
            .collect()
    }

    /// Exactly `N` numbers of entry `key` (error naming file, line and key otherwise).
    pub fn fixed<const N: usize>(&self, key: &str) -> Result<[f64; N]> {
        let v = self.values(key)?;
        let line = self.get(key).map_or(0, |e| e.line);
        v.try_into().map_err(|v: Vec<f64>| {
            Error::parse(
                &self.path,
                line,
                key,
                format!("{} values, expected {N}", v.len()),
            )
        })
    }

    /// A row-major 3×3 matrix from 9 values.
    pub fn matrix3(&self, key: &str) -> Result<Matrix3<f64>> {
        Ok(Matrix3::from_row_slice(&self.fixed::<9>(key)?))
    }

    /// A row-major 3×4 matrix from 12 values.
    pub fn matrix3x4(&self, key: &str) -> Result<Matrix3x4<f64>> {
        Ok(Matrix3x4::from_row_slice(&self.fixed::<12>(key)?))
    }

    /// The rigid transform of a row-major 3×4 matrix `[R | t]` (12 values), with R checked and
    /// snapped to the nearest rotation.
    pub fn rigid3x4(&self, key: &str) -> Result<Isometry3<f64>> {
        let m = self.matrix3x4(key)?;
        let line = self.get(key).map_or(0, |e| e.line);
        let r: Matrix3<f64> = m.fixed_view::<3, 3>(0, 0).into_owned();
        let t = Vector3::new(m[(0, 3)], m[(1, 3)], m[(2, 3)]);
        rigid_from_parts(&r, &t).map_err(|reason| Error::parse(&self.path, line, key, reason))
    }
}

/// Largest absolute entry of RᵀR − I.
pub fn orthonormality_error(r: &Matrix3<f64>) -> f64 {
    (r.transpose() * r - Matrix3::identity()).abs().max()
}

/// An isometry from a nearly orthonormal R and a translation; rejects R that is not a rotation
/// within [`ROTATION_TOLERANCE`] (the reason is returned for the caller's error).
pub(crate) fn rigid_from_parts(
    r: &Matrix3<f64>,
    t: &Vector3<f64>,
) -> std::result::Result<Isometry3<f64>, String> {
    let err = orthonormality_error(r);
    if err.is_nan() || err > ROTATION_TOLERANCE {
        return Err(format!(
            "not a rotation matrix (|RᵀR − I| = {err:.3e} > {ROTATION_TOLERANCE:e})"
        ));
    }
    if r.determinant() <= 0.0 {
        return Err("a reflection, not a rotation (determinant ≤ 0)".to_string());
    }
    let rot = Rotation3::from_matrix_eps(r, 1e-15, 100, Rotation3::identity());
    Ok(Isometry3::from_parts(
        Translation3::from(*t),
        UnitQuaternion::from_rotation_matrix(&rot),
    ))
}

/// A rigid calibration `R:`/`T:` as printed in the file, with its isometry.
#[derive(Clone, Debug, PartialEq)]
pub struct RigidCalib {
    /// The 3×3 rotation as printed (row-major in the file).
    pub rotation: Matrix3<f64>,
    /// The translation, metres.
    pub translation: Vector3<f64>,
    /// The `calib_time:` text, if present.
    pub calib_time: Option<String>,
    /// The transform, with the rotation snapped to the nearest exact rotation.
    pub isometry: Isometry3<f64>,
}

impl RigidCalib {
    /// Largest absolute entry of RᵀR − I of the rotation as printed.
    pub fn orthonormality_error(&self) -> f64 {
        orthonormality_error(&self.rotation)
    }

    /// The homogeneous 4×4 matrix of the printed R and T.
    pub fn matrix4(&self) -> Matrix4<f64> {
        let mut m = Matrix4::identity();
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&self.rotation);
        m.fixed_view_mut::<3, 1>(0, 3).copy_from(&self.translation);
        m
    }
}

/// Reads a rigid calibration file (`calib_imu_to_velo.txt`, `calib_velo_to_cam.txt`): `R:` nine
/// values (row-major), `T:` three values; `calib_time:` is kept as text and other keys are
/// ignored. Errors name the file, line and field.
pub fn read_rigid_calib(path: impl AsRef<Path>) -> Result<RigidCalib> {
    let file = CalibFile::read(path)?;
    rigid_calib_from(&file)
}

/// The rigid calibration of an already split file.
pub fn rigid_calib_from(file: &CalibFile) -> Result<RigidCalib> {
    let rotation = file.matrix3("R")?;
    let translation = Vector3::from(file.fixed::<3>("T")?);
    let line = file.get("R").map_or(0, |e| e.line);
    let isometry = rigid_from_parts(&rotation, &translation)
        .map_err(|reason| Error::parse(&file.path, line, "R", reason))?;
    Ok(RigidCalib {
        rotation,
        translation,
        calib_time: file.get("calib_time").map(|e| e.text.clone()),
        isometry,
    })
}

/// The simple part of `calib_cam_to_cam.txt`.
#[derive(Clone, Debug, PartialEq)]
pub struct CamToCamCalib {
    /// Rectifying rotation of camera 0 (`R_rect_00`).
    pub r_rect_00: Matrix3<f64>,
    /// Projection of rectified camera 2 coordinates (of camera 0's rectified frame) to the
    /// image of camera 2 (`P_rect_02`).
    pub p_rect_02: Matrix3x4<f64>,
}

/// Reads `R_rect_00` and `P_rect_02` from `calib_cam_to_cam.txt`; the other entries are left in
/// the file (read them with [`CalibFile`]).
pub fn read_cam_to_cam(path: impl AsRef<Path>) -> Result<CamToCamCalib> {
    let file = CalibFile::read(path)?;
    Ok(CamToCamCalib {
        r_rect_00: file.matrix3("R_rect_00")?,
        p_rect_02: file.matrix3x4("P_rect_02")?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const IMU_TO_VELO: &str = "calib_time: 25-May-2012 16:47:16\n\
        R: 9.999976e-01 7.553071e-04 -2.035826e-03 -7.854027e-04 9.998898e-01 -1.482298e-02 \
        2.024406e-03 1.482454e-02 9.998881e-01\n\
        T: -8.086759e-01 3.195559e-01 -7.997231e-01\n";

    #[test]
    fn parses_real_imu_to_velo() {
        let f = CalibFile::parse(Path::new("calib_imu_to_velo.txt"), IMU_TO_VELO).unwrap();
        let c = rigid_calib_from(&f).unwrap();
        assert_eq!(c.calib_time.as_deref(), Some("25-May-2012 16:47:16"));
        assert_eq!(c.rotation[(0, 1)], 7.553071e-04);
        assert_eq!(c.rotation[(1, 0)], -7.854027e-04);
        assert!(c.orthonormality_error() < 1e-6);
        assert!((c.isometry.translation.vector - c.translation).norm() < 1e-15);
        let snapped = c.isometry.rotation.to_rotation_matrix().into_inner();
        assert!((snapped - c.rotation).abs().max() < 1e-6);
        assert_eq!(c.matrix4()[(2, 3)], -7.997231e-01);
    }

    #[test]
    fn malformed_files_name_line_and_field() {
        let p = Path::new("calib_imu_to_velo.txt");
        let short = IMU_TO_VELO.replace(" 9.998881e-01\n", "\n");
        let msg = rigid_calib_from(&CalibFile::parse(p, &short).unwrap())
            .unwrap_err()
            .to_string();
        assert_eq!(msg, "calib_imu_to_velo.txt:2: R: 8 values, expected 9");
        let bad = IMU_TO_VELO.replace("3.195559e-01", "x");
        let msg = rigid_calib_from(&CalibFile::parse(p, &bad).unwrap())
            .unwrap_err()
            .to_string();
        assert!(
            msg.starts_with("calib_imu_to_velo.txt:3: T[1]: `x`"),
            "{msg}"
        );
        let no_t = "R: 1 0 0 0 1 0 0 0 1\n";
        let msg = rigid_calib_from(&CalibFile::parse(p, no_t).unwrap())
            .unwrap_err()
            .to_string();
        assert!(msg.contains(":0: T: missing"), "{msg}");
        let skew = "R: 1 0 0 0 2 0 0 0 1\nT: 0 0 0\n";
        assert!(rigid_calib_from(&CalibFile::parse(p, skew).unwrap()).is_err());
        let mirror = "R: 1 0 0 0 1 0 0 0 -1\nT: 0 0 0\n";
        assert!(rigid_calib_from(&CalibFile::parse(p, mirror).unwrap()).is_err());
        assert!(CalibFile::parse(p, "R 1 2 3\n").is_err());
    }

    #[test]
    fn rigid3x4_reads_odometry_style_entries() {
        let f =
            CalibFile::parse(Path::new("calib.txt"), "Tr: 0 -1 0 1 0 0 -1 2 1 0 0 3\n").unwrap();
        let t = f.rigid3x4("Tr").unwrap();
        assert_eq!(t.translation.vector, Vector3::new(1.0, 2.0, 3.0));
        let x = t.rotation * Vector3::x();
        assert!((x - Vector3::new(0.0, 0.0, 1.0)).norm() < 1e-12);
    }
}
