//! Murty's k-best ranked assignment: the K most probable hypotheses, found exactly, and the
//! marginals they imply.
//!
//! The association problem becomes a rectangular assignment problem with n rows (tracks) and
//! m + n columns: column j < m is measurement j with cost −log φᵢ(j + 1), and column m + i is
//! track i's private "missed" column with cost −log φᵢ(0) (the other tracks may not use it).
//! This is the cost matrix used for the GLMB update by Vo & Vo (2013, "Labeled random finite
//! sets and multi-object conjugate priors", Section IV) and Reuter et al. (2014, "The labeled
//! multi-Bernoulli filter", Section III). Each row is first shifted by its largest log weight,
//! which subtracts the row minimum from every cost: all costs are ≥ 0 and the ranking is
//! unchanged because every hypothesis takes exactly one entry per row.
//!
//! Murty (1968, "An algorithm for ranking all the assignments in order of increasing cost")
//! partitions the solutions other than the best one into disjoint subproblems: for the i-th
//! free row of the best solution, the rows before it are fixed to their columns in that
//! solution and row i is forbidden its column. Each subproblem is solved with the Hungarian
//! method of [`crate::assignment`]; the best remaining subproblem yields the next
//! hypothesis and is partitioned in turn. Not for: approximate marginals of large groups
//! (see the Gibbs and belief-propagation associators).

use super::problem::Accumulator;
use super::problem::{AssociationProblem, Associator, Hypothesis, Marginals};
use super::tables::{prepare, LogTable, Prepared};
use crate::assignment;
use crate::rng::FilterRng;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Marginals from the `k` most probable hypotheses (Murty's ranked assignment), normalised
/// over those hypotheses. Exact when `k` is at least the number of admissible hypotheses.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct MurtyAssociator {
    /// Number of best hypotheses kept (0 is treated as 1).
    pub k: usize,
}

impl Default for MurtyAssociator {
    /// k = 200: every hypothesis of up to 3 tracks and 5 measurements (136 of them at most),
    /// and the dominant ones of the larger groups the filter usually sees.
    fn default() -> Self {
        Self { k: 200 }
    }
}

impl MurtyAssociator {
    /// The `k` best hypotheses, best first (see [`ranked_hypotheses`]).
    pub fn ranked(&self, problem: &AssociationProblem) -> Vec<Hypothesis> {
        ranked_hypotheses(problem, self.k)
    }
}

impl Associator for MurtyAssociator {
    fn marginals(&self, problem: &AssociationProblem, _rng: &mut FilterRng) -> Marginals {
        match prepare(problem) {
            Prepared::Done(m) => m,
            Prepared::Table(t) => marginals_of_table(&t, self.k),
        }
    }
}

/// The `k` most probable admissible hypotheses of `problem`, in order of non-increasing
/// weight, each with its log weight Σᵢ log φᵢ(θ(i)) on the problem's own scale. Fewer are
/// returned if fewer exist; none if the problem is malformed or infeasible. Ties are broken
/// deterministically.
pub fn ranked_hypotheses(problem: &AssociationProblem, k: usize) -> Vec<Hypothesis> {
    let Some(table) = LogTable::new(problem) else {
        return Vec::new();
    };
    ranked(&table, k)
        .into_iter()
        .map(|(theta, _)| Hypothesis {
            log_weight: problem.log_weight(&theta),
            assignment: theta,
        })
        .collect()
}

/// Marginals from the `k` best hypotheses of a table.
pub(crate) fn marginals_of_table(table: &LogTable, k: usize) -> Marginals {
    let mut acc = Accumulator::new(table.n, table.m);
    for (theta, lw) in ranked(table, k.max(1)) {
        acc.add(&theta, lw);
    }
    acc.finish()
}

/// The n × (m + n) cost matrix of a table (+∞ = forbidden).
pub(crate) fn cost_matrix(table: &LogTable) -> Vec<f64> {
    let (n, m) = (table.n, table.m);
    let cols = m + n;
    let mut cost = vec![f64::INFINITY; n * cols];
    for i in 0..n {
        let row = table.row(i);
        let out = &mut cost[i * cols..(i + 1) * cols];
        for j in 0..m {
            out[j] = -row[j + 1];
        }
        out[m + i] = -row[0];
    }
    cost
}

/// Hypothesis (0 = missed, j ≥ 1 = measurement j − 1) from the assigned columns.
fn to_theta(cols: &[usize], m: usize) -> Vec<usize> {
    cols.iter()
        .map(|&c| if c < m { c + 1 } else { 0 })
        .collect()
}

