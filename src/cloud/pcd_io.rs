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

// ---------------------------------------------------------------- header

/// The numeric kind of a field (`TYPE`).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
enum Kind {
    Float,
    Unsigned,
    Signed,
}

/// One field of the header with its byte offset inside a record.
#[derive(Clone, Debug)]
struct Field {
    name: String,
    kind: Kind,
    size: usize,
    count: usize,
    /// Bytes of the record before this field.
    offset: usize,
    /// Values of the ascii line before this field.
    column: usize,
}

#[derive(Debug)]
struct Header {
    fields: Vec<Field>,
    /// Bytes per point (sum of `SIZE × COUNT`).
    record: usize,
    /// Values per point (sum of `COUNT`).
    values: usize,
    points: usize,
    encoding: PcdEncoding,
    /// Byte offset of the data, just after the `DATA` line.
    data_start: usize,
    /// One-based number of the `DATA` line.
    data_line: usize,
}

fn parse_header(path: &Path, bytes: &[u8]) -> Result<Header> {
    let mut names: Option<(usize, Vec<String>)> = None;
    let mut sizes: Option<(usize, Vec<usize>)> = None;
    let mut kinds: Option<(usize, Vec<Kind>)> = None;
    let mut counts: Option<(usize, Vec<usize>)> = None;
    let mut width: Option<u64> = None;
    let mut height: Option<u64> = None;
    let mut points: Option<(usize, u64)> = None;
    let mut at = 0;
    let mut line_no = 0;
    loop {
        line_no += 1;
        if at >= bytes.len() {
            return Err(Error::parse(
                path,
                line_no,
                "header",
                "the file ends before the DATA line",
            ));
        }
        let end = bytes[at..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |k| at + k);
        let raw = &bytes[at..end];
        at = (end + 1).min(bytes.len());
        // Comments may hold any bytes.
        if raw.trim_ascii_start().starts_with(b"#") {
            continue;
        }
        let line = std::str::from_utf8(raw)
            .map_err(|_| Error::parse(path, line_no, "header", "line is not text"))?
            .trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let mut words = line.split_whitespace();
        let keyword = words.next().unwrap_or("");
        let rest: Vec<&str> = words.collect();
        let err = |reason: String| Error::parse(path, line_no, keyword, reason);
        match keyword.to_ascii_uppercase().as_str() {
            "VERSION" => {
                let v = rest.first().copied().unwrap_or("");
                if ![".7", "0.7", ".6", "0.6", ".5", "0.5"].contains(&v) || rest.len() != 1 {
                    return Err(err(format!(
                        "unsupported version `{}` (expected 0.5, 0.6 or 0.7)",
                        rest.join(" ")
                    )));
                }
            }
            "FIELDS" | "COLUMNS" => {
                if rest.is_empty() {
                    return Err(err("no field names".into()));
                }
                names = Some((line_no, rest.iter().map(|s| s.to_string()).collect()));
            }
            "SIZE" => {
                let v = rest
                    .iter()
                    .map(|s| match *s {
                        "1" => Ok(1),
                        "2" => Ok(2),
                        "4" => Ok(4),
                        "8" => Ok(8),
                        other => Err(err(format!("size `{other}` is not 1, 2, 4 or 8"))),
                    })
                    .collect::<Result<Vec<usize>>>()?;
                sizes = Some((line_no, v));
            }
            "TYPE" => {
                let v = rest
                    .iter()
                    .map(|s| match *s {
                        "F" | "f" => Ok(Kind::Float),
                        "U" | "u" => Ok(Kind::Unsigned),
                        "I" | "i" => Ok(Kind::Signed),
                        other => Err(err(format!("type `{other}` is not F, U or I"))),
                    })
                    .collect::<Result<Vec<Kind>>>()?;
                kinds = Some((line_no, v));
            }
            "COUNT" => {
                let v = rest
                    .iter()
                    .map(|s| match s.parse::<usize>() {
                        Ok(n) if n >= 1 => Ok(n),
                        _ => Err(err(format!("count `{s}` is not a positive integer"))),
                    })
                    .collect::<Result<Vec<usize>>>()?;
                counts = Some((line_no, v));
            }
            "WIDTH" | "HEIGHT" | "POINTS" => {
                let n = match rest.as_slice() {
                    [s] => s.parse::<u64>().ok(),
                    _ => None,
                }
                .ok_or_else(|| err(format!("`{}` is not a whole number", rest.join(" "))))?;
                match keyword.to_ascii_uppercase().as_str() {
                    "WIDTH" => width = Some(n),
                    "HEIGHT" => height = Some(n),
                    _ => points = Some((line_no, n)),
                }
            }
            "VIEWPOINT" => {
                let ok = rest.len() == 7
                    && rest
                        .iter()
                        .all(|s| s.parse::<f64>().is_ok_and(f64::is_finite));
                if !ok {
                    return Err(err(
                        "expected 7 finite numbers (translation, quaternion w x y z)".into(),
                    ));
                }
            }
            "DATA" => {
                let encoding = match rest.as_slice() {
                    [e] if e.eq_ignore_ascii_case("ascii") => PcdEncoding::Ascii,
                    [e] if e.eq_ignore_ascii_case("binary") => PcdEncoding::Binary,
                    [e] if e.eq_ignore_ascii_case("binary_compressed") => {
                        PcdEncoding::BinaryCompressed
                    }
                    _ => {
                        return Err(err(format!(
                            "unknown encoding `{}` (expected ascii, binary or \
                             binary_compressed)",
                            rest.join(" ")
                        )))
                    }
                };
                let (names_line, names) = names.ok_or_else(|| {
                    Error::parse(path, line_no, "FIELDS", "no FIELDS line before DATA")
                })?;
                let n = names.len();
                let same = |what: &str, line: usize, len: usize| {
                    if len == n {
                        Ok(())
                    } else {
                        Err(Error::parse(
                            path,
                            line,
                            what,
                            format!("{len} entries for {n} fields (line {names_line})"),
                        ))
                    }
                };
                let (sizes_line, sizes) = sizes.ok_or_else(|| {
                    Error::parse(path, line_no, "SIZE", "no SIZE line before DATA")
                })?;
                same("SIZE", sizes_line, sizes.len())?;
                let (kinds_line, kinds) = kinds.ok_or_else(|| {
                    Error::parse(path, line_no, "TYPE", "no TYPE line before DATA")
                })?;
                same("TYPE", kinds_line, kinds.len())?;
                let counts = match counts {
                    Some((l, c)) => {
                        same("COUNT", l, c.len())?;
                        c
                    }
                    None => vec![1; n],
                };
                let mut fields = Vec::with_capacity(n);
                let (mut record, mut values) = (0usize, 0usize);
                for (k, name) in names.into_iter().enumerate() {
                    let (kind, size, count) = (kinds[k], sizes[k], counts[k]);
                    if kind == Kind::Float && size < 4 {
                        return Err(Error::parse(
                            path,
                            sizes_line,
                            "SIZE",
                            format!("field `{name}` is F of {size} bytes (must be 4 or 8)"),
                        ));
                    }
                    let offset = record;
                    let column = values;
                    let overflow =
                        || Error::parse(path, line_no, "COUNT", "the record size overflows");
                    record = size
                        .checked_mul(count)
                        .and_then(|b| record.checked_add(b))
                        .ok_or_else(overflow)?;
                    values = values.checked_add(count).ok_or_else(overflow)?;
                    fields.push(Field {
                        name,
                        kind,
                        size,
                        count,
                        offset,
                        column,
                    });
                }
                let width_height = match (width, height) {
                    (Some(w), h) => Some(w.checked_mul(h.unwrap_or(1))),
                    (None, _) => None,
                };
                let points = match (points, width_height) {
                    (Some((l, p)), Some(wh)) => {
                        if wh != Some(p) {
                            return Err(Error::parse(
                                path,
                                l,
                                "POINTS",
                                format!(
                                    "{p} points but WIDTH × HEIGHT is {} × {}",
                                    width.unwrap_or(0),
                                    height.unwrap_or(1)
                                ),
                            ));
                        }
                        p
                    }
                    (Some((_, p)), None) => p,
                    (None, Some(Some(wh))) => wh,
                    (None, Some(None)) => {
                        return Err(Error::parse(
                            path,
                            line_no,
                            "WIDTH",
                            "WIDTH × HEIGHT overflows",
                        ))
                    }
                    (None, None) => {
                        return Err(Error::parse(
                            path,
                            line_no,
                            "POINTS",
                            "neither POINTS nor WIDTH before DATA",
                        ))
                    }
                };
                let remaining = (bytes.len() - at) as u64;
                // Every point takes at least one byte of data in every encoding but the
                // compressed one, whose sizes are checked separately; refuse larger counts
                // before any of them reaches an allocation.
                let points = usize::try_from(points)
                    .ok()
                    .filter(|_| encoding == PcdEncoding::BinaryCompressed || points <= remaining)
                    .ok_or_else(|| {
                        Error::parse(
                            path,
                            line_no,
                            "POINTS",
                            format!(
                                "{points} points announced but only {remaining} bytes follow \
                                 the header"
                            ),
                        )
                    })?;
                return Ok(Header {
                    fields,
                    record,
                    values,
                    points,
                    encoding,
                    data_start: at,
                    data_line: line_no,
                });
            }
            _ => return Err(err("unknown header keyword".into())),
        }
    }
}

