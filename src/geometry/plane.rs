//! Planes and rectangular plane patches.
//!
//! A [`Plane`] is an infinite plane in Hessian normal form `n·p + d = 0` with a unit normal
//! `n`; its parameter vector is `β = [n; d]` (the state of a plane landmark). A [`PlanePatch`]
//! is the bounded part of a plane that was actually observed, summarised as a 4-vertex
//! rectangle with an area and an extent — the quantities the plane-prediction metrics compare
//! (areas, vertex distances, angle between normals).
//!
//! Not for: segmenting planes from point clouds (see [`crate::cloud::planes`]).

use super::FrameChange;
use crate::error::{Error, Result};
use nalgebra::{Isometry3, Matrix3, Point2, Point3, SymmetricEigen, Vector2, Vector3};

/// Tolerance on `|d|` below which a plane counts as passing through the origin when choosing
/// the canonical orientation of its normal (metres).
const ORIGIN_EPS: f64 = 1e-12;

/// Whether the unit-normal plane (`normal`, `offset`) must be negated to be canonical: the
/// one sign rule of the crate (see [`Plane`]).
fn flips(normal: [f64; 3], offset: f64) -> bool {
    if offset.abs() > ORIGIN_EPS {
        offset < 0.0
    } else {
        let [x, y, z] = normal;
        [z, y, x].into_iter().find(|c| *c != 0.0).unwrap_or(0.0) < 0.0
    }
}

/// The canonical representative of β = [n, d]: the normal scaled to unit length (d with it)
/// and the sign of [`Plane`] (d ≥ 0, the normal towards the origin; through the origin, the
/// first non-zero of n_z, n_y, n_x positive). A zero or non-finite normal is returned as it is.
pub fn canonical(beta: &[f64; 4]) -> [f64; 4] {
    let [x, y, z, d] = *beta;
    let norm = (x * x + y * y + z * z).sqrt();
    if !(norm.is_finite() && norm > 0.0) {
        return *beta;
    }
    let mut s = 1.0 / norm;
    if flips([x * s, y * s, z * s], d * s) {
        s = -s;
    }
    [x * s, y * s, z * s, d * s]
}

/// An infinite plane `{p : n·p + d = 0}` with a unit normal `n`.
///
/// # Sign convention
/// `d` is the signed offset: `n·p + d` is the signed distance of `p` from the plane. Every
/// constructor returns the *canonical* orientation with `d ≥ 0`, i.e. the normal points from
/// the plane towards the coordinate origin (the sensor), and `d` is the distance from the
/// origin to the plane. A plane through the origin (`|d| ≤ 1e-12`) instead gets the normal
/// whose first non-zero component (in the order z, y, x) is positive. For a ground plane below
/// a sensor at the origin, the canonical normal therefore points up (`n ≈ +z`) and `d` is the
/// sensor height.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Plane {
    /// Unit normal.
    pub normal: Vector3<f64>,
    /// Signed offset `d` in `n·p + d = 0` (metres); `d ≥ 0` in canonical form.
    pub offset: f64,
}

impl Plane {
    /// The plane `n·p + d = 0`, normalised (`n` scaled to unit length, `d` with it) and put in
    /// canonical orientation. Fails on a (near-)zero or non-finite normal or a non-finite `d`.
    pub fn new(normal: Vector3<f64>, offset: f64) -> Result<Self> {
        let norm = normal.norm();
        if !norm.is_finite() || !offset.is_finite() {
            return Err(Error::invalid("plane", "non-finite normal or offset"));
        }
        if norm < 1e-12 {
            return Err(Error::invalid("plane", "normal has (near) zero length"));
        }
        Ok(Self::canonical(normal / norm, offset / norm))
    }

    /// Flips `(n, d)` to the canonical orientation described on [`Plane`].
    fn canonical(normal: Vector3<f64>, offset: f64) -> Self {
        if flips([normal.x, normal.y, normal.z], offset) {
            Plane {
                normal: -normal,
                offset: -offset,
            }
        } else {
            Plane { normal, offset }
        }
    }

    /// The plane through a point with the given normal (normalised, canonical).
    pub fn from_point_normal(point: &Point3<f64>, normal: Vector3<f64>) -> Result<Self> {
        Self::new(normal, -normal.dot(&point.coords))
    }

