//! Minimum-cost rectangular assignment (the Hungarian method with potentials, O(n²m)).
//!
//! Shared by Murty's ranked assignment in the association step and by the optimal
//! sub-pattern metrics. Costs may be `+∞` to forbid a pairing. Not for: ranked (k-best)
//! solutions — see `filter::association::murty`.

/// Solves the assignment of every one of `rows` rows to a distinct column among `cols`
/// (`rows ≤ cols`), minimising the summed cost. `cost` is row-major `rows × cols`.
///
/// Returns the column of each row and the total cost, or `None` when `rows > cols`, a cost is
/// NaN, or every complete assignment uses a forbidden (+∞) pairing.
pub fn solve(cost: &[f64], rows: usize, cols: usize) -> Option<(Vec<usize>, f64)> {
    if rows > cols || cost.len() != rows * cols || cost.iter().any(|c| c.is_nan()) {
        return None;
    }
    if rows == 0 {
        return Some((Vec::new(), 0.0));
    }
    // Replace +∞ by a finite sentinel bigger than any feasible total, then reject solutions
    // that use it.
    let finite_max = cost
        .iter()
        .filter(|c| c.is_finite())
        .fold(0.0f64, |a, &c| a.max(c.abs()));
    let big = (finite_max + 1.0) * (rows as f64 + 1.0) * 4.0;
    let at = |i: usize, j: usize| {
        let c = cost[i * cols + j];
        if c.is_finite() {
            c
        } else if c > 0.0 {
            big
        } else {
            -big
        }
    };
    // One-based e-maxx formulation: u, v potentials; p[j] = row matched to column j.
    let mut u = vec![0.0; rows + 1];
    let mut v = vec![0.0; cols + 1];
    let mut p = vec![0usize; cols + 1];
    let mut way = vec![0usize; cols + 1];
    let mut minv = vec![0.0; cols + 1];
    let mut used = vec![false; cols + 1];
    for i in 1..=rows {
        p[0] = i;
        let mut j0 = 0;
        minv.iter_mut().for_each(|m| *m = f64::INFINITY);
        used.iter_mut().for_each(|b| *b = false);
        loop {
            used[j0] = true;
            let i0 = p[j0];
            let mut delta = f64::INFINITY;
            let mut j1 = 0;
            for j in 1..=cols {
                if !used[j] {
                    let cur = at(i0 - 1, j - 1) - u[i0] - v[j];
                    if cur < minv[j] {
                        minv[j] = cur;
                        way[j] = j0;
                    }
                    if minv[j] < delta {
                        delta = minv[j];
                        j1 = j;
                    }
                }
            }
            for j in 0..=cols {
                if used[j] {
                    u[p[j]] += delta;
                    v[j] -= delta;
                } else {
                    minv[j] -= delta;
                }
            }
            j0 = j1;
            if p[j0] == 0 {
                break;
            }
        }
        loop {
            let j1 = way[j0];
            p[j0] = p[j1];
            j0 = j1;
            if j0 == 0 {
                break;
            }
        }
    }
    let mut assign = vec![0usize; rows];
    for j in 1..=cols {
        if p[j] != 0 {
            assign[p[j] - 1] = j - 1;
        }
    }
    let mut total = 0.0;
    for (i, &j) in assign.iter().enumerate() {
        let c = cost[i * cols + j];
        if !c.is_finite() {
            return None;
        }
        total += c;
    }
    Some((assign, total))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn brute(cost: &[f64], rows: usize, cols: usize) -> Option<f64> {
        fn rec(cost: &[f64], rows: usize, cols: usize, i: usize, used: &mut Vec<bool>) -> f64 {
            if i == rows {
                return 0.0;
            }
            let mut best = f64::INFINITY;
            for j in 0..cols {
                if !used[j] {
                    used[j] = true;
                    let c = cost[i * cols + j] + rec(cost, rows, cols, i + 1, used);
                    used[j] = false;
                    best = best.min(c);
                }
            }
            best
        }
        let b = rec(cost, rows, cols, 0, &mut vec![false; cols]);
        b.is_finite().then_some(b)
    }

    #[test]
    fn small_known_case() {
        let cost = [4.0, 1.0, 3.0, 2.0, 0.0, 5.0, 3.0, 2.0, 2.0];
        let (a, t) = solve(&cost, 3, 3).unwrap();
        assert_eq!(t, 5.0);
        assert_eq!(a, vec![1, 0, 2]);
    }

    #[test]
    fn infeasible_is_none() {
        let inf = f64::INFINITY;
        assert!(solve(&[inf, inf, 1.0, 2.0], 2, 2).is_none());
        assert!(solve(&[1.0, 2.0], 2, 1).is_none());
    }

    proptest! {
        #[test]
        fn matches_brute_force(rows in 1usize..5, extra in 0usize..3, seed in proptest::collection::vec(-50.0f64..50.0, 40), forbid in proptest::collection::vec(0u8..6, 40)) {
            let cols = rows + extra;
            let cost: Vec<f64> = (0..rows * cols).map(|k| if forbid[k] == 0 { f64::INFINITY } else { seed[k] }).collect();
            let expect = brute(&cost, rows, cols);
            match solve(&cost, rows, cols) {
                None => prop_assert!(expect.is_none()),
                Some((a, t)) => {
                    let e = expect.unwrap();
                    prop_assert!((t - e).abs() < 1e-9, "{} vs {}", t, e);
                    let mut seen = a.clone(); seen.sort(); seen.dedup();
                    prop_assert_eq!(seen.len(), rows);
                }
            }
        }
    }
}