/// Bytes of the packed (binary or decompressed) data: points × record size.
fn data_bytes(path: &Path, header: &Header) -> Result<usize> {
    header.points.checked_mul(header.record).ok_or_else(|| {
        Error::parse(
            path,
            header.data_line,
            "POINTS",
            format!(
                "{} points of {} bytes overflow",
                header.points, header.record
            ),
        )
    })
}

fn truncated(path: &Path, header: &Header, need: usize, have: usize) -> Error {
    Error::parse(
        path,
        0,
        "data",
        format!(
            "truncated: {} points of {} bytes need {need} bytes, {have} follow the header",
            header.points, header.record
        ),
    )
}

/// Where x, y, z, intensity and label sit among the fields.
struct Roles {
    xyz: [Field; 3],
    intensity: Option<Field>,
    label: Option<Field>,
}

impl Roles {
    fn of(path: &Path, fields: &[Field]) -> Result<Roles> {
        let find = |pred: &dyn Fn(&str) -> bool| fields.iter().find(|f| pred(&f.name)).cloned();
        let single = |f: Option<Field>| -> Result<Option<Field>> {
            match f {
                Some(f) if f.count != 1 => Err(Error::parse(
                    path,
                    0,
                    f.name.clone(),
                    format!("COUNT is {} (must be 1)", f.count),
                )),
                other => Ok(other),
            }
        };
        let axis = |name: &str| -> Result<Field> {
            single(find(&|n| n == name))?.ok_or_else(|| {
                Error::parse(
                    path,
                    0,
                    "FIELDS",
                    format!("the points have no `{name}` field"),
                )
            })
        };
        let intensity = single(find(&|n| {
            n.eq_ignore_ascii_case("intensity") || n.eq_ignore_ascii_case("reflectance")
        }))?;
        let label = single(find(&|n| n == "label"))?;
        Ok(Roles {
            xyz: [axis("x")?, axis("y")?, axis("z")?],
            intensity,
            label,
        })
    }
}

