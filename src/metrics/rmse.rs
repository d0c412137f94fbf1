//! Single-object error summaries: the root-mean-square of a sequence of error vectors, and the
//! time-averaged normalised innovation squared (NIS) with its two-sided 95 % chi-square
//! acceptance interval, the usual filter-consistency check (as in Bar-Shalom, Li &
//! Kirubarajan 2001).
//!
//! Chi-square quantiles come from the Wilson–Hilferty (1931) cube-root normal approximation,
//! `χ²_k(P) ≈ k·(1 − 2/(9k) + z_P·√(2/(9k)))³` with `z_P` the standard normal quantile, which
//! is within about 1 % of tabulated values for `k ≥ 10` (the case of an average over many
//! steps) and coarser for a handful of degrees of freedom. Not for: multi-object errors (see
//! [`ospa`](mod@super::ospa) and [`gospa`](mod@super::gospa)).

use serde::{Deserialize, Serialize};

use crate::error::{Error, Result};

/// Root-mean-square of the Euclidean norms of `errors`: `√( (1/N) Σ ‖e_k‖² )`.
///
/// Returns 0 for an empty sequence. Non-finite components are not rejected: they propagate, so
/// a NaN component makes the result NaN.
///
/// ```
/// use smc_lmb::metrics::rms_error;
/// // Norms 5 and 0 → √((25 + 0) / 2).
/// let r = rms_error(&[vec![3.0, 4.0], vec![0.0, 0.0]]);
/// assert!((r - 12.5f64.sqrt()).abs() < 1e-12);
/// ```
pub fn rms_error<E: AsRef<[f64]>>(errors: &[E]) -> f64 {
    if errors.is_empty() {
        return 0.0;
    }
    let sum: f64 = errors
        .iter()
        .map(|e| e.as_ref().iter().map(|v| v * v).sum::<f64>())
        .sum();
    (sum / errors.len() as f64).sqrt()
}

/// The averaged-NIS consistency check of a run.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NisCheck {
    /// Mean of the NIS values.
    pub mean: f64,
    /// Lower end of the 95 % interval: `χ²_{N·m}(0.025) / N`.
    pub lower: f64,
    /// Upper end of the 95 % interval: `χ²_{N·m}(0.975) / N`.
    pub upper: f64,
    /// Number `N` of NIS values averaged.
    pub steps: usize,
    /// Measurement dimension `m`.
    pub dim: usize,
    /// Whether `lower ≤ mean ≤ upper`.
    pub consistent: bool,
}

/// Averages the NIS values `nis` (one per step, each an `m = dim`-dimensional innovation's
/// `νᵀ S⁻¹ ν`) and compares the mean with its two-sided 95 % interval. For a consistent filter
/// `N` times the mean is chi-square with `N·m` degrees of freedom.
///
/// Returns [`Error::InvalidInput`] when `nis` is empty, `dim` is 0, or a value is negative or
/// not finite.
pub fn average_nis(nis: &[f64], dim: usize) -> Result<NisCheck> {
    if nis.is_empty() {
        return Err(Error::invalid("NIS sequence", "empty"));
    }
    if dim == 0 {
        return Err(Error::invalid("measurement dimension", "0"));
    }
    if let Some(k) = nis.iter().position(|v| !(v.is_finite() && *v >= 0.0)) {
        return Err(Error::invalid(
            format!("NIS value {k}"),
            format!("{} (must be finite and non-negative)", nis[k]),
        ));
    }
    let n = nis.len() as f64;
    let dof = n * dim as f64;
    let mean = nis.iter().sum::<f64>() / n;
    let lower = chi_square_quantile(dof, 0.025) / n;
    let upper = chi_square_quantile(dof, 0.975) / n;
    Ok(NisCheck {
        mean,
        lower,
        upper,
        steps: nis.len(),
        dim,
        consistent: lower <= mean && mean <= upper,
    })
}

/// The `prob` quantile of the chi-square distribution with `dof` degrees of freedom, by the
/// Wilson–Hilferty approximation (see the [module docs](self) for accuracy). Returns NaN when
/// `dof` is not positive and finite or `prob` is not strictly between 0 and 1; the result is
/// clamped at 0 where the approximation would go negative (tiny `dof` and `prob`).
pub fn chi_square_quantile(dof: f64, prob: f64) -> f64 {
    if !(dof.is_finite() && dof > 0.0 && prob > 0.0 && prob < 1.0) {
        return f64::NAN;
    }
    let h = 2.0 / (9.0 * dof);
    let root = 1.0 - h + normal_quantile(prob) * h.sqrt();
    dof * root.max(0.0).powi(3)
}

