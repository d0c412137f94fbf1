//! The fourteen geometric features of a scan segment after Arras, Mozos & Burgard (ICRA 2007),
//! the shape profile seed 003 (Sec. IV) feeds to its Fuzzy ART classifier, and their
//! normalisation to `[0, 1]`.
//!
//! Not for: grouping points into segments, classifying the profile, or tracking.
//!
//! # The features (in [`Features`] order)
//!
//! For the `n` points `p_i` of a segment, in beam order, with centroid `p̄`:
//!
//! | # | feature | definition |
//! |---|---|---|
//! | 0 | number of points | `n` |
//! | 1 | standard deviation | `√(Σ‖p_i − p̄‖² / (n − 1))` (0 for one point) |
//! | 2 | mean average deviation from the median | `Σ‖p_i − p̃‖ / n`, `p̃` the component-wise median |
//! | 3 | jump distance from the preceding segment | given by the caller |
//! | 4 | jump distance to the succeeding segment | given by the caller |
//! | 5 | width | `‖p_n − p_1‖` |
//! | 6 | linearity | residual sum of squares of the total-least-squares line: `n·λ_min` of the points' covariance |
//! | 7 | circularity | `Σ (r_c − ‖p_i − c‖)²` of the algebraic (Kåsa) circle fit with centre `c`, radius `r_c` |
//! | 8 | radius | `r_c` |
//! | 9 | boundary length | `Σ‖p_i − p_{i−1}‖` |
//! | 10 | boundary regularity | sample standard deviation of the distances `‖p_i − p_{i−1}‖` |
//! | 11 | mean curvature | mean over consecutive triples of `4A / (d_a d_b d_c)`, the inverse circumradius (`A` the triangle's area, `d` its sides) |
//! | 12 | mean angular difference | mean over inner points of the unsigned angle between `p_i − p_{i−1}` and `p_{i+1} − p_i` |
//! | 13 | mean speed | given by the caller |
//!
//! The circle fit minimises `Σ (x² + y² + D x + E y + F)²`; with fewer than three points, or
//! collinear points (singular system), the radius is [`MAX_RADIUS`] and the circularity equals
//! the linearity (the limit of a circle becoming a line); with one or two points the radius
//! is half the width and the circularity 0. Curvature and angular difference are 0 with fewer
//! than three points, degenerate triples contribute 0.
//!
//! Arras et al. compute the mean speed from two scans with associated segments. Here the
//! caller supplies it; the moving-object detector uses the displacement of the cluster's
//! centroid (world frame) from the nearest cluster of the previous scan, divided by the time
//! between the scans (0 when none lies within its association gate).

use crate::error::{Error, Result};
use crate::numerics::sym2::symmetric2_eigenvalues;
use nalgebra::{Matrix3, Vector3};

/// Number of features.
pub const NUM_FEATURES: usize = 14;

/// Radius reported for collinear segments (m).
pub const MAX_RADIUS: f64 = 100.0;

/// A feature vector in the order of the module table.
pub type Features = [f64; NUM_FEATURES];

/// Normalisation ranges `[lo, hi]` per feature: [`normalise`] maps `lo → 0`, `hi → 1` and
/// clips outside. Chosen for people and robots seen by an indoor scanner with 0.5° beams:
/// 1–60 points, deviations up to 0.5 m, jumps up to 5 m, width and boundary up to 2 and 3 m,
/// residual sums up to 1 m², radius up to 2 m, curvature up to 10 m⁻¹, angles up to π,
/// speeds up to 3 m/s.
pub const FEATURE_RANGES: [[f64; 2]; NUM_FEATURES] = [
    [1.0, 60.0],
    [0.0, 0.5],
    [0.0, 0.5],
    [0.0, 5.0],
    [0.0, 5.0],
    [0.0, 2.0],
    [0.0, 1.0],
    [0.0, 1.0],
    [0.0, 2.0],
    [0.0, 3.0],
    [0.0, 0.5],
    [0.0, 10.0],
    [0.0, std::f64::consts::PI],
    [0.0, 3.0],
];

/// What the segment's points alone do not tell.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SegmentContext {
    /// Distance from the preceding segment's last point to this one's first point (m).
    pub jump_prev: f64,
    /// Distance from this one's last point to the succeeding segment's first point (m).
    pub jump_next: f64,
    /// Mean speed (m/s).
    pub speed: f64,
}

