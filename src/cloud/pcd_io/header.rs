//! The header of a PCD file: its fields ([`Field`], with their [`Kind`], size, count, byte
//! offset and ascii column), the point count and the data encoding ([`Header`]), read by
//! [`parse_header`] up to and including the `DATA` line, and the sizes of the data they imply
//! ([`data_bytes`], [`truncated`]).
//!
//! Not for: reading the points that follow the header (see [`super::decode`] and
//! [`super::lzf`]) or writing a header (see [`super::encode_pcd`]).

use super::PcdEncoding;
use crate::error::{Error, Result};
use std::path::Path;

/// The numeric kind of a field (`TYPE`).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(super) enum Kind {
    Float,
    Unsigned,
    Signed,
}

/// One field of the header with its byte offset inside a record.
#[derive(Clone, Debug)]
pub(super) struct Field {
    pub(super) name: String,
    pub(super) kind: Kind,
    pub(super) size: usize,
    pub(super) count: usize,
    /// Bytes of the record before this field.
    pub(super) offset: usize,
    /// Values of the ascii line before this field.
    pub(super) column: usize,
}

/// What a PCD header says about the data after it.
#[derive(Debug)]
pub(super) struct Header {
    pub(super) fields: Vec<Field>,
    /// Bytes per point (sum of `SIZE × COUNT`).
    pub(super) record: usize,
    /// Values per point (sum of `COUNT`).
    pub(super) values: usize,
    /// Points announced (checked against the bytes after the header).
    pub(super) points: usize,
    pub(super) encoding: PcdEncoding,
    /// Byte offset of the data, just after the `DATA` line.
    pub(super) data_start: usize,
    /// One-based number of the `DATA` line.
    pub(super) data_line: usize,
}

/// Reads the header of `bytes` up to its `DATA` line, skipping blank lines and `#` comments.
///
/// Errors ([`Error::Parse`] naming `path`, the line and the keyword): the file ends before
/// `DATA`, a line is not text, a keyword line is malformed or unknown, or the fields and the
/// point count given before `DATA` do not add up (see [`Columns::fields`], [`place`],
/// [`Extent::announced`] and [`within`]).
pub(super) fn parse_header(path: &Path, bytes: &[u8]) -> Result<Header> {
    let mut lines = Lines {
        path,
        bytes,
        at: 0,
        line_no: 0,
    };
    let mut keywords = Keywords::default();
    let (line_no, keyword, rest) = loop {
        let line = lines.next_line()?;
        let line_no = lines.line_no;
        let mut words = line.split_whitespace();
        let keyword = words.next().unwrap_or("");
        let rest: Vec<&str> = words.collect();
        if keyword.eq_ignore_ascii_case("DATA") {
            break (line_no, keyword, rest);
        }
        keywords.take(path, line_no, keyword, &rest)?;
    };
    let encoding = encoding(&rest).ok_or_else(|| {
        Error::parse(
            path,
            line_no,
            keyword,
            format!(
                "unknown encoding `{}` (expected ascii, binary or \
                 binary_compressed)",
                rest.join(" ")
            ),
        )
    })?;
    let Keywords { columns, extent } = keywords;
    let (sizes_line, mut fields) = columns.fields(path, line_no)?;
    let (record, values) = place(path, sizes_line, line_no, &mut fields)?;
    let points = extent.announced(path, line_no)?;
    let remaining = (bytes.len() - lines.at) as u64;
    let points = within(path, line_no, points, encoding, remaining)?;
    Ok(Header {
        fields,
        record,
        values,
        points,
        encoding,
        data_start: lines.at,
        data_line: line_no,
    })
}

/// The lines of a header, read one at a time.
struct Lines<'a> {
    /// The file, only used in messages.
    path: &'a Path,
    bytes: &'a [u8],
    /// Byte offset of the next line.
    at: usize,
    /// One-based number of the line read last.
    line_no: usize,
}

