//! The machinery the association methods share, crate-internal: the common preparation of
//! a problem ([`prepare`]: trivial, malformed and infeasible problems answered at once, the
//! rest turned into a [`LogTable`] of row-shifted log weights), answered with the
//! [`Marginals`] of [`super::problem`] (whose accumulator sums enumerated or sampled
//! hypotheses).
//!
//! Not for: public API (nothing here is exported) or any one method's search (see the
//! associator modules).

use super::problem::{AssociationProblem, Marginals};

/// A problem after the common preparation: either already answered, or a table of row-shifted
/// log weights for a method to work on.
pub(crate) enum Prepared {
    /// Trivial, malformed or infeasible: the marginals are known.
    Done(Marginals),
    /// At least two tracks and one measurement, every row with an admissible entry.
    Table(LogTable),
}

/// Log weights shifted so that each row's maximum is 0, with the miss entry first:
/// `w[i * (m + 1)]` is track i's miss entry and `w[i * (m + 1) + j]` measurement j − 1.
///
/// A row whose maximum is +∞ keeps 0 for its +∞ entries and −∞ for the rest (the limit of
/// the shift). Finite entries below [`LOG_FLOOR`] are raised to it so that the costs handed to
/// the assignment solver stay far from overflow; such weights are zero in `f64` unless nothing
/// else is admissible.
pub(crate) struct LogTable {
    /// Number of tracks.
    pub n: usize,
    /// Number of measurements.
    pub m: usize,
    /// Row-major `n × (m + 1)` shifted log weights.
    pub w: Vec<f64>,
}

/// Lowest finite shifted log weight kept in a [`LogTable`].
pub(crate) const LOG_FLOOR: f64 = -1e12;

impl LogTable {
    /// Row stride.
    #[inline]
    pub fn stride(&self) -> usize {
        self.m + 1
    }

    /// Row `i`: miss entry then one entry per measurement.
    #[inline]
    pub fn row(&self, i: usize) -> &[f64] {
        &self.w[i * (self.m + 1)..(i + 1) * (self.m + 1)]
    }

    /// Shifted log weight of a hypothesis (0 = missed, j ≥ 1 = measurement j − 1); assumes
    /// the hypothesis is admissible apart from −∞ entries.
    pub fn log_weight(&self, theta: &[usize]) -> f64 {
        let s = self.stride();
        theta
            .iter()
            .enumerate()
            .map(|(i, &j)| self.w[i * s + j])
            .sum()
    }

    /// Whether any track's miss entry is forbidden (only then can the problem be infeasible).
    pub fn has_forbidden_miss(&self) -> bool {
        (0..self.n).any(|i| self.w[i * self.stride()] == f64::NEG_INFINITY)
    }
}

impl LogTable {
    /// The shifted table of a problem; `None` if the problem is malformed or some track has
    /// no admissible entry at all (then no hypothesis is admissible).
    pub fn new(problem: &AssociationProblem) -> Option<Self> {
        if !problem.is_well_formed() {
            return None;
        }
        let (n, m) = (problem.n_tracks, problem.n_meas);
        let s = m + 1;
        let mut w = Vec::with_capacity(n * s);
        for i in 0..n {
            let start = w.len();
            w.extend((0..s).map(|j| problem.log_phi(i, j)));
            let row = &mut w[start..];
            let max = row.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            if max == f64::NEG_INFINITY {
                return None;
            }
            for v in row.iter_mut() {
                *v = if max == f64::INFINITY {
                    if *v == f64::INFINITY {
                        0.0
                    } else {
                        f64::NEG_INFINITY
                    }
                } else if *v == f64::NEG_INFINITY {
                    f64::NEG_INFINITY
                } else {
                    (*v - max).max(LOG_FLOOR)
                };
            }
        }
        Some(LogTable { n, m, w })
    }
}

/// Common preparation of every method (see [`Prepared`]).
pub(crate) fn prepare(problem: &AssociationProblem) -> Prepared {
    let (n, m) = (problem.n_tracks, problem.n_meas);
    if n == 0 || m == 0 || !problem.is_well_formed() {
        return Prepared::Done(Marginals::all_missed(n, m));
    }
    match LogTable::new(problem) {
        None => Prepared::Done(Marginals::all_missed(n, m)),
        Some(table) if n == 1 => Prepared::Done(single_track(&table)),
        Some(table) => Prepared::Table(table),
    }
}

/// Exact marginals of a one-track table: its row normalised.
fn single_track(table: &LogTable) -> Marginals {
    let row = table.row(0);
    let total: f64 = row.iter().map(|v| v.exp()).sum();
    Marginals {
        n_tracks: 1,
        n_meas: table.m,
        miss: vec![row[0].exp() / total],
        detect: row[1..].iter().map(|v| v.exp() / total).collect(),
    }
}
