//! PCD point clouds (the Point Cloud Library's format, as PCL and ROS write it): reading the
//! points of a `.pcd` file into a [`PointCloud`] and writing a cloud out, optionally with a
//! label per point.
//!
//! Reading understands headers of versions 0.5, 0.6 and 0.7 (`VERSION`, `FIELDS` or
//! `COLUMNS`, `SIZE`, `TYPE`, `COUNT`, `WIDTH`, `HEIGHT`, `VIEWPOINT`, `POINTS`, `DATA`, and
//! `#` comments) and the three data encodings: `ascii` (one point a line), `binary` (packed
//! little-endian records, one per point) and `binary_compressed` (a `u32` compressed size, a
//! `u32` uncompressed size and an LZF stream holding the fields column by column). Types are
//! `F` (4 or 8 bytes), `U` and `I` (1, 2, 4 or 8 bytes).
//!
//! Fields `x`, `y`, `z` are required; `intensity` or `reflectance` (any case) becomes the
//! cloud's intensity (`U` of 1 byte divided by 255 and of 2 bytes by 65535, as
//! [`super::ply_io`] does, every other type taken as it is; 0 when absent); a `label` field
//! (whole numbers from 0 to 2^32 − 1, of any type) is returned by [`read_pcd_with`]. Every other field (`rgb`, `normal_x`, padding `_`, fields with
//! `COUNT` > 1, ...) is skipped by its `SIZE × COUNT` bytes. `VIEWPOINT` is checked but not
//! applied (as PCL does on load).
//!
//! PCL marks the invalid points of an organised cloud with NaN coordinates. As for KITTI `.bin`
//! scans ([`super::kitti_bin`]), [`read_pcd`] refuses a point holding a NaN or infinite value,
//! naming it, and [`read_pcd_with`] with [`NonFinite::Skip`] leaves such points out and counts
//! them in [`PcdScan::skipped`].
//!
//! Every size in the header is checked against the file before anything is allocated for it.
//! Bytes after the last point are ignored. [`decode_pcd`] and [`encode_pcd`] do the same on
//! bytes in memory.
//!
//! Writing produces version 0.7 with `x y z intensity` as `F 4` (plus `label` as `U 4` for
//! [`write_pcd_labelled`]), `WIDTH` = point count, `HEIGHT 1`, in the chosen [`PcdEncoding`]
//! (binary_compressed output is LZF-compressed here too), through
//! [`crate::atomic::write_atomically`]. Every encoding round-trips `f32` values exactly.
//!
//! Not for: meshes or polygon files, big-endian binary PCD, or LAS, PLY and KITTI `.bin` files.

use super::kitti_bin::NonFinite;
use super::points::PointCloud;
use crate::atomic::write_atomically;
use crate::error::{Error, Result};
use std::io::Write;
use std::path::Path;

mod decode;
mod header;
mod lzf;
#[cfg(test)]
mod tests;

use decode::{read_ascii, value, Roles, Sink};
use header::{data_bytes, parse_header, truncated, Field};
use lzf::{decompress_data, lzf_compress};

/// How [`write_pcd`] encodes the points (the header's `DATA` line).
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub enum PcdEncoding {
    /// One text line per point.
    Ascii,
    /// Packed little-endian records (the default; what PCL and ROS usually write).
    #[default]
    Binary,
    /// Column-major fields, LZF-compressed.
    BinaryCompressed,
}

/// A cloud read by [`read_pcd_with`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PcdScan {
    /// The points kept.
    pub cloud: PointCloud,
    /// One label per kept point when the file has an integer `label` field.
    pub labels: Option<Vec<u32>>,
    /// How many points were left out because a value was NaN or infinite
    /// (always 0 with [`NonFinite::Error`]).
    pub skipped: usize,
}

/// Reads a PCD file; a point holding a NaN or infinite value is an error naming it.
///
/// Errors: as [`read_pcd_with`].
pub fn read_pcd(path: impl AsRef<Path>) -> Result<PointCloud> {
    read_pcd_with(path, NonFinite::Error).map(|scan| scan.cloud)
}

/// Reads a PCD file, treating points with non-finite values as `policy` says.
///
/// Errors: the file cannot be read ([`Error::Io`]); the header is malformed (unknown keyword,
/// version or `DATA` encoding, `FIELDS`, `SIZE`, `TYPE` and `COUNT` of different lengths, an
/// unsupported type and size, no `x`, `y` or `z`, `POINTS` ≠ `WIDTH` × `HEIGHT`), the data is
/// truncated or announces more than the file holds, an ascii line is malformed (with its line
/// number), the LZF stream is corrupt, a label is not a 32-bit unsigned integer, or (with
/// [`NonFinite::Error`]) a point holds a non-finite value ([`Error::Parse`] naming the file).
pub fn read_pcd_with(path: impl AsRef<Path>, policy: NonFinite) -> Result<PcdScan> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    decode_pcd(path, &bytes, policy)
}

/// Decodes the bytes of a PCD file already in memory (`path` is only used in messages).
///
/// Errors: as [`read_pcd_with`].
pub fn decode_pcd(path: impl AsRef<Path>, bytes: &[u8], policy: NonFinite) -> Result<PcdScan> {
    let path = path.as_ref();
    let header = parse_header(path, bytes)?;
    let data = &bytes[header.data_start..];
    let roles = Roles::of(path, &header.fields)?;
    let mut sink = Sink::new(path, &roles, policy);
    match header.encoding {
        PcdEncoding::Ascii => read_ascii(path, &header, data, &mut sink)?,
        PcdEncoding::Binary => {
            let need = data_bytes(path, &header)?;
            if need > data.len() {
                return Err(truncated(path, &header, need, data.len()));
            }
            sink.reserve(header.points);
            for i in 0..header.points {
                let record = &data[i * header.record..(i + 1) * header.record];
                sink.point(0, i, |f: &Field| value(f, &record[f.offset..]))?;
            }
        }
        PcdEncoding::BinaryCompressed => {
            let raw = decompress_data(path, &header, data)?;
            let n = header.points;
            sink.reserve(n);
            for i in 0..n {
                sink.point(0, i, |f: &Field| {
                    let at = n * f.offset + i * f.size * f.count;
                    value(f, &raw[at..])
                })?;
            }
        }
    }
    Ok(sink.finish())
}

