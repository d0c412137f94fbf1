//! Plane-prediction errors: how well a plane patch predicted into the next frame matches the
//! patch segmented there (Gostar et al. 2019, Sec. 5, Tables 1–6).
//!
//! Per associated pair of a predicted and a segmented [`PlanePatch`] the reported quantities
//! are the two areas, for each predicted vertex the distance to the closest segmented vertex,
//! and the sign-free angle between the normals ([`PlanePairError`]). Over many pairs the
//! distribution is summarised by medians and 90th percentiles ([`PlanePredictionSummary`]).
//!
//! # Association
//! [`associate_planes`] pairs predicted and segmented patches by an optimal assignment
//! ([`crate::assignment::solve`]) on what describes a wall whatever part of it is seen: its
//! plane and where along it the two patches lie ([`WallGate`]). For a predicted patch P and a
//! segmented patch S:
//!
//! - θ, the angle between the normals;
//! - g, the plane gap: the mean of the distance of S's centre from P's plane and of P's
//!   centre from S's plane;
//! - o, the overlap along the wall: both patches' vertices projected on the horizontal
//!   direction of P's plane (n × z; a patch's first side for a near-horizontal plane) give two
//!   intervals, and o is the length they share over the shorter interval's length.
//!
//! Pairs with `θ > max_angle`, `g > max_plane_gap` or `o < min_overlap` are forbidden; the
//! others cost `θ / max_angle + g / max_plane_gap + (1 − o)`, and a patch may stay unpaired
//! (at a cost of 3, the largest a gated pair can have). Two views of one long facade whose
//! centres lie metres apart (its visible stretch moves with the vehicle) are so paired, and two
//! parallel walls along one street are not.
//!
//! # Percentiles
//! Percentiles use the nearest-rank rule: for `n` sorted values and a percentage `p`, the
//! value at rank `max(1, ⌈p·n/100⌉)` (1-based). The median is the 50th percentile under the
//! same rule (the lower middle value for an even `n`). Empty inputs give NaN.
//!
//! Not for: segmenting planes or predicting them (see [`crate::pipeline::plane_prediction`]).

use crate::geometry::PlanePatch;

/// The errors of one predicted plane patch against its associated segmented patch.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PlanePairError {
    /// Frame of the segmented patch (the frame predicted into).
    pub frame: usize,
    /// Area of the predicted patch (m²).
    pub predicted_area: f64,
    /// Area of the segmented patch (m²).
    pub segmented_area: f64,
    /// For each predicted vertex, the distance to the closest segmented vertex (m).
    pub vertex_distances: [f64; 4],
    /// Sign-free angle between the normals (rad, in `[0, π/2]`).
    pub normal_angle_rad: f64,
    /// The same angle in degrees.
    pub normal_angle_deg: f64,
}

impl PlanePairError {
    /// The errors of `predicted` against `segmented`, attributed to `frame`.
    pub fn between(frame: usize, predicted: &PlanePatch, segmented: &PlanePatch) -> Self {
        let angle = predicted.plane.angle_to(&segmented.plane);
        PlanePairError {
            frame,
            predicted_area: predicted.area,
            segmented_area: segmented.area,
            vertex_distances: predicted.vertex_distances(segmented),
            normal_angle_rad: angle,
            normal_angle_deg: angle.to_degrees(),
        }
    }

    /// Component-wise mean of several errors of the same pair (e.g. over Monte-Carlo runs);
    /// `None` for an empty list. The frame is taken from the first entry.
    pub fn mean(errors: &[PlanePairError]) -> Option<PlanePairError> {
        let first = errors.first()?;
        let n = errors.len() as f64;
        let avg = |f: &dyn Fn(&PlanePairError) -> f64| errors.iter().map(f).sum::<f64>() / n;
        let rad = avg(&|e| e.normal_angle_rad);
        Some(PlanePairError {
            frame: first.frame,
            predicted_area: avg(&|e| e.predicted_area),
            segmented_area: avg(&|e| e.segmented_area),
            vertex_distances: [0, 1, 2, 3].map(|i| avg(&|e| e.vertex_distances[i])),
            normal_angle_rad: rad,
            normal_angle_deg: rad.to_degrees(),
        })
    }
}

