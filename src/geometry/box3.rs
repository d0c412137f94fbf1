//! Oriented 3-D boxes standing upright on the ground plane (rotated about z only), as lidar
//! object detectors and the KITTI tracking benchmark describe road users, and their overlap:
//! bird's-eye-view IoU (the rotated rectangles' intersection area by convex polygon clipping)
//! and 3-D IoU (that area × the vertical overlap).
//!
//! Conventions: the sensor frame is x forward, y left, z up; [`Box3::center`] is the centre of
//! the box (not of its bottom face); [`Box3::size`] is `[length, width, height]` with the length
//! along the heading; [`Box3::yaw`] is the heading about z, counter-clockwise from x.
//!
//! Not for: fitting boxes to points (see [`crate::cloud::boxes`]), KITTI's camera-frame label
//! layout (see [`crate::kitti::labels`]), or boxes tilted out of the ground plane.

use nalgebra::Point3;

/// An oriented box upright about z.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Box3 {
    /// Centre of the box (not of its bottom face), metres.
    pub center: Point3<f64>,
    /// Length (along the heading), width, height, metres.
    pub size: [f64; 3],
    /// Heading of the length axis about z, radians counter-clockwise from x.
    pub yaw: f64,
}

impl Box3 {
    /// The box with the given centre, `[length, width, height]` and heading.
    pub fn new(center: Point3<f64>, size: [f64; 3], yaw: f64) -> Self {
        Self { center, size, yaw }
    }

    /// Unit vectors of the length axis (heading) and of the width axis (90° to its left), in
    /// the x–y plane.
    pub fn axes(&self) -> ([f64; 2], [f64; 2]) {
        let (s, c) = self.yaw.sin_cos();
        ([c, s], [-s, c])
    }

    /// The four corners of the bird's-eye footprint in counter-clockwise order: front-right,
    /// front-left, rear-left, rear-right (front = along the heading).
    pub fn bev_corners(&self) -> [[f64; 2]; 4] {
        let (u, v) = self.axes();
        let (hl, hw) = (self.size[0] / 2.0, self.size[1] / 2.0);
        let at = |a: f64, b: f64| {
            [
                self.center.x + a * u[0] + b * v[0],
                self.center.y + a * u[1] + b * v[1],
            ]
        };
        [at(hl, -hw), at(hl, hw), at(-hl, hw), at(-hl, -hw)]
    }

    /// The eight corners: the bottom face in [`bev_corners`](Self::bev_corners) order, then the
    /// top face in the same order.
    pub fn corners(&self) -> [Point3<f64>; 8] {
        let bev = self.bev_corners();
        let (z0, z1) = self.z_range();
        std::array::from_fn(|i| {
            let [x, y] = bev[i % 4];
            Point3::new(x, y, if i < 4 { z0 } else { z1 })
        })
    }

    /// Heights of the bottom and top faces.
    pub fn z_range(&self) -> (f64, f64) {
        let h = self.size[2] / 2.0;
        (self.center.z - h, self.center.z + h)
    }

    /// Coordinates of `p` in the box frame: (along the heading, across to the left, up), from
    /// the centre.
    pub fn local(&self, p: &Point3<f64>) -> [f64; 3] {
        let (s, c) = self.yaw.sin_cos();
        let d = p - self.center;
        [c * d.x + s * d.y, -s * d.x + c * d.y, d.z]
    }

    /// Whether `p` lies inside the box grown by `margin` metres on every side (a negative
    /// margin shrinks it). Points on the faces count as inside.
    pub fn contains(&self, p: &Point3<f64>, margin: f64) -> bool {
        let [a, b, z] = self.local(p);
        a.abs() <= self.size[0] / 2.0 + margin
            && b.abs() <= self.size[1] / 2.0 + margin
            && z.abs() <= self.size[2] / 2.0 + margin
    }

    /// Footprint area, length × width (m²).
    pub fn bev_area(&self) -> f64 {
        self.size[0] * self.size[1]
    }

