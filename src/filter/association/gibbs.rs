//! Gibbs sampling of association hypotheses, after Vo, Vo & Hoang (2017, "An efficient
//! implementation of the generalized labeled multi-Bernoulli filter", IEEE TSP, Section III:
//! the Gibbs sampler).
//!
//! The target is the distribution of hypotheses proportional to their weight Πᵢ φᵢ(θ(i)).
//! Given the other tracks' entries, track i's entry is categorical: "missed" with weight
//! φᵢ(0), measurement j with weight φᵢ(j) if no other track uses j, and 0 otherwise — so a
//! sweep over all tracks costs O(n·m). The chain starts from the best hypothesis (found with
//! the Hungarian method) so that the most probable hypothesis is always included and the
//! start is admissible even when some miss weight is zero. Only the set of *distinct*
//! hypotheses visited is used: their marginals are computed from their exact weights,
//! normalised over that set, as the paper does for the GLMB components it keeps.
//!
//! Note that when a track's miss weight is zero the chain need not reach every hypothesis
//! (two such tracks can swap measurements only through a state where one of them misses).
//! Not for: exact marginals (use enough samples, or Murty or enumeration for small groups).

use super::murty::best_assignment;
use super::problem::Accumulator;
use super::problem::{AssociationProblem, Associator, Hypothesis, Marginals};
use super::tables::{prepare, LogTable, Prepared};
use crate::rng::FilterRng;
use rand::RngExt;
use std::collections::HashSet;

/// Marginals over the distinct hypotheses visited by a Gibbs sampler.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct GibbsAssociator {
    /// Number of Gibbs sweeps (each updates every track once and yields one hypothesis);
    /// the starting hypothesis is always included as well.
    pub samples: usize,
}

impl Default for GibbsAssociator {
    /// 1000 sweeps: thousands of times the number of hypotheses that carry noticeable weight
    /// in the groups of a few tracks the filter produces.
    fn default() -> Self {
        Self { samples: 1000 }
    }
}

impl Associator for GibbsAssociator {
    fn marginals(&self, problem: &AssociationProblem, rng: &mut FilterRng) -> Marginals {
        let table = match prepare(problem) {
            Prepared::Done(m) => return m,
            Prepared::Table(t) => t,
        };
        let mut acc = Accumulator::new(table.n, table.m);
        for theta in sample(&table, self.samples, rng) {
            acc.add(&theta, table.log_weight(&theta));
        }
        acc.finish()
    }
}

/// The distinct hypotheses visited by `samples` Gibbs sweeps from the best hypothesis, in
/// the order first visited, with their log weights on the problem's own scale. Empty if the
/// problem is malformed or infeasible. Deterministic given the state of `rng`.
pub fn distinct_hypotheses(
    problem: &AssociationProblem,
    samples: usize,
    rng: &mut FilterRng,
) -> Vec<Hypothesis> {
    let Some(table) = LogTable::new(problem) else {
        return Vec::new();
    };
    sample(&table, samples, rng)
        .into_iter()
        .map(|theta| Hypothesis {
            log_weight: problem.log_weight(&theta),
            assignment: theta,
        })
        .collect()
}

/// Marks a measurement no track uses.
const UNUSED: usize = usize::MAX;

/// Runs the chain; returns the distinct hypotheses (0 = missed, j = measurement j − 1).
fn sample(table: &LogTable, samples: usize, rng: &mut FilterRng) -> Vec<Vec<usize>> {
    let (n, m) = (table.n, table.m);
    let Some(mut theta) = best_assignment(table) else {
        return Vec::new();
    };
    let mut owner = vec![UNUSED; m];
    for (i, &j) in theta.iter().enumerate() {
        if j > 0 {
            owner[j - 1] = i;
        }
    }
    let mut seen: HashSet<Vec<usize>> = HashSet::new();
    seen.insert(theta.clone());
    let mut distinct = vec![theta.clone()];
    let mut prob = vec![0.0; m + 1];
    // Linear weights relative to each row's maximum, computed once.
    let linear: Vec<f64> = table.w.iter().map(|v| v.exp()).collect();
    for _ in 0..samples {
        for i in 0..n {
            if theta[i] > 0 {
                owner[theta[i] - 1] = UNUSED;
            }
            let row = table.row(i);
            let lin = &linear[i * (m + 1)..(i + 1) * (m + 1)];
            let open = |j: usize| row[j] > f64::NEG_INFINITY && (j == 0 || owner[j - 1] == UNUSED);
            let mut total = 0.0;
            let mut last = theta[i];
            for (j, p) in prob.iter_mut().enumerate() {
                *p = if open(j) {
                    last = j;
                    lin[j]
                } else {
                    0.0
                };
                total += *p;
            }
            if total < 1e-250 {
                // Every admissible entry is far below the row maximum (taken by others):
                // rescale by the largest admissible log weight instead.
                let max = (0..=m)
                    .filter(|&j| open(j))
                    .map(|j| row[j])
                    .fold(f64::NEG_INFINITY, f64::max);
                total = 0.0;
                for (j, p) in prob.iter_mut().enumerate() {
                    if open(j) {
                        *p = (row[j] - max).exp();
                    }
                    total += *p;
                }
            }
            // The current entry is admissible, so `total > 0` and `last` is admissible.
            let u = rng.random::<f64>() * total;
            let mut cum = 0.0;
            let mut pick = last;
            for (j, &p) in prob.iter().enumerate() {
                cum += p;
                if u < cum {
                    pick = j;
                    break;
                }
            }
            theta[i] = pick;
            if pick > 0 {
                owner[pick - 1] = i;
            }
        }
        if !seen.contains(theta.as_slice()) {
            seen.insert(theta.clone());
            distinct.push(theta.clone());
        }
    }
    distinct
}

