//! PLY point clouds: reading the `vertex` element of an ASCII or binary PLY file into a
//! [`PointCloud`], and writing a cloud as binary little-endian PLY, optionally coloured by a
//! label per point.
//!
//! Reading takes `x`, `y`, `z` (float or double) and, when present, an intensity property named
//! `intensity`, `reflectance`, `scalar_intensity` or `scalar` (any case): float and double values
//! are taken as they are, `uchar` is divided by 255 and `ushort` by 65535. Missing intensity
//! reads as 0. Other elements (faces, ...) and properties are skipped.
//!
//! Writing produces `float x, y, z, intensity` per vertex (exact for `f32` data), plus
//! `uchar red, green, blue` from [`label_colour`] for [`write_ply_labelled`], through
//! [`crate::atomic::write_atomically`].
//!
//! Not for: meshes (faces are ignored), or LAS and KITTI `.bin` files.

use super::palette::label_colour;
use super::points::PointCloud;
use crate::atomic::write_atomically;
use crate::error::{Error, Result};
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{PropertyAccess, PropertyAccessResult};
use std::io::{BufReader, Write};
use std::path::Path;

/// One vertex as the parser fills it.
#[derive(Default)]
struct Vertex {
    xyz: [f32; 3],
    intensity: f32,
}

fn is_intensity(name: &str) -> bool {
    ["intensity", "reflectance", "scalar_intensity", "scalar"]
        .iter()
        .any(|n| name.eq_ignore_ascii_case(n))
}

impl Vertex {
    fn set(&mut self, name: &str, value: f32) -> PropertyAccessResult {
        match name {
            "x" => self.xyz[0] = value,
            "y" => self.xyz[1] = value,
            "z" => self.xyz[2] = value,
            n if is_intensity(n) => self.intensity = value,
            _ => return PropertyAccessResult::Ignored,
        }
        PropertyAccessResult::Set
    }
}

impl PropertyAccess for Vertex {
    fn new() -> Self {
        Vertex::default()
    }
    fn set_float(&mut self, name: &str, value: f32) -> PropertyAccessResult {
        self.set(name, value)
    }
    fn set_double(&mut self, name: &str, value: f64) -> PropertyAccessResult {
        self.set(name, value as f32)
    }
    fn set_uchar(&mut self, name: &str, value: u8) -> PropertyAccessResult {
        if is_intensity(name) {
            self.intensity = f32::from(value) / 255.0;
            return PropertyAccessResult::Set;
        }
        PropertyAccessResult::Ignored
    }
    fn set_ushort(&mut self, name: &str, value: u16) -> PropertyAccessResult {
        if is_intensity(name) {
            self.intensity = f32::from(value) / 65535.0;
            return PropertyAccessResult::Set;
        }
        PropertyAccessResult::Ignored
    }
}

/// Reads the vertices of a PLY file (ASCII, binary little or big endian).
///
/// Errors: the file cannot be opened ([`Error::Io`]); its header or payload is malformed or
/// truncated, it has no `vertex` element, or the vertices lack `x`, `y` or `z`
/// ([`Error::Parse`] naming the file).
pub fn read_ply(path: impl AsRef<Path>) -> Result<PointCloud> {
    let path = path.as_ref();
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let mut reader = BufReader::new(file);
    let ply = Parser::<Vertex>::new()
        .read_ply(&mut reader)
        .map_err(|e| Error::parse(path, 0, "ply", e.to_string()))?;
    let element = ply
        .header
        .elements
        .get("vertex")
        .ok_or_else(|| Error::parse(path, 0, "vertex", "the file has no vertex element"))?;
    for axis in ["x", "y", "z"] {
        if !element.properties.contains_key(axis) {
            return Err(Error::parse(
                path,
                0,
                "vertex",
                format!("vertices have no `{axis}` property"),
            ));
        }
    }
    let vertices = ply.payload.get("vertex").map(Vec::as_slice).unwrap_or(&[]);
    if vertices.len() != element.count {
        return Err(Error::parse(
            path,
            0,
            "vertex",
            format!(
                "header announces {} vertices, file holds {}",
                element.count,
                vertices.len()
            ),
        ));
    }
    let mut cloud = PointCloud::with_capacity(vertices.len());
    for v in vertices {
        cloud.push(v.xyz[0], v.xyz[1], v.xyz[2], v.intensity);
    }
    Ok(cloud)
}