// ---------------------------------------------------------------- values

/// The first value of field `f` at the start of `bytes` (little-endian), as f64.
fn value(f: &Field, bytes: &[u8]) -> Result<f64, String> {
    let src = bytes
        .get(..f.size)
        .ok_or_else(|| format!("field `{}` runs past the data", f.name))?;
    let mut buf = [0u8; 8];
    buf[..f.size].copy_from_slice(src);
    Ok(match (f.kind, f.size) {
        (Kind::Float, 4) => f64::from(f32::from_le_bytes([buf[0], buf[1], buf[2], buf[3]])),
        (Kind::Float, _) => f64::from_le_bytes(buf),
        (Kind::Unsigned, _) => u64::from_le_bytes(buf) as f64,
        (Kind::Signed, n) => {
            let shift = 64 - 8 * n as u32;
            ((i64::from_le_bytes(buf) << shift) >> shift) as f64
        }
    })
}

/// Parses one ascii value of field `f`.
fn parse_value(f: &Field, token: &str) -> Result<f64, String> {
    let bad = || {
        format!(
            "`{token}` is not a {} of {} bytes",
            kind_name(f.kind),
            f.size
        )
    };
    let bits = 8 * f.size as u32;
    match f.kind {
        // Parsed at the field's own precision: no double rounding through f64.
        Kind::Float if f.size == 4 => token.parse::<f32>().map(f64::from).map_err(|_| bad()),
        Kind::Float => token.parse::<f64>().map_err(|_| bad()),
        Kind::Unsigned => {
            let v = token.parse::<u64>().map_err(|_| bad())?;
            if bits < 64 && v >> bits != 0 {
                return Err(bad());
            }
            Ok(v as f64)
        }
        Kind::Signed => {
            let v = token.parse::<i64>().map_err(|_| bad())?;
            if bits < 64 && (v < -(1i64 << (bits - 1)) || v >= 1i64 << (bits - 1)) {
                return Err(bad());
            }
            Ok(v as f64)
        }
    }
}

fn kind_name(kind: Kind) -> &'static str {
    match kind {
        Kind::Float => "float",
        Kind::Unsigned => "unsigned integer",
        Kind::Signed => "signed integer",
    }
}

/// Collects the points, applying the intensity scaling, the label check and the policy.
struct Sink<'a> {
    path: &'a Path,
    roles: &'a Roles,
    policy: NonFinite,
    scan: PcdScan,
}

impl<'a> Sink<'a> {
    fn new(path: &'a Path, roles: &'a Roles, policy: NonFinite) -> Self {
        let scan = PcdScan {
            labels: roles.label.as_ref().map(|_| Vec::new()),
            ..PcdScan::default()
        };
        Sink {
            path,
            roles,
            policy,
            scan,
        }
    }

    /// Reserves room for `n` points (`n` already checked against the file).
    fn reserve(&mut self, n: usize) {
        self.scan.cloud = PointCloud::with_capacity(n);
        if let Some(labels) = &mut self.scan.labels {
            labels.reserve(n);
        }
    }

    /// Takes point `i` (on ascii line `line`, 0 for binary data), reading each role's value
    /// with `get`.
    fn point(
        &mut self,
        line: usize,
        i: usize,
        get: impl Fn(&Field) -> Result<f64, String>,
    ) -> Result<()> {
        let err = |field: String, reason: String| Error::parse(self.path, line, field, reason);
        let mut v = [0f32; 4];
        for (k, f) in self.roles.xyz.iter().enumerate() {
            v[k] = get(f).map_err(|r| err(format!("point {i}"), r))? as f32;
        }
        if let Some(f) = &self.roles.intensity {
            let raw = get(f).map_err(|r| err(format!("point {i}"), r))?;
            v[3] = match (f.kind, f.size) {
                (Kind::Unsigned, 1) => raw / 255.0,
                (Kind::Unsigned, 2) => raw / 65535.0,
                _ => raw,
            } as f32;
        }
        let label = match &self.roles.label {
            Some(f) => {
                let raw = get(f).map_err(|r| err(format!("point {i}"), r))?;
                if !(raw >= 0.0 && raw <= f64::from(u32::MAX) && raw.fract() == 0.0) {
                    return Err(err(
                        format!("point {i} (label)"),
                        format!("{raw} is not a 32-bit unsigned integer"),
                    ));
                }
                Some(raw as u32)
            }
            None => None,
        };
        if let Some(k) = v.iter().position(|x| !x.is_finite()) {
            match self.policy {
                NonFinite::Error => {
                    let name = match k {
                        3 => self
                            .roles
                            .intensity
                            .as_ref()
                            .map_or("intensity", |f| &f.name),
                        k => &self.roles.xyz[k].name,
                    };
                    return Err(err(
                        format!("point {i} ({name})"),
                        format!("value is {} (must be finite)", v[k]),
                    ));
                }
                NonFinite::Skip => {
                    self.scan.skipped += 1;
                    return Ok(());
                }
            }
        }
        self.scan.cloud.push(v[0], v[1], v[2], v[3]);
        if let (Some(labels), Some(l)) = (&mut self.scan.labels, label) {
            labels.push(l);
        }
        Ok(())
    }