    /// The least-squares plane through `points` (total least squares: the normal is the
    /// eigenvector of the smallest eigenvalue of the points' covariance; the plane passes
    /// through their centroid). Needs at least three points that are not all collinear.
    pub fn from_points(points: &[Point3<f64>]) -> Result<Self> {
        if points.len() < 3 {
            return Err(Error::invalid(
                "plane fit",
                format!("needs at least 3 points, got {}", points.len()),
            ));
        }
        let n = points.len() as f64;
        let centroid = points
            .iter()
            .fold(Vector3::zeros(), |acc, p| acc + p.coords)
            / n;
        let mut cov = Matrix3::zeros();
        for p in points {
            let q = p.coords - centroid;
            cov += q * q.transpose();
        }
        Self::from_moments(&centroid, &(cov / n))
    }

    /// The least-squares plane from a centroid and the (population) covariance of the points
    /// about it. Fails when the covariance is not finite or the points are (nearly) collinear.
    pub fn from_moments(centroid: &Vector3<f64>, covariance: &Matrix3<f64>) -> Result<Self> {
        if !centroid
            .iter()
            .chain(covariance.iter())
            .all(|v| v.is_finite())
        {
            return Err(Error::invalid("plane fit", "non-finite points"));
        }
        let eig = SymmetricEigen::new(*covariance);
        let mut order = [0usize, 1, 2];
        order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
        let middle = eig.eigenvalues[order[1]];
        let largest = eig.eigenvalues[order[2]];
        if largest <= 0.0 || middle <= largest * 1e-14 {
            return Err(Error::invalid("plane fit", "points are (nearly) collinear"));
        }
        let normal: Vector3<f64> = eig.eigenvectors.column(order[0]).into_owned();
        Self::from_point_normal(&Point3::from(*centroid), normal)
    }

    /// Signed distance `n·p + d` (positive on the side of the origin in canonical form).
    pub fn signed_distance(&self, p: &Point3<f64>) -> f64 {
        self.normal.dot(&p.coords) + self.offset
    }

    /// Unsigned distance from `p` to the plane (metres).
    pub fn distance(&self, p: &Point3<f64>) -> f64 {
        self.signed_distance(p).abs()
    }

    /// Orthogonal projection of `p` onto the plane.
    pub fn project(&self, p: &Point3<f64>) -> Point3<f64> {
        p - self.normal * self.signed_distance(p)
    }

    /// The plane expressed in the frame where points map as `p' = T p` (see
    /// [`Plane::moved_by`]).
    pub fn transform(&self, pose: &Isometry3<f64>) -> Self {
        self.moved_by(&FrameChange::from_isometry(pose))
    }

    /// The plane in the new frame of `change` ([`FrameChange::move_plane`]: `n' = R n`,
    /// `d' = d − n'·t`, renormalised), put back in canonical orientation.
    pub fn moved_by(&self, change: &FrameChange) -> Self {
        let [x, y, z, d] = change.move_plane(self.as_vector());
        Self::canonical(Vector3::new(x, y, z), d)
    }

    /// The parameter vector `β = [n_x, n_y, n_z, d]`.
    pub fn as_vector(&self) -> [f64; 4] {
        [self.normal.x, self.normal.y, self.normal.z, self.offset]
    }

    /// The plane with parameter vector `β = [n; d]`; `n` need not be unit length (β is
    /// renormalised) and the result is canonical.
    pub fn from_vector(beta: [f64; 4]) -> Result<Self> {
        Self::new(Vector3::new(beta[0], beta[1], beta[2]), beta[3])
    }

    /// Angle between the two planes' normals ignoring their signs, in `[0, π/2]` radians.
    pub fn angle_to(&self, other: &Plane) -> f64 {
        let c = self.normal.dot(&other.normal).abs().min(1.0);
        // atan2 of |n×m| and |n·m| is accurate for small and right angles alike.
        self.normal.cross(&other.normal).norm().atan2(c)
    }

    /// Angle between the normal and the vertical axis `+z`, sign-free, in `[0, π/2]`
    /// (0 for a horizontal plane, π/2 for a vertical wall).
    pub fn tilt(&self) -> f64 {
        let c = self.normal.z.abs().min(1.0);
        Vector2::new(self.normal.x, self.normal.y).norm().atan2(c)
    }

