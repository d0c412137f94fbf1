//! LAS point clouds (ASPRS LAS 1.2, uncompressed): reading into a [`PointCloud`] and writing
//! one out, optionally coloured by a label per point.
//!
//! Coordinates are stored as 32-bit integers with a scale of 1 mm ([`LAS_SCALE`]) and an offset
//! per axis taken from the cloud's bounds (the minimum rounded down to a whole metre), so a
//! round trip changes each coordinate by at most half a millimetre. Intensity (reflectance in
//! [0, 1] for KITTI) is stored as `round(i · 65535)` and read back as `value / 65535`.
//!
//! Labelled exports ([`write_las_labelled`]) use point format 2 (with RGB): the colour of each
//! point comes from [`label_colour`] (16 bits a channel, the 8-bit value times 257) and the label
//! itself goes into the **point source id** field (so labels must fit in 16 bits). Plain exports
//! ([`write_las`]) use point format 0.
//!
//! Every write goes through [`crate::atomic::write_bytes`]: the file appears complete or not at
//! all.
//!
//! Not for: LAZ (compressed) output or KITTI `.bin` scans (see [`super::kitti_bin`]).

use super::palette::label_colour;
use super::points::PointCloud;
use crate::atomic::write_bytes;
use crate::error::{Error, Result};
use las::point::Format;
use las::{Builder, Color, Point, Reader, Transform, Vector, Version, Writer};
use std::io::Cursor;
use std::path::Path;

/// Scale of the stored integer coordinates (metres per unit).
pub const LAS_SCALE: f64 = 0.001;

/// Reads a LAS file: x, y, z as `f32` from the scaled coordinates, intensity normalised from
/// `u16` to [0, 1]. Compressed LAZ is not decoded (the `las` crate's `laz` feature is not
/// enabled): such a file is an error naming it.
///
/// Errors: the file cannot be opened ([`Error::Io`]); its header is not LAS, or it holds
/// fewer point records than its header announces, e.g. a truncated file, or a record length
/// field reaches past the end of the file ([`Error::Parse`] naming the file). Such sizes are
/// checked before anything is allocated for them.
pub fn read_las(path: impl AsRef<Path>) -> Result<PointCloud> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    check_sizes(path, &bytes)?;
    let mut reader = Reader::new(Cursor::new(bytes))
        .map_err(|e| Error::parse(path, 0, "header", e.to_string()))?;
    let expected = reader.header().number_of_points();
    let data = reader
        .read_all()
        .map_err(|e| Error::parse(path, 0, "points", e.to_string()))?;
    if data.len() as u64 != expected {
        return Err(Error::parse(
            path,
            0,
            "points",
            format!(
                "header announces {expected} points, file holds {}",
                data.len()
            ),
        ));
    }
    let mut cloud = PointCloud::with_capacity(data.len());
    for (((x, y), z), i) in data.x().zip(data.y()).zip(data.z()).zip(data.intensity()) {
        cloud.push(x as f32, y as f32, z as f32, f32::from(i) / 65535.0);
    }
    Ok(cloud)
}

/// Bytes of an extended VLR's header; its `u64` record length starts at byte 20.
const EVLR_HEADER_LEN: u64 = 60;

