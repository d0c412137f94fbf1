//! Track labels: the pair (birth step, index among that step's births). Labels are unique
//! for the life of a filter run and never reused; they are what makes the multi-Bernoulli
//! *labelled*. Not for: identities across runs.

use serde::{Deserialize, Serialize};

/// The label of a track: born at step `birth_step` as the `index`-th birth of that step.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct Label {
    /// Filter step at which the track was born.
    pub birth_step: u32,
    /// Index among the births of that step.
    pub index: u32,
}

impl Label {
    /// A new label.
    pub const fn new(birth_step: u32, index: u32) -> Self {
        Label { birth_step, index }
    }

    /// A 64-bit key used to derive per-track random streams.
    pub const fn key(self) -> u64 {
        ((self.birth_step as u64) << 32) | self.index as u64
    }
}

impl std::fmt::Display for Label {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "({},{})", self.birth_step, self.index)
    }
}