/// The most probable hypothesis of a table, or `None` if none is admissible.
pub(crate) fn best_assignment(table: &LogTable) -> Option<Vec<usize>> {
    let cost = cost_matrix(table);
    assignment::solve(&cost, table.n, table.m + table.n).map(|(cols, _)| to_theta(&cols, table.m))
}

/// Marks a row that is not fixed to a column.
const FREE: usize = usize::MAX;

/// A subproblem of Murty's partition with its optimal solution.
struct Node {
    /// Total cost of `cols`.
    cost: f64,
    /// Creation order, to break ties deterministically (first created first).
    seq: u64,
    /// Optimal column of every row.
    cols: Vec<usize>,
    /// Column each row is fixed to, or [`FREE`].
    fixed: Vec<usize>,
    /// (row, column) pairs this subproblem forbids, for rows that are still free.
    excluded: Vec<(usize, usize)>,
}

impl PartialEq for Node {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Node {}
impl PartialOrd for Node {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Node {
    /// Reversed, so that the max-heap pops the cheapest (then oldest) node.
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .cost
            .total_cmp(&self.cost)
            .then(other.seq.cmp(&self.seq))
    }
}

/// Solves the subproblem given by `fixed` rows and `excluded` pairs: the fixed rows and their
/// columns are removed, the excluded pairs set to +∞, and the rest handed to the Hungarian
/// solver. Returns every row's column and the total cost.
fn solve_sub(
    cost: &[f64],
    n: usize,
    cols: usize,
    fixed: &[usize],
    excluded: &[(usize, usize)],
) -> Option<(Vec<usize>, f64)> {
    let mut taken = vec![false; cols];
    let mut row_index = vec![FREE; n];
    let mut free_rows = Vec::with_capacity(n);
    for (r, &c) in fixed.iter().enumerate() {
        if c == FREE {
            row_index[r] = free_rows.len();
            free_rows.push(r);
        } else {
            taken[c] = true;
        }
    }
    let mut col_index = vec![FREE; cols];
    let mut free_cols = Vec::with_capacity(cols);
    for c in 0..cols {
        if !taken[c] {
            col_index[c] = free_cols.len();
            free_cols.push(c);
        }
    }
    let (fr, fc) = (free_rows.len(), free_cols.len());
    let mut sub = Vec::with_capacity(fr * fc);
    for &r in &free_rows {
        sub.extend(free_cols.iter().map(|&c| cost[r * cols + c]));
    }
    for &(r, c) in excluded {
        if row_index[r] != FREE && col_index[c] != FREE {
            sub[row_index[r] * fc + col_index[c]] = f64::INFINITY;
        }
    }
    let (assign, _) = assignment::solve(&sub, fr, fc)?;
    let mut out = fixed.to_vec();
    for (k, &r) in free_rows.iter().enumerate() {
        out[r] = free_cols[assign[k]];
    }
    let total: f64 = out
        .iter()
        .enumerate()
        .map(|(r, &c)| cost[r * cols + c])
        .sum();
    total.is_finite().then_some((out, total))
}

/// The `k` best hypotheses of a table with their shifted log weights, best first.
pub(crate) fn ranked(table: &LogTable, k: usize) -> Vec<(Vec<usize>, f64)> {
    let (n, m) = (table.n, table.m);
    let cols = m + n;
    let mut out = Vec::new();
    if k == 0 {
        return out;
    }
    let cost = cost_matrix(table);
    let root_fixed = vec![FREE; n];
    let Some((best, best_cost)) = solve_sub(&cost, n, cols, &root_fixed, &[]) else {
        return out;
    };
    let mut seq = 0u64;
    let mut heap = BinaryHeap::new();
    heap.push(Node {
        cost: best_cost,
        seq,
        cols: best,
        fixed: root_fixed,
        excluded: Vec::new(),
    });
    while let Some(node) = heap.pop() {
        let theta = to_theta(&node.cols, m);
        let lw = table.log_weight(&theta);
        out.push((theta, lw));
        if out.len() >= k {
            break;
        }
        // Partition the node's remaining solutions: child r fixes the free rows before r to
        // the node's solution and forbids row r its column there.
        let mut fixed = node.fixed.clone();
        for r in 0..n {
            if node.fixed[r] != FREE {
                continue;
            }
            let mut excluded: Vec<(usize, usize)> = node
                .excluded
                .iter()
                .copied()
                .filter(|&(row, _)| fixed[row] == FREE)
                .collect();
            excluded.push((r, node.cols[r]));
            if let Some((sol, c)) = solve_sub(&cost, n, cols, &fixed, &excluded) {
                seq += 1;
                heap.push(Node {
                    cost: c,
                    seq,
                    cols: sol,
                    fixed: fixed.clone(),
                    excluded,
                });
            }
            fixed[r] = node.cols[r];
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::testutil::*;
    use super::super::ExhaustiveAssociator;
    use super::*;
    use crate::rng::seeded;
    use proptest::prelude::*;

    /// The n × (m + n) cost matrix written out directly from the problem.
    fn reference_cost(p: &AssociationProblem) -> Vec<f64> {
        let (n, m) = (p.n_tracks, p.n_meas);
        let mut c = Vec::new();
        for i in 0..n {
            for j in 0..m {
                c.push(-p.log_detect[i * m + j]);
            }
            for k in 0..n {
                c.push(if k == i {
                    -p.log_miss[i]
                } else {
                    f64::INFINITY
                });
            }
        }
        c
    }

    #[test]
    fn ranks_a_hand_computed_case() {
        // Same problem as the exhaustive hand-computed case: weights
        // (0,0) 2, (0,1) 3, (1,0) 4, (2,0) 2, (2,1) 3.
        let ln = f64::ln;
        let p = AssociationProblem::new(
            2,
            2,
            vec![ln(1.0), ln(2.0)],
            vec![ln(2.0), ln(1.0), ln(3.0), f64::NEG_INFINITY],
        )
        .unwrap();
        let r = ranked_hypotheses(&p, 10);
        assert_eq!(r.len(), 5);
        assert_eq!(r[0].assignment, vec![1, 0]);
        assert!((r[0].log_weight - ln(4.0)).abs() < 1e-14);
        let weights: Vec<f64> = r.iter().map(|h| h.log_weight.exp()).collect();
        for (w, e) in weights.iter().zip([4.0, 3.0, 3.0, 2.0, 2.0]) {
            assert!((w - e).abs() < 1e-12, "{weights:?}");
        }
        assert_eq!(ranked_hypotheses(&p, 2).len(), 2);
        assert!(ranked_hypotheses(&p, 0).is_empty());
    }

    #[test]
    fn fewer_hypotheses_than_k_mean_exact_marginals_on_larger_group() {
        // 5 tracks, 4 measurements: 501 hypotheses, all ranked with k = 2000.
        let p = AssociationProblem::new(
            5,
            4,
            (0..5).map(|i| -0.3 * i as f64).collect(),
            (0..20).map(|k| -((k * 5 % 7) as f64) * 0.4).collect(),
        )
        .unwrap();
        let r = ranked_hypotheses(&p, 2000);
        assert_eq!(r.len(), brute_hypotheses(&p).len());
        let mg = MurtyAssociator { k: 2000 }.marginals(&p, &mut seeded(0));
        assert!(max_diff(&mg, &brute_marginals(&p).unwrap()) < 1e-12);
    }

    proptest! {
        #[test]
        fn large_k_equals_exhaustive(p in problems(4, 4, -8.0, 4.0, 4, true)) {
            let mut rng = seeded(0);
            let mg = MurtyAssociator { k: 1000 }.marginals(&p, &mut rng);
            let ex = ExhaustiveAssociator::default().marginals(&p, &mut rng);
            assert_valid(&p, &mg);
            prop_assert!(max_diff(&mg, &ex) < 1e-12, "{:?} vs {:?}", mg, ex);
            if let Some(exact) = brute_marginals(&p) {
                prop_assert!(max_diff(&mg, &exact) < 1e-12);
            }
        }

        #[test]
        fn ranked_list_is_sorted_distinct_and_starts_at_optimum(
            p in problems(4, 4, -8.0, 4.0, 3, true),
            k in 1usize..80,
        ) {
            let r = ranked_hypotheses(&p, k);
            let all = brute_hypotheses(&p);
            prop_assert_eq!(r.len(), k.min(all.len()));
            for w in r.windows(2) {
                prop_assert!(w[0].log_weight >= w[1].log_weight - 1e-12);
            }
            let mut seen: Vec<&Vec<usize>> = r.iter().map(|h| &h.assignment).collect();
            seen.sort();
            seen.dedup();
            prop_assert_eq!(seen.len(), r.len());
            for h in &r {
                let lw = all.iter().find(|(t, _)| t == &h.assignment).map(|x| x.1);
                prop_assert_eq!(lw, Some(h.log_weight));
            }
            // The k-th best weight by sorting the enumeration matches.
            let mut sorted: Vec<f64> = all.iter().map(|x| x.1).collect();
            sorted.sort_by(|a, b| b.total_cmp(a));
            for (h, w) in r.iter().zip(&sorted) {
                prop_assert!((h.log_weight - w).abs() < 1e-9);
            }
            let (n, m) = (p.n_tracks, p.n_meas);
            match assignment::solve(&reference_cost(&p), n, m + n) {
                Some((_, c)) => prop_assert!((r[0].log_weight + c).abs() < 1e-9),
                None => prop_assert!(r.is_empty()),
            }
        }
    }
}
