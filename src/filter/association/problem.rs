//! The association problem and its answer: [`AssociationProblem`] (log weights of one group
//! of tracks and measurements), [`Hypothesis`] (one admissible map from tracks to
//! measurements), [`Marginals`] (what the LMB update consumes) and the [`Associator`] trait
//! that turns the first into the last.
//!
//! These are the types every association method and the filter share; checking a problem's
//! shape and values and weighing a single hypothesis live here too.
//! Not for: solving a problem (see the associator modules) or choosing a method from a
//! configuration (see [`AssociationMethod`](super::AssociationMethod)).

use crate::rng::FilterRng;

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

impl<T: Associator + ?Sized> Associator for Box<T> {
    fn marginals(&self, problem: &AssociationProblem, rng: &mut FilterRng) -> Marginals {
        (**self).marginals(problem, rng)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
