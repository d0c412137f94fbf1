//! Data association: from the table of track/measurement likelihoods to the marginal
//! probability that each track is missed (or absent) or generated each measurement.
//!
//! The LMB update only needs these marginals (the GLMB → LMB approximation); how they are
//! found is the [`Associator`]'s business. Three methods are built in — Murty's k-best ranked
//! assignments ([`MurtyAssociator`]), Gibbs sampling ([`GibbsAssociator`]) and loopy belief
//! propagation ([`LbpAssociator`]) — plus exhaustive enumeration for small problems and tests
//! ([`ExhaustiveAssociator`]). [`AssociationMethod`] selects one from a configuration.
//! Not for: gating or likelihood evaluation.
//!
//! All methods work in the log domain and share the same conventions:
//!
//! * multiplying every weight of one track's row by a constant does not change the marginals
//!   (every hypothesis takes exactly one entry from each row), so each row is first shifted
//!   so that its largest log weight is 0 — weights such as e^−800 never underflow;
//! * a forbidden pairing (log weight −∞) always gets marginal exactly 0;
//! * a problem without any admissible hypothesis (for instance a track whose miss weight is
//!   −∞ and whose measurements are all taken) yields [`Marginals::all_missed`];
//! * a group of one track, or without measurements, is answered exactly without running the
//!   method.

pub mod exhaustive;
pub mod gibbs;
pub mod lbp;
pub mod murty;

pub use exhaustive::ExhaustiveAssociator;
pub use gibbs::{distinct_hypotheses, GibbsAssociator};
pub use lbp::LbpAssociator;
pub use murty::{ranked_hypotheses, MurtyAssociator};

use crate::rng::FilterRng;
use std::str::FromStr;

/// One association problem (an independent group of tracks and measurements), in log weights.
///
/// A hypothesis θ maps each track to "missed or absent" (0) or to one measurement, no
/// measurement used twice. Its weight is Πᵢ φᵢ(θ(i)) with log φᵢ(0) = `log_miss[i]` and
/// log φᵢ(j+1) = `log_detect[i * n_meas + j]` (−∞ forbids the pairing).
#[derive(Clone, Debug, PartialEq)]
pub struct AssociationProblem {
    /// Number of tracks (rows).
    pub n_tracks: usize,
    /// Number of measurements (columns).
    pub n_meas: usize,
    /// log φᵢ(0) for every track: log(1 − r + r·η_miss).
    pub log_miss: Vec<f64>,
    /// log φᵢ(j) for track i and measurement j, row-major `n_tracks × n_meas`:
    /// log(r·η_j) with η_j = Σ wᵢ p_D g(z_j | xᵢ) / κ(z_j).
    pub log_detect: Vec<f64>,
}

impl AssociationProblem {
    /// A problem from its parts, checking the lengths and that no log weight is NaN or +∞
    /// (−∞ is allowed and forbids the pairing).
    pub fn new(
        n_tracks: usize,
        n_meas: usize,
        log_miss: Vec<f64>,
        log_detect: Vec<f64>,
    ) -> crate::Result<Self> {
        if log_miss.len() != n_tracks {
            return Err(crate::Error::invalid(
                "association problem",
                format!("{} miss weights for {n_tracks} tracks", log_miss.len()),
            ));
        }
        if Some(log_detect.len()) != n_tracks.checked_mul(n_meas) {
            return Err(crate::Error::invalid(
                "association problem",
                format!(
                    "{} detection weights for {n_tracks} tracks × {n_meas} measurements",
                    log_detect.len()
                ),
            ));
        }
        let bad = |v: &f64| v.is_nan() || *v == f64::INFINITY;
        if let Some(i) = log_miss.iter().position(bad) {
            return Err(crate::Error::invalid(
                format!("miss log weight of track {i}"),
                format!("{} (must be finite or −∞)", log_miss[i]),
            ));
        }
        if let Some(k) = log_detect.iter().position(bad) {
            return Err(crate::Error::invalid(
                format!(
                    "detection log weight of track {} and measurement {}",
                    k / n_meas,
                    k % n_meas
                ),
                format!("{} (must be finite or −∞)", log_detect[k]),
            ));
        }
        Ok(Self {
            n_tracks,
            n_meas,
            log_miss,
            log_detect,
        })
    }

