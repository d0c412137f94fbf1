//! The crate's error type: every failure caused by input data or configuration is a value
//! that names what was wrong and where (file, line, field). Library code never panics on input.

use std::path::PathBuf;

/// Errors returned by the library.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A value handed to the library is unusable (NaN, negative variance, wrong dimension, ...).
    #[error("invalid {what}: {reason}")]
    InvalidInput {
        /// What was invalid, e.g. `measurement 3 of frame 12`.
        what: String,
        /// Why.
        reason: String,
    },
    /// A text file could not be parsed.
    #[error("{}:{line}: {field}: {reason}", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// One-based line number (0 when the whole file is concerned).
        line: usize,
        /// The field or element that was wrong.
        field: String,
        /// Why.
        reason: String,
    },
    /// Reading or writing a file failed.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
}

impl Error {
    /// Shorthand for [`Error::InvalidInput`].
    pub fn invalid(what: impl Into<String>, reason: impl Into<String>) -> Self {
        Error::InvalidInput {
            what: what.into(),
            reason: reason.into(),
        }
    }

    /// Shorthand for [`Error::Parse`].
    pub fn parse(
        path: impl Into<PathBuf>,
        line: usize,
        field: impl Into<String>,
        reason: impl Into<String>,
    ) -> Self {
        Error::Parse {
            path: path.into(),
            line,
            field: field.into(),
            reason: reason.into(),
        }
    }

    /// Shorthand for [`Error::Io`].
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }
}

/// The library's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Checks that every value is finite; names the first offender.
pub fn ensure_finite(what: &str, values: &[f64]) -> Result<()> {
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(i) => Err(Error::invalid(
            what,
            format!("component {i} is {} (must be finite)", values[i]),
        )),
    }
}

/// Checks a parameter that must be finite and > 0.
pub fn ensure_positive(what: &str, v: f64) -> Result<()> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(
            what,
            format!("{v} (must be finite and positive)"),
        ))
    }
}

/// Checks a parameter that must be finite and ≥ 0.
pub fn ensure_non_negative(what: &str, v: f64) -> Result<()> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(
            what,
            format!("{v} (must be finite and non-negative)"),
        ))
    }
}

/// Checks a `[low, high]` range: both ends finite and ≥ 0, and not decreasing.
pub fn ensure_range(what: &str, r: [f64; 2]) -> Result<()> {
    ensure_non_negative(what, r[0])?;
    ensure_non_negative(what, r[1])?;
    if r[1] < r[0] {
        return Err(Error::invalid(
            what,
            format!("[{}, {}] is decreasing", r[0], r[1]),
        ));
    }
    Ok(())
}

/// Checks a probability (in [0, 1]; NaN fails).
pub fn ensure_probability(what: &str, p: f64) -> Result<()> {
    if (0.0..=1.0).contains(&p) {
        Ok(())
    } else {
        Err(Error::invalid(what, format!("{p} (must lie in [0, 1])")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_range_must_be_non_negative_finite_and_not_decreasing() {
        assert!(ensure_range("r", [0.0, 0.0]).is_ok());
        assert!(ensure_range("r", [0.5, 2.0]).is_ok());
        let msg = ensure_range("street.wall_gap", [2.0, 1.0])
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("street.wall_gap") && msg.contains("decreasing"),
            "{msg}"
        );
        assert!(ensure_range("r", [-0.1, 1.0]).is_err());
        assert!(ensure_range("r", [0.0, f64::NAN]).is_err());
        assert!(ensure_range("r", [0.0, f64::INFINITY]).is_err());
    }
}
