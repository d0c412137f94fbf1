//! Errors of an estimated trajectory against a reference, both as poses of each frame in the
//! frame of the first (frame k → frame 0):
//!
//! * relative pose errors (RPE) between consecutive frames: E_k = (Q_k⁻¹Q_{k+1})⁻¹(P_k⁻¹P_{k+1})
//!   for reference Q and estimate P, as a translation (m) and a rotation angle (°);
//! * the KITTI odometry benchmark's segment errors (Geiger et al., CVPR 2012, devkit
//!   `evaluate_odometry`): for every 10th first frame and every segment length
//!   100, 200, …, 800 m of reference path, the same relative error between the first frame
//!   and the first frame at least that far along, divided by the length; reported as a
//!   percentage (translation) and in °/100 m (rotation).

use crate::error::{Error, Result};
use nalgebra::Isometry3;

/// The segment lengths of the KITTI odometry benchmark, metres.
pub const KITTI_SEGMENT_LENGTHS: [f64; 8] =
    [100.0, 200.0, 300.0, 400.0, 500.0, 600.0, 700.0, 800.0];

/// Error of one relative motion.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct PoseError {
    /// Norm of the translation error, metres.
    pub translation: f64,
    /// Angle of the rotation error, degrees.
    pub rotation_deg: f64,
}

/// Mean, median and maximum of a list of values.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Spread {
    /// Arithmetic mean.
    pub mean: f64,
    /// Median (mean of the two middle values for an even count).
    pub median: f64,
    /// Largest value.
    pub max: f64,
}

impl Spread {
    /// The spread of `values`; `None` when empty.
    pub fn of(values: &[f64]) -> Option<Spread> {
        if values.is_empty() {
            return None;
        }
        let mut v = values.to_vec();
        v.sort_by(f64::total_cmp);
        let n = v.len();
        let median = if n % 2 == 1 {
            v[n / 2]
        } else {
            0.5 * (v[n / 2 - 1] + v[n / 2])
        };
        Some(Spread {
            mean: v.iter().sum::<f64>() / n as f64,
            median,
            max: v[n - 1],
        })
    }
}

/// The error of the estimated motion from frame `a` to `b` against the reference's.
pub fn motion_error(
    estimate: &[Isometry3<f64>],
    reference: &[Isometry3<f64>],
    a: usize,
    b: usize,
) -> PoseError {
    let q = reference[a].inverse() * reference[b];
    let p = estimate[a].inverse() * estimate[b];
    let e = q.inverse() * p;
    PoseError {
        translation: e.translation.vector.norm(),
        rotation_deg: e.rotation.angle().to_degrees(),
    }
}

/// Relative pose errors between consecutive frames (one fewer than the poses).
///
/// Errors: the reference holds fewer poses than the estimate.
pub fn relative_pose_errors(
    estimate: &[Isometry3<f64>],
    reference: &[Isometry3<f64>],
) -> Result<Vec<PoseError>> {
    ensure_covered(estimate, reference)?;
    Ok((1..estimate.len())
        .map(|k| motion_error(estimate, reference, k - 1, k))
        .collect())
}

/// Length of the path through the poses' positions, metres.
pub fn path_length(poses: &[Isometry3<f64>]) -> f64 {
    poses
        .windows(2)
        .map(|w| (w[1].translation.vector - w[0].translation.vector).norm())
        .sum()
}

/// KITTI's averaged segment errors.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct SegmentErrors {
    /// Mean translation error over all segments, percent of the segment length.
    pub translation_percent: f64,
    /// Mean rotation error over all segments, degrees per 100 m.
    pub rotation_deg_per_100m: f64,
    /// Number of segments evaluated.
    pub segments: usize,
}

