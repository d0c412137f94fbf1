//! Cardinality error: how far the estimated number of objects is from the true number, step by
//! step and on average. Not for: where the objects are (see [`ospa`](mod@super::ospa) and
//! [`gospa`](mod@super::gospa), whose cardinality parts also account for positions via the
//! cut-off).

use serde::{Deserialize, Serialize};

/// Per-step cardinality errors of a run and their means.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CardinalityError {
    /// `|n_est − n_true|` at each step.
    pub per_step: Vec<usize>,
    /// Mean of `per_step` (0 for a run with no steps).
    pub mean: f64,
    /// Mean of the signed error `n_est − n_true` (positive when the tracker over-counts; 0 for
    /// a run with no steps).
    pub mean_signed: f64,
}

/// Cardinality error of a run given `(n_true, n_est)` for each step.
///
/// ```
/// use smc_lmb::metrics::cardinality_error;
/// let e = cardinality_error([(2, 2), (2, 3), (3, 1)]);
/// assert_eq!(e.per_step, vec![0, 1, 2]);
/// assert_eq!(e.mean, 1.0);
/// ```
pub fn cardinality_error<I>(counts: I) -> CardinalityError
where
    I: IntoIterator<Item = (usize, usize)>,
{
    let mut per_step = Vec::new();
    let mut signed = 0.0;
    for (n_true, n_est) in counts {
        per_step.push(n_true.abs_diff(n_est));
        signed += n_est as f64 - n_true as f64;
    }
    let steps = per_step.len();
    let (mean, mean_signed) = if steps == 0 {
        (0.0, 0.0)
    } else {
        let total: usize = per_step.iter().sum();
        (total as f64 / steps as f64, signed / steps as f64)
    };
    CardinalityError {
        per_step,
        mean,
        mean_signed,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn hand_case() {
        // (true, est): (3, 3) → 0; (3, 1) → 2 (signed −2); (2, 5) → 3 (+3); (0, 1) → 1 (+1).
        // mean = (0 + 2 + 3 + 1) / 4 = 1.5; mean signed = (0 − 2 + 3 + 1) / 4 = 0.5.
        let e = cardinality_error(vec![(3, 3), (3, 1), (2, 5), (0, 1)]);
        assert_eq!(e.per_step, vec![0, 2, 3, 1]);
        assert_relative_eq!(e.mean, 1.5);
        assert_relative_eq!(e.mean_signed, 0.5);
    }

    #[test]
    fn empty_run() {
        let e = cardinality_error(std::iter::empty());
        assert!(e.per_step.is_empty());
        assert_eq!((e.mean, e.mean_signed), (0.0, 0.0));
    }
}