    fn finish(self) -> PcdScan {
        self.scan
    }
}

// ---------------------------------------------------------------- ascii

fn read_ascii(path: &Path, header: &Header, data: &[u8], sink: &mut Sink) -> Result<()> {
    let text = std::str::from_utf8(data)
        .map_err(|e| Error::parse(path, 0, "data", format!("ascii data is not text: {e}")))?;
    // A point takes at least one character per value and a separator after each.
    let min_line = header.values.saturating_mul(2).saturating_sub(1).max(1);
    if header.points > text.len() / min_line + 1 {
        return Err(Error::parse(
            path,
            header.data_line,
            "POINTS",
            format!(
                "{} points of {} values cannot fit in the {} bytes after the header",
                header.points,
                header.values,
                text.len()
            ),
        ));
    }
    sink.reserve(header.points);
    let mut i = 0;
    let mut tokens: Vec<&str> = Vec::with_capacity(header.values.min(1024));
    for (k, line) in text.lines().enumerate() {
        let line_no = header.data_line + 1 + k;
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        if i == header.points {
            return Err(Error::parse(
                path,
                line_no,
                "data",
                format!("more lines than the {} points announced", header.points),
            ));
        }
        tokens.clear();
        tokens.extend(line.split_whitespace());
        if tokens.len() != header.values {
            return Err(Error::parse(
                path,
                line_no,
                format!("point {i}"),
                format!(
                    "{} values on the line, the header announces {}",
                    tokens.len(),
                    header.values
                ),
            ));
        }
        sink.point(line_no, i, |f: &Field| parse_value(f, tokens[f.column]))?;
        i += 1;
    }
    if i < header.points {
        return Err(Error::parse(
            path,
            0,
            "data",
            format!(
                "truncated: {} points announced, {i} lines of points found",
                header.points
            ),
        ));
    }
    Ok(())
}

// ---------------------------------------------------------------- binary_compressed

/// Largest output of an LZF stream per input byte: a three-byte back-reference copies up to
/// 264 bytes.
const LZF_MAX_RATIO: usize = 88;

/// Reads the sizes of a binary_compressed block, checks them against the header and the file,
/// and decompresses it.
fn decompress_data(path: &Path, header: &Header, data: &[u8]) -> Result<Vec<u8>> {
    if data.len() < 8 {
        return Err(Error::parse(
            path,
            0,
            "data",
            format!(
                "truncated: {} bytes after the header, the two sizes need 8",
                data.len()
            ),
        ));
    }
    let word = |k: usize| u32::from_le_bytes([data[k], data[k + 1], data[k + 2], data[k + 3]]);
    let (packed, unpacked) = (word(0) as usize, word(4) as usize);
    let need = data_bytes(path, header)?;
    if unpacked != need {
        return Err(Error::parse(
            path,
            0,
            "data",
            format!(
                "uncompressed size {unpacked} bytes, but {} points of {} bytes need {need}",
                header.points, header.record
            ),
        ));
    }
    let body = &data[8..];
    if packed > body.len() {
        return Err(Error::parse(
            path,
            0,
            "data",
            format!(
                "truncated: compressed size {packed} bytes, {} follow the sizes",
                body.len()
            ),
        ));
    }
    if unpacked > packed.saturating_mul(LZF_MAX_RATIO) {
        return Err(Error::parse(
            path,
            0,
            "data",
            format!("{packed} compressed bytes cannot hold {unpacked} bytes of LZF output"),
        ));
    }
    lzf_decompress(&body[..packed], unpacked)
        .map_err(|reason| Error::parse(path, 0, "LZF data", reason))
}