impl<'a> Lines<'a> {
    /// The next line that is neither blank nor a `#` comment, trimmed.
    ///
    /// Errors: the file ends first, or the line is not text (comments may hold any bytes).
    fn next_line(&mut self) -> Result<&'a str> {
        let (path, bytes) = (self.path, self.bytes);
        loop {
            self.line_no += 1;
            if self.at >= bytes.len() {
                return Err(Error::parse(
                    path,
                    self.line_no,
                    "header",
                    "the file ends before the DATA line",
                ));
            }
            let end = bytes[self.at..]
                .iter()
                .position(|&b| b == b'\n')
                .map_or(bytes.len(), |k| self.at + k);
            let raw = &bytes[self.at..end];
            self.at = (end + 1).min(bytes.len());
            // Comments may hold any bytes.
            if raw.trim_ascii_start().starts_with(b"#") {
                continue;
            }
            let line = std::str::from_utf8(raw)
                .map_err(|_| Error::parse(path, self.line_no, "header", "line is not text"))?
                .trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            return Ok(line);
        }
    }
}

/// What the keyword lines before `DATA` said so far.
#[derive(Default)]
struct Keywords {
    columns: Columns,
    extent: Extent,
}

/// The `FIELDS` (or `COLUMNS`), `SIZE`, `TYPE` and `COUNT` lists, each with the one-based
/// number of its line (the last such line counts).
#[derive(Default)]
struct Columns {
    names: Option<(usize, Vec<String>)>,
    sizes: Option<(usize, Vec<usize>)>,
    kinds: Option<(usize, Vec<Kind>)>,
    counts: Option<(usize, Vec<usize>)>,
}

/// The `WIDTH`, `HEIGHT` and `POINTS` values (with the `POINTS` line's number).
#[derive(Default)]
struct Extent {
    width: Option<u64>,
    height: Option<u64>,
    points: Option<(usize, u64)>,
}

impl Keywords {
    /// Takes keyword line `line_no` (any keyword but `DATA`; `rest` holds the words after it).
    ///
    /// Errors: an unsupported version, no field names, a size, type or count that is not
    /// allowed, a width, height or point count that is not a whole number, a viewpoint that
    /// is not 7 finite numbers, or an unknown keyword ([`Error::Parse`] naming the keyword as
    /// written).
    fn take(&mut self, path: &Path, line_no: usize, keyword: &str, rest: &[&str]) -> Result<()> {
        let err = |reason: String| Error::parse(path, line_no, keyword, reason);
        let columns = &mut self.columns;
        let extent = &mut self.extent;
        match keyword.to_ascii_uppercase().as_str() {
            "VERSION" => version(rest).map_err(err)?,
            "FIELDS" | "COLUMNS" => {
                if rest.is_empty() {
                    return Err(err("no field names".into()));
                }
                columns.names = Some((line_no, rest.iter().map(|s| s.to_string()).collect()));
            }
            "SIZE" => columns.sizes = Some((line_no, each(rest, size).map_err(err)?)),
            "TYPE" => columns.kinds = Some((line_no, each(rest, kind).map_err(err)?)),
            "COUNT" => columns.counts = Some((line_no, each(rest, count).map_err(err)?)),
            "WIDTH" => extent.width = Some(whole(rest).map_err(err)?),
            "HEIGHT" => extent.height = Some(whole(rest).map_err(err)?),
            "POINTS" => extent.points = Some((line_no, whole(rest).map_err(err)?)),
            "VIEWPOINT" => viewpoint(rest).map_err(err)?,
            _ => return Err(err("unknown header keyword".into())),
        }
        Ok(())
    }
}

/// Checks the words of a `VERSION` line: one of 0.5, 0.6 and 0.7 (with or without the 0).
fn version(rest: &[&str]) -> Result<(), String> {
    let v = rest.first().copied().unwrap_or("");
    if ![".7", "0.7", ".6", "0.6", ".5", "0.5"].contains(&v) || rest.len() != 1 {
        return Err(format!(
            "unsupported version `{}` (expected 0.5, 0.6 or 0.7)",
            rest.join(" ")
        ));
    }
    Ok(())
}

