//! Exact marginals by enumerating every admissible hypothesis.
//!
//! The number of hypotheses grows like Σₖ C(n, k)·m!/(m − k)!, so this is for small groups
//! and for checking the approximate methods in tests. Beyond a cap the enumeration is
//! abandoned and Murty's ranked assignment answers instead. Not for: large groups.

use super::murty::{self, MurtyAssociator};
use super::problem::Accumulator;
use super::problem::{AssociationProblem, Associator, Marginals};
use super::tables::{prepare, LogTable, Prepared};
use crate::rng::FilterRng;

/// Exact marginals by depth-first enumeration of all admissible hypotheses.
///
/// If the group has more than `max_hypotheses` admissible hypotheses (or the search visits
/// more than `max_hypotheses · (n_tracks + 1)` partial hypotheses), enumeration stops and
/// [`MurtyAssociator::default`] answers instead, which is exact only when its k covers all
/// hypotheses.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct ExhaustiveAssociator {
    /// Cap on the number of hypotheses enumerated.
    pub max_hypotheses: usize,
}

impl Default for ExhaustiveAssociator {
    /// A cap of 100 000 hypotheses (for example every hypothesis of 4 tracks and 12
    /// measurements, about 30 000).
    fn default() -> Self {
        Self {
            max_hypotheses: 100_000,
        }
    }
}

impl Associator for ExhaustiveAssociator {
    fn marginals(&self, problem: &AssociationProblem, _rng: &mut FilterRng) -> Marginals {
        let table = match prepare(problem) {
            Prepared::Done(m) => return m,
            Prepared::Table(t) => t,
        };
        match enumerate(&table, self.max_hypotheses) {
            Some(m) => m,
            None => {
                let murty = MurtyAssociator::default();
                murty::marginals_of_table(&table, murty.k, murty.min_weight)
            }
        }
    }
}

/// Depth-first search over tracks, skipping forbidden entries and measurements already used.
struct Search<'a> {
    table: &'a LogTable,
    used: Vec<bool>,
    theta: Vec<usize>,
    acc: Accumulator,
    leaves: usize,
    nodes: usize,
    max_leaves: usize,
    max_nodes: usize,
    aborted: bool,
}

impl Search<'_> {
    fn visit(&mut self, i: usize, log_weight: f64) {
        if self.aborted {
            return;
        }
        self.nodes += 1;
        if i == self.table.n {
            self.leaves += 1;
            if self.leaves > self.max_leaves {
                self.aborted = true;
            } else {
                self.acc.add(&self.theta, log_weight);
            }
            return;
        }
        if self.nodes > self.max_nodes {
            self.aborted = true;
            return;
        }
        for j in 0..=self.table.m {
            let v = self.table.row(i)[j];
            if v == f64::NEG_INFINITY || (j > 0 && self.used[j - 1]) {
                continue;
            }
            if j > 0 {
                self.used[j - 1] = true;
            }
            self.theta[i] = j;
            self.visit(i + 1, log_weight + v);
            if j > 0 {
                self.used[j - 1] = false;
            }
            if self.aborted {
                return;
            }
        }
    }
}

/// Exact marginals of a table, or `None` when the cap is exceeded.
fn enumerate(table: &LogTable, max_hypotheses: usize) -> Option<Marginals> {
    let mut search = Search {
        table,
        used: vec![false; table.m],
        theta: vec![0; table.n],
        acc: Accumulator::new(table.n, table.m),
        leaves: 0,
        nodes: 0,
        max_leaves: max_hypotheses,
        max_nodes: max_hypotheses.saturating_mul(table.n + 1),
        aborted: false,
    };
    search.visit(0, 0.0);
    (!search.aborted).then(|| search.acc.finish())
}

#[cfg(test)]
mod tests {
    use super::super::testutil::*;
    use super::*;
    use crate::rng::seeded;
    use proptest::prelude::*;

    /// Two tracks, two measurements, weights chosen by hand:
    ///
    /// ```text
    ///            miss  z1  z2
    /// track 1:    1    2   1
    /// track 2:    2    3   0 (forbidden)
    /// ```
    ///
    /// Admissible hypotheses (θ1, θ2) and weights:
    /// (0,0) 1·2 = 2, (0,1) 1·3 = 3, (1,0) 2·2 = 4, (2,0) 1·2 = 2, (2,1) 1·3 = 3;
    /// (1,1) reuses z1 and (·,2) is forbidden for track 2. Total 14.
    /// Track 1: miss (2+3)/14 = 5/14, z1 4/14, z2 (2+3)/14 = 5/14.
    /// Track 2: miss (2+4+2)/14 = 8/14, z1 (3+3)/14 = 6/14, z2 0.
    #[test]
    fn hand_computed_two_by_two() {
        let ln = f64::ln;
        let p = AssociationProblem::new(
            2,
            2,
            vec![ln(1.0), ln(2.0)],
            vec![ln(2.0), ln(1.0), ln(3.0), f64::NEG_INFINITY],
        )
        .unwrap();
        let mg = ExhaustiveAssociator::default().marginals(&p, &mut seeded(0));
        let expect_miss = [5.0 / 14.0, 8.0 / 14.0];
        let expect_detect = [4.0 / 14.0, 5.0 / 14.0, 6.0 / 14.0, 0.0];
        for (a, b) in mg.miss.iter().zip(&expect_miss) {
            assert!((a - b).abs() < 1e-14, "{mg:?}");
        }
        for (a, b) in mg.detect.iter().zip(&expect_detect) {
            assert!((a - b).abs() < 1e-14, "{mg:?}");
        }
        assert_eq!(mg.detect[3], 0.0);
    }

    #[test]
    fn cap_falls_back_to_ranked_assignment() {
        // 6 tracks × 6 measurements, all admissible: 13 327 hypotheses > cap of 10.
        let p = AssociationProblem::new(
            6,
            6,
            (0..6).map(|i| -(i as f64)).collect(),
            (0..36).map(|k| -((k * 7 % 11) as f64)).collect(),
        )
        .unwrap();
        let small = ExhaustiveAssociator { max_hypotheses: 10 };
        let mg = small.marginals(&p, &mut seeded(0));
        let murty = MurtyAssociator::default().marginals(&p, &mut seeded(0));
        assert_eq!(mg, murty);
        // Without the cap the answer is exact.
        let exact = ExhaustiveAssociator::default().marginals(&p, &mut seeded(0));
        assert!(max_diff(&exact, &brute_marginals(&p).unwrap()) < 1e-12);
    }

    proptest! {
        #[test]
        fn matches_plain_enumeration(p in problems(4, 4, -8.0, 4.0, 4, true)) {
            let mg = ExhaustiveAssociator::default().marginals(&p, &mut seeded(0));
            assert_valid(&p, &mg);
            match brute_marginals(&p) {
                Some(exact) => prop_assert!(max_diff(&mg, &exact) < 1e-12),
                None => prop_assert_eq!(mg, Marginals::all_missed(p.n_tracks, p.n_meas)),
            }
        }
    }
}