/// Decompresses an LZF stream (liblzf's format) that must produce exactly `len` bytes.
///
/// Each control byte `c` starts either a literal run (`c < 32`: the next `c + 1` bytes) or a
/// back-reference: length `c >> 5` (7 means: add the next byte), plus 2; distance
/// `((c & 31) << 8 | next byte) + 1` back from the end of the output.
fn lzf_decompress(input: &[u8], len: usize) -> Result<Vec<u8>, String> {
    let mut out = Vec::with_capacity(len);
    let mut at = 0;
    while at < input.len() {
        let ctrl = usize::from(input[at]);
        at += 1;
        if ctrl < 32 {
            let run = ctrl + 1;
            let lit = input
                .get(at..at + run)
                .ok_or_else(|| format!("literal run of {run} bytes at byte {} is cut", at - 1))?;
            if out.len() + run > len {
                return Err(format!("output exceeds the announced {len} bytes"));
            }
            out.extend_from_slice(lit);
            at += run;
        } else {
            let start = at - 1;
            let mut n = ctrl >> 5;
            if n == 7 {
                n += usize::from(
                    *input
                        .get(at)
                        .ok_or_else(|| format!("back-reference at byte {start} is cut"))?,
                );
                at += 1;
            }
            let low = usize::from(
                *input
                    .get(at)
                    .ok_or_else(|| format!("back-reference at byte {start} is cut"))?,
            );
            at += 1;
            let distance = ((ctrl & 31) << 8 | low) + 1;
            let n = n + 2;
            if distance > out.len() {
                return Err(format!(
                    "back-reference at byte {start} reaches {distance} bytes back, only {} \
                     decoded",
                    out.len()
                ));
            }
            if out.len() + n > len {
                return Err(format!("output exceeds the announced {len} bytes"));
            }
            let from = out.len() - distance;
            for k in 0..n {
                out.push(out[from + k]);
            }
        }
    }
    if out.len() != len {
        return Err(format!(
            "stream ends after {} bytes of the announced {len}",
            out.len()
        ));
    }
    Ok(out)
}

/// Compresses `input` as an LZF stream (greedy, one hash-table probe per position).
fn lzf_compress(input: &[u8]) -> Vec<u8> {
    const HASH_BITS: u32 = 14;
    const MAX_DISTANCE: usize = 1 << 13;
    const MAX_LEN: usize = 7 + 255 + 2;
    fn literals(out: &mut Vec<u8>, mut lit: &[u8]) {
        while !lit.is_empty() {
            let n = lit.len().min(32);
            out.push((n - 1) as u8);
            out.extend_from_slice(&lit[..n]);
            lit = &lit[n..];
        }
    }
    let mut out = Vec::with_capacity(input.len() + input.len() / 32 + 1);
    let mut table = vec![usize::MAX; 1 << HASH_BITS];
    let (mut i, mut lit_start) = (0, 0);
    while i + 3 <= input.len() {
        let key =
            u32::from(input[i]) << 16 | u32::from(input[i + 1]) << 8 | u32::from(input[i + 2]);
        let h = (key.wrapping_mul(2_654_435_761) >> (32 - HASH_BITS)) as usize;
        let candidate = table[h];
        table[h] = i;
        if candidate != usize::MAX
            && i - candidate <= MAX_DISTANCE
            && input[candidate..candidate + 3] == input[i..i + 3]
        {
            let max = MAX_LEN.min(input.len() - i);
            let mut n = 3;
            while n < max && input[candidate + n] == input[i + n] {
                n += 1;
            }
            literals(&mut out, &input[lit_start..i]);
            let distance = i - candidate - 1;
            let l = n - 2;
            if l < 7 {
                out.push((l << 5 | distance >> 8) as u8);
            } else {
                out.push((7 << 5 | distance >> 8) as u8);
                out.push((l - 7) as u8);
            }
            out.push(distance as u8);
            i += n;
            lit_start = i;
        } else {
            i += 1;
        }
    }
    literals(&mut out, &input[lit_start..]);
    out
}