/// KITTI's segment errors over the lengths `lengths` (usually [`KITTI_SEGMENT_LENGTHS`]),
/// starting every 10th frame as the devkit does; `Ok(None)` when the reference path is shorter
/// than the shortest length.
///
/// Errors: the reference holds fewer poses than the estimate.
pub fn segment_errors(
    estimate: &[Isometry3<f64>],
    reference: &[Isometry3<f64>],
    lengths: &[f64],
) -> Result<Option<SegmentErrors>> {
    ensure_covered(estimate, reference)?;
    let n = estimate.len();
    let mut dist = vec![0.0; n];
    for k in 1..n {
        dist[k] = dist[k - 1]
            + (reference[k].translation.vector - reference[k - 1].translation.vector).norm();
    }
    let (mut t_sum, mut r_sum, mut count) = (0.0, 0.0, 0usize);
    for first in (0..n).step_by(10) {
        for &len in lengths {
            let Some(last) = (first..n).find(|&k| dist[k] > dist[first] + len) else {
                continue;
            };
            let e = motion_error(estimate, reference, first, last);
            t_sum += e.translation / len;
            r_sum += e.rotation_deg / len;
            count += 1;
        }
    }
    if count == 0 {
        return Ok(None);
    }
    Ok(Some(SegmentErrors {
        translation_percent: 100.0 * t_sum / count as f64,
        rotation_deg_per_100m: 100.0 * r_sum / count as f64,
        segments: count,
    }))
}

fn ensure_covered(estimate: &[Isometry3<f64>], reference: &[Isometry3<f64>]) -> Result<()> {
    if reference.len() < estimate.len() {
        return Err(Error::invalid(
            "reference trajectory",
            format!(
                "{} poses for {} estimated ones",
                reference.len(),
                estimate.len()
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    fn straight(n: usize, step: f64) -> Vec<Isometry3<f64>> {
        (0..n)
            .map(|k| Isometry3::translation(step * k as f64, 0.0, 0.0))
            .collect()
    }

    #[test]
    fn a_scaled_trajectory_has_the_scale_error_everywhere() {
        let truth = straight(301, 1.0);
        let est = straight(301, 1.01);
        let rpe = relative_pose_errors(&est, &truth).unwrap();
        assert_eq!(rpe.len(), 300);
        assert!(rpe.iter().all(|e| (e.translation - 0.01).abs() < 1e-9));
        let s = segment_errors(&est, &truth, &KITTI_SEGMENT_LENGTHS)
            .unwrap()
            .unwrap();
        // Segments end at the first frame strictly past the length (101 m for 100 m, ...):
        // the mean over the 30 segments of 1 % × (L + 1) / L.
        let mut expected = 0.0;
        let mut count = 0;
        for first in (0..301).step_by(10) {
            for len in KITTI_SEGMENT_LENGTHS {
                if first as f64 + len < 300.0 {
                    expected += (len + 1.0) / len;
                    count += 1;
                }
            }
        }
        assert_eq!(s.segments, count);
        assert!(
            (s.translation_percent - expected / count as f64).abs() < 1e-9,
            "{s:?}"
        );
        assert_eq!(s.rotation_deg_per_100m, 0.0);
        assert_eq!(path_length(&truth), 300.0);
    }

    #[test]
    fn short_paths_have_no_segment_errors_and_short_references_are_refused() {
        let truth = straight(50, 0.35);
        assert_eq!(
            segment_errors(&truth, &truth, &KITTI_SEGMENT_LENGTHS).unwrap(),
            None
        );
        let e = relative_pose_errors(&truth, &truth[..10])
            .unwrap_err()
            .to_string();
        assert!(e.contains("10 poses for 50"), "{e}");
    }

    #[test]
    fn a_rotation_error_is_reported_in_degrees() {
        let truth = straight(2, 1.0);
        let mut est = truth.clone();
        est[1] = Isometry3::new(
            Vector3::new(1.0, 0.0, 0.0),
            Vector3::new(0.0, 0.0, 1f64.to_radians()),
        );
        let e = relative_pose_errors(&est, &truth).unwrap()[0];
        assert!((e.rotation_deg - 1.0).abs() < 1e-9);
        assert!(e.translation < 1e-12);
        let s = Spread::of(&[3.0, 1.0, 2.0, 10.0]).unwrap();
        assert_eq!((s.mean, s.median, s.max), (4.0, 2.5, 10.0));
    }
}