    /// Whether the vector lengths agree with `n_tracks` and `n_meas`. Associators answer a
    /// malformed problem with [`Marginals::all_missed`].
    pub fn is_well_formed(&self) -> bool {
        self.log_miss.len() == self.n_tracks
            && Some(self.log_detect.len()) == self.n_tracks.checked_mul(self.n_meas)
    }

    /// log φᵢ(j): `j = 0` is the miss entry, `j ≥ 1` measurement `j − 1`. NaN reads as −∞.
    ///
    /// Panics if `i` or `j` is out of range.
    pub fn log_phi(&self, i: usize, j: usize) -> f64 {
        let v = if j == 0 {
            self.log_miss[i]
        } else {
            self.log_detect[i * self.n_meas + (j - 1)]
        };
        if v.is_nan() {
            f64::NEG_INFINITY
        } else {
            v
        }
    }

    /// log Πᵢ φᵢ(θ(i)) of a hypothesis given as one entry per track (0 = missed, j ≥ 1 =
    /// measurement j − 1). Returns −∞ if the hypothesis is not admissible (wrong length, an
    /// index out of range, or a measurement used twice).
    pub fn log_weight(&self, assignment: &[usize]) -> f64 {
        if assignment.len() != self.n_tracks || !self.is_well_formed() {
            return f64::NEG_INFINITY;
        }
        let mut used = vec![false; self.n_meas];
        let mut total = 0.0;
        for (i, &j) in assignment.iter().enumerate() {
            if j > self.n_meas {
                return f64::NEG_INFINITY;
            }
            if j > 0 {
                if used[j - 1] {
                    return f64::NEG_INFINITY;
                }
                used[j - 1] = true;
            }
            total += self.log_phi(i, j);
        }
        if total.is_nan() {
            f64::NEG_INFINITY
        } else {
            total
        }
    }
}

/// Marginal association probabilities: every row (miss + detections) sums to one.
#[derive(Clone, Debug, PartialEq)]
pub struct Marginals {
    /// Number of tracks.
    pub n_tracks: usize,
    /// Number of measurements.
    pub n_meas: usize,
    /// P(θ(i) = 0) per track.
    pub miss: Vec<f64>,
    /// P(θ(i) = j) row-major `n_tracks × n_meas`.
    pub detect: Vec<f64>,
}

impl Marginals {
    /// Every track missed with probability one: the answer when there is nothing to
    /// associate, or when no hypothesis is admissible.
    pub fn all_missed(n_tracks: usize, n_meas: usize) -> Self {
        Self {
            n_tracks,
            n_meas,
            miss: vec![1.0; n_tracks],
            detect: vec![0.0; n_tracks.saturating_mul(n_meas)],
        }
    }

    /// Marginals of a weighted set of hypotheses, normalised over that set (log-sum-exp, so
    /// log weights of any magnitude are fine). Hypotheses whose weight is −∞ or NaN, or whose
    /// assignment has the wrong length or an index beyond `n_meas`, are ignored; if nothing
    /// is left the result is [`Marginals::all_missed`]. Duplicates count twice.
    pub fn from_hypotheses(n_tracks: usize, n_meas: usize, hypotheses: &[Hypothesis]) -> Self {
        let mut acc = Accumulator::new(n_tracks, n_meas);
        for h in hypotheses {
            if h.assignment.len() == n_tracks && h.assignment.iter().all(|&j| j <= n_meas) {
                acc.add(&h.assignment, h.log_weight);
            }
        }
        acc.finish()
    }

