//! The OSPA distance (optimal sub-pattern assignment) between two finite point sets, as
//! proposed by Schuhmacher, Vo & Vo (2008), with its usual split into a localisation and a
//! cardinality component.
//!
//! For sets `X` (`m` points) and `Y` (`n` points) with `m ≤ n`, cut-off `c > 0` and order
//! `p ≥ 1`, writing `d_c(x, y) = min(c, ‖x − y‖)`:
//!
//! ```text
//! OSPA(X, Y)^p = ( min over injections π of Σ_i d_c(x_i, y_π(i))^p  +  c^p (n − m) ) / n
//! ```
//!
//! and OSPA is 0 when both sets are empty. The metric is symmetric in its arguments, never
//! exceeds `c`, and equals `c` when exactly one set is empty. Not for: labelled tracks over
//! time (see [`ospa2`](mod@super::ospa2)) or an unnormalised error that separates misses from
//! false alarms (see [`gospa`](mod@super::gospa)).

use serde::{Deserialize, Serialize};

use super::points::{as_slices, check_cut_off_and_order, check_points, euclidean};
use crate::assignment;
use crate::error::{Error, Result};

/// The OSPA distance and its two components.
///
/// With `n` the size of the larger set, the components are
/// `localisation = (Σ_assigned d_c^p / n)^(1/p)` and
/// `cardinality = (c^p · |n − m| / n)^(1/p)`, so that
/// `distance^p = localisation^p + cardinality^p`.
#[derive(Copy, Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Ospa {
    /// The OSPA distance, in `[0, c]`.
    pub distance: f64,
    /// The part due to the positions of the optimally paired points.
    pub localisation: f64,
    /// The part due to the difference in the number of points.
    pub cardinality: f64,
}

impl Ospa {
    /// The value for two empty sets.
    const ZERO: Ospa = Ospa {
        distance: 0.0,
        localisation: 0.0,
        cardinality: 0.0,
    };
}

/// OSPA distance of cut-off `c` and order `p` between point sets `x` and `y` (Euclidean base
/// distance).
///
/// Both sets may be empty. Returns [`Error::InvalidInput`] when `c` is not positive and finite,
/// `p` is not finite or below 1, a coordinate is not finite, or the points do not all share one
/// dimension.
///
/// ```
/// use smc_lmb::metrics::ospa;
/// // {0, 10} against {1}, c = 5, p = 1: pair 0↔1 (cost 1), one unpaired point (cost 5),
/// // normalised by the larger size 2 → (1 + 5) / 2 = 3.
/// let o = ospa(&[vec![0.0], vec![10.0]], &[vec![1.0]], 5.0, 1.0).unwrap();
/// assert!((o.distance - 3.0).abs() < 1e-12);
/// ```
pub fn ospa<P, Q>(x: &[P], y: &[Q], c: f64, p: f64) -> Result<Ospa>
where
    P: AsRef<[f64]>,
    Q: AsRef<[f64]>,
{
    check_cut_off_and_order(c, p)?;
    let (xs, ys) = (as_slices(x), as_slices(y));
    check_points(&[("first set", &xs), ("second set", &ys)])?;
    ospa_with(xs.len(), ys.len(), |i, j| euclidean(xs[i], ys[j]), c, p)
}