/// The fourteen features of a segment (see the module table). Errors on an empty segment or
/// non-finite values.
pub fn segment_features(points: &[[f64; 2]], context: &SegmentContext) -> Result<Features> {
    if points.is_empty() {
        return Err(Error::invalid("segment features", "no points"));
    }
    if points.iter().flatten().any(|v| !v.is_finite())
        || ![context.jump_prev, context.jump_next, context.speed]
            .iter()
            .all(|v| v.is_finite())
    {
        return Err(Error::invalid("segment features", "non-finite input"));
    }
    let n = points.len();
    let nf = n as f64;
    let dist = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    let (mx, my) = points
        .iter()
        .fold((0.0, 0.0), |(x, y), p| (x + p[0], y + p[1]));
    let mean = [mx / nf, my / nf];
    let (mut cxx, mut cxy, mut cyy) = (0.0, 0.0, 0.0);
    for p in points {
        let (dx, dy) = (p[0] - mean[0], p[1] - mean[1]);
        cxx += dx * dx;
        cxy += dx * dy;
        cyy += dy * dy;
    }
    let std_dev = if n > 1 {
        ((cxx + cyy) / (nf - 1.0)).sqrt()
    } else {
        0.0
    };
    let median = [median_of(points, 0), median_of(points, 1)];
    let mad = points.iter().map(|&p| dist(p, median)).sum::<f64>() / nf;
    let width = dist(points[0], points[n - 1]);
    // Smallest eigenvalue of the scatter matrix = residual sum of squares of the TLS line.
    let linearity = symmetric2_eigenvalues(cxx, cxy, cyy).0.max(0.0);
    let (radius, circularity) = if n < 3 {
        (0.5 * width, 0.0)
    } else {
        match fit_circle(points) {
            Some((c, r)) => {
                let res = points.iter().map(|&p| (r - dist(p, c)).powi(2)).sum();
                (r, res)
            }
            None => (MAX_RADIUS, linearity),
        }
    };
    let steps = || points.windows(2).map(|w| dist(w[0], w[1]));
    let boundary = steps().sum::<f64>();
    let regularity = if n > 2 {
        let m = boundary / (nf - 1.0);
        (steps().map(|d| (d - m).powi(2)).sum::<f64>() / (nf - 2.0)).sqrt()
    } else {
        0.0
    };
    let (mut curvature, mut angular) = (0.0, 0.0);
    if n >= 3 {
        for w in points.windows(3) {
            let (a, b, c) = (w[0], w[1], w[2]);
            let (u, v) = ([b[0] - a[0], b[1] - a[1]], [c[0] - b[0], c[1] - b[1]]);
            let cross = u[0] * v[1] - u[1] * v[0];
            let dot = u[0] * v[0] + u[1] * v[1];
            let (da, db, dc) = (dist(a, b), dist(b, c), dist(a, c));
            if da > 0.0 && db > 0.0 && dc > 0.0 {
                curvature += 2.0 * cross.abs() / (da * db * dc);
            }
            if da > 0.0 && db > 0.0 {
                angular += cross.atan2(dot).abs();
            }
        }
        curvature /= nf - 2.0;
        angular /= nf - 2.0;
    }
    Ok([
        nf,
        std_dev,
        mad,
        context.jump_prev,
        context.jump_next,
        width,
        linearity,
        circularity,
        radius.min(MAX_RADIUS),
        boundary,
        regularity,
        curvature,
        angular,
        context.speed,
    ])
}

/// Maps each feature through its [`FEATURE_RANGES`] entry onto `[0, 1]` (clipped).
pub fn normalise(features: &Features) -> Features {
    let mut out = [0.0; NUM_FEATURES];
    for (k, o) in out.iter_mut().enumerate() {
        let [lo, hi] = FEATURE_RANGES[k];
        *o = ((features[k] - lo) / (hi - lo)).clamp(0.0, 1.0);
    }
    out
}

