//! Rays in the plane: where a ray first meets a circle (a ray-cast laser beam hitting a
//! person, a pole).
//!
//! Not for: ray casting against whole scenes (see the simulators in [`crate::sim`]).

/// Distance along the ray `origin + t·dir` (`dir` of unit length) to the first crossing of
/// the circle, for `t > 0`; a ray starting inside the circle hits its far side.
pub fn ray_circle(origin: [f64; 2], dir: [f64; 2], center: [f64; 2], radius: f64) -> Option<f64> {
    let f = [origin[0] - center[0], origin[1] - center[1]];
    let b = f[0] * dir[0] + f[1] * dir[1];
    let c = f[0] * f[0] + f[1] * f[1] - radius * radius;
    let disc = b * b - c;
    if disc < 0.0 {
        return None;
    }
    let s = disc.sqrt();
    let (t1, t2) = (-b - s, -b + s);
    if t1 > 0.0 {
        Some(t1)
    } else if t2 > 0.0 {
        Some(t2)
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ray_meets_the_near_side_from_outside_and_the_far_side_from_inside() {
        // Circle of radius 1 at (5, 0): from the origin along x the first crossing is at 4.
        assert!((ray_circle([0.0, 0.0], [1.0, 0.0], [5.0, 0.0], 1.0).unwrap() - 4.0).abs() < 1e-12);
        // From the centre the far side is 1 away.
        assert!((ray_circle([5.0, 0.0], [0.0, 1.0], [5.0, 0.0], 1.0).unwrap() - 1.0).abs() < 1e-12);
        // Pointing away, or passing beside, it misses.
        assert!(ray_circle([0.0, 0.0], [-1.0, 0.0], [5.0, 0.0], 1.0).is_none());
        assert!(ray_circle([0.0, 0.0], [0.0, 1.0], [5.0, 0.0], 1.0).is_none());
    }
}