/// Checks the sizes in the header of `bytes` against the file: the `las` crate reserves
/// memory for the announced points and for the first extended VLR before it reads them, so a
/// header announcing 10^12 points (or a count × record length that overflows) must be refused
/// here.
fn check_sizes(path: &Path, bytes: &[u8]) -> Result<()> {
    let raw = las::raw::Header::read_from(bytes)
        .map_err(|e| Error::parse(path, 0, "header", e.to_string()))?;
    let len = bytes.len() as u64;
    // The count the crate uses: the legacy 32-bit field unless it is zero (LAS 1.4 R15).
    let legacy = u64::from(raw.number_of_point_records);
    let count = match raw.large_file {
        Some(large) if legacy == 0 => large.number_of_point_records,
        _ => legacy,
    };
    let record_len = u64::from(raw.point_data_record_length);
    let end = count
        .checked_mul(record_len)
        .and_then(|n| n.checked_add(u64::from(raw.offset_to_point_data)));
    // Compressed (LAZ) points are smaller than their records; the crate refuses them later.
    let compressed = raw.point_data_record_format & 0xC0 != 0;
    if end.is_none_or(|end| end > len && !compressed) {
        return Err(Error::parse(
            path,
            0,
            "points",
            format!(
                "header announces {count} points of {record_len} bytes from byte {}, beyond \
                 the file's {len} bytes",
                raw.offset_to_point_data
            ),
        ));
    }
    if let Some(evlr) = raw.evlr {
        if evlr.start_of_first_evlr > 0 && evlr.number_of_evlrs > 0 {
            let start = evlr.start_of_first_evlr;
            let header_end = start.checked_add(EVLR_HEADER_LEN).filter(|&e| e <= len);
            let Some(header_end) = header_end else {
                return Err(Error::parse(
                    path,
                    0,
                    "extended VLR",
                    format!("starts at byte {start}, beyond the file's {len} bytes"),
                ));
            };
            let at = (start + 20) as usize;
            let mut field = [0u8; 8];
            field.copy_from_slice(&bytes[at..at + 8]);
            let record = u64::from_le_bytes(field);
            if record > len - header_end {
                return Err(Error::parse(
                    path,
                    0,
                    "extended VLR",
                    format!(
                        "record of {record} bytes at byte {header_end}, beyond the file's \
                         {len} bytes"
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Writes `cloud` as LAS 1.2, point format 0 (no colour), atomically.
///
/// Errors: a point holds a NaN or infinite value, or a coordinate is too far from the others to
/// fit the 1 mm integer grid ([`Error::InvalidInput`]); the file cannot be written ([`Error::Io`]).
pub fn write_las(path: impl AsRef<Path>, cloud: &PointCloud) -> Result<()> {
    write(path.as_ref(), cloud, None)
}

/// Writes `cloud` as LAS 1.2, point format 2, coloured by `labels` (one per point) with
/// [`label_colour`]; each label is also stored in the point source id field.
///
/// Errors: as [`write_las`], plus a label count different from the point count or a label above
/// 65535 ([`Error::InvalidInput`]).
pub fn write_las_labelled(
    path: impl AsRef<Path>,
    cloud: &PointCloud,
    labels: &[u32],
) -> Result<()> {
    super::palette::check_label_count(labels, cloud.len())?;
    if let Some(i) = labels.iter().position(|&l| l > u32::from(u16::MAX)) {
        return Err(Error::invalid(
            "labels",
            format!(
                "label {} of point {i} does not fit the 16-bit point source id",
                labels[i]
            ),
        ));
    }
    write(path.as_ref(), cloud, Some(labels))
}

fn write(path: &Path, cloud: &PointCloud, labels: Option<&[u32]>) -> Result<()> {
    if let Some(i) = cloud.first_non_finite() {
        return Err(Error::invalid(
            "point cloud",
            format!("point {i} has a NaN or infinite value; LAS cannot store it"),
        ));
    }
    let offset = match cloud.bounds() {
        Some(b) => b.min.map(|m| f64::from(m).floor()),
        None => [0.0; 3],
    };
    let transform = |o: f64| Transform {
        scale: LAS_SCALE,
        offset: o,
    };
    let mut builder = Builder::from(Version::new(1, 2));
    builder.point_format = Format::new(if labels.is_some() { 2 } else { 0 })
        .map_err(|e| Error::invalid("LAS point format", e.to_string()))?;
    builder.transforms = Vector {
        x: transform(offset[0]),
        y: transform(offset[1]),
        z: transform(offset[2]),
    };
    builder.generating_software = "smc-lmb".to_string();
    let header = builder
        .into_header()
        .map_err(|e| Error::invalid("LAS header", e.to_string()))?;
    let las_err = |e: las::Error| Error::invalid("LAS output", format!("{}: {e}", path.display()));
    let mut writer = Writer::new(Cursor::new(Vec::new()), header).map_err(las_err)?;
    for (i, p) in cloud.iter().enumerate() {
        let mut point = Point {
            x: f64::from(p.x),
            y: f64::from(p.y),
            z: f64::from(p.z),
            intensity: (f64::from(p.intensity).clamp(0.0, 1.0) * 65535.0).round() as u16,
            ..Default::default()
        };
        if let Some(labels) = labels {
            let [r, g, b] = label_colour(labels[i]);
            point.color = Some(Color::new(
                u16::from(r) * 257,
                u16::from(g) * 257,
                u16::from(b) * 257,
            ));
            point.point_source_id = labels[i] as u16;
        }
        writer.write_point(point).map_err(las_err)?;
    }
    let bytes = writer.into_inner().map_err(las_err)?.into_inner();
    write_bytes(path, &bytes)
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
    fn round_trip_within_a_millimetre() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.las");
        let cloud = sample();
        write_las(&path, &cloud).unwrap();
        let back = read_las(&path).unwrap();
        assert_eq!(back.len(), cloud.len());
        for (a, b) in cloud.iter().zip(back.iter()) {
            assert!((a.x - b.x).abs() <= 1e-3 && (a.y - b.y).abs() <= 1e-3);
            assert!((a.z - b.z).abs() <= 1e-3);
            assert!((a.intensity - b.intensity).abs() <= 1e-4);
        }
    }

    #[test]
    fn labelled_stores_colour_and_source_id() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("l.las");
        write_las_labelled(&path, &sample(), &[0, 3, 3]).unwrap();
        let mut reader = Reader::from_path(&path).unwrap();
        let data = reader.read_all().unwrap();
        let ids: Vec<u16> = data.point_source_id().collect();
        assert_eq!(ids, vec![0, 3, 3]);
        let rgb: Vec<_> = data.rgb().unwrap().collect();
        let [r, g, b] = label_colour(3);
        assert_eq!(
            rgb[1],
            (u16::from(r) * 257, u16::from(g) * 257, u16::from(b) * 257)
        );
        assert_ne!(rgb[0], rgb[1]);
        assert_eq!(read_las(&path).unwrap().len(), 3);
    }

    #[test]
    fn bad_labels_and_nan_are_refused_without_output() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.las");
        assert!(write_las_labelled(&path, &sample(), &[1, 2]).is_err());
        assert!(write_las_labelled(&path, &sample(), &[1, 2, 70_000]).is_err());
        let mut c = sample();
        c.push(f32::NAN, 0.0, 0.0, 0.0);
        assert!(write_las(&path, &c).is_err());
        assert!(!path.exists());
    }

    #[test]
    fn truncated_file_is_an_error_naming_it() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.las");
        let mut cloud = PointCloud::new();
        for k in 0..100 {
            cloud.push(k as f32, 0.5 * k as f32, 1.0, 0.1);
        }
        write_las(&path, &cloud).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
        let err = read_las(&path).unwrap_err().to_string();
        assert!(err.contains("t.las"), "{err}");
        std::fs::write(&path, b"not a las file at all").unwrap();
        let err = read_las(&path).unwrap_err().to_string();
        assert!(err.contains("t.las"), "{err}");
    }

    #[test]
    fn a_point_count_beyond_the_file_is_refused_before_allocating() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("n.las");
        write_las(&path, &sample()).unwrap();
        let mut bytes = std::fs::read(&path).unwrap();
        // The legacy point count, a u32 at byte 107: 4e9 records of 20 bytes.
        bytes[107..111].copy_from_slice(&u32::MAX.to_le_bytes());
        std::fs::write(&path, &bytes).unwrap();
        let err = read_las(&path).unwrap_err().to_string();
        assert!(
            err.contains("n.las") && err.contains("announces 4294967295 points"),
            "{err}"
        );
    }

    #[test]
    fn empty_cloud_round_trips() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("e.las");
        write_las(&path, &PointCloud::new()).unwrap();
        assert!(read_las(&path).unwrap().is_empty());
    }
}