/// Distribution of plane-prediction errors over many pairs (nearest-rank percentiles, see the
/// module documentation). Fields are NaN when there is nothing to summarise.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PlanePredictionSummary {
    /// Median normal angle (degrees).
    pub median_normal_angle_deg: f64,
    /// 90th percentile of the normal angle (degrees).
    pub p90_normal_angle_deg: f64,
    /// Median over all vertex distances of all pairs (m).
    pub median_vertex_distance_m: f64,
    /// 90th percentile over all vertex distances of all pairs (m).
    pub p90_vertex_distance_m: f64,
    /// Mean execution time of the prediction step (ms).
    pub mean_prediction_ms: f64,
    /// Number of pairs summarised.
    pub pairs: usize,
}

impl PlanePredictionSummary {
    /// Summarises pair errors and prediction times (ms).
    pub fn from_pairs(pairs: &[PlanePairError], prediction_ms: &[f64]) -> Self {
        let angles: Vec<f64> = pairs.iter().map(|p| p.normal_angle_deg).collect();
        let vertices: Vec<f64> = pairs.iter().flat_map(|p| p.vertex_distances).collect();
        let mean_ms = if prediction_ms.is_empty() {
            f64::NAN
        } else {
            prediction_ms.iter().sum::<f64>() / prediction_ms.len() as f64
        };
        PlanePredictionSummary {
            median_normal_angle_deg: percentile(&angles, 50.0),
            p90_normal_angle_deg: percentile(&angles, 90.0),
            median_vertex_distance_m: percentile(&vertices, 50.0),
            p90_vertex_distance_m: percentile(&vertices, 90.0),
            mean_prediction_ms: mean_ms,
            pairs: pairs.len(),
        }
    }
}

/// Nearest-rank percentile `p` (in percent, clamped to `[0, 100]`) of `values`: the value at
/// 1-based rank `max(1, ⌈p·n/100⌉)` of the sorted values. NaN for an empty slice; NaN values
/// sort last.
pub fn percentile(values: &[f64], p: f64) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let n = sorted.len();
    let p = if p.is_nan() { 0.0 } else { p.clamp(0.0, 100.0) };
    let rank = ((p / 100.0 * n as f64).ceil() as usize).clamp(1, n);
    sorted[rank - 1]
}

/// The gates of [`associate_planes`] (see the module documentation).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct WallGate {
    /// Largest angle between the normals (rad).
    pub max_angle: f64,
    /// Largest plane gap (m).
    pub max_plane_gap: f64,
    /// Smallest overlap along the wall, as a fraction of the shorter patch's length.
    pub min_overlap: f64,
}

impl Default for WallGate {
    /// 10°, 1 m and half the shorter patch.
    fn default() -> Self {
        WallGate {
            max_angle: 10f64.to_radians(),
            max_plane_gap: 1.0,
            min_overlap: 0.5,
        }
    }
}

impl WallGate {
    /// Whether every gate can pass anything: positive, finite angle and gap, an overlap
    /// fraction in [0, 1].
    pub fn is_usable(&self) -> bool {
        self.max_angle > 0.0
            && self.max_angle.is_finite()
            && self.max_plane_gap > 0.0
            && self.max_plane_gap.is_finite()
            && (0.0..=1.0).contains(&self.min_overlap)
    }

