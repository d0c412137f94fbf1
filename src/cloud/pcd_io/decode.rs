//! Turning the data of a PCD file into points: where `x`, `y`, `z`, intensity and label sit
//! among the fields ([`Roles`]), the value of a field in a binary record or on an ascii line,
//! and the [`Sink`] that scales intensities, checks labels and applies the [`NonFinite`]
//! policy to each point; [`read_ascii`] reads the lines of `DATA ascii`.
//!
//! Not for: the header (see [`super::header`]) or decompressing `binary_compressed` data (see
//! [`super::lzf`]).

use super::header::{Field, Header, Kind};
use super::PcdScan;
use crate::cloud::kitti_bin::NonFinite;
use crate::cloud::points::PointCloud;
use crate::error::{Error, Result};
use std::path::Path;

/// Where x, y, z, intensity and label sit among the fields.
pub(super) struct Roles {
    xyz: [Field; 3],
    intensity: Option<Field>,
    label: Option<Field>,
}

impl Roles {
    pub(super) fn of(path: &Path, fields: &[Field]) -> Result<Roles> {
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

/// The first value of field `f` at the start of `bytes` (little-endian), as f64.
pub(super) fn value(f: &Field, bytes: &[u8]) -> Result<f64, String> {
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

/// The name of `kind` in messages.
fn kind_name(kind: Kind) -> &'static str {
    match kind {
        Kind::Float => "float",
        Kind::Unsigned => "unsigned integer",
        Kind::Signed => "signed integer",
    }
}

/// Collects the points, applying the intensity scaling, the label check and the policy.
pub(super) struct Sink<'a> {
    path: &'a Path,
    roles: &'a Roles,
    policy: NonFinite,
    scan: PcdScan,
}

impl<'a> Sink<'a> {
    pub(super) fn new(path: &'a Path, roles: &'a Roles, policy: NonFinite) -> Self {
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
    pub(super) fn reserve(&mut self, n: usize) {
        self.scan.cloud = PointCloud::with_capacity(n);
        if let Some(labels) = &mut self.scan.labels {
            labels.reserve(n);
        }
    }

    /// Takes point `i` (on ascii line `line`, 0 for binary data), reading each role's value
    /// with `get`.
    pub(super) fn point(
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

    pub(super) fn finish(self) -> PcdScan {
        self.scan
    }
}

// ---------------------------------------------------------------- ascii

/// Reads the points of `DATA ascii` (one a line; blank lines and `#` comments skipped) into
/// `sink`, numbering lines from the header's `DATA` line.
///
/// Errors: the data is not text, cannot hold the announced points, or has more or fewer point
/// lines than announced; a line holds the wrong number of values or a malformed one (naming
/// its line); or `sink` refuses a point.
pub(super) fn read_ascii(path: &Path, header: &Header, data: &[u8], sink: &mut Sink) -> Result<()> {
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
