//! Shared checks and the Euclidean base distance for the point-set metrics. Not for: any
//! metric itself.

use crate::error::{ensure_finite, Error, Result};

/// Checks that `c` is a usable cut-off and `p` a usable order.
pub(crate) fn check_cut_off_and_order(c: f64, p: f64) -> Result<()> {
    if !(c.is_finite() && c > 0.0) {
        return Err(Error::invalid(
            "cut-off c",
            format!("{c} (must be positive and finite)"),
        ));
    }
    if !(p.is_finite() && p >= 1.0) {
        return Err(Error::invalid(
            "order p",
            format!("{p} (must be finite and at least 1)"),
        ));
    }
    Ok(())
}

/// Checks that every point of every set is finite and that all points share one dimension.
/// `sets` pairs a name (for the error message) with a list of points.
pub(crate) fn check_points(sets: &[(&str, &[&[f64]])]) -> Result<()> {
    let mut dim: Option<usize> = None;
    for (name, pts) in sets {
        for (i, x) in pts.iter().enumerate() {
            let what = format!("{name} point {i}");
            ensure_finite(&what, x)?;
            match dim {
                None => dim = Some(x.len()),
                Some(d) if d != x.len() => {
                    return Err(Error::invalid(
                        what,
                        format!("dimension {} (expected {d})", x.len()),
                    ))
                }
                Some(_) => {}
            }
        }
    }
    Ok(())
}

/// Euclidean distance between two points of equal dimension.
pub(crate) fn euclidean(a: &[f64], b: &[f64]) -> f64 {
    debug_assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(u, v)| (u - v) * (u - v))
        .sum::<f64>()
        .sqrt()
}

/// Borrows every point of a set as a plain slice.
pub(crate) fn as_slices<P: AsRef<[f64]>>(pts: &[P]) -> Vec<&[f64]> {
    pts.iter().map(|x| x.as_ref()).collect()
}
