//! Data association: from the table of track/measurement likelihoods to the marginal
//! probability that each track is missed (or absent) or generated each measurement.
//!
//! The LMB update only needs these marginals (the GLMB → LMB approximation); how they are
//! found is the [`Associator`]'s business. Three methods are built in — Murty's k-best ranked
//! assignments, Gibbs sampling and loopy belief propagation — plus exhaustive enumeration for
//! small problems and tests. Not for: gating or likelihood evaluation.

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

/// Turns an [`AssociationProblem`] into [`Marginals`].
pub trait Associator: Send + Sync {
    /// Marginal association probabilities. Randomised methods draw from `rng` only.
    fn marginals(&self, problem: &AssociationProblem, rng: &mut FilterRng) -> Marginals;
}