    /// P(θ(i) = j + 1) for all measurements j of track `i`.
    ///
    /// Panics if `i` is out of range.
    pub fn detect_row(&self, i: usize) -> &[f64] {
        &self.detect[i * self.n_meas..(i + 1) * self.n_meas]
    }
}

/// One association hypothesis with its log weight.
#[derive(Clone, Debug, PartialEq)]
pub struct Hypothesis {
    /// θ(i) per track: 0 = missed or absent, j ≥ 1 = measurement j − 1.
    pub assignment: Vec<usize>,
    /// log Πᵢ φᵢ(θ(i)).
    pub log_weight: f64,
}

/// Turns an [`AssociationProblem`] into [`Marginals`].
pub trait Associator: Send + Sync {
    /// Marginal association probabilities. Randomised methods draw from `rng` only.
    fn marginals(&self, problem: &AssociationProblem, rng: &mut FilterRng) -> Marginals;
}

/// A configurable choice of association method.
///
/// Serialised with a `method` tag, e.g. `{"method": "murty", "k": 200}` or
/// `{"method": "lbp", "max_iterations": 100, "tolerance": 1e-9}`.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "method", rename_all = "snake_case")]
pub enum AssociationMethod {
    /// Murty's k-best ranked assignment ([`MurtyAssociator`]).
    Murty {
        /// Number of best hypotheses kept (default 200).
        #[serde(default = "default_murty_k")]
        k: usize,
    },
    /// Gibbs sampling of hypotheses ([`GibbsAssociator`]).
    Gibbs {
        /// Number of Gibbs sweeps (default 1000).
        #[serde(default = "default_gibbs_samples")]
        samples: usize,
    },
    /// Loopy belief propagation ([`LbpAssociator`]).
    Lbp {
        /// Iteration cap (default 100).
        #[serde(default = "default_lbp_iterations")]
        max_iterations: usize,
        /// Stop when no message changes by more than this (default 1e-9).
        #[serde(default = "default_lbp_tolerance")]
        tolerance: f64,
    },
    /// Exhaustive enumeration ([`ExhaustiveAssociator`] with its default cap).
    Exhaustive,
}

fn default_murty_k() -> usize {
    MurtyAssociator::default().k
}
fn default_gibbs_samples() -> usize {
    GibbsAssociator::default().samples
}
fn default_lbp_iterations() -> usize {
    LbpAssociator::default().max_iterations
}
fn default_lbp_tolerance() -> f64 {
    LbpAssociator::default().tolerance
}

impl Default for AssociationMethod {
    /// Loopy belief propagation with 100 iterations and tolerance 10⁻⁹: fast, deterministic
    /// and accurate for the small groups the filter produces.
    fn default() -> Self {
        let lbp = LbpAssociator::default();
        AssociationMethod::Lbp {
            max_iterations: lbp.max_iterations,
            tolerance: lbp.tolerance,
        }
    }
}

impl Associator for AssociationMethod {
    fn marginals(&self, problem: &AssociationProblem, rng: &mut FilterRng) -> Marginals {
        match *self {
            AssociationMethod::Murty { k } => MurtyAssociator { k }.marginals(problem, rng),
            AssociationMethod::Gibbs { samples } => {
                GibbsAssociator { samples }.marginals(problem, rng)
            }
            AssociationMethod::Lbp {
                max_iterations,
                tolerance,
            } => LbpAssociator {
                max_iterations,
                tolerance,
            }
            .marginals(problem, rng),
            AssociationMethod::Exhaustive => {
                ExhaustiveAssociator::default().marginals(problem, rng)
            }
        }
    }
}

impl FromStr for AssociationMethod {
    type Err = crate::Error;