    /// Volume, length × width × height (m³).
    pub fn volume(&self) -> f64 {
        self.size[0] * self.size[1] * self.size[2]
    }
}

/// Most vertices a convex polygon clipped from a rectangle by four half-planes can have.
const MAX_VERTICES: usize = 8;

/// A convex polygon of at most [`MAX_VERTICES`] vertices, on the stack.
#[derive(Copy, Clone)]
struct Poly {
    v: [[f64; 2]; MAX_VERTICES],
    n: usize,
}

impl Poly {
    fn area(&self) -> f64 {
        let mut twice = 0.0;
        for i in 0..self.n {
            let [x0, y0] = self.v[i];
            let [x1, y1] = self.v[(i + 1) % self.n];
            twice += x0 * y1 - x1 * y0;
        }
        (twice / 2.0).abs()
    }

    /// Sutherland–Hodgman: the part of `self` on the left of (or on) the directed line p → q.
    fn clip(&self, p: [f64; 2], q: [f64; 2]) -> Poly {
        let side = |a: [f64; 2]| (q[0] - p[0]) * (a[1] - p[1]) - (q[1] - p[1]) * (a[0] - p[0]);
        let mut out = Poly {
            v: [[0.0; 2]; MAX_VERTICES],
            n: 0,
        };
        let mut push = |a: [f64; 2]| {
            // A convex polygon cut by one line gains at most one vertex; the bound only guards
            // against rounding producing a degenerate extra vertex.
            if out.n < MAX_VERTICES {
                out.v[out.n] = a;
                out.n += 1;
            }
        };
        for i in 0..self.n {
            let a = self.v[i];
            let b = self.v[(i + 1) % self.n];
            let (sa, sb) = (side(a), side(b));
            if sa >= 0.0 {
                push(a);
            }
            if (sa >= 0.0) != (sb >= 0.0) {
                let t = sa / (sa - sb);
                push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
            }
        }
        out
    }
}

/// The footprint corners of `b` with `origin` subtracted (keeps the clipping arithmetic near
/// zero for boxes far from the sensor origin).
fn shifted_corners(b: &Box3, origin: [f64; 2]) -> [[f64; 2]; 4] {
    b.bev_corners().map(|[x, y]| [x - origin[0], y - origin[1]])
}

/// Area of the intersection of the two boxes' bird's-eye footprints (m²), by clipping one
/// rectangle against the other's four edges. Zero-size boxes have zero intersection.
pub fn bev_intersection_area(a: &Box3, b: &Box3) -> f64 {
    let origin = [a.center.x, a.center.y];
    let ca = shifted_corners(a, origin);
    let cb = shifted_corners(b, origin);
    let mut poly = Poly {
        v: [[0.0; 2]; MAX_VERTICES],
        n: 4,
    };
    poly.v[..4].copy_from_slice(&ca);
    // A rectangle with negative size would list its corners clockwise; clipping expects the
    // clipping polygon counter-clockwise.
    let ccw = b.size[0] * b.size[1] >= 0.0;
    for i in 0..4 {
        if poly.n < 3 {
            return 0.0;
        }
        let (p, q) = if ccw {
            (cb[i], cb[(i + 1) % 4])
        } else {
            (cb[(i + 1) % 4], cb[i])
        };
        poly = poly.clip(p, q);
    }
    if poly.n < 3 {
        return 0.0;
    }
    // Rounding can leave a hair more than the smaller footprint.
    poly.area().min(a.bev_area().abs()).min(b.bev_area().abs())
}

/// Length of the overlap of the two boxes' vertical extents (m), zero when they are apart.
pub fn vertical_overlap(a: &Box3, b: &Box3) -> f64 {
    let (a0, a1) = a.z_range();
    let (b0, b1) = b.z_range();
    (a1.min(b1) - a0.max(b0)).max(0.0)
}