    /// An orthonormal in-plane basis `(u, v)` with `u × v = n`. For planes that are not close
    /// to horizontal, `u` is horizontal (`u = ẑ × n`, normalised) and `v` points up the plane;
    /// for near-horizontal planes `u = ŷ × n`, normalised (≈ +x for the ground).
    pub fn basis(&self) -> (Vector3<f64>, Vector3<f64>) {
        let n = self.normal;
        let helper = if n.z.abs() < 0.9 {
            Vector3::z()
        } else {
            Vector3::y()
        };
        let u = helper.cross(&n).normalize();
        let v = n.cross(&u);
        (u, v)
    }
}

/// A bounded, observed piece of a plane: the oriented bounding rectangle of its points
/// projected into the plane.
///
/// The rectangle is the *minimum-area* enclosing rectangle of the projected points, found by
/// rotating one side along each edge of their 2-D convex hull (the optimum always has a side
/// collinear with a hull edge). Unlike PCA axes this is exact for rectangular point sets and
/// does not depend on how the points are distributed inside.
///
/// `extent = (length, height)`: for planes tilted more than 45° from horizontal (walls),
/// `height` is the side closer to the vertical and `length` the other one; for
/// near-horizontal planes (ground) `length` is the longer side. `vertices` are the corners in
/// order around the rectangle: `v0`, `v1 = v0 + length·a`, `v2 = v1 + height·b`,
/// `v3 = v0 + height·b`, with `a`, `b` the rectangle's unit side directions.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanePatch {
    /// The supporting infinite plane.
    pub plane: Plane,
    /// Rectangle corners in order around the rectangle (metres).
    pub vertices: [Point3<f64>; 4],
    /// Rectangle area `length · height` (m²).
    pub area: f64,
    /// `(length, height)` of the rectangle (metres); see the type documentation.
    pub extent: (f64, f64),
}

impl PlanePatch {
    /// The minimum-area bounding rectangle, on `plane`, of `points` projected into `plane`.
    /// Fails on an empty or non-finite point set. One point gives a zero-size patch, collinear
    /// points a zero-height one.
    pub fn from_points(plane: Plane, points: &[Point3<f64>]) -> Result<Self> {
        if points.is_empty() {
            return Err(Error::invalid("plane patch", "no points"));
        }
        let (u, v) = plane.basis();
        // Work relative to the first point projected into the plane, for accuracy far from
        // the origin.
        let origin = plane.project(&points[0]);
        let mut pts2: Vec<Point2<f64>> = Vec::with_capacity(points.len());
        for p in points {
            let q = p - origin;
            let (x, y) = (q.dot(&u), q.dot(&v));
            if !x.is_finite() || !y.is_finite() {
                return Err(Error::invalid("plane patch", "non-finite point"));
            }
            pts2.push(Point2::new(x, y));
        }
        let hull = convex_hull(&mut pts2);
        let rect = min_area_rectangle(&hull);
        // 3-D side directions of the rectangle.
        let dir3 = |d: Vector2<f64>| u * d.x + v * d.y;
        let (mut a2, mut b2) = (rect.axis, Vector2::new(-rect.axis.y, rect.axis.x));
        let (mut la, mut lb) = (rect.size.0, rect.size.1);
        let (mut ca, mut cb) = (rect.min.0, rect.min.1);
        let horizontal = plane.normal.z.abs() > std::f64::consts::FRAC_1_SQRT_2;
        let swap = if horizontal {
            lb > la
        } else {
            dir3(a2).z.abs() > dir3(b2).z.abs()
        };
        if swap {
            std::mem::swap(&mut a2, &mut b2);
            std::mem::swap(&mut la, &mut lb);
            std::mem::swap(&mut ca, &mut cb);
        }
        // Make the height direction point up (or, when it is horizontal, keep it as is) and
        // the length direction complete a right-handed pair with the normal where possible.
        let (a3, b3) = (dir3(a2), dir3(b2));
        let (a3, b3, ca, cb) = if b3.z < -1e-12 {
            (a3, -b3, ca, -(cb + lb))
        } else {
            (a3, b3, ca, cb)
        };
        let v0 = origin + a3 * ca + b3 * cb;
        let v1 = v0 + a3 * la;
        let v2 = v1 + b3 * lb;
        let v3 = v0 + b3 * lb;
        Ok(PlanePatch {
            plane,
            vertices: [v0, v1, v2, v3],
            area: la * lb,
            extent: (la, lb),
        })
    }