    /// Parses `murty`, `gibbs`, `lbp` or `exhaustive` (case-insensitive), each with its
    /// defaults (k = 200, 1000 samples, 100 iterations with tolerance 10⁻⁹), optionally
    /// followed by `:N` to set k, the number of samples or the iteration cap, e.g. `murty:500`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let s = s.trim().to_ascii_lowercase();
        let (name, arg) = match s.split_once(':') {
            Some((n, a)) => (n.trim(), Some(a.trim())),
            None => (s.as_str(), None),
        };
        let number = |a: Option<&str>, default: usize| -> crate::Result<usize> {
            match a {
                None => Ok(default),
                Some(a) => a.parse::<usize>().map_err(|e| {
                    crate::Error::invalid("association method", format!("{name}:{a}: {e}"))
                }),
            }
        };
        match name {
            "murty" => Ok(AssociationMethod::Murty {
                k: number(arg, MurtyAssociator::default().k)?,
            }),
            "gibbs" => Ok(AssociationMethod::Gibbs {
                samples: number(arg, GibbsAssociator::default().samples)?,
            }),
            "lbp" => {
                let lbp = LbpAssociator::default();
                Ok(AssociationMethod::Lbp {
                    max_iterations: number(arg, lbp.max_iterations)?,
                    tolerance: lbp.tolerance,
                })
            }
            "exhaustive" if arg.is_none() => Ok(AssociationMethod::Exhaustive),
            _ => Err(crate::Error::invalid(
                "association method",
                format!("`{s}` (expected murty, gibbs, lbp or exhaustive, optionally `:N`)"),
            )),
        }
    }
}

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

/// Streaming log-sum-exp accumulation of hypothesis weights into marginals.
pub(crate) struct Accumulator {
    n: usize,
    m: usize,
    /// Largest log weight seen; the sums are relative to it.
    max: f64,
    miss: Vec<f64>,
    detect: Vec<f64>,
}

impl Accumulator {
    /// Empty accumulator.
    pub fn new(n: usize, m: usize) -> Self {
        Self {
            n,
            m,
            max: f64::NEG_INFINITY,
            miss: vec![0.0; n],
            detect: vec![0.0; n.saturating_mul(m)],
        }
    }

    /// Adds one hypothesis (entries 0 = missed, j ≥ 1 = measurement j − 1, all ≤ m).
    pub fn add(&mut self, theta: &[usize], log_weight: f64) {
        if log_weight.is_nan() || log_weight == f64::NEG_INFINITY {
            return;
        }
        if log_weight > self.max {
            // exp(−∞) = 0 covers both the first hypothesis and a jump to +∞.
            let scale = (self.max - log_weight).exp();
            self.miss.iter_mut().for_each(|v| *v *= scale);
            self.detect.iter_mut().for_each(|v| *v *= scale);
            self.max = log_weight;
        }
        let w = if log_weight == f64::INFINITY {
            1.0
        } else {
            (log_weight - self.max).exp()
        };
        for (i, &j) in theta.iter().enumerate() {
            if j == 0 {
                self.miss[i] += w;
            } else {
                self.detect[i * self.m + j - 1] += w;
            }
        }
    }

    /// Normalised marginals; [`Marginals::all_missed`] if nothing was added.
    pub fn finish(mut self) -> Marginals {
        if self.max == f64::NEG_INFINITY {
            return Marginals::all_missed(self.n, self.m);
        }
        for i in 0..self.n {
            let row = &mut self.detect[i * self.m..(i + 1) * self.m];
            let total = self.miss[i] + row.iter().sum::<f64>();
            self.miss[i] /= total;
            row.iter_mut().for_each(|v| *v /= total);
        }
        Marginals {
            n_tracks: self.n,
            n_meas: self.m,
            miss: self.miss,
            detect: self.detect,
        }
    }
}

#[cfg(test)]
pub(crate) mod testutil {
    //! Independent reference computations for the association tests: plain enumeration of
    //! all (m + 1)ⁿ maps, rejecting those that reuse a measurement.

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
}

