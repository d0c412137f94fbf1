//! The generalised OSPA distance (GOSPA) with α = 2, from Rahmathullah, García-Fernández &
//! Svensson (2017), split into localisation, missed-object and false-alarm parts.
//!
//! For truth `X`, estimates `Y`, cut-off `c > 0` and order `p ≥ 1`, GOSPA with α = 2 is
//!
//! ```text
//! GOSPA(X, Y)^p = min over partial pairings γ of
//!                 Σ_(i,j)∈γ ‖x_i − y_j‖^p  +  (c^p / 2) · (#unpaired truths + #unpaired estimates)
//! ```
//!
//! where only pairs closer than `c` are worth pairing (a pair at distance `≥ c` costs at least
//! `c^p`, the same as leaving both unpaired). Unlike OSPA it is not normalised by the set size,
//! so it grows with the number of objects, and it tells misses from false alarms. Not for:
//! labelled tracks over time (see [`ospa2`](mod@super::ospa2)).

use serde::{Deserialize, Serialize};

use super::points::{as_slices, check_cut_off_and_order, check_points, euclidean};
use crate::assignment;
use crate::error::{Error, Result};

/// GOSPA (α = 2) and its parts.
///
/// The three parts are stored as their contributions to `distance^p` (they are *not* raised to
/// `1/p`), so that `distance^p = localisation + missed + false_alarms` exactly:
///
/// * `localisation = Σ ‖x − y‖^p` over the pairs of the optimal pairing (each closer than `c`);
/// * `missed = (c^p / 2) · n_missed`;
/// * `false_alarms = (c^p / 2) · n_false`.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Gospa {
    /// The GOSPA distance (unnormalised; in the same unit as the points).
    pub distance: f64,
    /// Contribution of the paired objects to `distance^p`: the sum of their distances to the
    /// power `p`.
    pub localisation: f64,
    /// Contribution of the missed truth objects to `distance^p`: `c^p / 2` each.
    pub missed: f64,
    /// Contribution of the false estimates to `distance^p`: `c^p / 2` each.
    pub false_alarms: f64,
    /// Number of truth objects left unpaired.
    pub n_missed: usize,
    /// Number of estimates left unpaired.
    pub n_false: usize,
}

/// GOSPA (α = 2) of cut-off `c` and order `p` between `truth` and `estimates` (Euclidean base
/// distance). The arguments are not interchangeable only in the naming of the parts: swapping
/// them swaps `missed` and `false_alarms` and leaves `distance` unchanged.
///
/// Both sets may be empty (GOSPA of two empty sets is 0). Returns [`Error::InvalidInput`] when
/// `c` is not positive and finite, `p` is not finite or below 1, a coordinate is not finite, or
/// the points do not all share one dimension.
///
/// ```
/// use smc_lmb::metrics::gospa;
/// // Truth {0, 10}, estimate {1}, c = 4, p = 1: pair 0↔1 (1), miss 10 (c/2 = 2) → GOSPA = 3.
/// let g = gospa(&[vec![0.0], vec![10.0]], &[vec![1.0]], 4.0, 1.0).unwrap();
/// assert!((g.distance - 3.0).abs() < 1e-12);
/// assert_eq!((g.n_missed, g.n_false), (1, 0));
/// ```
pub fn gospa<P, Q>(truth: &[P], estimates: &[Q], c: f64, p: f64) -> Result<Gospa>
where
    P: AsRef<[f64]>,
    Q: AsRef<[f64]>,
{
    check_cut_off_and_order(c, p)?;
    let (xs, ys) = (as_slices(truth), as_slices(estimates));
    check_points(&[("truth", &xs), ("estimate", &ys)])?;
    let pairing = gated_pairing(&xs, &ys, c, p)?;
    let half = c.powf(p) / 2.0;
    let mut localisation = 0.0;
    let mut n_paired = 0;
    for (i, j) in pairing.iter().enumerate() {
        if let Some(j) = *j {
            localisation += euclidean(xs[i], ys[j]).powf(p);
            n_paired += 1;
        }
    }
    let n_missed = xs.len() - n_paired;
    let n_false = ys.len() - n_paired;
    let missed = half * n_missed as f64;
    let false_alarms = half * n_false as f64;
    Ok(Gospa {
        distance: (localisation + missed + false_alarms).powf(1.0 / p),
        localisation,
        missed,
        false_alarms,
        n_missed,
        n_false,
    })
}

