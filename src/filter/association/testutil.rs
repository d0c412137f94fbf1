//! Independent reference computations for the association tests: plain enumeration of
//! all (m + 1)ⁿ maps, rejecting those that reuse a measurement.
//!
//! Not for: the library itself (compiled for tests only); it deliberately shares nothing
//! with the methods' own tables so that it can check them.

use super::{AssociationProblem, Marginals};
use proptest::prelude::*;

/// Every admissible hypothesis (0 = missed, j = measurement j − 1) with its log weight.
pub fn brute_hypotheses(p: &AssociationProblem) -> Vec<(Vec<usize>, f64)> {
    let (n, m) = (p.n_tracks, p.n_meas);
    let total = (m + 1).pow(n as u32);
    let mut out = Vec::new();
    for code in 0..total {
        let mut c = code;
        let theta: Vec<usize> = (0..n)
            .map(|_| {
                let j = c % (m + 1);
                c /= m + 1;
                j
            })
            .collect();
        let mut used = vec![false; m + 1];
        let mut ok = true;
        let mut lw = 0.0;
        for (i, &j) in theta.iter().enumerate() {
            if j > 0 {
                ok &= !used[j];
                used[j] = true;
                lw += p.log_detect[i * m + j - 1];
            } else {
                lw += p.log_miss[i];
            }
        }
        if ok && lw > f64::NEG_INFINITY {
            out.push((theta, lw));
        }
    }
    out
}

/// Exact marginals by enumeration; `None` if nothing is admissible.
pub fn brute_marginals(p: &AssociationProblem) -> Option<Marginals> {
    let hyps = brute_hypotheses(p);
    let max = hyps.iter().map(|h| h.1).fold(f64::NEG_INFINITY, f64::max);
    if max == f64::NEG_INFINITY {
        return None;
    }
    let (n, m) = (p.n_tracks, p.n_meas);
    let mut miss = vec![0.0; n];
    let mut detect = vec![0.0; n * m];
    let mut z = 0.0;
    for (theta, lw) in &hyps {
        let w = (lw - max).exp();
        z += w;
        for (i, &j) in theta.iter().enumerate() {
            if j == 0 {
                miss[i] += w;
            } else {
                detect[i * m + j - 1] += w;
            }
        }
    }
    miss.iter_mut().for_each(|v| *v /= z);
    detect.iter_mut().for_each(|v| *v /= z);
    Some(Marginals {
        n_tracks: n,
        n_meas: m,
        miss,
        detect,
    })
}

/// Largest absolute difference between two sets of marginals of the same shape.
pub fn max_diff(a: &Marginals, b: &Marginals) -> f64 {
    assert_eq!((a.n_tracks, a.n_meas), (b.n_tracks, b.n_meas));
    a.miss
        .iter()
        .zip(&b.miss)
        .chain(a.detect.iter().zip(&b.detect))
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Checks the invariants every method must satisfy: finite entries in [0, 1], rows
/// summing to one, and exact zeros where the problem forbids the pairing.
pub fn assert_valid(p: &AssociationProblem, mg: &Marginals) {
    assert_eq!(mg.n_tracks, p.n_tracks);
    assert_eq!(mg.n_meas, p.n_meas);
    assert_eq!(mg.miss.len(), p.n_tracks);
    assert_eq!(mg.detect.len(), p.n_tracks * p.n_meas);
    for i in 0..p.n_tracks {
        let row = &mg.detect[i * p.n_meas..(i + 1) * p.n_meas];
        let sum = mg.miss[i] + row.iter().sum::<f64>();
        assert!((sum - 1.0).abs() < 1e-9, "row {i} sums to {sum}: {mg:?}");
        for &v in std::iter::once(&mg.miss[i]).chain(row) {
            assert!(v.is_finite() && (0.0..=1.0 + 1e-12).contains(&v), "{mg:?}");
        }
        for (j, &v) in row.iter().enumerate() {
            if p.log_detect[i * p.n_meas + j] == f64::NEG_INFINITY {
                assert_eq!(v, 0.0, "forbidden pair ({i}, {j}) got {v}");
            }
        }
        // Only the all-missed answer to an infeasible problem may give a forbidden miss.
        if p.log_miss[i] == f64::NEG_INFINITY && !brute_hypotheses(p).is_empty() {
            assert_eq!(mg.miss[i], 0.0, "forbidden miss of track {i}");
        }
    }
}

/// Random problems with up to `max_n` tracks and `max_m` measurements, log weights in
/// `[lo, hi]` and about one entry in `1/forbid_one_in` forbidden (misses only when
/// `forbid_miss`).
pub fn problems(
    max_n: usize,
    max_m: usize,
    lo: f64,
    hi: f64,
    forbid_one_in: u8,
    forbid_miss: bool,
) -> impl Strategy<Value = AssociationProblem> {
    (1..=max_n, 0..=max_m).prop_flat_map(move |(n, m)| {
        let cells = n * (m + 1);
        (
            proptest::collection::vec(lo..=hi, cells),
            proptest::collection::vec(0..forbid_one_in.max(1), cells),
        )
            .prop_map(move |(vals, forbid)| {
                let at = |k: usize, is_miss: bool| {
                    if forbid[k] == 0 && forbid_one_in > 0 && (!is_miss || forbid_miss) {
                        f64::NEG_INFINITY
                    } else {
                        vals[k]
                    }
                };
                let log_miss = (0..n).map(|i| at(i * (m + 1), true)).collect();
                let log_detect = (0..n)
                    .flat_map(|i| (0..m).map(move |j| (i, j)))
                    .map(|(i, j)| at(i * (m + 1) + j + 1, false))
                    .collect();
                AssociationProblem {
                    n_tracks: n,
                    n_meas: m,
                    log_miss,
                    log_detect,
                }
            })
    })
}
