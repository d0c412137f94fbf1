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
//!
//! The module's files:
//!
//! * `problem.rs` — the shared vocabulary: [`AssociationProblem`], [`Hypothesis`],
//!   [`Marginals`] (with the log-sum-exp accumulator of hypotheses) and the [`Associator`]
//!   trait;
//! * `method.rs` — [`AssociationMethod`], the configurable choice of method (serde and
//!   `murty:500`-style parsing, defaults);
//! * `tables.rs` — crate-internal machinery every method shares: the common preparation of a
//!   problem and the row-shifted log-weight table;
//! * `murty.rs`, `gibbs.rs`, `lbp.rs`, `exhaustive.rs` — one algorithm each;
//! * `testutil.rs` and `tests.rs` (tests only) — an independent brute-force reference, and the
//!   checks that hold every method to the conventions above.

pub mod exhaustive;
pub mod gibbs;
pub mod lbp;
mod method;
pub mod murty;
mod problem;
mod tables;
#[cfg(test)]
mod tests;
#[cfg(test)]
pub(crate) mod testutil;

pub use exhaustive::ExhaustiveAssociator;
pub use gibbs::{distinct_hypotheses, GibbsAssociator};
pub use lbp::LbpAssociator;
pub use method::{AssociationMethod, MAX_GIBBS_SAMPLES, MAX_LBP_ITERATIONS, MAX_MURTY_K};
pub use murty::{ranked_hypotheses, MurtyAssociator};
pub use problem::{AssociationProblem, Associator, Hypothesis, Marginals};
