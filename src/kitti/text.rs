//! Small functions shared by the KITTI text readers: reading a whole file with an error that
//! names it, and turning one whitespace-separated token into a number with an error that names
//! file, line and field.
//!
//! Not for: any particular file format (each has its own module).

use crate::error::{Error, Result};
use std::path::Path;

/// Reads a whole text file; a missing or unreadable file is an [`Error::Io`] naming it, and
/// bytes that are not UTF-8 an [`Error::Parse`] naming the line.
pub(crate) fn read_text(path: &Path) -> Result<String> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path, e))?;
    String::from_utf8(bytes).map_err(|e| {
        let good = &e.as_bytes()[..e.utf8_error().valid_up_to()];
        let line = good.iter().filter(|&&b| b == b'\n').count() + 1;
        Error::parse(path, line, "text", "not valid UTF-8")
    })
}

/// Parses a finite `f64`; the error names `path`, `line` and `field`.
pub(crate) fn parse_f64(path: &Path, line: usize, field: &str, token: &str) -> Result<f64> {
    match token.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(v) => Err(Error::parse(
            path,
            line,
            field,
            format!("`{token}` is {v} (must be finite)"),
        )),
        Err(_) => Err(Error::parse(
            path,
            line,
            field,
            format!("`{token}` is not a number"),
        )),
    }
}

/// The non-blank lines of `text` with their one-based line numbers, trailing whitespace removed.
pub(crate) fn numbered_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    text.lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim_end()))
        .filter(|(_, l)| !l.trim().is_empty())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_and_their_errors() {
        let p = Path::new("f.txt");
        assert_eq!(parse_f64(p, 3, "lat", "1.5e2").unwrap(), 150.0);
        let msg = parse_f64(p, 3, "lat", "abc").unwrap_err().to_string();
        assert_eq!(msg, "f.txt:3: lat: `abc` is not a number");
        assert!(parse_f64(p, 3, "lat", "NaN").is_err());
        assert!(parse_f64(p, 3, "lat", "inf").is_err());
    }

    #[test]
    fn blank_lines_are_skipped_but_counted() {
        let v: Vec<_> = numbered_lines("a\n\n  \nb  \n").collect();
        assert_eq!(v, vec![(1, "a"), (4, "b")]);
    }
}
