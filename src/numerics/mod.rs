//! Numerical kernels the per-particle and per-point loops share: a slice exponential and a
//! slice logarithm on vector lanes ([`exp`], [`ln`]), a full-precision `atan2` for whole
//! slices ([`atan`]) and an integer floor without a libm call ([`floor`]), and the eigenvalues
//! of a symmetric 2 × 2 matrix ([`sym2`]). The first four are exact replacements of the standard library's
//! functions (within their documented error), written so that the compiler inlines or
//! vectorises them.
//!
//! Not for: models or statistics; anything here is a plain function of numbers.

pub(crate) mod atan;
pub(crate) mod exp;
pub(crate) mod floor;
#[cfg(feature = "kitti")]
pub(crate) mod ln;
#[cfg(feature = "laser2d")]
pub(crate) mod sym2;

/// How many units in the last place of `b` the value `a` is from it (tests of the kernels).
#[cfg(test)]
fn ulps(a: f64, b: f64) -> f64 {
    if a == b {
        return 0.0;
    }
    (a - b).abs() / (b.abs() * f64::EPSILON)
}