    /// The cost of pairing `p` (predicted) with `s` (segmented), `None` when a gate forbids it.
    pub fn cost(&self, p: &PlanePatch, s: &PlanePatch) -> Option<f64> {
        let angle = p.plane.angle_to(&s.plane);
        if angle > self.max_angle {
            return None;
        }
        let gap = 0.5 * (p.plane.distance(&s.centre()) + s.plane.distance(&p.centre()));
        if !(gap <= self.max_plane_gap) {
            return None;
        }
        let overlap = overlap_along(p, s);
        if !(overlap >= self.min_overlap) {
            return None;
        }
        Some(angle / self.max_angle + gap / self.max_plane_gap + (1.0 - overlap))
    }
}

/// The share of the shorter of the two patches' extents along `p`'s wall that the other one
/// covers (see the module documentation), in [0, 1]; 0 for degenerate patches.
pub fn overlap_along(p: &PlanePatch, s: &PlanePatch) -> f64 {
    let horizontal = p.plane.normal.cross(&nalgebra::Vector3::z());
    let axis = if horizontal.norm() > 0.1 {
        horizontal.normalize()
    } else {
        let side = p.vertices[1] - p.vertices[0];
        if side.norm() == 0.0 {
            return 0.0;
        }
        side.normalize()
    };
    let span = |q: &PlanePatch| {
        q.vertices
            .iter()
            .map(|v| v.coords.dot(&axis))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                (lo.min(x), hi.max(x))
            })
    };
    let ((a0, a1), (b0, b1)) = (span(p), span(s));
    let shorter = (a1 - a0).min(b1 - b0);
    if !(shorter > 0.0) {
        return 0.0;
    }
    ((a1.min(b1) - a0.max(b0)) / shorter).clamp(0.0, 1.0)
}

