//! Bounds of a particle cloud's planar position (components 0 and 2), for per-track shortcuts
//! that must give exactly the per-particle answer: when a model's answer cannot change
//! anywhere inside the bounds, it is set for the whole track at once, and work per particle is
//! skipped (see [`crate::pipeline::people_tracking::models::OcclusionDetection`], [`crate::pipeline::people_tracking::models::ResolutionDetection`],
//! [`crate::pipeline::people_tracking::models::FieldOfViewSurvival`]).
//!
//! The bounds are conservative: every particle lies inside them, and the derived ranges and
//! bearings are widened by a few units in the last place, so a shortcut that trusts them never
//! disagrees with the per-particle rule it replaces.
//!
//! Not for: weighted statistics (mean, spread) of a cloud, or gating.

use crate::filter::ParticleSet;

/// Relative widening of derived distances, far above their rounding error.
const REL: f64 = 1e-12;

/// Axis-aligned box around the planar positions of a particle cloud.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct CloudBox {
    /// Smallest x of any particle.
    pub min_x: f64,
    /// Largest x of any particle.
    pub max_x: f64,
    /// Smallest y of any particle.
    pub min_y: f64,
    /// Largest y of any particle.
    pub max_y: f64,
}

/// Distances and bearings of a box as a sensor sees it.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct PolarBounds {
    /// No point of the box is nearer (slightly shrunk).
    pub d_min: f64,
    /// No point of the box is farther (slightly widened).
    pub d_max: f64,
    /// Smallest bearing (rad, counter-clockwise from the sensor's x axis) of any point.
    pub bearing_min: f64,
    /// Largest bearing of any point.
    pub bearing_max: f64,
}

impl CloudBox {
    /// The box around components 0 (x) and 2 (y) of every particle; `None` for sets without
    /// particles, of dimension below 3, or with a non-finite position (or positions beyond
    /// 1e300 m, whose sum overflows).
    pub fn of(particles: &ParticleSet) -> Option<Self> {
        if particles.dim() < 3 || particles.is_empty() {
            return None;
        }
        let (min_x, max_x, fx) = extent(particles.component(0));
        let (min_y, max_y, fy) = extent(particles.component(2));
        (fx && fy).then_some(CloudBox {
            min_x,
            max_x,
            min_y,
            max_y,
        })
    }

    /// Squared distance from (`px`, `py`) to the nearest point of the box (0 inside), shrunk
    /// by a relative 1e-12 so that no particle's own squared distance falls below it.
    pub fn min_distance_squared(&self, px: f64, py: f64) -> f64 {
        let dx = (self.min_x - px).max(px - self.max_x).max(0.0);
        let dy = (self.min_y - py).max(py - self.max_y).max(0.0);
        (dx * dx + dy * dy) * (1.0 - 4.0 * REL)
    }

    /// The box's corners.
    fn corners(&self) -> [(f64, f64); 4] {
        [
            (self.min_x, self.min_y),
            (self.max_x, self.min_y),
            (self.min_x, self.max_y),
            (self.max_x, self.max_y),
        ]
    }

    /// Ranges and bearings of the box from a sensor at (`sx`, `sy`) whose x axis points along
    /// (`c`, `s`) (cos and sin of its heading). `None` unless the whole box lies strictly in
    /// front of the sensor (positive local x), where bearings stay inside (−π/2, π/2) and the
    /// extreme bearings are those of corners.
    pub fn polar_from(&self, sx: f64, sy: f64, c: f64, s: f64) -> Option<PolarBounds> {
        let mut out = PolarBounds {
            d_min: 0.0,
            d_max: 0.0,
            bearing_min: f64::INFINITY,
            bearing_max: f64::NEG_INFINITY,
        };
        for (x, y) in self.corners() {
            let (dx, dy) = (x - sx, y - sy);
            let (lx, ly) = (c * dx + s * dy, -s * dx + c * dy);
            if lx.is_nan() || lx <= 0.0 {
                return None;
            }
            let b = ly.atan2(lx);
            out.bearing_min = out.bearing_min.min(b);
            out.bearing_max = out.bearing_max.max(b);
            out.d_max = out.d_max.max((dx * dx + dy * dy).sqrt());
        }
        // A point's bearing is a monotone function of l_y / l_x, which over the box (all of it
        // in front) is extreme at corners; distances are invariant under the rotation.
        out.d_min = self.min_distance_squared(sx, sy).sqrt() * (1.0 - 4.0 * REL);
        out.d_max *= 1.0 + 4.0 * REL;
        Some(out)
    }
}