/// Intersection over union of the bird's-eye footprints, in [0, 1]. Zero when the union has
/// no area (degenerate boxes) or an input is not finite.
pub fn iou_bev(a: &Box3, b: &Box3) -> f64 {
    let inter = bev_intersection_area(a, b);
    ratio(inter, a.bev_area().abs() + b.bev_area().abs() - inter)
}

/// Intersection over union of the boxes' volumes (footprint intersection × vertical overlap
/// over the union of volumes), in [0, 1]. Zero when the union has no volume or an input is
/// not finite.
pub fn iou_3d(a: &Box3, b: &Box3) -> f64 {
    let dz = vertical_overlap(a, b);
    let inter = if dz > 0.0 {
        bev_intersection_area(a, b) * dz
    } else {
        0.0
    };
    ratio(inter, a.volume().abs() + b.volume().abs() - inter)
}

fn ratio(inter: f64, union: f64) -> f64 {
    if union > 0.0 && inter.is_finite() {
        (inter / union).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::seeded;
    use approx::assert_abs_diff_eq;
    use proptest::prelude::*;
    use rand::RngExt;
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

    fn bx(x: f64, y: f64, z: f64, l: f64, w: f64, h: f64, yaw: f64) -> Box3 {
        Box3::new(Point3::new(x, y, z), [l, w, h], yaw)
    }

    /// Reference IoU by counting the points of a regular grid over the union's bounding box
    /// that fall in each box (uses only `contains`, not the clipping code). `bev` ignores z.
    fn grid_iou(a: &Box3, b: &Box3, n: usize, bev: bool) -> f64 {
        let corners: Vec<Point3<f64>> = a.corners().into_iter().chain(b.corners()).collect();
        let lo = corners.iter().fold([f64::MAX; 3], |m, p| {
            [m[0].min(p.x), m[1].min(p.y), m[2].min(p.z)]
        });
        let hi = corners.iter().fold([f64::MIN; 3], |m, p| {
            [m[0].max(p.x), m[1].max(p.y), m[2].max(p.z)]
        });
        let nz = if bev { 1 } else { n };
        let (mut both, mut either) = (0u64, 0u64);
        for i in 0..n {
            let x = lo[0] + (i as f64 + 0.5) / n as f64 * (hi[0] - lo[0]);
            for j in 0..n {
                let y = lo[1] + (j as f64 + 0.5) / n as f64 * (hi[1] - lo[1]);
                for k in 0..nz {
                    let p = if bev {
                        Point3::new(x, y, a.center.z)
                    } else {
                        let z = lo[2] + (k as f64 + 0.5) / nz as f64 * (hi[2] - lo[2]);
                        Point3::new(x, y, z)
                    };
                    let (ia, ib) = if bev {
                        let pb = Point3::new(x, y, b.center.z);
                        (a.contains(&p, 0.0), b.contains(&pb, 0.0))
                    } else {
                        (a.contains(&p, 0.0), b.contains(&p, 0.0))
                    };
                    both += (ia && ib) as u64;
                    either += (ia || ib) as u64;
                }
            }
        }
        both as f64 / either as f64
    }

    #[test]
    fn hand_computed_cases() {
        let a = bx(3.0, -2.0, 0.5, 4.0, 2.0, 1.5, 0.3);
        assert_abs_diff_eq!(iou_bev(&a, &a), 1.0, epsilon = 1e-12);
        assert_abs_diff_eq!(iou_3d(&a, &a), 1.0, epsilon = 1e-12);
        // Disjoint footprints; and the same footprint stacked without vertical overlap.
        let far = bx(30.0, 10.0, 0.5, 4.0, 2.0, 1.5, 1.0);
        assert_eq!(iou_bev(&a, &far), 0.0);
        assert_eq!(iou_3d(&a, &far), 0.0);
        let above = bx(3.0, -2.0, 2.5, 4.0, 2.0, 1.5, 0.3);
        assert_abs_diff_eq!(iou_bev(&a, &above), 1.0, epsilon = 1e-12);
        assert_eq!(iou_3d(&a, &above), 0.0);
        // Axis-aligned 2×2 squares shifted by half a side: overlap 2, union 6.
        let s = bx(0.0, 0.0, 0.0, 2.0, 2.0, 1.0, 0.0);
        let t = bx(1.0, 0.0, 0.0, 2.0, 2.0, 1.0, 0.0);
        assert_abs_diff_eq!(iou_bev(&s, &t), 1.0 / 3.0, epsilon = 1e-12);
        assert_abs_diff_eq!(iou_3d(&s, &t), 1.0 / 3.0, epsilon = 1e-12);
        // Same, plus half the height shifted: intersection 2·0.5 = 1, union 4 + 4 − 1 = 7.
        let u = bx(1.0, 0.0, 0.5, 2.0, 2.0, 1.0, 0.0);
        assert_abs_diff_eq!(iou_3d(&s, &u), 1.0 / 7.0, epsilon = 1e-12);
        // A square turned by 90° is the same square; a 4×2 box turned by 90° about its centre
        // overlaps itself in a 2×2 square: 4 / (8 + 8 − 4) = 1/3.
        let r = bx(0.0, 0.0, 0.0, 2.0, 2.0, 1.0, FRAC_PI_2);
        assert_abs_diff_eq!(iou_bev(&s, &r), 1.0, epsilon = 1e-12);
        let long = bx(0.0, 0.0, 0.0, 4.0, 2.0, 1.0, 0.0);
        let long_r = bx(0.0, 0.0, 0.0, 4.0, 2.0, 1.0, FRAC_PI_2);
        assert_abs_diff_eq!(iou_bev(&long, &long_r), 1.0 / 3.0, epsilon = 1e-12);
        // Heading reversed: the same box.
        let back = Box3 {
            yaw: a.yaw + PI,
            ..a
        };
        assert_abs_diff_eq!(iou_3d(&a, &back), 1.0, epsilon = 1e-12);
        // Unit square and the same square turned 45°: the intersection is a regular octagon
        // of inradius 1/2, area 2(√2 − 1); union 2 − that.
        let q = bx(0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 0.0);
        let q45 = bx(0.0, 0.0, 0.0, 1.0, 1.0, 1.0, FRAC_PI_4);
        let oct = 2.0 * (2f64.sqrt() - 1.0);
        assert_abs_diff_eq!(iou_bev(&q, &q45), oct / (2.0 - oct), epsilon = 1e-12);
    }

    #[test]
    fn corners_and_contains() {
        let b = bx(5.0, 0.0, 1.0, 4.0, 2.0, 1.0, FRAC_PI_2);
        let c = b.bev_corners();
        // Heading +y: front-right is (+1, +2) from the centre, then counter-clockwise.
        let expect = [[6.0, 2.0], [4.0, 2.0], [4.0, -2.0], [6.0, -2.0]];
        for (got, want) in c.iter().zip(expect) {
            assert_abs_diff_eq!(got[0], want[0], epsilon = 1e-12);
            assert_abs_diff_eq!(got[1], want[1], epsilon = 1e-12);
        }
        let k = b.corners();
        assert_abs_diff_eq!(k[0].z, 0.5);
        assert_abs_diff_eq!(k[7].z, 1.5);
        assert_abs_diff_eq!(k[5].x, 4.0, epsilon = 1e-12);
        assert_abs_diff_eq!(b.volume(), 8.0);
        assert!(b.contains(&Point3::new(5.9, 1.9, 1.4), 0.0));
        assert!(!b.contains(&Point3::new(6.1, 0.0, 1.0), 0.0));
        assert!(b.contains(&Point3::new(6.1, 0.0, 1.0), 0.2));
        assert!(!b.contains(&Point3::new(5.0, 0.0, 1.6), 0.0));
        assert!(!b.contains(&Point3::new(5.0, 0.0, 1.3), -0.3));
    }

    #[test]
    fn degenerate_and_non_finite_boxes() {
        let a = bx(0.0, 0.0, 0.0, 4.0, 2.0, 1.5, 0.0);
        let flat = bx(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        assert_eq!(iou_bev(&flat, &flat), 0.0);
        assert_eq!(iou_3d(&a, &flat), 0.0);
        let nan = bx(f64::NAN, 0.0, 0.0, 4.0, 2.0, 1.5, 0.0);
        assert_eq!(iou_bev(&a, &nan), 0.0);
        assert_eq!(iou_3d(&nan, &a), 0.0);
    }

    fn random_box(rng: &mut impl RngExt) -> Box3 {
        bx(
            rng.random_range(-2.0..2.0),
            rng.random_range(-2.0..2.0),
            rng.random_range(-0.5..0.5),
            rng.random_range(0.3..5.0),
            rng.random_range(0.3..3.0),
            rng.random_range(0.5..2.0),
            rng.random_range(-PI..PI),
        )
    }

    #[test]
    fn agrees_with_grid_counting_on_random_boxes() {
        let mut rng = seeded(11);
        let mut overlapping = 0;
        for case in 0..40 {
            let a = random_box(&mut rng);
            let b = random_box(&mut rng);
            let bev_ref = grid_iou(&a, &b, 800, true);
            let bev = iou_bev(&a, &b);
            assert!(
                (bev - bev_ref).abs() < 5e-3,
                "case {case}: {bev} vs {bev_ref}"
            );
            if case % 4 == 0 {
                let ref3 = grid_iou(&a, &b, 120, false);
                let got = iou_3d(&a, &b);
                assert!((got - ref3).abs() < 1.5e-2, "case {case}: {got} vs {ref3}");
            }
            overlapping += (bev_ref > 0.05) as usize;
        }
        // The random boxes must exercise partial overlaps, not just disjoint pairs.
        assert!(overlapping >= 15, "{overlapping}");
    }

    fn arb_box() -> impl Strategy<Value = Box3> {
        (
            -3.0..3.0f64,
            -3.0..3.0f64,
            -1.0..1.0f64,
            0.1..6.0f64,
            0.1..3.0f64,
            0.1..3.0f64,
            -10.0..10.0f64,
        )
            .prop_map(|(x, y, z, l, w, h, yaw)| bx(x, y, z, l, w, h, yaw))
    }

    proptest! {
        #[test]
        fn iou_is_symmetric_bounded_and_rigid(
            a in arb_box(),
            b in arb_box(),
            (tx, ty, tz, rot) in (-50.0..50.0f64, -50.0..50.0f64, -5.0..5.0f64, -PI..PI),
        ) {
            let (bev, b3) = (iou_bev(&a, &b), iou_3d(&a, &b));
            prop_assert!((0.0..=1.0).contains(&bev));
            prop_assert!((0.0..=1.0).contains(&b3));
            prop_assert!((bev - iou_bev(&b, &a)).abs() < 1e-9);
            prop_assert!((b3 - iou_3d(&b, &a)).abs() < 1e-9);
            // 3-D IoU cannot exceed the footprint IoU times one (vertical IoU ≤ 1) and is the
            // footprint one when the heights coincide.
            prop_assert!(b3 <= bev + 1e-9);
            prop_assert!((iou_bev(&a, &a) - 1.0).abs() < 1e-9);
            // A common rigid motion (rotation about z then translation) changes nothing.
            let (s, c) = rot.sin_cos();
            let mv = |q: &Box3| bx(
                c * q.center.x - s * q.center.y + tx,
                s * q.center.x + c * q.center.y + ty,
                q.center.z + tz,
                q.size[0], q.size[1], q.size[2], q.yaw + rot,
            );
            prop_assert!((iou_bev(&mv(&a), &mv(&b)) - bev).abs() < 1e-7);
            prop_assert!((iou_3d(&mv(&a), &mv(&b)) - b3).abs() < 1e-7);
        }
    }
}
