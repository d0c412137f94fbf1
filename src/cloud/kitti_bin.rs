//! KITTI Velodyne `.bin` scans: a headerless sequence of points, each four little-endian `f32`
//! values `x, y, z, reflectance` (16 bytes a point, Velodyne frame: x forward, y left, z up).
//!
//! Reading maps the file into memory and reinterprets the bytes in place when they are aligned
//! (always the case for a fresh map on a little-endian machine), otherwise decodes a copy.
//! Writing goes through a temporary file that replaces the target in one rename.
//!
//! Not for: other point-cloud formats, or finding the files of a drive (see [`crate::kitti`]).

use super::points::PointCloud;
use crate::atomic::write_atomically;
use crate::error::{Error, Result};
use memmap2::Mmap;
use std::borrow::Cow;
use std::fs::File;
use std::io::Write;
use std::path::Path;

/// Bytes per point in a `.bin` file.
pub const BYTES_PER_POINT: usize = 16;

/// What to do with points that have a NaN or infinite value.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub enum NonFinite {
    /// Fail, naming the first offending point (the default).
    #[default]
    Error,
    /// Drop such points and count them in [`BinScan::skipped`].
    Skip,
}

/// A scan read by [`read_kitti_bin_with`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BinScan {
    /// The points kept.
    pub cloud: PointCloud,
    /// How many points were dropped because a value was NaN or infinite
    /// (always 0 with [`NonFinite::Error`]).
    pub skipped: usize,
}

/// Reads a `.bin` scan; any NaN or infinite value is an error naming the point.
pub fn read_kitti_bin(path: impl AsRef<Path>) -> Result<PointCloud> {
    read_kitti_bin_with(path, NonFinite::Error).map(|scan| scan.cloud)
}

/// Reads a `.bin` scan, treating non-finite values as `policy` says.
///
/// Errors: the file cannot be opened or mapped ([`Error::Io`]); its size is not a multiple of
/// 16 bytes, or (with [`NonFinite::Error`]) a point holds a non-finite value ([`Error::Parse`]
/// with the file, line 0 and the size or the point index as the field). An empty file is a valid
/// empty scan.
pub fn read_kitti_bin_with(path: impl AsRef<Path>, policy: NonFinite) -> Result<BinScan> {
    let path = path.as_ref();
    let file = File::open(path).map_err(|e| Error::io(path, e))?;
    let size = file.metadata().map_err(|e| Error::io(path, e))?.len();
    check_size(path, size)?;
    if size == 0 {
        return Ok(BinScan::default());
    }
    // SAFETY: the map is only read, and only inside this function; every value is copied into
    // the returned cloud before the map is dropped. A concurrent truncation of the file by
    // another process is the one hazard of any file mapping and is outside this crate's control.
    let map = unsafe { Mmap::map(&file) }.map_err(|e| Error::io(path, e))?;
    if map.len() as u64 != size {
        return Err(Error::parse(
            path,
            0,
            "size",
            format!(
                "file changed while being read ({size} bytes, then {})",
                map.len()
            ),
        ));
    }
    decode(path, &map, policy)
}

/// Decodes the bytes of a `.bin` file already in memory (`path` is only used in messages).
pub fn decode_kitti_bin(
    path: impl AsRef<Path>,
    bytes: &[u8],
    policy: NonFinite,
) -> Result<BinScan> {
    let path = path.as_ref();
    check_size(path, bytes.len() as u64)?;
    decode(path, bytes, policy)
}

fn check_size(path: &Path, size: u64) -> Result<()> {
    if !size.is_multiple_of(BYTES_PER_POINT as u64) {
        return Err(Error::parse(
            path,
            0,
            "size",
            format!(
                "{size} bytes is not a multiple of {BYTES_PER_POINT} \
                 (x, y, z, reflectance as little-endian f32 per point)"
            ),
        ));
    }
    Ok(())
}

/// Views `bytes` as records without copying when possible, otherwise decodes a copy.
fn records(bytes: &[u8]) -> Cow<'_, [[f32; 4]]> {
    if cfg!(target_endian = "little") {
        if let Ok(view) = bytemuck::try_cast_slice::<u8, [f32; 4]>(bytes) {
            return Cow::Borrowed(view);
        }
    }
    Cow::Owned(
        bytes
            .chunks_exact(BYTES_PER_POINT)
            .map(|c| {
                let f = |k: usize| {
                    f32::from_le_bytes([c[4 * k], c[4 * k + 1], c[4 * k + 2], c[4 * k + 3]])
                };
                [f(0), f(1), f(2), f(3)]
            })
            .collect(),
    )
}