/// Reads each word of a `SIZE`, `TYPE` or `COUNT` line with `parse`; the first that fails
/// gives the reason.
fn each<T>(rest: &[&str], parse: impl Fn(&str) -> Result<T, String>) -> Result<Vec<T>, String> {
    rest.iter().map(|s| parse(s)).collect()
}

/// One `SIZE`: 1, 2, 4 or 8 bytes.
fn size(word: &str) -> Result<usize, String> {
    match word {
        "1" => Ok(1),
        "2" => Ok(2),
        "4" => Ok(4),
        "8" => Ok(8),
        other => Err(format!("size `{other}` is not 1, 2, 4 or 8")),
    }
}

/// One `TYPE`: `F`, `U` or `I` (either case).
fn kind(word: &str) -> Result<Kind, String> {
    match word {
        "F" | "f" => Ok(Kind::Float),
        "U" | "u" => Ok(Kind::Unsigned),
        "I" | "i" => Ok(Kind::Signed),
        other => Err(format!("type `{other}` is not F, U or I")),
    }
}

/// One `COUNT`: a positive integer.
fn count(word: &str) -> Result<usize, String> {
    match word.parse::<usize>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err(format!("count `{word}` is not a positive integer")),
    }
}

/// The single whole number of a `WIDTH`, `HEIGHT` or `POINTS` line.
fn whole(rest: &[&str]) -> Result<u64, String> {
    match rest {
        [s] => s.parse::<u64>().ok(),
        _ => None,
    }
    .ok_or_else(|| format!("`{}` is not a whole number", rest.join(" ")))
}

/// Checks the words of a `VIEWPOINT` line: 7 finite numbers (not applied to the points).
fn viewpoint(rest: &[&str]) -> Result<(), String> {
    let ok = rest.len() == 7
        && rest
            .iter()
            .all(|s| s.parse::<f64>().is_ok_and(f64::is_finite));
    if !ok {
        return Err("expected 7 finite numbers (translation, quaternion w x y z)".into());
    }
    Ok(())
}

/// The encoding named by the words of a `DATA` line (any case), if it is one.
fn encoding(rest: &[&str]) -> Option<PcdEncoding> {
    match rest {
        [e] if e.eq_ignore_ascii_case("ascii") => Some(PcdEncoding::Ascii),
        [e] if e.eq_ignore_ascii_case("binary") => Some(PcdEncoding::Binary),
        [e] if e.eq_ignore_ascii_case("binary_compressed") => Some(PcdEncoding::BinaryCompressed),
        _ => None,
    }
}

impl Columns {
    /// The fields at the `DATA` line `line_no`, in order, not yet placed (offsets and columns
    /// 0; see [`place`]), with the number of the `SIZE` line. A missing `COUNT` line means 1
    /// each.
    ///
    /// Errors: no `FIELDS`, `SIZE` or `TYPE` line before `DATA` (naming the `DATA` line), or
    /// a `SIZE`, `TYPE` or `COUNT` line whose length differs from the field count (naming
    /// that line), checked in this order.
    fn fields(self, path: &Path, line_no: usize) -> Result<(usize, Vec<Field>)> {
        let (names_line, names) = self
            .names
            .ok_or_else(|| Error::parse(path, line_no, "FIELDS", "no FIELDS line before DATA"))?;
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
        let (sizes_line, sizes) = self
            .sizes
            .ok_or_else(|| Error::parse(path, line_no, "SIZE", "no SIZE line before DATA"))?;
        same("SIZE", sizes_line, sizes.len())?;
        let (kinds_line, kinds) = self
            .kinds
            .ok_or_else(|| Error::parse(path, line_no, "TYPE", "no TYPE line before DATA"))?;
        same("TYPE", kinds_line, kinds.len())?;
        let counts = match self.counts {
            Some((l, c)) => {
                same("COUNT", l, c.len())?;
                c
            }
            None => vec![1; n],
        };
        let fields = names
            .into_iter()
            .enumerate()
            .map(|(k, name)| Field {
                name,
                kind: kinds[k],
                size: sizes[k],
                count: counts[k],
                offset: 0,
                column: 0,
            })
            .collect();
        Ok((sizes_line, fields))
    }
}