#[cfg(test)]
mod tests {
    use super::super::testutil::*;
    use super::*;
    use crate::rng::seeded;
    use proptest::prelude::*;

    /// Problems of 2–3 tracks and 1–3 measurements (at most 34 hypotheses) with log weights
    /// in [−0.5, 0.5], so that every hypothesis has probability at least e^−3 / 34 ≈ 0.15 %.
    fn moderate_problem(seed: u64) -> AssociationProblem {
        let mut g = seeded(seed);
        let n = g.random_range(2..=3usize);
        let m = g.random_range(1..=3usize);
        let mut r = |_| g.random::<f64>() - 0.5;
        AssociationProblem::new(
            n,
            m,
            (0..n).map(&mut r).collect(),
            (0..n * m).map(&mut r).collect(),
        )
        .unwrap()
    }

    #[test]
    fn visits_every_hypothesis_and_is_then_exact() {
        for seed in 0..30 {
            let p = moderate_problem(seed);
            let all = brute_hypotheses(&p);
            assert!(all.len() <= 34);
            let mut rng = seeded(100 + seed);
            let visited = distinct_hypotheses(&p, 2000, &mut rng);
            assert_eq!(visited.len(), all.len(), "seed {seed}");
            let mg = GibbsAssociator { samples: 2000 }.marginals(&p, &mut seeded(100 + seed));
            assert_valid(&p, &mg);
            let exact = brute_marginals(&p).unwrap();
            assert!(max_diff(&mg, &exact) < 1e-9, "seed {seed}");
        }
    }

    #[test]
    fn deterministic_for_a_fixed_seed() {
        let p = AssociationProblem::new(
            4,
            5,
            vec![-1.0, -0.5, -2.0, 0.0],
            (0..20).map(|k| ((k * 13 % 7) as f64) * 0.3 - 1.0).collect(),
        )
        .unwrap();
        let g = GibbsAssociator { samples: 300 };
        let a = g.marginals(&p, &mut seeded(9));
        let b = g.marginals(&p, &mut seeded(9));
        assert_eq!(a, b);
        let ha = distinct_hypotheses(&p, 300, &mut seeded(9));
        let hb = distinct_hypotheses(&p, 300, &mut seeded(9));
        assert_eq!(ha, hb);
    }

    #[test]
    fn zero_samples_is_the_best_hypothesis() {
        // Best hypothesis: track 0 → z1 (weight 3), track 1 → miss (weight 2).
        let ln = f64::ln;
        let p = AssociationProblem::new(
            2,
            2,
            vec![ln(1.0), ln(2.0)],
            vec![ln(3.0), ln(1.0), ln(0.5), f64::NEG_INFINITY],
        )
        .unwrap();
        let h = distinct_hypotheses(&p, 0, &mut seeded(0));
        assert_eq!(h.len(), 1);
        assert_eq!(h[0].assignment, vec![1, 0]);
        let mg = GibbsAssociator { samples: 0 }.marginals(&p, &mut seeded(0));
        assert_eq!(mg.detect, vec![1.0, 0.0, 0.0, 0.0]);
        assert_eq!(mg.miss, vec![0.0, 1.0]);
    }

    #[test]
    fn conditional_far_below_row_maximum() {
        // Track 1 must take z0, which track 0 prefers by e^800; track 0 is left with
        // "missed" (e^−800) or z1 (e^−801): P(missed) = e / (1 + e).
        let ninf = f64::NEG_INFINITY;
        let p = AssociationProblem::new(2, 2, vec![-800.0, ninf], vec![0.0, -801.0, 0.0, ninf])
            .unwrap();
        let mg = GibbsAssociator { samples: 200 }.marginals(&p, &mut seeded(3));
        assert_valid(&p, &mg);
        let e = std::f64::consts::E;
        assert!((mg.miss[0] - e / (1.0 + e)).abs() < 1e-12, "{mg:?}");
        assert!((mg.detect[1] - 1.0 / (1.0 + e)).abs() < 1e-12);
        assert_eq!(mg.detect[0], 0.0);
        assert_eq!(mg.detect[2], 1.0);
    }

    proptest! {
        /// Normalising over a subset S of hypotheses moves every marginal by at most the
        /// probability mass outside S: P(a) − P(a | S) = (1 − P(S))·(P(a | Sᶜ) − P(a | S)).
        #[test]
        fn error_bounded_by_unvisited_mass(p in problems(4, 4, -4.0, 2.0, 4, true), seed in 0u64..1000) {
            let mg = GibbsAssociator { samples: 200 }.marginals(&p, &mut seeded(seed));
            assert_valid(&p, &mg);
            let Some(exact) = brute_marginals(&p) else {
                prop_assert_eq!(mg, Marginals::all_missed(p.n_tracks, p.n_meas));
                return Ok(());
            };
            let visited = distinct_hypotheses(&p, 200, &mut seeded(seed));
            let all = brute_hypotheses(&p);
            let max = all.iter().map(|h| h.1).fold(f64::NEG_INFINITY, f64::max);
            let z: f64 = all.iter().map(|h| (h.1 - max).exp()).sum();
            let inside: f64 = all
                .iter()
                .filter(|h| visited.iter().any(|v| v.assignment == h.0))
                .map(|h| (h.1 - max).exp())
                .sum();
            let outside = 1.0 - inside / z;
            prop_assert!(max_diff(&mg, &exact) <= outside + 1e-9);
            // Every visited hypothesis is admissible, with its exact weight.
            for v in &visited {
                let lw = all.iter().find(|h| h.0 == v.assignment).map(|h| h.1);
                prop_assert_eq!(lw, Some(v.log_weight));
            }
        }
    }
}