fn decode(path: &Path, bytes: &[u8], policy: NonFinite) -> Result<BinScan> {
    const NAMES: [&str; 4] = ["x", "y", "z", "reflectance"];
    let recs = records(bytes);
    // Every value finite (a branch-free pass): the columns straight from the records.
    let finite = |r: &[f32; 4]| r.iter().fold(true, |ok, v| ok & v.is_finite());
    if recs.iter().fold(true, |ok, r| ok & finite(r)) {
        return Ok(BinScan {
            cloud: PointCloud::from_records(&recs),
            skipped: 0,
        });
    }
    let mut cloud = PointCloud::with_capacity(recs.len());
    let mut skipped = 0;
    for (i, r) in recs.iter().enumerate() {
        if let Some(k) = r.iter().position(|v| !v.is_finite()) {
            match policy {
                NonFinite::Error => {
                    return Err(Error::parse(
                        path,
                        0,
                        format!("point {i} ({})", NAMES[k]),
                        format!("value is {} (must be finite)", r[k]),
                    ))
                }
                NonFinite::Skip => {
                    skipped += 1;
                    continue;
                }
            }
        }
        cloud.push(r[0], r[1], r[2], r[3]);
    }
    Ok(BinScan { cloud, skipped })
}

/// Encodes a cloud in the `.bin` layout (16 bytes a point, little-endian).
pub fn encode_kitti_bin(cloud: &PointCloud) -> Vec<u8> {
    let mut out = Vec::with_capacity(cloud.len() * BYTES_PER_POINT);
    let (x, y, z, r) = cloud.columns();
    for i in 0..cloud.len() {
        for v in [x[i], y[i], z[i], r[i]] {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    out
}

/// Writes a cloud as a `.bin` scan, atomically: a temporary file in the same folder is written,
/// flushed and renamed over `path`, so readers never see a partial scan.
pub fn write_kitti_bin(path: impl AsRef<Path>, cloud: &PointCloud) -> Result<()> {
    let bytes = encode_kitti_bin(cloud);
    write_atomically(path.as_ref(), |w| w.write_all(&bytes))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> PointCloud {
        let mut c = PointCloud::new();
        c.push(1.5, -2.25, 0.125, 0.5);
        c.push(-10.0, 3.0, -1.75, 0.0);
        c.push(80.0, 0.0, 2.0, 1.0);
        c
    }

    #[test]
    fn write_then_read_is_exact() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("0000000000.bin");
        write_kitti_bin(&p, &sample()).unwrap();
        assert_eq!(std::fs::metadata(&p).unwrap().len(), 48);
        assert_eq!(read_kitti_bin(&p).unwrap(), sample());
    }

    #[test]
    fn unaligned_bytes_are_copied_not_cast() {
        let bytes = encode_kitti_bin(&sample());
        let mut shifted = vec![0u8; bytes.len() + 1];
        shifted[1..].copy_from_slice(&bytes);
        let scan = decode_kitti_bin("mem.bin", &shifted[1..], NonFinite::Error).unwrap();
        assert_eq!(scan.cloud, sample());
    }

    #[test]
    fn empty_file_is_an_empty_cloud() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("empty.bin");
        std::fs::write(&p, b"").unwrap();
        assert!(read_kitti_bin(&p).unwrap().is_empty());
    }

    #[test]
    fn size_not_multiple_of_16_names_file_and_size() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("bad.bin");
        std::fs::write(&p, [0u8; 17]).unwrap();
        let msg = read_kitti_bin(&p).unwrap_err().to_string();
        assert!(msg.contains("bad.bin") && msg.contains("17 bytes"), "{msg}");
    }

    #[test]
    fn nan_is_an_error_or_skipped() {
        let mut c = sample();
        c.push(1.0, f32::NAN, 0.0, 0.0);
        c.push(2.0, 0.0, f32::INFINITY, 0.0);
        c.push(3.0, 0.0, 0.0, 0.0);
        let bytes = encode_kitti_bin(&c);
        let msg = decode_kitti_bin("scan.bin", &bytes, NonFinite::Error)
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("scan.bin") && msg.contains("point 3 (y)"),
            "{msg}"
        );
        let scan = decode_kitti_bin("scan.bin", &bytes, NonFinite::Skip).unwrap();
        assert_eq!(scan.skipped, 2);
        assert_eq!(scan.cloud.len(), 4);
        assert_eq!(scan.cloud.xs()[3], 3.0);
    }

    #[test]
    fn missing_file_names_the_file() {
        let msg = read_kitti_bin("/nonexistent/dir/0000000007.bin")
            .unwrap_err()
            .to_string();
        assert!(msg.contains("0000000007.bin"), "{msg}");
    }
}
