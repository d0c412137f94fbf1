//! One frame's measurements: a contiguous table of fixed-dimension vectors, checked to be
//! finite when built. Not for: what a measurement means (that is the measurement model's).

use crate::error::{Error, Result};

/// The measurements of one frame (row `j` is measurement `j`).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Measurements {
    dim: usize,
    data: Vec<f64>,
}

impl Measurements {
    /// An empty set of `dim`-dimensional measurements.
    pub fn empty(dim: usize) -> Self {
        Measurements {
            dim,
            data: Vec::new(),
        }
    }

    /// Builds the set from rows; every row must have `dim` finite components.
    pub fn from_rows<R: AsRef<[f64]>>(dim: usize, rows: &[R]) -> Result<Self> {
        let mut m = Self::empty(dim);
        for (j, row) in rows.iter().enumerate() {
            m.push(row.as_ref()).map_err(|e| match e {
                Error::InvalidInput { reason, .. } => {
                    Error::invalid(format!("measurement {j}"), reason)
                }
                other => other,
            })?;
        }
        Ok(m)
    }

    /// Like [`Measurements::from_rows`] but leaves out rows with a NaN or infinite component;
    /// returns the set and the indices of the rows left out. Rows of the wrong length are
    /// still an error.
    pub fn from_rows_skipping_non_finite<R: AsRef<[f64]>>(
        dim: usize,
        rows: &[R],
    ) -> Result<(Self, Vec<usize>)> {
        let mut m = Self::empty(dim);
        let mut skipped = Vec::new();
        for (j, row) in rows.iter().enumerate() {
            let row = row.as_ref();
            if row.len() != dim {
                return Err(Error::invalid(
                    format!("measurement {j}"),
                    format!("has {} components, expected {dim}", row.len()),
                ));
            }
            if row.iter().all(|v| v.is_finite()) {
                m.data.extend_from_slice(row);
            } else {
                skipped.push(j);
            }
        }
        Ok((m, skipped))
    }

    /// Appends one measurement.
    pub fn push(&mut self, z: &[f64]) -> Result<()> {
        if z.len() != self.dim {
            return Err(Error::invalid(
                "measurement",
                format!("has {} components, expected {}", z.len(), self.dim),
            ));
        }
        crate::error::ensure_finite("measurement", z)?;
        self.data.extend_from_slice(z);
        Ok(())
    }

    /// Dimension of each measurement.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Number of measurements.
    pub fn len(&self) -> usize {
        self.data.len().checked_div(self.dim).unwrap_or(0)
    }

    /// True when the frame has no measurement.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Measurement `j`.
    pub fn get(&self, j: usize) -> &[f64] {
        &self.data[j * self.dim..(j + 1) * self.dim]
    }

    /// All measurements in order.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = &[f64]> + '_ {
        self.data.chunks_exact(self.dim.max(1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_nan_and_names_the_row() {
        let err = Measurements::from_rows(2, &[[1.0, 2.0], [f64::NAN, 0.0]]).unwrap_err();
        let msg = err.to_string();
        assert!(msg.contains("measurement 1"), "{msg}");
        assert!(msg.contains("NaN"), "{msg}");
    }

    #[test]
    fn skipping_keeps_the_finite_rows() {
        let rows = [[1.0, 2.0], [f64::INFINITY, 0.0], [3.0, 4.0]];
        let (m, skipped) = Measurements::from_rows_skipping_non_finite(2, &rows).unwrap();
        assert_eq!(m.len(), 2);
        assert_eq!(m.get(1), &[3.0, 4.0]);
        assert_eq!(skipped, vec![1]);
        assert!(Measurements::from_rows(2, &[[1.0]]).is_err());
    }
}