fn median_of(points: &[[f64; 2]], axis: usize) -> f64 {
    let mut v: Vec<f64> = points.iter().map(|p| p[axis]).collect();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Algebraic circle fit: centre and radius, `None` when the system is singular or the
/// radius is not real.
fn fit_circle(points: &[[f64; 2]]) -> Option<([f64; 2], f64)> {
    // Centre the data for conditioning.
    let nf = points.len() as f64;
    let (ox, oy) = points
        .iter()
        .fold((0.0, 0.0), |(x, y), p| (x + p[0] / nf, y + p[1] / nf));
    let mut a = Matrix3::<f64>::zeros();
    let mut b = Vector3::<f64>::zeros();
    for p in points {
        let (x, y) = (p[0] - ox, p[1] - oy);
        let row = Vector3::new(x, y, 1.0);
        let rhs = -(x * x + y * y);
        a += row * row.transpose();
        b += row * rhs;
    }
    // Relative singularity test: collinear points make the 3×3 system rank 2.
    let scale = a.norm().max(f64::MIN_POSITIVE);
    if a.determinant().abs() <= 1e-12 * scale * scale * scale {
        return None;
    }
    let s = a.lu().solve(&b)?;
    let (cx, cy) = (-0.5 * s[0], -0.5 * s[1]);
    let r2 = cx * cx + cy * cy - s[2];
    (r2 > 0.0 && r2.is_finite()).then(|| ([cx + ox, cy + oy], r2.sqrt()))
}

#[cfg(test)]
mod tests {
    use super::*;

    const NONE: SegmentContext = SegmentContext {
        jump_prev: 1.5,
        jump_next: 2.5,
        speed: 0.7,
    };

    #[test]
    fn straight_line_by_hand() {
        let pts = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0], [4.0, 0.0]];
        let f = segment_features(&pts, &NONE).unwrap();
        assert_eq!(f[0], 5.0);
        // Squared distances to (2, 0): 4, 1, 0, 1, 4 → √(10 / 4).
        assert!((f[1] - 2.5f64.sqrt()).abs() < 1e-12);
        // Median (2, 0): mean of 2, 1, 0, 1, 2.
        assert!((f[2] - 1.2).abs() < 1e-12);
        assert_eq!((f[3], f[4], f[13]), (1.5, 2.5, 0.7));
        assert!((f[5] - 4.0).abs() < 1e-12);
        assert!(f[6].abs() < 1e-12);
        assert_eq!(f[8], MAX_RADIUS);
        assert!((f[9] - 4.0).abs() < 1e-12);
        assert!(f[10].abs() < 1e-12);
        assert!(f[11].abs() < 1e-12 && f[12].abs() < 1e-12);
    }

    #[test]
    fn quarter_circle_arc_by_hand() {
        // Unit circle at 0°, 30°, 60°, 90°.
        let pts: Vec<[f64; 2]> = [0.0f64, 30.0, 60.0, 90.0]
            .iter()
            .map(|a| [a.to_radians().cos(), a.to_radians().sin()])
            .collect();
        let f = segment_features(&pts, &NONE).unwrap();
        let deg = |d: f64| d.to_radians();
        // Along (1,1)/√2 the points sit at cos 45°, cos 15°, cos 15°, cos 45°; across at
        // ±sin 45°, ±sin 15°. The line residual is the along-spread: (cos 15° − cos 45°)².
        let along = (deg(15.0).cos() - deg(45.0).cos()).powi(2);
        let across = 2.0 * (deg(45.0).sin().powi(2) + deg(15.0).sin().powi(2));
        assert!((f[1] - ((along + across) / 3.0).sqrt()).abs() < 1e-12);
        assert!((f[5] - 2f64.sqrt()).abs() < 1e-12);
        assert!((f[6] - along).abs() < 1e-12);
        assert!(f[7].abs() < 1e-20 + 1e-12);
        assert!((f[8] - 1.0).abs() < 1e-12);
        // Three chords of 30°: 2 sin 15° each.
        assert!((f[9] - 6.0 * deg(15.0).sin()).abs() < 1e-12);
        assert!(f[10].abs() < 1e-12);
        // Every triple lies on the unit circle: curvature 1; each turn is 30°.
        assert!((f[11] - 1.0).abs() < 1e-12);
        assert!((f[12] - deg(30.0)).abs() < 1e-12);
        // Median (0.683, 0.683): the middle two of each coordinate.
        let m = 0.5 * (deg(30.0).cos() + deg(60.0).cos());
        let mad = pts.iter().map(|p| (p[0] - m).hypot(p[1] - m)).sum::<f64>() / 4.0;
        assert!((f[2] - mad).abs() < 1e-12);
    }

    #[test]
    fn small_segments_and_errors() {
        let f = segment_features(&[[1.0, 1.0]], &NONE).unwrap();
        assert_eq!((f[0], f[1], f[5], f[8], f[9]), (1.0, 0.0, 0.0, 0.0, 0.0));
        let f = segment_features(&[[0.0, 0.0], [0.0, 0.4]], &NONE).unwrap();
        assert!((f[8] - 0.2).abs() < 1e-12 && f[7] == 0.0);
        assert!(segment_features(&[], &NONE).is_err());
        assert!(segment_features(&[[f64::NAN, 0.0]], &NONE).is_err());
    }

    #[test]
    fn normalisation_clips_into_the_unit_interval() {
        let mut f = [0.0; NUM_FEATURES];
        f[0] = 30.5; // halfway between 1 and 60
        f[5] = 10.0; // beyond 2 m
        f[12] = -1.0;
        let g = normalise(&f);
        assert!((g[0] - 0.5).abs() < 1e-12);
        assert_eq!(g[5], 1.0);
        assert_eq!(g[12], 0.0);
        assert!(g.iter().all(|v| (0.0..=1.0).contains(v)));
    }
}
