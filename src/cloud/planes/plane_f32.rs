//! A plane with f32 coefficients, for the residuals of many points in the RANSAC rounds and
//! the band grid's passes (the points are f32).
//!
//! Not for: plane geometry in general (see [`crate::geometry::Plane`]).

use crate::geometry::Plane;

/// Plane with f32 coefficients for fast residuals.
#[derive(Copy, Clone)]
pub(super) struct PlaneF32 {
    pub(super) n: [f32; 3],
    pub(super) d: f32,
}

impl PlaneF32 {
    pub(super) fn new(p: &Plane) -> Self {
        PlaneF32 {
            n: [p.normal.x as f32, p.normal.y as f32, p.normal.z as f32],
            d: p.offset as f32,
        }
    }
    #[inline]
    pub(super) fn residual_signed(&self, p: &[f32; 3]) -> f32 {
        self.n[0] * p[0] + self.n[1] * p[1] + self.n[2] * p[2] + self.d
    }
    #[inline]
    pub(super) fn residual(&self, p: &[f32; 3]) -> f32 {
        (self.n[0] * p[0] + self.n[1] * p[1] + self.n[2] * p[2] + self.d).abs()
    }
    /// The normal's coefficients, widened.
    pub(super) fn normal_f64(&self) -> [f64; 3] {
        self.n.map(f64::from)
    }
    /// The offset, widened.
    pub(super) fn offset_f64(&self) -> f64 {
        self.d as f64
    }
}