    /// The bounding rectangle, on a wall-like `plane`, of `points` projected into it, with its
    /// sides along the plane's horizontal direction `u` and up-slope direction `v` of
    /// [`Plane::basis`] instead of the minimum-area orientation. For walls this keeps the
    /// rectangle upright however ragged the visible outline is (a partly occluded facade, a
    /// stepped roof line), so the same wall seen twice gives the same corners; its area is at
    /// least that of [`PlanePatch::from_points`]. Vertices as there (`v0` bottom start,
    /// `v1` bottom end, `v2` top end, `v3` top start). Fails on an empty or non-finite point
    /// set.
    pub fn upright_from_points(plane: Plane, points: &[Point3<f64>]) -> Result<Self> {
        if points.is_empty() {
            return Err(Error::invalid("plane patch", "no points"));
        }
        let (u, v) = plane.basis();
        let origin = plane.project(&points[0]);
        let (mut u_lo, mut u_hi, mut v_lo, mut v_hi) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for p in points {
            let q = p - origin;
            let (x, y) = (q.dot(&u), q.dot(&v));
            if !x.is_finite() || !y.is_finite() {
                return Err(Error::invalid("plane patch", "non-finite point"));
            }
            u_lo = u_lo.min(x);
            u_hi = u_hi.max(x);
            v_lo = v_lo.min(y);
            v_hi = v_hi.max(y);
        }
        let (length, height) = (u_hi - u_lo, v_hi - v_lo);
        let v0 = origin + u * u_lo + v * v_lo;
        let v1 = v0 + u * length;
        let v2 = v1 + v * height;
        let v3 = v0 + v * height;
        Ok(PlanePatch {
            plane,
            vertices: [v0, v1, v2, v3],
            area: length * height,
            extent: (length, height),
        })
    }

    /// An upright patch (see [`PlanePatch::upright_from_points`]) with its bottom edge lowered
    /// along the patch's up direction to where the edge's midpoint meets `ground`. Unchanged
    /// when the bottom already reaches the ground or the patch's sides are parallel to it.
    pub fn lowered_to(&self, ground: &Plane) -> PlanePatch {
        let [v0, v1, v2, v3] = self.vertices;
        let (length, height) = self.extent;
        if height.is_nan() || height <= 0.0 {
            return self.clone();
        }
        let up = (v3 - v0) / height;
        let along = ground.normal.dot(&up);
        if along.abs() < 1e-6 {
            return self.clone();
        }
        let mid = Point3::from((v0.coords + v1.coords) / 2.0);
        let t = -ground.signed_distance(&mid) / along;
        if t.is_nan() || t >= 0.0 {
            return self.clone();
        }
        let height = height - t;
        PlanePatch {
            plane: self.plane,
            vertices: [v0 + up * t, v1 + up * t, v2, v3],
            area: length * height,
            extent: (length, height),
        }
    }

    /// Centroid of the four vertices (the rectangle's centre).
    pub fn centre(&self) -> Point3<f64> {
        let s = self
            .vertices
            .iter()
            .fold(Vector3::zeros(), |acc, p| acc + p.coords);
        Point3::from(s / 4.0)
    }

    /// The patch in the frame where points map as `p' = T p` (plane and vertices moved; area
    /// and extent unchanged).
    pub fn transform(&self, pose: &Isometry3<f64>) -> Self {
        self.moved_by(&FrameChange::from_isometry(pose))
    }

    /// The patch in the new frame of `change` (plane and vertices moved; area and extent
    /// unchanged).
    pub fn moved_by(&self, change: &FrameChange) -> Self {
        PlanePatch {
            plane: self.plane.moved_by(change),
            vertices: self.vertices.map(|p| change.move_point(&p)),
            area: self.area,
            extent: self.extent,
        }
    }

    /// For each vertex of `self`, the distance to the closest vertex of `other` (metres).
    pub fn vertex_distances(&self, other: &PlanePatch) -> [f64; 4] {
        self.vertices.map(|p| {
            other
                .vertices
                .iter()
                .map(|q| (p - q).norm())
                .fold(f64::INFINITY, f64::min)
        })
    }
}