/// Writes `cloud` as binary little-endian PLY (`float x, y, z, intensity`), atomically.
///
/// Errors: the file cannot be written ([`Error::Io`]). Non-finite values are written as they
/// are (PLY floats can hold them).
pub fn write_ply(path: impl AsRef<Path>, cloud: &PointCloud) -> Result<()> {
    write(path.as_ref(), cloud, None)
}

/// Writes `cloud` as binary little-endian PLY with `uchar red, green, blue` per vertex from
/// [`label_colour`] of its label (one label per point), atomically.
///
/// Errors: a label count different from the point count ([`Error::InvalidInput`]); the file
/// cannot be written ([`Error::Io`]).
pub fn write_ply_labelled(
    path: impl AsRef<Path>,
    cloud: &PointCloud,
    labels: &[u32],
) -> Result<()> {
    super::palette::check_label_count(labels, cloud.len())?;
    write(path.as_ref(), cloud, Some(labels))
}

fn write(path: &Path, cloud: &PointCloud, labels: Option<&[u32]>) -> Result<()> {
    let mut header = format!(
        "ply\nformat binary_little_endian 1.0\ncomment written by smc-lmb\n\
         element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         property float intensity\n",
        cloud.len()
    );
    if labels.is_some() {
        header.push_str("property uchar red\nproperty uchar green\nproperty uchar blue\n");
    }
    header.push_str("end_header\n");
    write_atomically(path, |w| {
        w.write_all(header.as_bytes())?;
        let mut record = Vec::with_capacity(19);
        for (i, p) in cloud.iter().enumerate() {
            record.clear();
            for v in [p.x, p.y, p.z, p.intensity] {
                record.extend_from_slice(&v.to_le_bytes());
            }
            if let Some(labels) = labels {
                record.extend_from_slice(&label_colour(labels[i]));
            }
            w.write_all(&record)?;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> PointCloud {
        let mut c = PointCloud::new();
        c.push(1.2345, -20.5, 0.25, 0.0);
        c.push(-3.0, 4.0, -1.75, 0.5);
        c.push(60.0, 0.001, 2.0, 1.0);
        c
    }

    #[test]
    fn binary_round_trip_is_exact() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.ply");
        write_ply(&path, &sample()).unwrap();
        assert_eq!(read_ply(&path).unwrap(), sample());
    }

    #[test]
    fn labelled_round_trip_keeps_points() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("l.ply");
        write_ply_labelled(&path, &sample(), &[0, 1, 2]).unwrap();
        assert_eq!(read_ply(&path).unwrap(), sample());
        assert!(write_ply_labelled(&path, &sample(), &[1]).is_err());
    }

    #[test]
    fn reads_ascii_with_double_and_extra_elements() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.ply");
        std::fs::write(
            &path,
            "ply\nformat ascii 1.0\nelement vertex 2\nproperty double x\nproperty double y\n\
             property double z\nproperty uchar intensity\nproperty uchar red\n\
             element face 1\nproperty list uchar int vertex_indices\nend_header\n\
             1 2 3 255 7\n4.5 5 6 0 8\n2 0 1\n",
        )
        .unwrap();
        let c = read_ply(&path).unwrap();
        assert_eq!(c.xs(), &[1.0, 4.5]);
        assert_eq!(c.zs(), &[3.0, 6.0]);
        assert_eq!(c.intensities(), &[1.0, 0.0]);
    }

    #[test]
    fn malformed_files_are_errors_naming_them() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.ply");
        std::fs::write(&path, "plx\nformat ascii 1.0\nend_header\n").unwrap();
        let err = read_ply(&path).unwrap_err().to_string();
        assert!(err.contains("bad.ply"), "{err}");

        write_ply(&path, &sample()).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        std::fs::write(&path, &bytes[..bytes.len() - 5]).unwrap();
        let err = read_ply(&path).unwrap_err().to_string();
        assert!(err.contains("bad.ply"), "{err}");

        std::fs::write(
            &path,
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n1\n",
        )
        .unwrap();
        let err = read_ply(&path).unwrap_err().to_string();
        assert!(err.contains("bad.ply") && err.contains('y'), "{err}");
    }
}