/// Pairs predicted with segmented patches by a gated optimal assignment (see the module
/// documentation): returns `(predicted index, segmented index)` pairs, sorted by the
/// predicted index. A gate that is not usable ([`WallGate::is_usable`]) pairs nothing.
pub fn associate_planes(
    predicted: &[PlanePatch],
    segmented: &[PlanePatch],
    gate: &WallGate,
) -> Vec<(usize, usize)> {
    let (n, m) = (predicted.len(), segmented.len());
    if n == 0 || m == 0 || !gate.is_usable() {
        return Vec::new();
    }
    // Columns: the m segmented patches, then n "unpaired" columns.
    const MISS: f64 = 3.0 + 1e-9;
    let cols = m + n;
    let mut cost = vec![MISS; n * cols];
    for (i, p) in predicted.iter().enumerate() {
        for (j, s) in segmented.iter().enumerate() {
            cost[i * cols + j] = gate.cost(p, s).unwrap_or(f64::INFINITY);
        }
    }
    match crate::assignment::solve(&cost, n, cols) {
        Some((assign, _)) => assign
            .into_iter()
            .enumerate()
            .filter(|&(i, j)| j < m && cost[i * cols + j].is_finite())
            .collect(),
        None => Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Plane;
    use approx::assert_abs_diff_eq;
    use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

    fn unit_square() -> PlanePatch {
        let plane = Plane::new(Vector3::z(), 0.0).unwrap();
        PlanePatch {
            plane,
            vertices: [
                Point3::new(0.0, 0.0, 0.0),
                Point3::new(1.0, 0.0, 0.0),
                Point3::new(1.0, 1.0, 0.0),
                Point3::new(0.0, 1.0, 0.0),
            ],
            area: 1.0,
            extent: (1.0, 1.0),
        }
    }

    /// A 4 m × 3 m wall at distance `y` with its normal turned by `yaw` about z.
    fn wall(x: f64, y: f64, yaw: f64) -> PlanePatch {
        let base = PlanePatch {
            plane: Plane::new(Vector3::y(), -y).unwrap(),
            vertices: [
                Point3::new(x, y, 0.0),
                Point3::new(x + 4.0, y, 0.0),
                Point3::new(x + 4.0, y, 3.0),
                Point3::new(x, y, 3.0),
            ],
            area: 12.0,
            extent: (4.0, 3.0),
        };
        let c = base.centre();
        let about_centre =
            Isometry3::from_parts(Translation3::from(c.coords), UnitQuaternion::identity())
                * Isometry3::rotation(Vector3::z() * yaw)
                * Isometry3::from_parts(Translation3::from(-c.coords), UnitQuaternion::identity());
        base.transform(&about_centre)
    }

    #[test]
    fn shifted_unit_square_has_vertex_distances_of_the_shift() {
        let a = unit_square();
        let b = a.transform(&Isometry3::translation(0.0, 0.0, 0.1));
        let e = PlanePairError::between(3, &a, &b);
        for d in e.vertex_distances {
            assert_abs_diff_eq!(d, 0.1, epsilon = 1e-12);
        }
        assert_eq!(e.frame, 3);
        assert_abs_diff_eq!(e.normal_angle_rad, 0.0, epsilon = 1e-12);
        assert_eq!((e.predicted_area, e.segmented_area), (1.0, 1.0));
    }

    #[test]
    fn normals_ten_degrees_apart() {
        let a = wall(0.0, 5.0, 0.0);
        let b = wall(0.0, 5.0, 10f64.to_radians());
        let e = PlanePairError::between(0, &a, &b);
        assert_abs_diff_eq!(e.normal_angle_deg, 10.0, epsilon = 1e-9);
        assert_abs_diff_eq!(e.normal_angle_rad, 10f64.to_radians(), epsilon = 1e-12);
    }

    #[test]
    fn nearest_rank_percentiles() {
        let v = [15.0, 20.0, 35.0, 40.0, 50.0];
        assert_eq!(percentile(&v, 30.0), 20.0);
        assert_eq!(percentile(&v, 40.0), 20.0);
        assert_eq!(percentile(&v, 50.0), 35.0);
        assert_eq!(percentile(&v, 100.0), 50.0);
        assert_eq!(percentile(&v, 0.0), 15.0);
        let w: Vec<f64> = (1..=10).map(f64::from).rev().collect();
        assert_eq!(percentile(&w, 50.0), 5.0);
        assert_eq!(percentile(&w, 90.0), 9.0);
        assert!(percentile(&[], 50.0).is_nan());
    }

    #[test]
    fn summary_of_known_pairs() {
        let mk = |deg: f64, d: f64| PlanePairError {
            frame: 1,
            predicted_area: 1.0,
            segmented_area: 1.0,
            vertex_distances: [d; 4],
            normal_angle_rad: deg.to_radians(),
            normal_angle_deg: deg,
        };
        let pairs: Vec<_> = (1..=10).map(|i| mk(i as f64, i as f64 / 10.0)).collect();
        let s = PlanePredictionSummary::from_pairs(&pairs, &[1.0, 2.0, 6.0]);
        assert_eq!(s.pairs, 10);
        assert_eq!(s.median_normal_angle_deg, 5.0);
        assert_eq!(s.p90_normal_angle_deg, 9.0);
        // 40 vertex distances, each value 4 times: rank 20 → 0.5, rank 36 → 0.9.
        assert_eq!(s.median_vertex_distance_m, 0.5);
        assert_eq!(s.p90_vertex_distance_m, 0.9);
        assert_abs_diff_eq!(s.mean_prediction_ms, 3.0, epsilon = 1e-12);
        let empty = PlanePredictionSummary::from_pairs(&[], &[]);
        assert!(empty.median_normal_angle_deg.is_nan() && empty.mean_prediction_ms.is_nan());
        let m = PlanePairError::mean(&[mk(2.0, 0.2), mk(4.0, 0.4)]).unwrap();
        assert_abs_diff_eq!(m.normal_angle_deg, 3.0, epsilon = 1e-12);
        assert_abs_diff_eq!(m.vertex_distances[2], 0.3, epsilon = 1e-12);
    }

    #[test]
    fn association_is_optimal_and_gated() {
        let predicted = vec![
            wall(0.0, 5.0, 0.0),
            wall(10.0, 5.0, 0.0),
            wall(0.0, 40.0, 0.0),
        ];
        // Segmented in a different order, slightly moved; nothing near the third prediction,
        // and one extra segmented wall turned by 45°.
        let segmented = vec![
            wall(10.2, 5.1, 0.01),
            wall(0.0, 20.0, std::f64::consts::FRAC_PI_4),
            wall(-0.1, 5.0, 0.0),
        ];
        let gate = WallGate::default();
        let pairs = associate_planes(&predicted, &segmented, &gate);
        assert_eq!(pairs, vec![(0, 2), (1, 0)]);
        // More predictions than segmented patches works too.
        let pairs = associate_planes(&predicted, &segmented[..1], &gate);
        assert_eq!(pairs, vec![(1, 0)]);
        assert!(associate_planes(&predicted, &[], &gate).is_empty());
        let unusable = WallGate {
            max_angle: f64::NAN,
            ..gate
        };
        assert!(associate_planes(&predicted, &segmented, &unusable).is_empty());
    }

    /// A 6 m high stretch of the wall y = `y` from x = `x0` to `x1`.
    fn stretch(x0: f64, x1: f64, y: f64) -> PlanePatch {
        PlanePatch {
            plane: Plane::new(Vector3::y(), -y).unwrap(),
            vertices: [
                Point3::new(x0, y, 0.0),
                Point3::new(x1, y, 0.0),
                Point3::new(x1, y, 6.0),
                Point3::new(x0, y, 6.0),
            ],
            area: 6.0 * (x1 - x0),
            extent: (x1 - x0, 6.0),
        }
    }

    #[test]
    fn overlap_is_the_shared_length_over_the_shorter_stretch() {
        // [−13, 36] and [−2, 44] share [−2, 36]: 38 m of the shorter 46 m.
        let o = overlap_along(&stretch(-13.0, 36.0, 8.0), &stretch(-2.0, 44.0, 8.2));
        assert_abs_diff_eq!(o, 38.0 / 46.0, epsilon = 1e-12);
        // One inside the other: all of the shorter; end to end: nothing.
        assert_abs_diff_eq!(
            overlap_along(&stretch(0.0, 20.0, 8.0), &stretch(5.0, 10.0, 8.0)),
            1.0,
            epsilon = 1e-12
        );
        assert_eq!(
            overlap_along(&stretch(0.0, 10.0, 8.0), &stretch(12.0, 20.0, 8.0)),
            0.0
        );
    }

    #[test]
    fn two_views_of_one_long_wall_pair_and_parallel_or_separate_walls_do_not() {
        // One 50 m facade, its visible stretch moved on by the vehicle: centres 8 m apart.
        let seen_before = stretch(-13.0, 36.0, 8.0);
        let seen_now = stretch(-2.0, 44.0, 8.1);
        assert!((seen_before.centre() - seen_now.centre()).norm() > 8.0);
        let gate = WallGate::default();
        assert_eq!(
            associate_planes(&[seen_before.clone()], &[seen_now.clone()], &gate),
            vec![(0, 0)]
        );
        // The cost: θ = 0, g = 0.1 m, o = 38/46.
        let cost = gate.cost(&seen_before, &seen_now).unwrap();
        assert_abs_diff_eq!(cost, 0.1 + (1.0 - 38.0 / 46.0), epsilon = 1e-9);
        // A parallel wall 3 m behind, or the next building along the street, is not it.
        assert!(
            associate_planes(&[seen_before.clone()], &[stretch(-2.0, 44.0, 11.0)], &gate)
                .is_empty()
        );
        assert!(associate_planes(
            &[stretch(0.0, 10.0, 8.0)],
            &[stretch(12.0, 20.0, 8.0)],
            &gate
        )
        .is_empty());
    }
}