/// Convex hull (Andrew's monotone chain), counter-clockwise, without collinear points.
/// Sorts `pts` in place. Returns one point for a single (or all-equal) input and two for
/// collinear input; panics on an empty slice.
pub(crate) fn convex_hull(pts: &mut [Point2<f64>]) -> Vec<Point2<f64>> {
    pts.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    let cross = |o: &Point2<f64>, a: &Point2<f64>, b: &Point2<f64>| {
        (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x)
    };
    let mut hull: Vec<Point2<f64>> = Vec::with_capacity(64);
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &Point2<f64>>> = if pass == 0 {
            Box::new(pts.iter())
        } else {
            Box::new(pts.iter().rev())
        };
        for p in iter {
            while hull.len() >= start + 2
                && cross(&hull[hull.len() - 2], &hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(*p);
        }
        hull.pop();
    }
    hull.dedup();
    if hull.len() > 1 && hull.first() == hull.last() {
        hull.pop();
    }
    if hull.is_empty() {
        hull.push(pts[0]);
    }
    hull
}

/// A rectangle in 2-D: unit side direction `axis`, sizes along `axis` and its left normal,
/// and the minimum coordinates along both.
struct Rect2 {
    axis: Vector2<f64>,
    size: (f64, f64),
    min: (f64, f64),
}

