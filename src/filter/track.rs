//! A Bernoulli track: label, existence probability and particle density. Not for: how tracks
//! are born, updated or pruned (see `lmb`, `birth`).

use super::{Label, ParticleSet};

/// One labelled Bernoulli component of the LMB density.
#[derive(Clone, Debug, PartialEq)]
pub struct Track {
    /// Unique label.
    pub label: Label,
    /// Existence probability r ∈ [0, 1].
    pub existence: f64,
    /// Particle representation of the state density.
    pub particles: ParticleSet,
    /// Number of steps since birth (0 at the birth step).
    pub age: u32,
    /// Sum over the track's life of the probability that it was detected (an expected count
    /// of associated measurements).
    pub expected_detections: f64,
}

impl Track {
    /// A new track at age 0.
    pub fn new(label: Label, existence: f64, particles: ParticleSet) -> Self {
        Track {
            label,
            existence,
            particles,
            age: 0,
            expected_detections: 0.0,
        }
    }
}

/// A state estimate of one track.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Estimate {
    /// Track label.
    pub label: Label,
    /// Existence probability.
    pub existence: f64,
    /// Weighted mean of the particle set.
    pub state: Vec<f64>,
    /// Steps since birth.
    pub age: u32,
}
