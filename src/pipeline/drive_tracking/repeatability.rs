//! How far the tracked walls move between consecutive frames: seed 001's errors (area, vertex
//! distances, normal angle) of each confirmed wall at frame k, moved into frame k + 1 with the
//! recorded ego motion, against the same label's wall at k + 1 — prediction against the
//! *tracked* wall, beside the paper's prediction against the next frame's segment (see
//! [`crate::pipeline::plane_prediction`]).
//!
//! Both walls are compared in the world frame of the tracks (`vertices_world`), where the
//! recorded motion is already applied and a static wall's prediction is the wall itself.
//!
//! Not for: running the tracker, or comparing against ground truth.

use super::output::{DriveTracks, TrackedPlane};
use crate::geometry::{Plane, PlanePatch};
use crate::metrics::PlanePairError;
use nalgebra::Point3;

/// The world-frame patch of a tracked wall, when it has corners that span a plane.
fn world_patch(p: &TrackedPlane) -> Option<PlanePatch> {
    let v = p.vertices_world?.map(|c| Point3::new(c[0], c[1], c[2]));
    let (a, b) = (v[1] - v[0], v[3] - v[0]);
    let plane = Plane::from_point_normal(&v[0], a.cross(&b)).ok()?;
    Some(PlanePatch {
        plane,
        vertices: v,
        area: a.norm() * b.norm(),
        extent: (a.norm(), b.norm()),
    })
}

/// For every pair of consecutive frames and every label confirmed with corners in both, the
/// errors of the wall at k (the prediction) against the wall at k + 1, attributed to k + 1.
/// Frames whose numbers are not consecutive are not paired.
pub fn tracked_wall_pairs(tracks: &DriveTracks) -> Vec<PlanePairError> {
    let mut out = Vec::new();
    for w in tracks.frames.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        if b.frame != a.frame + 1 {
            continue;
        }
        for next in &b.planes {
            let Some(prev) = a.planes.iter().find(|p| p.label == next.label) else {
                continue;
            };
            if let (Some(pred), Some(seen)) = (world_patch(prev), world_patch(next)) {
                out.push(PlanePairError::between(b.frame, &pred, &seen));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::filter::Label;
    use crate::pipeline::drive_tracking::output::{StageTimes, TrackedFrame, TrackingSummary};

    fn wall(label: Label, x0: f64, yaw_deg: f64) -> TrackedPlane {
        // A 10 m × 3 m wall starting at (x0, 5, 0), turned by `yaw_deg` about z.
        let (s, c) = yaw_deg.to_radians().sin_cos();
        let corner = |u: f64, z: f64| [x0 + c * u, 5.0 + s * u, z];
        TrackedPlane {
            id: 1,
            label,
            normal: [0.0, 1.0, 0.0],
            offset: 5.0,
            vertices: None,
            vertices_world: Some([
                corner(0.0, 0.0),
                corner(10.0, 0.0),
                corner(10.0, 3.0),
                corner(0.0, 3.0),
            ]),
            area: 30.0,
            existence: 1.0,
            detection: None,
        }
    }

    fn frame(frame: usize, planes: Vec<TrackedPlane>) -> TrackedFrame {
        TrackedFrame {
            frame,
            time: frame as f64 * 0.1,
            ego_position: [0.0; 3],
            ego_yaw: 0.0,
            detected_planes: planes.len(),
            detected_clusters: 0,
            planes,
            clusters: Vec::new(),
            times: StageTimes::default(),
        }
    }

    #[test]
    fn same_label_in_consecutive_frames_is_paired_and_scored() {
        let (l1, l2) = (Label::new(0, 0), Label::new(0, 1));
        let frames = vec![
            frame(3, vec![wall(l1, 0.0, 0.0), wall(l2, 20.0, 0.0)]),
            // l1 slid 0.2 m along itself and turned by 1°; l2 gone; a new label appears.
            frame(
                4,
                vec![wall(l1, 0.2, 1.0), wall(Label::new(4, 0), 40.0, 0.0)],
            ),
            // A gap in the frame numbers: not paired with frame 4.
            frame(6, vec![wall(l1, 0.2, 1.0)]),
        ];
        let tracks = DriveTracks {
            drive: "test".into(),
            seed: 1,
            particles: 10,
            ego: "oxts".into(),
            summary: TrackingSummary::of(&frames),
            frames,
        };
        let pairs = tracked_wall_pairs(&tracks);
        assert_eq!(pairs.len(), 1);
        let p = &pairs[0];
        assert_eq!(p.frame, 4);
        assert!((p.normal_angle_deg - 1.0).abs() < 1e-9, "{p:?}");
        assert!((p.predicted_area - 30.0).abs() < 1e-9);
        // The start corners are 0.2 m apart; the far corners also swing by 10 m × 1°.
        assert!((p.vertex_distances[0] - 0.2).abs() < 1e-9, "{p:?}");
        let swing = (10.0 - (10.0f64 * 1f64.to_radians().cos() + 0.2))
            .hypot(10.0 * 1f64.to_radians().sin());
        assert!((p.vertex_distances[1] - swing).abs() < 1e-9, "{p:?}");
    }
}