/// OSPA between a set of `m` and a set of `n` abstract elements whose base distance is given by
/// `base(i, j)` (element `i` of the first set, element `j` of the second). `c` and `p` must
/// already be checked; `base` must return non-negative values that are not NaN.
pub(crate) fn ospa_with(
    m: usize,
    n: usize,
    base: impl Fn(usize, usize) -> f64,
    c: f64,
    p: f64,
) -> Result<Ospa> {
    let large = m.max(n);
    let small = m.min(n);
    if large == 0 {
        return Ok(Ospa::ZERO);
    }
    // Rows index the smaller set so that the solver sees rows ≤ cols.
    let mut cost = Vec::with_capacity(small * large);
    for r in 0..small {
        for s in 0..large {
            let d = if m <= n { base(r, s) } else { base(s, r) };
            cost.push(d.min(c).powf(p));
        }
    }
    let (_, assigned) = assignment::solve(&cost, small, large)
        .ok_or_else(|| Error::invalid("OSPA base distance", "not a number"))?;
    let nf = large as f64;
    let unpaired = c.powf(p) * (large - small) as f64;
    let inv_p = 1.0 / p;
    Ok(Ospa {
        distance: ((assigned + unpaired) / nf).powf(inv_p),
        localisation: (assigned / nf).powf(inv_p),
        cardinality: (unpaired / nf).powf(inv_p),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    fn pts(v: &[f64]) -> Vec<Vec<f64>> {
        v.iter().map(|&a| vec![a]).collect()
    }

    #[test]
    fn hand_case_one_dimension_p1() {
        // {0, 10} vs {1}, c = 5, p = 1. Best pairing 0↔1: d_c = 1. Unpaired point: c = 5.
        // OSPA = (1 + 5) / 2 = 3; localisation = 1/2; cardinality = 5/2.
        let o = ospa(&pts(&[0.0, 10.0]), &pts(&[1.0]), 5.0, 1.0).unwrap();
        assert_relative_eq!(o.distance, 3.0, epsilon = 1e-12);
        assert_relative_eq!(o.localisation, 0.5, epsilon = 1e-12);
        assert_relative_eq!(o.cardinality, 2.5, epsilon = 1e-12);
    }

    #[test]
    fn hand_case_two_dimensions_p2_with_cut_off() {
        // X = {(0,0), (10,0)}, Y = {(3,4), (10,1), (50,50)}, c = 6, p = 2.
        // Distances: (0,0)-(3,4) = 5, (0,0)-(10,1) = √101 → cut to 6, (10,0)-(3,4) = √65 → 6,
        // (10,0)-(10,1) = 1, anything to (50,50) → 6.
        // Best: (0,0)↔(3,4) and (10,0)↔(10,1): 25 + 1 = 26. One unpaired: 36.
        // OSPA² = (26 + 36) / 3 = 62/3; localisation² = 26/3; cardinality² = 36/3 = 12.
        let x = vec![vec![0.0, 0.0], vec![10.0, 0.0]];
        let y = vec![vec![3.0, 4.0], vec![10.0, 1.0], vec![50.0, 50.0]];
        let o = ospa(&x, &y, 6.0, 2.0).unwrap();
        assert_relative_eq!(o.distance, (62.0f64 / 3.0).sqrt(), epsilon = 1e-12);
        assert_relative_eq!(o.localisation, (26.0f64 / 3.0).sqrt(), epsilon = 1e-12);
        assert_relative_eq!(o.cardinality, 12.0f64.sqrt(), epsilon = 1e-12);
    }

    #[test]
    fn hand_case_optimal_not_greedy() {
        // X = {0, 2}, Y = {1, 4}, c = 100, p = 1. Greedy nearest for 0 takes 1 (cost 1), then
        // 2↔4 (cost 2): total 3. Alternative 0↔4, 2↔1: 4 + 1 = 5. Optimal = 3, OSPA = 3/2.
        let o = ospa(&pts(&[0.0, 2.0]), &pts(&[1.0, 4.0]), 100.0, 1.0).unwrap();
        assert_relative_eq!(o.distance, 1.5, epsilon = 1e-12);
        assert_eq!(o.cardinality, 0.0);
    }

    #[test]
    fn empty_sets() {
        let e: Vec<Vec<f64>> = Vec::new();
        assert_eq!(ospa(&e, &e, 3.0, 1.0).unwrap(), Ospa::ZERO);
        let one = ospa(&e, &pts(&[1.0, 2.0]), 3.0, 2.0).unwrap();
        assert_relative_eq!(one.distance, 3.0, epsilon = 1e-12);
        assert_relative_eq!(one.cardinality, 3.0, epsilon = 1e-12);
        assert_eq!(one.localisation, 0.0);
        let other = ospa(&pts(&[1.0]), &e, 3.0, 1.0).unwrap();
        assert_relative_eq!(other.distance, 3.0, epsilon = 1e-12);
    }

    #[test]
    fn invalid_inputs_are_errors() {
        let a = pts(&[0.0]);
        assert!(ospa(&a, &a, 0.0, 1.0).is_err());
        assert!(ospa(&a, &a, f64::INFINITY, 1.0).is_err());
        assert!(ospa(&a, &a, 1.0, 0.5).is_err());
        assert!(ospa(&a, &a, 1.0, f64::NAN).is_err());
        assert!(ospa(&a, &pts(&[f64::NAN]), 1.0, 1.0).is_err());
        assert!(ospa(&a, &[vec![0.0, 1.0]], 1.0, 1.0).is_err());
    }

    /// Brute force: the smaller set is matched to every ordered choice of points of the larger.
    fn brute(x: &[Vec<f64>], y: &[Vec<f64>], c: f64, p: f64) -> f64 {
        let (s, l) = if x.len() <= y.len() { (x, y) } else { (y, x) };
        if l.is_empty() {
            return 0.0;
        }
        fn rec(s: &[Vec<f64>], l: &[Vec<f64>], c: f64, p: f64, i: usize, used: &mut [bool]) -> f64 {
            if i == s.len() {
                return 0.0;
            }
            let mut best = f64::INFINITY;
            for j in 0..l.len() {
                if !used[j] {
                    used[j] = true;
                    let d = euclidean(&s[i], &l[j]).min(c).powf(p);
                    best = best.min(d + rec(s, l, c, p, i + 1, used));
                    used[j] = false;
                }
            }
            best
        }
        let total =
            rec(s, l, c, p, 0, &mut vec![false; l.len()]) + c.powf(p) * (l.len() - s.len()) as f64;
        (total / l.len() as f64).powf(1.0 / p)
    }

    fn set(max: usize) -> impl Strategy<Value = Vec<Vec<f64>>> {
        proptest::collection::vec(proptest::collection::vec(-10.0f64..10.0, 2), 0..=max)
    }

    proptest! {
        #[test]
        fn symmetric_bounded_and_split(x in set(5), y in set(5), c in 0.5f64..20.0, p in 1.0f64..4.0) {
            let a = ospa(&x, &y, c, p).unwrap();
            let b = ospa(&y, &x, c, p).unwrap();
            prop_assert!((a.distance - b.distance).abs() < 1e-9);
            prop_assert!(a.distance >= 0.0 && a.distance <= c * (1.0 + 1e-12));
            let split = a.localisation.powf(p) + a.cardinality.powf(p);
            prop_assert!((a.distance.powf(p) - split).abs() < 1e-9 * (1.0 + split));
            if x.is_empty() != y.is_empty() {
                prop_assert!((a.distance - c).abs() < 1e-12);
            }
        }

        #[test]
        fn zero_for_identical_sets(x in set(6), c in 0.5f64..20.0, p in 1.0f64..4.0) {
            let o = ospa(&x, &x, c, p).unwrap();
            prop_assert!(o.distance.abs() < 1e-9);
        }

        #[test]
        fn matches_brute_force(x in set(4), y in set(5), c in 0.5f64..20.0, p in 1.0f64..3.0) {
            let o = ospa(&x, &y, c, p).unwrap();
            let b = brute(&x, &y, c, p);
            prop_assert!((o.distance - b).abs() < 1e-9, "{} vs {}", o.distance, b);
        }
    }
}