#[cfg(test)]
mod tests {
    use super::testutil::*;
    use super::*;
    use crate::rng::seeded;
    use proptest::prelude::*;

    fn all_methods() -> Vec<AssociationMethod> {
        vec![
            AssociationMethod::Murty { k: 1000 },
            AssociationMethod::Gibbs { samples: 500 },
            AssociationMethod::default(),
            AssociationMethod::Exhaustive,
        ]
    }

    #[test]
    fn parse_names_and_defaults() {
        assert_eq!(
            "murty".parse::<AssociationMethod>().unwrap(),
            AssociationMethod::Murty { k: 200 }
        );
        assert_eq!(
            " Gibbs ".parse::<AssociationMethod>().unwrap(),
            AssociationMethod::Gibbs { samples: 1000 }
        );
        assert_eq!(
            "lbp".parse::<AssociationMethod>().unwrap(),
            AssociationMethod::Lbp {
                max_iterations: 100,
                tolerance: 1e-9
            }
        );
        assert_eq!(
            "exhaustive".parse::<AssociationMethod>().unwrap(),
            AssociationMethod::Exhaustive
        );
        assert_eq!(
            "murty:500".parse::<AssociationMethod>().unwrap(),
            AssociationMethod::Murty { k: 500 }
        );
        assert!("hungarian".parse::<AssociationMethod>().is_err());
        assert!("murty:x".parse::<AssociationMethod>().is_err());
        assert_eq!(AssociationMethod::default(), "lbp".parse().unwrap());
    }