/// Standard normal quantile for `0 < prob < 1` by the rational approximation of Hastings as
/// tabulated by Abramowitz & Stegun (1964, eq. 26.2.23); absolute error below 4.5·10⁻⁴.
fn normal_quantile(prob: f64) -> f64 {
    // The formula gives the upper-tail point t for a tail mass q ≤ 0.5; use symmetry.
    let upper_tail = |q: f64| {
        let t = (-2.0 * q.ln()).sqrt();
        let num = 2.515517 + t * (0.802853 + t * 0.010328);
        let den = 1.0 + t * (1.432788 + t * (0.189269 + t * 0.001308));
        t - num / den
    };
    if prob < 0.5 {
        -upper_tail(prob)
    } else {
        upper_tail(1.0 - prob)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn rms_hand_case() {
        // Norms: ‖(1,2,2)‖ = 3, ‖(0,0,4)‖ = 4, ‖(0,0,0)‖ = 0 → √((9 + 16 + 0) / 3) = √(25/3).
        let e = vec![vec![1.0, 2.0, 2.0], vec![0.0, 0.0, 4.0], vec![0.0; 3]];
        assert_relative_eq!(rms_error(&e), (25.0f64 / 3.0).sqrt(), epsilon = 1e-12);
        let none: Vec<Vec<f64>> = Vec::new();
        assert_eq!(rms_error(&none), 0.0);
        assert!(rms_error(&[vec![f64::NAN]]).is_nan());
    }

    #[test]
    fn normal_quantile_known_points() {
        // Φ⁻¹(0.975) = 1.959964, Φ⁻¹(0.5) = 0, Φ⁻¹(0.05) = −1.644854.
        assert!((normal_quantile(0.975) - 1.959964).abs() < 5e-4);
        assert!(normal_quantile(0.5).abs() < 5e-4);
        assert!((normal_quantile(0.05) + 1.644854).abs() < 5e-4);
    }

    #[test]
    fn chi_square_against_tables() {
        // Tabulated quantiles, required within 1 %.
        for (dof, prob, table) in [
            (20.0, 0.975, 34.170),
            (20.0, 0.025, 9.591),
            (100.0, 0.975, 129.56),
            (100.0, 0.025, 74.22),
            (10.0, 0.95, 18.307),
            (50.0, 0.05, 34.764),
        ] {
            let q = chi_square_quantile(dof, prob);
            assert!(
                (q - table).abs() / table < 0.01,
                "χ²_{dof}({prob}) = {q}, table {table}"
            );
        }
        assert!(chi_square_quantile(0.0, 0.5).is_nan());
        assert!(chi_square_quantile(5.0, 1.0).is_nan());
        assert!(chi_square_quantile(5.0, f64::NAN).is_nan());
    }

    #[test]
    fn averaged_nis_hand_case() {
        // N = 10 values with mean 2.2, m = 2 → 20 degrees of freedom.
        // Interval: χ²_20(0.025)/10 ≈ 9.591/10 = 0.959, χ²_20(0.975)/10 ≈ 34.17/10 = 3.417.
        let nis = [1.0, 3.0, 2.0, 2.0, 2.5, 1.5, 3.5, 0.5, 4.0, 2.0];
        let c = average_nis(&nis, 2).unwrap();
        assert_relative_eq!(c.mean, 2.2, epsilon = 1e-12);
        assert!((c.lower - 0.9591).abs() < 0.01);
        assert!((c.upper - 3.417).abs() < 0.03);
        assert!(c.consistent);
        assert_eq!((c.steps, c.dim), (10, 2));
        // Mean 5 is above 3.417: inconsistent (over-confident filter).
        assert!(!average_nis(&[5.0; 10], 2).unwrap().consistent);
    }

    #[test]
    fn averaged_nis_rejects_bad_input() {
        assert!(average_nis(&[], 2).is_err());
        assert!(average_nis(&[1.0], 0).is_err());
        assert!(average_nis(&[1.0, f64::NAN], 1).is_err());
        assert!(average_nis(&[-1.0], 1).is_err());
    }
}