/// The GOSPA (α = 2) pairing: for every truth point, the index of its estimate or `None`.
/// Only pairs strictly closer than `c` are ever reported; the pairing minimises
/// `Σ_paired d^p + (c^p/2)(unpaired truths + unpaired estimates)`. Points must already be
/// checked (finite, common dimension) and `c`, `p` valid.
pub(crate) fn gated_pairing(
    truth: &[&[f64]],
    estimates: &[&[f64]],
    c: f64,
    p: f64,
) -> Result<Vec<Option<usize>>> {
    let (m, n) = (truth.len(), estimates.len());
    if m == 0 || n == 0 {
        return Ok(vec![None; m]);
    }
    // Rows: truth. Columns: the n estimates, then one private "miss" column per truth.
    // Pairing i↔j costs min(d, c)^p; a miss column costs c^p. Every assignment of this matrix
    // differs from the GOSPA objective by the constant (n − m)·c^p/2, because each unpaired
    // estimate adds c^p/2 and each truth row adds a shift of c^p/2. A pair at distance ≥ c ties
    // with "miss + false alarm" and is reported as unpaired.
    let cols = n + m;
    let cp = c.powf(p);
    let mut cost = vec![f64::INFINITY; m * cols];
    for (i, x) in truth.iter().enumerate() {
        for (j, y) in estimates.iter().enumerate() {
            cost[i * cols + j] = euclidean(x, y).min(c).powf(p);
        }
        cost[i * cols + n + i] = cp;
    }
    let (cols_of, _) = assignment::solve(&cost, m, cols)
        .ok_or_else(|| Error::invalid("GOSPA pairing", "no finite assignment"))?;
    Ok(cols_of
        .into_iter()
        .enumerate()
        .map(|(i, j)| (j < n && euclidean(truth[i], estimates[j]) < c).then_some(j))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    #[test]
    fn hand_case_miss_and_false_alarm() {
        // Truth X = {(0,0), (20,0)}, estimates Y = {(3,4), (0,30)}, c = 10, p = 2.
        // Distances: (0,0)-(3,4) = 5; (0,0)-(0,30) = 30; (20,0)-(3,4) = √305 ≈ 17.5;
        // (20,0)-(0,30) = √1300 ≈ 36. Only (0,0)↔(3,4) is closer than c.
        // localisation = 5² = 25; (20,0) missed: c²/2 = 50; (0,30) false: 50.
        // GOSPA² = 25 + 50 + 50 = 125 → GOSPA = √125.
        let x = vec![vec![0.0, 0.0], vec![20.0, 0.0]];
        let y = vec![vec![3.0, 4.0], vec![0.0, 30.0]];
        let g = gospa(&x, &y, 10.0, 2.0).unwrap();
        assert_relative_eq!(g.localisation, 25.0, epsilon = 1e-12);
        assert_relative_eq!(g.missed, 50.0, epsilon = 1e-12);
        assert_relative_eq!(g.false_alarms, 50.0, epsilon = 1e-12);
        assert_eq!((g.n_missed, g.n_false), (1, 1));
        assert_relative_eq!(g.distance, 125.0f64.sqrt(), epsilon = 1e-12);
    }

    #[test]
    fn hand_case_pairing_beats_unpairing_only_below_cut_off() {
        // 1-D, p = 1, c = 4. Truth {0}, estimate {3}: d = 3 < 4 → pair, GOSPA = 3.
        // Truth {0}, estimate {5}: d = 5 ≥ 4 → miss (2) + false (2) = 4.
        let g = gospa(&[vec![0.0]], &[vec![3.0]], 4.0, 1.0).unwrap();
        assert_relative_eq!(g.distance, 3.0, epsilon = 1e-12);
        assert_eq!((g.n_missed, g.n_false), (0, 0));
        let g = gospa(&[vec![0.0]], &[vec![5.0]], 4.0, 1.0).unwrap();
        assert_relative_eq!(g.distance, 4.0, epsilon = 1e-12);
        assert_eq!((g.n_missed, g.n_false), (1, 1));
    }

    #[test]
    fn more_truth_than_estimates() {
        // Truth {0, 1, 2}, estimate {1.5}, c = 2, p = 1. Best: 1↔1.5 or 2↔1.5 (0.5 each),
        // two misses at c/2 = 1 each → GOSPA = 0.5 + 2 = 2.5.
        let x = vec![vec![0.0], vec![1.0], vec![2.0]];
        let g = gospa(&x, &[vec![1.5]], 2.0, 1.0).unwrap();
        assert_relative_eq!(g.distance, 2.5, epsilon = 1e-12);
        assert_eq!((g.n_missed, g.n_false), (2, 0));
    }

    #[test]
    fn empty_sets() {
        let e: Vec<Vec<f64>> = Vec::new();
        let g = gospa(&e, &e, 3.0, 2.0).unwrap();
        assert_eq!(g.distance, 0.0);
        // Two missed truths, c = 3, p = 2: 2 · 9/2 = 9 → GOSPA = 3.
        let g = gospa(&[vec![0.0], vec![1.0]], &e, 3.0, 2.0).unwrap();
        assert_relative_eq!(g.distance, 3.0, epsilon = 1e-12);
        assert_eq!((g.n_missed, g.n_false), (2, 0));
        let g = gospa(&e, &[vec![0.0]], 3.0, 2.0).unwrap();
        assert_eq!((g.n_missed, g.n_false), (0, 1));
    }

    #[test]
    fn invalid_inputs_are_errors() {
        let a = vec![vec![0.0]];
        assert!(gospa(&a, &a, -1.0, 1.0).is_err());
        assert!(gospa(&a, &a, 1.0, 0.0).is_err());
        assert!(gospa(&a, &[vec![f64::INFINITY]], 1.0, 1.0).is_err());
        assert!(gospa(&a, &[vec![0.0, 0.0]], 1.0, 1.0).is_err());
    }

    /// Brute force over every partial pairing.
    fn brute(x: &[Vec<f64>], y: &[Vec<f64>], c: f64, p: f64) -> f64 {
        fn rec(x: &[Vec<f64>], y: &[Vec<f64>], c: f64, p: f64, i: usize, used: &mut [bool]) -> f64 {
            if i == x.len() {
                let free = used.iter().filter(|u| !**u).count();
                return c.powf(p) / 2.0 * free as f64;
            }
            let mut best = c.powf(p) / 2.0 + rec(x, y, c, p, i + 1, used);
            for j in 0..y.len() {
                if !used[j] {
                    used[j] = true;
                    let d = euclidean(&x[i], &y[j]).powf(p);
                    best = best.min(d + rec(x, y, c, p, i + 1, used));
                    used[j] = false;
                }
            }
            best
        }
        rec(x, y, c, p, 0, &mut vec![false; y.len()]).powf(1.0 / p)
    }

    fn set(max: usize) -> impl Strategy<Value = Vec<Vec<f64>>> {
        proptest::collection::vec(proptest::collection::vec(-10.0f64..10.0, 2), 0..=max)
    }

    proptest! {
        #[test]
        fn parts_add_up_and_match_brute_force(x in set(4), y in set(4), c in 0.5f64..20.0, p in 1.0f64..3.0) {
            let g = gospa(&x, &y, c, p).unwrap();
            let sum = g.localisation + g.missed + g.false_alarms;
            prop_assert!((g.distance.powf(p) - sum).abs() < 1e-9 * (1.0 + sum));
            prop_assert!((g.distance - brute(&x, &y, c, p)).abs() < 1e-9);
            prop_assert_eq!(x.len() - g.n_missed, y.len() - g.n_false);
            let s = gospa(&y, &x, c, p).unwrap();
            prop_assert!((s.distance - g.distance).abs() < 1e-9);
        }
    }
}