/// (min, max, all finite) of `v`, in four independent lanes the compiler can vectorise.
fn extent(v: &[f64]) -> (f64, f64, bool) {
    let (mut lo, mut hi, mut probe) = ([f64::INFINITY; 4], [f64::NEG_INFINITY; 4], [0.0; 4]);
    let chunks = v.chunks_exact(4);
    let rest = chunks.remainder();
    for c in chunks {
        for k in 0..4 {
            let x = c[k];
            lo[k] = if x < lo[k] { x } else { lo[k] };
            hi[k] = if x > hi[k] { x } else { hi[k] };
            // the sum turns non-finite with any NaN or infinite x (positions never come near
            // overflowing it)
            probe[k] += x;
        }
    }
    for &x in rest {
        lo[0] = if x < lo[0] { x } else { lo[0] };
        hi[0] = if x > hi[0] { x } else { hi[0] };
        probe[0] += x;
    }
    let min = lo.iter().copied().fold(f64::INFINITY, f64::min);
    let max = hi.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    (min, max, probe.iter().sum::<f64>().is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn set(points: &[(f64, f64)]) -> ParticleSet {
        let rows: Vec<Vec<f64>> = points.iter().map(|p| vec![p.0, 0.0, p.1, 0.0]).collect();
        ParticleSet::from_rows(&rows, &vec![1.0; points.len()]).unwrap()
    }

    #[test]
    fn box_of_a_cloud_and_non_finite_positions() {
        let b = CloudBox::of(&set(&[(1.0, -2.0), (3.0, 5.0), (-1.0, 0.5)])).unwrap();
        assert_eq!((b.min_x, b.max_x, b.min_y, b.max_y), (-1.0, 3.0, -2.0, 5.0));
        assert!(CloudBox::of(&set(&[(1.0, f64::NAN)])).is_none());
        assert!(CloudBox::of(&set(&[(f64::INFINITY, 0.0)])).is_none());
        // the nearest point of [−1, 3] × [−2, 5] to (6, 9) is the corner (3, 5): 3² + 4²
        assert!((b.min_distance_squared(6.0, 9.0) - 25.0).abs() < 1e-9);
        assert_eq!(b.min_distance_squared(0.0, 0.0), 0.0);
    }

    #[test]
    fn boxes_behind_or_around_the_sensor_have_no_polar_bounds() {
        let b = CloudBox::of(&set(&[(-1.0, -1.0), (1.0, 1.0)])).unwrap();
        assert!(b.polar_from(0.0, 0.0, 1.0, 0.0).is_none());
        let ahead = CloudBox::of(&set(&[(4.0, -1.0), (5.0, 1.0)])).unwrap();
        let p = ahead.polar_from(0.0, 0.0, 1.0, 0.0).unwrap();
        assert!((p.d_min - 4.0).abs() < 1e-9 && (p.d_max - 26f64.sqrt()).abs() < 1e-9);
        assert!((p.bearing_max - 0.25f64.atan()).abs() < 1e-12);
        assert!((p.bearing_min + 0.25f64.atan()).abs() < 1e-12);
        // facing +y, the same box lies to the right (negative bearings), wholly in front? no:
        // local x = y, which is negative for part of it
        assert!(ahead.polar_from(0.0, 0.0, 0.0, 1.0).is_none());
    }

    proptest! {
        #[test]
        fn every_particle_lies_inside_the_polar_bounds(
            pts in proptest::collection::vec((-20.0f64..20.0, -20.0f64..20.0), 1..40),
            sx in -5.0f64..5.0, sy in -5.0f64..5.0, heading in -3.2f64..3.2,
        ) {
            let b = CloudBox::of(&set(&pts)).unwrap();
            let (s, c) = heading.sin_cos();
            for &(x, y) in &pts {
                let d2 = (x - sx).powi(2) + (y - sy).powi(2);
                prop_assert!(b.min_distance_squared(sx, sy) <= d2);
            }
            if let Some(p) = b.polar_from(sx, sy, c, s) {
                for &(x, y) in &pts {
                    let (dx, dy) = (x - sx, y - sy);
                    let (lx, ly) = (c * dx + s * dy, -s * dx + c * dy);
                    let d = (lx * lx + ly * ly).sqrt();
                    let bearing = ly.atan2(lx);
                    prop_assert!(p.d_min <= d && d <= p.d_max, "{p:?} {d}");
                    prop_assert!(
                        p.bearing_min - 1e-12 <= bearing && bearing <= p.bearing_max + 1e-12,
                        "{p:?} {bearing}"
                    );
                }
            }
        }
    }
}
