//! Planar poses ([`Pose2`]) and rigid motions on them: composing, inverting, relating two
//! poses, moving points, and the SE(3) form a filter's step context holds. A pose `a` is read as the map `p ↦ R(a.θ)·p + (a.x, a.y)` from its own frame into
//! the frame it is expressed in.
//!
//! Not for: estimating motions (see the ICP module of [`crate::laser2d`]) or uncertainty
//! propagation.

use super::wrap_angle;
use nalgebra::{Isometry3, Vector3};

/// A planar pose: position `(x, y)` in metres and heading `theta` in radians.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose2 {
    /// x coordinate (m).
    pub x: f64,
    /// y coordinate (m).
    pub y: f64,
    /// Heading (rad), counter-clockwise from the x axis.
    pub theta: f64,
}

impl Pose2 {
    /// A pose from its three components.
    pub fn new(x: f64, y: f64, theta: f64) -> Self {
        Pose2 { x, y, theta }
    }

    /// True when all three components are finite.
    pub fn is_finite(&self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.theta.is_finite()
    }
}

/// `a ∘ b`: first `b`, then `a` (the pose `b`, given in `a`'s frame, expressed in the frame
/// of `a`). Heading wrapped to (−π, π].
pub fn compose(a: Pose2, b: Pose2) -> Pose2 {
    let (s, c) = a.theta.sin_cos();
    Pose2::new(
        a.x + c * b.x - s * b.y,
        a.y + s * b.x + c * b.y,
        wrap_angle(a.theta + b.theta),
    )
}

/// The inverse motion: `compose(a, inverse(a))` is the identity.
pub fn inverse(a: Pose2) -> Pose2 {
    let (s, c) = a.theta.sin_cos();
    Pose2::new(
        -(c * a.x + s * a.y),
        s * a.x - c * a.y,
        wrap_angle(-a.theta),
    )
}

/// The pose of `b` seen from `a`: `inverse(a) ∘ b`.
pub fn between(a: Pose2, b: Pose2) -> Pose2 {
    compose(inverse(a), b)
}

/// Moves the point `p` by the pose: `R(θ)·p + (x, y)`.
pub fn transform_point(pose: Pose2, p: [f64; 2]) -> [f64; 2] {
    let (s, c) = pose.theta.sin_cos();
    [pose.x + c * p[0] - s * p[1], pose.y + s * p[0] + c * p[1]]
}

/// The identity pose.
pub fn identity() -> Pose2 {
    Pose2::new(0.0, 0.0, 0.0)
}

/// The platform pose of a planar odometry pose, as the filter's
/// [`StepContext`](crate::filter::StepContext) holds it.
pub fn platform_isometry(pose: Pose2) -> Isometry3<f64> {
    Isometry3::new(
        Vector3::new(pose.x, pose.y, 0.0),
        Vector3::new(0.0, 0.0, pose.theta),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Pose2, b: Pose2) -> bool {
        (a.x - b.x).abs() < 1e-12
            && (a.y - b.y).abs() < 1e-12
            && wrap_angle(a.theta - b.theta).abs() < 1e-12
    }

    #[test]
    fn compose_by_hand() {
        // A quarter turn left at (1, 0), then one metre forward: ends at (1, 1) facing +y.
        let a = Pose2::new(1.0, 0.0, std::f64::consts::FRAC_PI_2);
        let b = Pose2::new(1.0, 0.0, 0.0);
        assert!(close(
            compose(a, b),
            Pose2::new(1.0, 1.0, std::f64::consts::FRAC_PI_2)
        ));
    }

    #[test]
    fn inverse_and_between() {
        let a = Pose2::new(0.3, -1.2, 2.5);
        let b = Pose2::new(-4.0, 0.7, -2.9);
        assert!(close(compose(a, inverse(a)), identity()));
        assert!(close(compose(inverse(a), a), identity()));
        assert!(close(compose(a, between(a, b)), b));
        let p = [0.4, -0.2];
        let q = transform_point(inverse(a), transform_point(a, p));
        assert!((q[0] - p[0]).abs() < 1e-12 && (q[1] - p[1]).abs() < 1e-12);
    }
}
