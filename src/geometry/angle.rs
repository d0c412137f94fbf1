//! Angles: the one wrap of an angle to (−π, π] that every module uses.
//!
//! Not for: angle statistics (circular means) or rotations (see [`super::pose2`]).

use std::f64::consts::{PI, TAU};

/// Wraps an angle to (−π, π].
pub fn wrap_angle(a: f64) -> f64 {
    if a > -PI && a <= PI {
        a
    } else {
        a - TAU * ((a - PI) / TAU).ceil()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_angle_maps_into_the_half_open_interval() {
        assert_eq!(wrap_angle(0.25), 0.25);
        assert_eq!(wrap_angle(PI), PI);
        assert!((wrap_angle(-PI) - PI).abs() < 1e-15);
        assert!((wrap_angle(3.0 * PI / 2.0) + PI / 2.0).abs() < 1e-12);
        assert!((wrap_angle(-7.0 * PI / 2.0) - PI / 2.0).abs() < 1e-12);
        for k in -5..=5 {
            let a = 0.3 + k as f64 * TAU;
            assert!((wrap_angle(a) - 0.3).abs() < 1e-12, "{a}");
        }
    }
}