/// Minimum-area rectangle enclosing a convex polygon, trying a side along every hull edge.
fn min_area_rectangle(hull: &[Point2<f64>]) -> Rect2 {
    let extent_along = |axis: Vector2<f64>| {
        let perp = Vector2::new(-axis.y, axis.x);
        let (mut a0, mut a1, mut b0, mut b1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for p in hull {
            let (a, b) = (p.coords.dot(&axis), p.coords.dot(&perp));
            a0 = a0.min(a);
            a1 = a1.max(a);
            b0 = b0.min(b);
            b1 = b1.max(b);
        }
        Rect2 {
            axis,
            size: (a1 - a0, b1 - b0),
            min: (a0, b0),
        }
    };
    let mut best = extent_along(Vector2::x());
    if hull.len() < 2 {
        return best;
    }
    let mut best_area = f64::INFINITY;
    for i in 0..hull.len() {
        let e = hull[(i + 1) % hull.len()] - hull[i];
        let len = e.norm();
        if len <= 0.0 {
            continue;
        }
        let r = extent_along(e / len);
        let area = r.size.0 * r.size.1;
        // Ties (e.g. collinear input, zero area) keep the longest side first.
        if area < best_area - 1e-12 || (area <= best_area + 1e-12 && r.size.0 > best.size.0) {
            best_area = area;
            best = r;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;
    use nalgebra::{Translation3, UnitQuaternion};
    use proptest::prelude::*;

    #[test]
    fn plane_from_exact_points() {
        let n = Vector3::new(1.0, -2.0, 0.5).normalize();
        let d = 3.0;
        let (u, v) = Plane::new(n, d).unwrap().basis();
        let base = Point3::from(-n * d);
        let pts: Vec<_> = (0..20)
            .map(|i| {
                let (a, b) = ((i as f64 * 0.37).sin() * 5.0, (i as f64 * 1.3).cos() * 2.0);
                base + u * a + v * b
            })
            .collect();
        let p = Plane::from_points(&pts).unwrap();
        assert_abs_diff_eq!(p.normal, n, epsilon = 1e-9);
        assert_abs_diff_eq!(p.offset, d, epsilon = 1e-9);
        for q in &pts {
            assert!(p.distance(q) < 1e-9);
        }
    }

    #[test]
    fn canonical_orientation_points_to_origin() {
        let ground = Plane::new(Vector3::new(0.0, 0.0, -2.0), -3.46).unwrap();
        assert_abs_diff_eq!(ground.normal, Vector3::z(), epsilon = 1e-15);
        assert_abs_diff_eq!(ground.offset, 1.73, epsilon = 1e-15);
        assert!(ground.signed_distance(&Point3::origin()) > 0.0);
        let through = Plane::new(Vector3::new(0.0, 0.0, -1.0), 0.0).unwrap();
        assert_eq!(through.normal, Vector3::z());
    }

    #[test]
    fn fit_rejects_degenerate_input() {
        let pts = [Point3::new(0.0, 0.0, 0.0), Point3::new(1.0, 0.0, 0.0)];
        assert!(Plane::from_points(&pts).is_err());
        let line: Vec<_> = (0..5).map(|i| Point3::new(i as f64, 0.0, 0.0)).collect();
        assert!(Plane::from_points(&line).is_err());
        assert!(Plane::new(Vector3::zeros(), 1.0).is_err());
        assert!(Plane::from_vector([f64::NAN, 0.0, 1.0, 0.0]).is_err());
    }

    #[test]
    fn vector_round_trip_renormalises() {
        let p = Plane::from_vector([0.0, 3.0, 4.0, 10.0]).unwrap();
        assert_abs_diff_eq!(p.normal, Vector3::new(0.0, 0.6, 0.8), epsilon = 1e-15);
        assert_abs_diff_eq!(p.offset, 2.0, epsilon = 1e-15);
        assert_eq!(Plane::from_vector(p.as_vector()).unwrap(), p);
    }

    #[test]
    fn angle_is_symmetric_and_sign_free() {
        let a = Plane::new(Vector3::new(1.0, 0.0, 0.0), 1.0).unwrap();
        let b = Plane::new(Vector3::new(1.0, 1.0, 0.0), -1.0).unwrap();
        let b_flipped = Plane {
            normal: -b.normal,
            offset: -b.offset,
        };
        let q = std::f64::consts::FRAC_PI_4;
        assert_abs_diff_eq!(a.angle_to(&b), q, epsilon = 1e-12);
        assert_abs_diff_eq!(b.angle_to(&a), q, epsilon = 1e-12);
        assert_abs_diff_eq!(a.angle_to(&b_flipped), q, epsilon = 1e-12);
        let c = Plane::new(Vector3::new(-1.0, 0.1, 0.0), 2.0).unwrap();
        assert!(a.angle_to(&c) <= std::f64::consts::FRAC_PI_2);
        assert_abs_diff_eq!(a.angle_to(&c), 0.1f64.atan(), epsilon = 1e-12);
        assert_abs_diff_eq!(a.angle_to(&a), 0.0, epsilon = 1e-15);
    }

    fn grid(x0: f64, x1: f64, z0: f64, z1: f64, n: usize) -> Vec<Point3<f64>> {
        let mut pts = Vec::new();
        for i in 0..=n {
            for j in 0..=n {
                let x = x0 + (x1 - x0) * i as f64 / n as f64;
                let z = z0 + (z1 - z0) * j as f64 / n as f64;
                pts.push(Point3::new(x, 5.0, z));
            }
        }
        pts
    }

    #[test]
    fn lowered_patch_reaches_the_ground_below_its_bottom_edge() {
        // Wall y = 5 seen from z = 0.3 to 3 over x in [0, 10]; the ground z = −0.2 + 0.01 x
        // (a 1 % slope along the wall) meets the bottom edge's midpoint (x = 5) at z = −0.15.
        let pts: Vec<_> = (0..=10)
            .flat_map(|i| [0.3, 3.0].map(|z| Point3::new(i as f64, 5.0, z)))
            .collect();
        let plane = Plane::from_points(&pts).unwrap();
        let patch = PlanePatch::upright_from_points(plane, &pts).unwrap();
        let n = Vector3::new(-0.01, 0.0, 1.0);
        let ground = Plane::new(n, 0.2).unwrap();
        let low = patch.lowered_to(&ground);
        assert_abs_diff_eq!(low.extent.0, 10.0, epsilon = 1e-9);
        assert_abs_diff_eq!(low.extent.1, 3.15, epsilon = 1e-9);
        assert_abs_diff_eq!(low.area, 31.5, epsilon = 1e-9);
        for k in [0, 1] {
            assert_abs_diff_eq!(low.vertices[k].z, -0.15, epsilon = 1e-9);
            assert_abs_diff_eq!(low.vertices[k].x, patch.vertices[k].x, epsilon = 1e-9);
        }
        assert_eq!(low.vertices[2], patch.vertices[2]);
        assert_eq!(low.vertices[3], patch.vertices[3]);
        // A bottom already at or below the ground, or a ground parallel to the sides: as is.
        let high_ground = Plane::new(Vector3::z(), -1.0).unwrap();
        assert_eq!(patch.lowered_to(&high_ground), patch);
        assert_eq!(patch.lowered_to(&plane), patch);
    }

    #[test]
    fn upright_patch_of_a_slanted_outline_keeps_horizontal_sides() {
        // A parallelogram on the wall y = 5: bottom edge x in [0, 10] at z = 0, top edge
        // x in [4, 14] at z = 3 (a stepped or partly occluded facade). The upright rectangle
        // is x in [0, 14], z in [0, 3], never smaller than the minimum-area one.
        let mut pts = Vec::new();
        for i in 0..=20 {
            for j in 0..=6 {
                let (s, t) = (i as f64 / 20.0, j as f64 / 6.0);
                pts.push(Point3::new(10.0 * s + 4.0 * t, 5.0, 3.0 * t));
            }
        }
        let plane = Plane::from_points(&pts).unwrap();
        let patch = PlanePatch::upright_from_points(plane, &pts).unwrap();
        assert_abs_diff_eq!(patch.extent.0, 14.0, epsilon = 1e-9);
        assert_abs_diff_eq!(patch.extent.1, 3.0, epsilon = 1e-9);
        assert_abs_diff_eq!(patch.area, 42.0, epsilon = 1e-9);
        let mut xs: Vec<f64> = patch.vertices.iter().map(|v| v.x).collect();
        xs.sort_by(f64::total_cmp);
        assert_abs_diff_eq!(xs[0], 0.0, epsilon = 1e-9);
        assert_abs_diff_eq!(xs[3], 14.0, epsilon = 1e-9);
        // v0 → v1 along the bottom (horizontal), v0 → v3 straight up.
        let (bottom, up) = (
            patch.vertices[1] - patch.vertices[0],
            patch.vertices[3] - patch.vertices[0],
        );
        assert_abs_diff_eq!(bottom.z, 0.0, epsilon = 1e-9);
        assert_abs_diff_eq!(up.x, 0.0, epsilon = 1e-9);
        assert_abs_diff_eq!(up.z, 3.0, epsilon = 1e-9);
        assert!(PlanePatch::from_points(plane, &pts).unwrap().area <= 42.0 + 1e-9);
        assert!(PlanePatch::upright_from_points(plane, &[]).is_err());
        let bad = [Point3::new(f64::NAN, 5.0, 0.0)];
        assert!(PlanePatch::upright_from_points(plane, &bad).is_err());
    }

    #[test]
    fn patch_of_axis_aligned_rectangle() {
        // A wall y = 5, x in [2, 12], z in [-1, 3].
        let pts = grid(2.0, 12.0, -1.0, 3.0, 40);
        let plane = Plane::from_points(&pts).unwrap();
        let patch = PlanePatch::from_points(plane, &pts).unwrap();
        assert_abs_diff_eq!(patch.area, 40.0, epsilon = 1e-6);
        assert_abs_diff_eq!(patch.extent.0, 10.0, epsilon = 1e-6);
        assert_abs_diff_eq!(patch.extent.1, 4.0, epsilon = 1e-6);
        let corners = [
            Point3::new(2.0, 5.0, -1.0),
            Point3::new(12.0, 5.0, -1.0),
            Point3::new(12.0, 5.0, 3.0),
            Point3::new(2.0, 5.0, 3.0),
        ];
        let reference = PlanePatch {
            plane,
            vertices: corners,
            area: 40.0,
            extent: (10.0, 4.0),
        };
        for d in patch.vertex_distances(&reference) {
            assert!(d < 1e-6, "{d}");
        }
        // Consecutive vertices: length side first, then height side going up.
        let side = patch.vertices[1] - patch.vertices[0];
        assert_abs_diff_eq!(side.norm(), 10.0, epsilon = 1e-6);
        assert!((patch.vertices[3] - patch.vertices[0]).z > 3.9);
        assert_abs_diff_eq!(patch.centre(), Point3::new(7.0, 5.0, 1.0), epsilon = 1e-6);
    }

    #[test]
    fn patch_of_sampled_rectangle_is_close() {
        use rand::RngExt;
        let mut rng = crate::rng::seeded(3);
        let pts: Vec<_> = (0..2000)
            .map(|_| {
                Point3::new(
                    rng.random_range(0.0..8.0),
                    rng.random_range(0.0..3.0),
                    -1.73 + rng.random_range(-0.01..0.01),
                )
            })
            .collect();
        let plane = Plane::from_points(&pts).unwrap();
        assert!(plane.tilt() < 0.01);
        let patch = PlanePatch::from_points(plane, &pts).unwrap();
        assert!((patch.area - 24.0).abs() < 0.5, "{}", patch.area);
        assert!((patch.extent.0 - 8.0).abs() < 0.1);
        assert!((patch.extent.1 - 3.0).abs() < 0.1);
    }

    #[test]
    fn degenerate_patches() {
        let plane = Plane::new(Vector3::z(), 1.0).unwrap();
        let one = PlanePatch::from_points(plane, &[Point3::new(1.0, 2.0, -1.0)]).unwrap();
        assert_eq!(one.area, 0.0);
        let line: Vec<_> = (0..5).map(|i| Point3::new(i as f64, 0.0, -1.0)).collect();
        let seg = PlanePatch::from_points(plane, &line).unwrap();
        assert_abs_diff_eq!(seg.extent.0, 4.0, epsilon = 1e-12);
        assert_abs_diff_eq!(seg.area, 0.0, epsilon = 1e-12);
        assert!(PlanePatch::from_points(plane, &[]).is_err());
    }

    #[test]
    fn vertex_distances_hand_case() {
        let plane = Plane::new(Vector3::z(), 0.0).unwrap();
        let unit = |dx: f64| PlanePatch {
            plane,
            vertices: [
                Point3::new(dx, 0.0, 0.0),
                Point3::new(dx + 1.0, 0.0, 0.0),
                Point3::new(dx + 1.0, 1.0, 0.0),
                Point3::new(dx, 1.0, 0.0),
            ],
            area: 1.0,
            extent: (1.0, 1.0),
        };
        // Shifted by 0.25: every vertex's nearest counterpart is 0.25 away.
        let d = unit(0.0).vertex_distances(&unit(0.25));
        for x in d {
            assert_abs_diff_eq!(x, 0.25, epsilon = 1e-12);
        }
        // Shifted by 0.75: the left vertices' nearest is the shifted left vertex (0.75), the
        // right vertices' nearest is the shifted left vertex (0.25).
        let d = unit(0.0).vertex_distances(&unit(0.75));
        assert_abs_diff_eq!(d[0], 0.75, epsilon = 1e-12);
        assert_abs_diff_eq!(d[1], 0.25, epsilon = 1e-12);
        assert_abs_diff_eq!(d[2], 0.25, epsilon = 1e-12);
        assert_abs_diff_eq!(d[3], 0.75, epsilon = 1e-12);
    }

    #[test]
    fn patch_transform_moves_vertices_onto_transformed_plane() {
        let pts = grid(0.0, 4.0, 0.0, 2.0, 8);
        let plane = Plane::from_points(&pts).unwrap();
        let patch = PlanePatch::from_points(plane, &pts).unwrap();
        let pose = Isometry3::from_parts(
            Translation3::new(1.0, -2.0, 0.3),
            UnitQuaternion::from_euler_angles(0.1, -0.2, 0.7),
        );
        let moved = patch.transform(&pose);
        for v in &moved.vertices {
            assert!(moved.plane.distance(v) < 1e-12);
        }
        assert_eq!(moved.area, patch.area);
        let back = moved.transform(&pose.inverse());
        for d in back.vertex_distances(&patch) {
            assert!(d < 1e-12);
        }
    }

    proptest! {
        #[test]
        fn transform_keeps_points_on_plane(
            nx in -1.0f64..1.0, ny in -1.0f64..1.0, nz in -1.0f64..1.0, d in -20.0f64..20.0,
            a in -10.0f64..10.0, b in -10.0f64..10.0,
            roll in -3.2f64..3.2, pitch in -1.5f64..1.5, yaw in -3.2f64..3.2,
            tx in -50.0f64..50.0, ty in -50.0f64..50.0, tz in -5.0f64..5.0,
        ) {
            prop_assume!(Vector3::new(nx, ny, nz).norm() > 0.1);
            let plane = Plane::new(Vector3::new(nx, ny, nz), d).unwrap();
            let (u, v) = plane.basis();
            let p = Point3::from(-plane.normal * plane.offset) + u * a + v * b;
            prop_assert!(plane.distance(&p) < 1e-9);
            let pose = Isometry3::from_parts(
                Translation3::new(tx, ty, tz),
                UnitQuaternion::from_euler_angles(roll, pitch, yaw),
            );
            let moved = plane.transform(&pose);
            prop_assert!((moved.normal.norm() - 1.0).abs() < 1e-12);
            prop_assert!(moved.offset >= 0.0);
            prop_assert!(moved.distance(&(pose * p)) < 1e-9);
            prop_assert!(moved.angle_to(&plane.transform(&pose)) < 1e-12);
        }
    }
}