/// Writes `cloud` as PCD 0.7 (`x y z intensity`, `F 4` each) in `encoding`, atomically.
///
/// Errors: the file cannot be written ([`Error::Io`]). Non-finite values are written as they
/// are (PCD holds them; PCL writes NaN for invalid points).
pub fn write_pcd(path: impl AsRef<Path>, cloud: &PointCloud, encoding: PcdEncoding) -> Result<()> {
    write(path.as_ref(), cloud, None, encoding)
}

/// Writes `cloud` as PCD 0.7 with a `label` field (`U 4`, one label per point) after
/// `x y z intensity`, in `encoding`, atomically. [`read_pcd_with`] returns the labels.
///
/// Errors: a label count different from the point count ([`Error::InvalidInput`]); the file
/// cannot be written ([`Error::Io`]).
pub fn write_pcd_labelled(
    path: impl AsRef<Path>,
    cloud: &PointCloud,
    labels: &[u32],
    encoding: PcdEncoding,
) -> Result<()> {
    write(path.as_ref(), cloud, Some(labels), encoding)
}

// ---------------------------------------------------------------- writing

/// Encodes the cloud (with `labels` when given) and writes it to `path` atomically.
fn write(
    path: &Path,
    cloud: &PointCloud,
    labels: Option<&[u32]>,
    encoding: PcdEncoding,
) -> Result<()> {
    let bytes = encode_pcd(cloud, labels, encoding)?;
    write_atomically(path, |w| w.write_all(&bytes))
}

/// Encodes a cloud as the bytes of a PCD 0.7 file (what [`write_pcd`] and
/// [`write_pcd_labelled`] write), with a `label` field when `labels` is given.
///
/// Errors: a label count different from the point count, or (binary_compressed) a cloud of
/// more than 4 GiB of data ([`Error::InvalidInput`]).
pub fn encode_pcd(
    cloud: &PointCloud,
    labels: Option<&[u32]>,
    encoding: PcdEncoding,
) -> Result<Vec<u8>> {
    if let Some(labels) = labels {
        super::palette::check_label_count(labels, cloud.len())?;
    }
    let n = cloud.len();
    let (fields, sizes, types, counts) = if labels.is_some() {
        (
            "x y z intensity label",
            "4 4 4 4 4",
            "F F F F U",
            "1 1 1 1 1",
        )
    } else {
        ("x y z intensity", "4 4 4 4", "F F F F", "1 1 1 1")
    };
    let data = match encoding {
        PcdEncoding::Ascii => "ascii",
        PcdEncoding::Binary => "binary",
        PcdEncoding::BinaryCompressed => "binary_compressed",
    };
    let header = format!(
        "# .PCD v0.7 - Point Cloud Data file format (written by smc-lmb)\nVERSION 0.7\n\
         FIELDS {fields}\nSIZE {sizes}\nTYPE {types}\nCOUNT {counts}\nWIDTH {n}\nHEIGHT 1\n\
         VIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA {data}\n"
    );
    let (x, y, z, r) = cloud.columns();
    let body = match encoding {
        PcdEncoding::Ascii => {
            let mut s = String::with_capacity(n * 40);
            for i in 0..n {
                use std::fmt::Write as _;
                // `{:?}` is the shortest text that reads back as the same f32.
                let _ = write!(s, "{:?} {:?} {:?} {:?}", x[i], y[i], z[i], r[i]);
                if let Some(labels) = labels {
                    let _ = write!(s, " {}", labels[i]);
                }
                s.push('\n');
            }
            s.into_bytes()
        }
        PcdEncoding::Binary => {
            let mut b = Vec::with_capacity(n * 20);
            for i in 0..n {
                for v in [x[i], y[i], z[i], r[i]] {
                    b.extend_from_slice(&v.to_le_bytes());
                }
                if let Some(labels) = labels {
                    b.extend_from_slice(&labels[i].to_le_bytes());
                }
            }
            b
        }
        PcdEncoding::BinaryCompressed => {
            let mut raw = Vec::with_capacity(n * 20);
            for column in [x, y, z, r] {
                for v in column {
                    raw.extend_from_slice(&v.to_le_bytes());
                }
            }
            if let Some(labels) = labels {
                for l in labels {
                    raw.extend_from_slice(&l.to_le_bytes());
                }
            }
            let packed = lzf_compress(&raw);
            let too_big = |what: &str| {
                Error::invalid(
                    "point cloud",
                    format!("{what} does not fit the 32-bit sizes of binary_compressed PCD"),
                )
            };
            let packed_len = u32::try_from(packed.len()).map_err(|_| too_big("compressed data"))?;
            let raw_len = u32::try_from(raw.len()).map_err(|_| too_big("the cloud"))?;
            let mut b = Vec::with_capacity(8 + packed.len());
            b.extend_from_slice(&packed_len.to_le_bytes());
            b.extend_from_slice(&raw_len.to_le_bytes());
            b.extend_from_slice(&packed);
            b
        }
    };
    let mut bytes = header.into_bytes();
    bytes.extend_from_slice(&body);
    Ok(bytes)
}