    #[test]
    fn serde_round_trip_uses_method_tag() {
        let m = AssociationMethod::Murty { k: 7 };
        let s = serde_json::to_string(&m).unwrap();
        assert_eq!(s, r#"{"method":"murty","k":7}"#);
        let back: AssociationMethod = serde_json::from_str(&s).unwrap();
        assert_eq!(back, m);
        let e: AssociationMethod = serde_json::from_str(r#"{"method":"exhaustive"}"#).unwrap();
        assert_eq!(e, AssociationMethod::Exhaustive);
        let l: AssociationMethod =
            serde_json::from_str(r#"{"method":"lbp","max_iterations":5,"tolerance":0.001}"#)
                .unwrap();
        assert_eq!(
            l,
            AssociationMethod::Lbp {
                max_iterations: 5,
                tolerance: 1e-3
            }
        );
    }

    #[test]
    fn new_checks_shape_and_values() {
        assert!(AssociationProblem::new(2, 1, vec![0.0, 0.0], vec![0.0, 0.0]).is_ok());
        assert!(AssociationProblem::new(2, 1, vec![0.0], vec![0.0, 0.0]).is_err());
        assert!(AssociationProblem::new(2, 1, vec![0.0, 0.0], vec![0.0]).is_err());
        assert!(AssociationProblem::new(1, 1, vec![f64::NAN], vec![0.0]).is_err());
        assert!(AssociationProblem::new(1, 1, vec![0.0], vec![f64::INFINITY]).is_err());
        assert!(AssociationProblem::new(1, 1, vec![f64::NEG_INFINITY], vec![0.0]).is_ok());
    }

    #[test]
    fn log_weight_rejects_reused_measurement() {
        let p =
            AssociationProblem::new(2, 2, vec![-1.0, -2.0], vec![-3.0, -4.0, -5.0, -6.0]).unwrap();
        assert_eq!(p.log_weight(&[0, 0]), -3.0);
        assert_eq!(p.log_weight(&[1, 2]), -3.0 - 6.0);
        assert_eq!(p.log_weight(&[2, 1]), -4.0 - 5.0);
        assert_eq!(p.log_weight(&[1, 1]), f64::NEG_INFINITY);
        assert_eq!(p.log_weight(&[3, 0]), f64::NEG_INFINITY);
        assert_eq!(p.log_weight(&[0]), f64::NEG_INFINITY);
    }

    #[test]
    fn from_hypotheses_normalises_in_log_domain() {
        // Two hypotheses with weights e^-1000 and 3·e^-1000.
        let hyps = [
            Hypothesis {
                assignment: vec![0, 1],
                log_weight: -1000.0,
            },
            Hypothesis {
                assignment: vec![1, 0],
                log_weight: -1000.0 + 3f64.ln(),
            },
            Hypothesis {
                assignment: vec![2, 2],
                log_weight: f64::NAN,
            },
        ];
        let mg = Marginals::from_hypotheses(2, 1, &hyps);
        assert!((mg.miss[0] - 0.25).abs() < 1e-12);
        assert!((mg.detect[0] - 0.75).abs() < 1e-12);
        assert!((mg.miss[1] - 0.75).abs() < 1e-12);
        assert!((mg.detect[1] - 0.25).abs() < 1e-12);
        assert_eq!(
            Marginals::from_hypotheses(2, 1, &[]),
            Marginals::all_missed(2, 1)
        );
    }

    #[test]
    fn trivial_groups_are_exact_for_every_method() {
        let mut rng = seeded(1);
        // One track: φ normalised. Weights 1, 2, 0 (forbidden), 5 scaled by e^-700.
        let p = AssociationProblem::new(
            1,
            3,
            vec![-700.0],
            vec![-700.0 + 2f64.ln(), f64::NEG_INFINITY, -700.0 + 5f64.ln()],
        )
        .unwrap();
        for method in all_methods() {
            let mg = method.marginals(&p, &mut rng);
            // −700 + ln 2 is only represented to about 1e−13.
            assert!((mg.miss[0] - 0.125).abs() < 1e-12, "{method:?}");
            assert!((mg.detect[0] - 0.25).abs() < 1e-12);
            assert_eq!(mg.detect[1], 0.0);
            assert!((mg.detect[2] - 0.625).abs() < 1e-12);
        }
        // No measurements: everything missed.
        let p = AssociationProblem::new(3, 0, vec![-1.0, -2.0, -3.0], vec![]).unwrap();
        for method in all_methods() {
            assert_eq!(method.marginals(&p, &mut rng), Marginals::all_missed(3, 0));
        }
        // No tracks.
        let p = AssociationProblem::new(0, 2, vec![], vec![]).unwrap();
        for method in all_methods() {
            assert_eq!(method.marginals(&p, &mut rng), Marginals::all_missed(0, 2));
        }
    }

    #[test]
    fn infeasible_and_malformed_give_all_missed() {
        let mut rng = seeded(2);
        let ninf = f64::NEG_INFINITY;
        // Both tracks must be detected but only measurement 0 is allowed for either.
        let p =
            AssociationProblem::new(2, 2, vec![ninf, ninf], vec![0.0, ninf, -1.0, ninf]).unwrap();
        // A row with nothing admissible.
        let q = AssociationProblem::new(2, 1, vec![0.0, ninf], vec![0.0, ninf]).unwrap();
        let malformed = AssociationProblem {
            n_tracks: 2,
            n_meas: 2,
            log_miss: vec![0.0],
            log_detect: vec![0.0; 3],
        };
        for method in all_methods() {
            assert_eq!(method.marginals(&p, &mut rng), Marginals::all_missed(2, 2));
            assert_eq!(method.marginals(&q, &mut rng), Marginals::all_missed(2, 1));
            assert_eq!(
                method.marginals(&malformed, &mut rng),
                Marginals::all_missed(2, 2)
            );
        }
    }

    #[test]
    fn underflowing_weights_give_normalised_marginals() {
        use rand::RngExt;
        let mut gen = seeded(4);
        for round in 0..20 {
            let (n, m) = (3, 3);
            let base: Vec<f64> = (0..n * (m + 1))
                .map(|_| -20.0 * gen.random::<f64>())
                .collect();
            // The same problem at three scales; e^−1000 and e^−100000 underflow in f64.
            for shift in [0.0, -1000.0, -1e5] {
                let p = AssociationProblem::new(
                    n,
                    m,
                    base[..n].iter().map(|v| v + shift).collect(),
                    base[n..].iter().map(|v| v + shift).collect(),
                )
                .unwrap();
                let exact = brute_marginals(&p).unwrap();
                for method in all_methods() {
                    let mut rng = seeded(round);
                    let mg = method.marginals(&p, &mut rng);
                    assert_valid(&p, &mg);
                    let err = max_diff(&mg, &exact);
                    match method {
                        AssociationMethod::Murty { .. } | AssociationMethod::Exhaustive => {
                            // The reference itself sums log weights of size ~3·10⁵ at the
                            // largest shift, which costs about 10⁻¹⁰.
                            let tol = if shift < -1e4 { 1e-9 } else { 1e-12 };
                            assert!(err < tol, "{method:?} {shift}: {err}");
                        }
                        AssociationMethod::Gibbs { samples } => {
                            // Off by at most the mass of the hypotheses never visited.
                            let visited = distinct_hypotheses(&p, samples, &mut seeded(round));
                            let all = brute_hypotheses(&p);
                            let max = all.iter().map(|h| h.1).fold(f64::NEG_INFINITY, f64::max);
                            let z: f64 = all.iter().map(|h| (h.1 - max).exp()).sum();
                            let seen: f64 =
                                visited.iter().map(|h| (h.log_weight - max).exp()).sum();
                            assert!(err <= 1.0 - seen / z + 1e-9, "{err}");
                        }
                        AssociationMethod::Lbp { .. } => {
                            // Scale-free: the same answer as the unshifted problem.
                            let q = AssociationProblem::new(
                                n,
                                m,
                                base[..n].to_vec(),
                                base[n..].to_vec(),
                            )
                            .unwrap();
                            let unshifted = method.marginals(&q, &mut rng);
                            assert!(max_diff(&mg, &unshifted) < 1e-9);
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn forced_detection_and_forbidden_pairs() {
        // Track 0 must take measurement 0 (its only admissible option), so track 1 — which
        // could take measurement 0 — must miss or take measurement 1.
        let ninf = f64::NEG_INFINITY;
        let p =
            AssociationProblem::new(2, 2, vec![ninf, -1.0], vec![-2.0, ninf, 0.0, -0.5]).unwrap();
        // Hypotheses: (1, 0) with weight e^(-2-1) and (1, 2) with weight e^(-2-0.5).
        let a = (-3.0f64).exp();
        let b = (-2.5f64).exp();
        let mut rng = seeded(5);
        for method in all_methods() {
            let mg = method.marginals(&p, &mut rng);
            assert_valid(&p, &mg);
            assert_eq!(mg.miss[0], 0.0);
            assert_eq!(mg.detect[1], 0.0);
            if !matches!(method, AssociationMethod::Lbp { .. }) {
                assert_eq!(mg.detect[2], 0.0, "{method:?}");
                assert!((mg.miss[1] - a / (a + b)).abs() < 1e-12);
                assert!((mg.detect[3] - b / (a + b)).abs() < 1e-12);
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        #[test]
        fn every_method_gives_valid_marginals(p in problems(5, 5, -30.0, 10.0, 4, true)) {
            let mut rng = seeded(6);
            for method in all_methods() {
                let mg = method.marginals(&p, &mut rng);
                assert_valid(&p, &mg);
                if brute_hypotheses(&p).is_empty() {
                    prop_assert_eq!(mg, Marginals::all_missed(p.n_tracks, p.n_meas));
                }
            }
        }
    }
}

impl<T: Associator + ?Sized> Associator for Box<T> {
    fn marginals(&self, problem: &AssociationProblem, rng: &mut FilterRng) -> Marginals {
        (**self).marginals(problem, rng)
    }
}