// ---------------------------------------------------------------- writing

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

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn sample() -> PointCloud {
        let mut c = PointCloud::new();
        c.push(1.2345, -20.5, 0.25, 0.0);
        c.push(-3.0, 4.0, -1.75, 0.5);
        c.push(60.0, 0.001, 2.0, 1.0);
        c.push(1e-7, -1e30, 3.25, 0.123_456_79);
        c
    }

    const ALL: [PcdEncoding; 3] = [
        PcdEncoding::Ascii,
        PcdEncoding::Binary,
        PcdEncoding::BinaryCompressed,
    ];

    fn header(
        fields: &str,
        sizes: &str,
        types: &str,
        counts: &str,
        n: usize,
        data: &str,
    ) -> String {
        format!(
            "# .PCD v0.7\nVERSION 0.7\nFIELDS {fields}\nSIZE {sizes}\nTYPE {types}\n\
             COUNT {counts}\nWIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\n\
             DATA {data}\n"
        )
    }

    fn decode(bytes: &[u8]) -> Result<PcdScan> {
        decode_pcd("mem.pcd", bytes, NonFinite::Error)
    }

    #[test]
    fn round_trips_are_exact_in_every_encoding() {
        let dir = tempfile::tempdir().unwrap();
        for encoding in ALL {
            let path = dir.path().join("c.pcd");
            write_pcd(&path, &sample(), encoding).unwrap();
            assert_eq!(read_pcd(&path).unwrap(), sample(), "{encoding:?}");
            write_pcd(&path, &PointCloud::new(), encoding).unwrap();
            assert!(read_pcd(&path).unwrap().is_empty(), "{encoding:?}");
        }
    }

    #[test]
    fn labelled_round_trip_returns_the_labels() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("l.pcd");
        for encoding in ALL {
            write_pcd_labelled(&path, &sample(), &[0, 7, u32::MAX, 3], encoding).unwrap();
            let scan = read_pcd_with(&path, NonFinite::Error).unwrap();
            assert_eq!(scan.cloud, sample());
            assert_eq!(scan.labels, Some(vec![0, 7, u32::MAX, 3]));
        }
        assert!(write_pcd_labelled(&path, &sample(), &[1], PcdEncoding::Binary).is_err());
        write_pcd(&path, &sample(), PcdEncoding::Binary).unwrap();
        assert_eq!(read_pcd_with(&path, NonFinite::Error).unwrap().labels, None);
    }

    #[test]
    fn reads_other_types_and_skips_other_fields() {
        // rgb (F 4), a 3-count normal (F 8), padding, U 2 intensity, I 1 z, U 2 label.
        let mut text = header(
            "rgb x normal _ y z intensity label",
            "4 8 8 1 4 1 2 2",
            "F F F U F I U U",
            "1 1 3 2 1 1 1 1",
            2,
            "ascii",
        );
        text.push_str("4.2e6 1.5 0.1 0.2 0.3 0 0 -2.5 -3 65535 12\n");
        text.push_str("\n0 -7 1 1 1 9 9 2 127 0 0\n");
        let scan = decode(text.as_bytes()).unwrap();
        assert_eq!(scan.cloud.xs(), &[1.5, -7.0]);
        assert_eq!(scan.cloud.ys(), &[-2.5, 2.0]);
        assert_eq!(scan.cloud.zs(), &[-3.0, 127.0]);
        assert_eq!(scan.cloud.intensities(), &[1.0, 0.0]);
        assert_eq!(scan.labels, Some(vec![12, 0]));

        // The same points as binary records.
        let mut bytes = header(
            "rgb x normal _ y z intensity label",
            "4 8 8 1 4 1 2 2",
            "F F F U F I U U",
            "1 1 3 2 1 1 1 1",
            2,
            "binary",
        )
        .into_bytes();
        for (x, y, z, i, l) in [
            (1.5f64, -2.5f32, -3i8, 65535u16, 12u16),
            (-7.0, 2.0, 127, 0, 0),
        ] {
            bytes.extend_from_slice(&4.2e6f32.to_le_bytes());
            bytes.extend_from_slice(&x.to_le_bytes());
            bytes.extend_from_slice(&[0u8; 24]);
            bytes.extend_from_slice(&[9, 9]);
            bytes.extend_from_slice(&y.to_le_bytes());
            bytes.extend_from_slice(&z.to_le_bytes());
            bytes.extend_from_slice(&i.to_le_bytes());
            bytes.extend_from_slice(&l.to_le_bytes());
        }
        assert_eq!(decode(&bytes).unwrap(), scan);
    }

    #[test]
    fn reflectance_and_old_headers_are_read() {
        let text = "VERSION .5\nCOLUMNS x y z reflectance\nSIZE 4 4 4 4\nTYPE F F F F\n\
                    WIDTH 1\nDATA ascii\n1 2 3 0.25\n";
        let scan = decode(text.as_bytes()).unwrap();
        assert_eq!(scan.cloud.intensities(), &[0.25]);
        let text = "VERSION 0.6\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nPOINTS 1\nDATA ascii\n\
                    1 2 3\n";
        let scan = decode(text.as_bytes()).unwrap();
        assert_eq!(scan.cloud.intensities(), &[0.0]);
        // A comment in Latin-1 and a CRLF header.
        let mut bytes = b"# caf\xe9\r\n".to_vec();
        bytes.extend_from_slice(text.replace('\n', "\r\n").as_bytes());
        assert_eq!(decode(&bytes).unwrap().cloud.xs(), &[1.0]);
    }

    /// A binary_compressed file of `n` points with fields `x y z` (F 4) and the given stream.
    fn compressed(n: usize, raw_len: usize, stream: &[u8]) -> Vec<u8> {
        let mut bytes =
            header("x y z", "4 4 4", "F F F", "1 1 1", n, "binary_compressed").into_bytes();
        bytes.extend_from_slice(&(stream.len() as u32).to_le_bytes());
        bytes.extend_from_slice(&(raw_len as u32).to_le_bytes());
        bytes.extend_from_slice(stream);
        bytes
    }

    #[test]
    fn binary_compressed_with_literals_only() {
        // Two points, column-major: x0 x1 y0 y1 z0 z1, 24 bytes in one literal run of 24
        // (control byte 23).
        let mut raw = Vec::new();
        for v in [1.0f32, 2.0, 3.0, 4.0, 5.0, 6.0] {
            raw.extend_from_slice(&v.to_le_bytes());
        }
        let mut stream = vec![23u8];
        stream.extend_from_slice(&raw);
        let scan = decode(&compressed(2, 24, &stream)).unwrap();
        assert_eq!(scan.cloud.xs(), &[1.0, 2.0]);
        assert_eq!(scan.cloud.ys(), &[3.0, 4.0]);
        assert_eq!(scan.cloud.zs(), &[5.0, 6.0]);
    }

    #[test]
    fn binary_compressed_with_back_references() {
        // Four points at (1, 1, 1), (1, 1, 1), (0, 0, 0), (0, 0, 0) hold, column-major,
        // x: 1 1 0 0, y: 1 1 0 0, z: 1 1 0 0 (1.0 = 00 00 80 3f).
        //   literal 4 bytes: 00 00 80 3f                          -> 1.0
        //   back-ref len 4 dist 4: ctrl (4-2)<<5 = 0x40, dist-1 = 3   -> 1.0 again
        //   literal 1 byte: 00; back-ref len 7 dist 1: (7-2)<<5 = 0xa0, 0 -> eight zeros
        //   back-ref len 16 dist 16: 7<<5 = 0xe0, extra 16-2-7 = 7, dist-1 = 15
        //                                                        -> y column = x column
        //   back-ref len 16 dist 16 again                          -> z column
        let stream = [
            0x03, 0x00, 0x00, 0x80, 0x3f, // literal 1.0
            0x40, 0x03, // copy 4 from 4 back
            0x00, 0x00, // literal 0x00
            0xa0, 0x00, // copy 7 from 1 back
            0xe0, 0x07, 0x0f, // copy 16 from 16 back
            0xe0, 0x07, 0x0f, // copy 16 from 16 back
        ];
        let scan = decode(&compressed(4, 48, &stream)).unwrap();
        let expected = [1.0, 1.0, 0.0, 0.0];
        assert_eq!(scan.cloud.xs(), &expected);
        assert_eq!(scan.cloud.ys(), &expected);
        assert_eq!(scan.cloud.zs(), &expected);
    }

    #[test]
    fn lzf_compress_then_decompress_is_identity() {
        let mut data: Vec<u8> = (0..5000u32).flat_map(|k| (k % 97).to_le_bytes()).collect();
        data.extend(std::iter::repeat_n(7u8, 1000));
        let packed = lzf_compress(&data);
        assert!(packed.len() < data.len() / 2);
        assert_eq!(lzf_decompress(&packed, data.len()).unwrap(), data);
        assert_eq!(lzf_decompress(&lzf_compress(b""), 0).unwrap(), b"");
        assert_eq!(lzf_decompress(&lzf_compress(b"ab"), 2).unwrap(), b"ab");
    }

    #[test]
    fn corrupt_lzf_is_an_error_naming_the_file() {
        for (stream, raw_len) in [
            (&[0x05u8, 1, 2][..], 12),        // literal run cut
            (&[0x00, 1, 0x20, 0x05][..], 12), // reference beyond the start
            (&[0xe0][..], 12),                // reference cut
            (&[0x02, 1, 2, 3][..], 12),       // ends early
            (&[0x0b, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x20, 0][..], 12), // too long
        ] {
            let err = decode(&compressed(1, raw_len, stream))
                .unwrap_err()
                .to_string();
            assert!(err.contains("mem.pcd") && err.contains("LZF"), "{err}");
        }
        // Sizes disagreeing with the header or the file.
        for (bytes, fault) in [
            (compressed(1, 16, &[0x00, 1]), "uncompressed size 16"),
            (compressed(1, 12, &[]), "cannot hold"),
        ] {
            let err = decode(&bytes).unwrap_err().to_string();
            assert!(err.contains("mem.pcd") && err.contains(fault), "{err}");
        }
        let mut huge = compressed(1, 12, &[]);
        let at = huge.len() - 8;
        huge[at..at + 4].copy_from_slice(&u32::MAX.to_le_bytes());
        let err = decode(&huge).unwrap_err().to_string();
        assert!(err.contains("truncated"), "{err}");
    }

    #[test]
    fn every_truncation_is_an_error_not_a_panic() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.pcd");
        for encoding in ALL {
            write_pcd_labelled(&path, &sample(), &[1, 2, 3, 4], encoding).unwrap();
            let bytes = std::fs::read(&path).unwrap();
            for n in 0..bytes.len() {
                // Without its final newline an ascii file is still whole.
                if encoding == PcdEncoding::Ascii && n == bytes.len() - 1 {
                    continue;
                }
                let res = decode(&bytes[..n]);
                assert!(res.is_err(), "{encoding:?} cut at {n} of {}", bytes.len());
                assert!(res.unwrap_err().to_string().contains("mem.pcd"));
            }
        }
    }

    #[test]
    fn bad_headers_are_errors_naming_the_file_and_the_fault() {
        let good = header("x y z", "4 4 4", "F F F", "1 1 1", 1, "ascii") + "1 2 3\n";
        assert!(decode(good.as_bytes()).is_ok());
        let cases: Vec<(String, &str)> = vec![
            (
                good.replace("DATA ascii", "DATA binary_lz4"),
                "unknown encoding",
            ),
            (
                good.replace("SIZE 4 4 4", "SIZE 4 4"),
                "2 entries for 3 fields",
            ),
            (
                good.replace("TYPE F F F", "TYPE F F F F"),
                "4 entries for 3 fields",
            ),
            (
                good.replace("COUNT 1 1 1", "COUNT 1 1"),
                "2 entries for 3 fields",
            ),
            (good.replace("COUNT 1 1 1", "COUNT 1 0 1"), "count `0`"),
            (good.replace("FIELDS x y z", "FIELDS x y w"), "no `z` field"),
            (good.replace("POINTS 1", "POINTS 2"), "WIDTH × HEIGHT"),
            (
                good.replace("VERSION 0.7", "VERSION 2.0"),
                "unsupported version",
            ),
            (good.replace("SIZE 4 4 4", "SIZE 4 4 3"), "size `3`"),
            (good.replace("SIZE 4 4 4", "SIZE 4 4 2"), "must be 4 or 8"),
            (good.replace("TYPE F F F", "TYPE F F Q"), "type `Q`"),
            (
                good.replace("VIEWPOINT 0 0 0 1 0 0 0", "VIEWPOINT 0 0"),
                "7 finite",
            ),
            (
                good.replace("HEIGHT 1", "HEIGHT 1\nSCALE 1"),
                "unknown header keyword",
            ),
            (good.replace("COUNT 1 1 1", "COUNT 2 1 1"), "COUNT is 2"),
            (
                good.replace("DATA ascii\n1 2 3\n", ""),
                "ends before the DATA line",
            ),
            (good.replace("1 2 3\n", "1 2\n"), "2 values on the line"),
            (good.replace("1 2 3\n", "1 2 x\n"), "`x` is not a float"),
            (good.replace("1 2 3\n", "1 2 3\n4 5 6\n"), "more lines"),
            (good.replace("1 2 3\n", "1 2 nan\n"), "must be finite"),
            (
                good.replace("POINTS 1", "POINTS 4000000000")
                    .replace("WIDTH 1", "WIDTH 4000000000"),
                "bytes follow the header",
            ),
            (
                good.replace("POINTS 1", "POINTS 3")
                    .replace("WIDTH 1", "WIDTH 3"),
                "cannot fit",
            ),
        ];
        for (text, fault) in cases {
            let err = decode(text.as_bytes()).unwrap_err().to_string();
            assert!(
                err.contains("mem.pcd") && err.contains(fault),
                "{fault}: {err}"
            );
        }
        // Line numbers of ascii data: the point is on line 12.
        let err = decode(good.replace("1 2 3\n", "1 2 x\n").as_bytes())
            .unwrap_err()
            .to_string();
        assert!(err.contains("mem.pcd:12:"), "{err}");
    }

    #[test]
    fn huge_binary_counts_are_refused_before_allocating() {
        for n in ["4000000000", "18446744073709551615"] {
            let text = header("x y z", "4 4 4", "F F F", "1 1 1", 1, "binary")
                .replace("WIDTH 1", &format!("WIDTH {n}"))
                .replace("POINTS 1", &format!("POINTS {n}"));
            let err = decode(text.as_bytes()).unwrap_err().to_string();
            assert!(err.contains("mem.pcd") && err.contains("POINTS"), "{err}");
        }
        // Within the file's size in points but not in bytes.
        let mut bytes = header("x y z", "4 4 4", "F F F", "1 1 1", 20, "binary").into_bytes();
        bytes.extend_from_slice(&[0u8; 100]);
        let err = decode(&bytes).unwrap_err().to_string();
        assert!(err.contains("truncated"), "{err}");
    }

    #[test]
    fn nan_points_are_refused_or_skipped() {
        let mut c = sample();
        c.push(f32::NAN, f32::NAN, f32::NAN, 0.0);
        c.push(5.0, 6.0, 7.0, f32::INFINITY);
        c.push(8.0, 9.0, 10.0, 0.5);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("nan.pcd");
        for encoding in ALL {
            write_pcd_labelled(&path, &c, &[0, 1, 2, 3, 4, 5, 6], encoding).unwrap();
            let err = read_pcd(&path).unwrap_err().to_string();
            assert!(
                err.contains("nan.pcd") && err.contains("point 4 (x)"),
                "{err}"
            );
            let scan = read_pcd_with(&path, NonFinite::Skip).unwrap();
            assert_eq!(scan.skipped, 2);
            assert_eq!(scan.cloud.len(), 5);
            assert_eq!(scan.cloud.xs()[4], 8.0);
            assert_eq!(scan.labels, Some(vec![0, 1, 2, 3, 6]));
        }
    }

    fn finite() -> impl Strategy<Value = f32> {
        prop_oneof![
            proptest::num::f32::NORMAL | proptest::num::f32::SUBNORMAL | proptest::num::f32::ZERO,
            -100.0..100.0f32,
        ]
    }

    proptest! {
        #[test]
        fn random_clouds_round_trip_exactly(
            points in proptest::collection::vec((finite(), finite(), finite(), finite(), any::<u32>()), 0..80),
            encoding in prop_oneof![
                Just(PcdEncoding::Ascii),
                Just(PcdEncoding::Binary),
                Just(PcdEncoding::BinaryCompressed),
            ],
            labelled in any::<bool>(),
        ) {
            let mut cloud = PointCloud::new();
            for p in &points {
                cloud.push(p.0, p.1, p.2, p.3);
            }
            let labels: Vec<u32> = points.iter().map(|p| p.4).collect();
            let bytes = encode_pcd(&cloud, labelled.then_some(&labels[..]), encoding).unwrap();
            let scan = decode(&bytes).unwrap();
            // Bit for bit, so that -0.0 and subnormals count too.
            let bits = |c: &PointCloud| {
                c.iter().map(|p| [p.x, p.y, p.z, p.intensity].map(f32::to_bits)).collect::<Vec<_>>()
            };
            prop_assert_eq!(bits(&scan.cloud), bits(&cloud));
            prop_assert_eq!(scan.labels, labelled.then_some(labels));
            prop_assert_eq!(scan.skipped, 0);
        }
    }

    #[test]
    fn missing_file_names_the_file() {
        let err = read_pcd("/nonexistent/dir/scan.pcd")
            .unwrap_err()
            .to_string();
        assert!(err.contains("scan.pcd"), "{err}");
    }
}
