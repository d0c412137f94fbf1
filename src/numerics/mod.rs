//! Numerical kernels the per-particle loops share: a slice exponential on vector lanes
//! ([`exp`]) and a full-precision `atan2` for whole slices ([`atan`]). Both are exact
//! replacements of the standard library's functions (within their documented error), written
//! so that the compiler vectorises them.
//!
//! Not for: models or statistics; anything here is a plain function of numbers.

pub(crate) mod atan;
pub(crate) mod exp;