/// Lays the fields out one after another: sets each field's byte offset in a record and its
/// column on an ascii line, and returns the record size (sum of `SIZE × COUNT`) and the values
/// per point (sum of `COUNT`).
///
/// Errors, field by field: an `F` field of fewer than 4 bytes (naming the `SIZE` line
/// `sizes_line`), or a record size or value count that overflows (naming the `DATA` line
/// `line_no`).
fn place(
    path: &Path,
    sizes_line: usize,
    line_no: usize,
    fields: &mut [Field],
) -> Result<(usize, usize)> {
    let (mut record, mut values) = (0usize, 0usize);
    for field in fields {
        let (kind, size, count) = (field.kind, field.size, field.count);
        if kind == Kind::Float && size < 4 {
            return Err(Error::parse(
                path,
                sizes_line,
                "SIZE",
                format!(
                    "field `{}` is F of {size} bytes (must be 4 or 8)",
                    field.name
                ),
            ));
        }
        let offset = record;
        let column = values;
        let overflow = || Error::parse(path, line_no, "COUNT", "the record size overflows");
        record = size
            .checked_mul(count)
            .and_then(|b| record.checked_add(b))
            .ok_or_else(overflow)?;
        values = values.checked_add(count).ok_or_else(overflow)?;
        field.offset = offset;
        field.column = column;
    }
    Ok((record, values))
}

impl Extent {
    /// The point count announced before the `DATA` line `line_no`: `POINTS`, which must equal
    /// `WIDTH` × `HEIGHT` when `WIDTH` is given too, or else `WIDTH` × `HEIGHT` (`HEIGHT` 1 when
    /// absent).
    ///
    /// Errors: `POINTS` ≠ `WIDTH` × `HEIGHT` (naming the `POINTS` line), `WIDTH` × `HEIGHT`
    /// overflows, or neither `POINTS` nor `WIDTH` is given.
    fn announced(&self, path: &Path, line_no: usize) -> Result<u64> {
        let (width, height) = (self.width, self.height);
        let width_height = match (width, height) {
            (Some(w), h) => Some(w.checked_mul(h.unwrap_or(1))),
            (None, _) => None,
        };
        match (self.points, width_height) {
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
                Ok(p)
            }
            (Some((_, p)), None) => Ok(p),
            (None, Some(Some(wh))) => Ok(wh),
            (None, Some(None)) => Err(Error::parse(
                path,
                line_no,
                "WIDTH",
                "WIDTH × HEIGHT overflows",
            )),
            (None, None) => Err(Error::parse(
                path,
                line_no,
                "POINTS",
                "neither POINTS nor WIDTH before DATA",
            )),
        }
    }
}

/// Checks the announced point count against the `remaining` bytes after the `DATA` line
/// `line_no`, before any of it reaches an allocation: every point takes at least one byte of
/// data in every encoding but the compressed one, whose sizes are checked separately.
///
/// Errors: more points than bytes (or than `usize` holds).
fn within(
    path: &Path,
    line_no: usize,
    points: u64,
    encoding: PcdEncoding,
    remaining: u64,
) -> Result<usize> {
    usize::try_from(points)
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
        })
}

/// Bytes of the packed (binary or decompressed) data: points × record size.
pub(super) fn data_bytes(path: &Path, header: &Header) -> Result<usize> {
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

/// The error for binary data of fewer bytes (`have`) than its points need (`need`).
pub(super) fn truncated(path: &Path, header: &Header, need: usize, have: usize) -> Error {
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
