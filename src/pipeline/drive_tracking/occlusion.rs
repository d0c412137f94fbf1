//! What a frame's clusters hide from the lidar: the occluders of a scan ([`ClusterOccluders`],
//! built from the frame's cluster boxes) and the share of a cluster track's silhouette that
//! they leave in view ([`ClusterOccluders::visible_share`]). The drive tracker hands the
//! occluders to its models with the update ([`crate::filter::LmbFilter::update_step_with`]),
//! and the cluster detection probability falls with the hidden share
//! ([`super::mixed::MixedDetection`]): a parked car behind the cars in front of it is not
//! expected to be detected in every frame, so the frames it is missed in do not cost it its
//! track.
//!
//! # The rule
//!
//! Each cluster of the frame, seen from the sensor (sensor frame, z up), covers an interval of
//! azimuth (its footprint's corners) and of elevation (from its lowest to its highest point,
//! taken at its nearest and farthest horizontal range so that the interval holds the whole
//! box), and lies at the horizontal range of its footprint's nearest point.
//!
//! A track's silhouette is the window of half-width asin(ρ / r) in azimuth about its bearing
//! and from z − h to z + h in height at its horizontal range r (its particles' mean, moved into
//! the sensor frame), sampled on a [`SAMPLES_AZIMUTH`] × [`SAMPLES_ELEVATION`] grid. A sample
//! is hidden when a cluster nearer than r − D covers it; D ([`OcclusionShape::depth`]) is
//! larger than the distance from a road user's box centre to its own nearest face (half a
//! car's length and the position's spread), so that a track's own cluster never hides it.
//! The visible share is the share of samples not hidden.
//!
//! The detection probability of the track is then p_D · (f + (1 − f) · visible share), with a
//! floor f ([`OcclusionShape::floor`]): the silhouettes are coarse (a box for an occluder, a
//! fixed window for the track), and a hidden car's roof or end often shows over or beside the
//! car in front; a track that could never be detected could not take such a detection either.
//!
//! Not for: occlusion by walls (segmented as planes, not clusters), the points themselves
//! (see [`crate::cloud::range_image`]), or the planar scanner's people (see
//! [`crate::pipeline::people_tracking::models::occlusion`]).

use super::detect::FrameDetections;
use crate::geometry::{wrap_angle, Box3};
use nalgebra::Point3;

/// Samples of a silhouette across its azimuth window.
pub const SAMPLES_AZIMUTH: usize = 9;
/// Samples of a silhouette across its height.
pub const SAMPLES_ELEVATION: usize = 5;

/// The silhouette of a cluster track and when it counts as hidden (see the module notes).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct OcclusionShape {
    /// Half-width ρ of the silhouette (m): half a car's width, about a pedestrian's stride.
    pub half_width: f64,
    /// Half-height h of the silhouette about the track's height (m).
    pub half_height: f64,
    /// An occluder must be nearer than the track by more than this (m): half a car's length
    /// (1.95 m, the class's mean length, [`crate::cloud::classes`]) and the measured centre's
    /// spread.
    pub depth: f64,
    /// Share of p_D a wholly hidden track keeps.
    pub floor: f64,
}

impl Default for OcclusionShape {
    fn default() -> Self {
        OcclusionShape {
            half_width: 0.8,
            half_height: 0.5,
            depth: 2.5,
            floor: 0.2,
        }
    }
}

/// One cluster as seen from the sensor.
#[derive(Copy, Clone, Debug, PartialEq)]
struct Occluder {
    /// Smallest azimuth of the footprint (rad).
    azimuth: f64,
    /// Azimuth span from there (rad, < π).
    span: f64,
    /// Elevation interval (rad).
    elevation: [f64; 2],
    /// Horizontal range of the footprint's nearest point (m).
    near: f64,
}

impl Occluder {
    /// The occluder of a box (sensor frame); `None` when the sensor stands inside its
    /// footprint or the box is not finite.
    fn of(b: &Box3) -> Option<Self> {
        let (s, c) = b.yaw.sin_cos();
        let [hl, hw] = [b.size[0] / 2.0, b.size[1] / 2.0];
        let centre = [b.center.x, b.center.y];
        // The sensor (origin) in the box's own axes.
        let local = [
            -(c * centre[0] + s * centre[1]),
            -(-s * centre[0] + c * centre[1]),
        ];
        let near = (local[0].abs() - hl)
            .max(0.0)
            .hypot((local[1].abs() - hw).max(0.0));
        if !(near > 0.0 && near.is_finite()) {
            return None;
        }
        let bearing = centre[1].atan2(centre[0]);
        let (mut lo, mut hi, mut far) = (f64::INFINITY, f64::NEG_INFINITY, 0.0f64);
        for (a, w) in [(hl, hw), (hl, -hw), (-hl, hw), (-hl, -hw)] {
            let x = centre[0] + c * a - s * w;
            let y = centre[1] + s * a + c * w;
            let d = wrap_angle(y.atan2(x) - bearing);
            lo = lo.min(d);
            hi = hi.max(d);
            far = far.max(x.hypot(y));
        }
        let (z_lo, z_hi) = (b.center.z - b.size[2] / 2.0, b.center.z + b.size[2] / 2.0);
        let el = |z: f64, r: f64| z.atan2(r);
        Some(Occluder {
            azimuth: bearing + lo,
            span: hi - lo,
            elevation: [
                el(z_lo, near).min(el(z_lo, far)),
                el(z_hi, near).max(el(z_hi, far)),
            ],
            near,
        })
    }

    fn covers(&self, azimuth: f64, elevation: f64) -> bool {
        let d = (azimuth - self.azimuth).rem_euclid(std::f64::consts::TAU);
        d <= self.span && (self.elevation[0]..=self.elevation[1]).contains(&elevation)
    }
}

/// The clusters of one frame as occluders (sensor frame), for the models of the step's
/// update (see the module notes).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ClusterOccluders {
    occluders: Vec<Occluder>,
}

impl ClusterOccluders {
    /// The occluders of the frame's clusters: each cluster's fitted box (the points' own
    /// bounding box at the fitted heading), or its axis-aligned bounds without one.
    pub fn of(detections: &FrameDetections) -> Self {
        Self::from_boxes(detections.clusters.iter().map(|d| match &d.shape {
            Some(s) => s.fitted,
            None => {
                let centre = Point3::from(std::array::from_fn::<f64, 3, _>(|i| {
                    (d.min[i] + d.max[i]) / 2.0
                }));
                Box3::new(centre, std::array::from_fn(|i| d.max[i] - d.min[i]), 0.0)
            }
        }))
    }

    /// The occluders of boxes in the sensor frame (boxes around the sensor are left out).
    pub fn from_boxes(boxes: impl IntoIterator<Item = Box3>) -> Self {
        ClusterOccluders {
            occluders: boxes.into_iter().filter_map(|b| Occluder::of(&b)).collect(),
        }
    }

    /// Number of occluders.
    pub fn len(&self) -> usize {
        self.occluders.len()
    }

    /// Whether there is none.
    pub fn is_empty(&self) -> bool {
        self.occluders.is_empty()
    }

    /// The share of the silhouette `shape` of an object at `position` (sensor frame) that no
    /// occluder nearer than its range less [`OcclusionShape::depth`] covers, in [0, 1]; 1 for
    /// an object within the silhouette's half-width of the sensor or at a position that is not
    /// finite.
    pub fn visible_share(&self, position: [f64; 3], shape: &OcclusionShape) -> f64 {
        let [x, y, z] = position;
        let r = x.hypot(y);
        if !(r > shape.half_width && z.is_finite()) {
            return 1.0;
        }
        let nearer = r - shape.depth;
        let half = (shape.half_width / r).asin();
        let bearing = y.atan2(x);
        let el = [
            (z - shape.half_height).atan2(r),
            (z + shape.half_height).atan2(r),
        ];
        let samples = grid(bearing - half, 2.0 * half, el);
        let mut covered = [false; SAMPLES_AZIMUTH * SAMPLES_ELEVATION];
        let front = self.occluders.iter().filter(|o| {
            o.near < nearer
                && o.elevation[1] >= el[0]
                && o.elevation[0] <= el[1]
                && overlaps(o, bearing - half, 2.0 * half)
        });
        for o in front {
            for (c, &(a, e)) in covered.iter_mut().zip(&samples) {
                *c = *c || o.covers(a, e);
            }
        }
        let hidden = covered.iter().filter(|&&c| c).count();
        let total = covered.len();
        1.0 - hidden as f64 / total as f64
    }
}

/// Whether `o`'s azimuth interval meets the interval from `start` over `span` (both < π).
fn overlaps(o: &Occluder, start: f64, span: f64) -> bool {
    let tau = std::f64::consts::TAU;
    let d = (start - o.azimuth).rem_euclid(tau);
    d <= o.span || tau - d <= span
}

/// The silhouette's sample directions (azimuth, elevation), cell centres of the grid.
fn grid(start: f64, span: f64, el: [f64; 2]) -> [(f64, f64); SAMPLES_AZIMUTH * SAMPLES_ELEVATION] {
    let mut out = [(0.0, 0.0); SAMPLES_AZIMUTH * SAMPLES_ELEVATION];
    for i in 0..SAMPLES_AZIMUTH {
        let a = start + span * (i as f64 + 0.5) / SAMPLES_AZIMUTH as f64;
        for j in 0..SAMPLES_ELEVATION {
            let e = el[0] + (el[1] - el[0]) * (j as f64 + 0.5) / SAMPLES_ELEVATION as f64;
            out[i * SAMPLES_ELEVATION + j] = (a, e);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn car(x: f64, y: f64, yaw: f64) -> Box3 {
        // A car standing on the road, the sensor 1.73 m above it.
        Box3::new(Point3::new(x, y, -1.73 + 0.75), [3.9, 1.6, 1.5], yaw)
    }

    const SHAPE: OcclusionShape = OcclusionShape {
        half_width: 0.8,
        half_height: 0.5,
        depth: 2.5,
        floor: 0.2,
    };

    #[test]
    fn a_car_behind_another_is_hidden_and_one_beside_it_is_not() {
        let front = ClusterOccluders::from_boxes([car(10.0, 0.0, 0.0)]);
        // Directly behind, along the ray, the same height: wholly hidden.
        assert_eq!(front.visible_share([20.0, 0.0, -0.98], &SHAPE), 0.0);
        // Off to the side by 10 m at 20 m: the front car spans ±~4.6° at 10 m, the object's
        // bearing is 26.6°: wholly in view.
        assert_eq!(front.visible_share([20.0, 10.0, -0.98], &SHAPE), 1.0);
        // In front of the occluder: nothing hides it.
        assert_eq!(front.visible_share([5.0, 0.0, -0.98], &SHAPE), 1.0);
        // Its own box never hides it: the object at the occluder's centre.
        assert_eq!(front.visible_share([10.0, 0.0, -0.98], &SHAPE), 1.0);
    }

    #[test]
    fn half_covered_by_the_edge_of_an_occluder() {
        // A car side-on at 10 m whose rear end lies on the bearing of an object at 30 m: the
        // occluder's azimuth interval ends at the object's bearing, so about half of the
        // azimuth samples (4 or 5 of 9 columns) are hidden.
        let edge = car(10.0, -1.95, 0.0); // spans y ∈ [−2.75, −1.15] … x ∈ [8.05, 11.95]
        let o = ClusterOccluders::from_boxes([edge]);
        // The bearing of the occluder's corner nearest the x axis, its largest azimuth.
        let a = (-1.15f64).atan2(11.95);
        let p = [30.0 * a.cos(), 30.0 * a.sin(), -1.2];
        let v = o.visible_share(p, &SHAPE);
        assert!((4.0 / 9.0..=5.0 / 9.0).contains(&v), "{v}");
    }

    #[test]
    fn over_a_low_occluder_the_top_shows() {
        // A low wall 0.6 m high at 8 m in front of a pedestrian-height object at 16 m: the
        // wall's top is seen at −7.4° at most (−1.13 m at 8.7 m); the silhouette spans
        // atan((−0.98 ∓ 0.5) / 16) = −5.3° … −1.7°: wholly above it.
        let wall = Box3::new(Point3::new(8.0, 0.0, -1.73 + 0.3), [0.3, 6.0, 0.6], 0.0);
        let o = ClusterOccluders::from_boxes([wall]);
        assert_eq!(o.visible_share([16.0, 0.0, -0.98], &SHAPE), 1.0);
    }

    #[test]
    fn wrap_around_the_rear_and_odd_positions() {
        // An occluder straddling azimuth ±π (behind the sensor) hides an object behind it.
        let o = ClusterOccluders::from_boxes([car(-10.0, 0.0, 0.0)]);
        assert_eq!(o.visible_share([-20.0, 0.0, -0.98], &SHAPE), 0.0);
        assert_eq!(o.visible_share([-20.0, 0.3, -0.98], &SHAPE), 0.0);
        // The sensor inside a box: no occluder.
        assert!(ClusterOccluders::from_boxes([car(0.5, 0.0, 0.0)]).is_empty());
        assert_eq!(o.visible_share([0.1, 0.0, 0.0], &SHAPE), 1.0);
        assert_eq!(o.visible_share([f64::NAN, 0.0, 0.0], &SHAPE), 1.0);
    }

    proptest::proptest! {
        #[test]
        fn the_visible_share_is_a_share_and_more_occluders_hide_more(
            boxes in proptest::collection::vec(
                (-40.0f64..40.0, -40.0f64..40.0, 0.0f64..3.2, 0.3f64..6.0, 0.3f64..3.0),
                0..40,
            ),
            px in -40.0f64..40.0, py in -40.0f64..40.0, pz in -2.0f64..1.0,
        ) {
            let all: Vec<Box3> = boxes
                .iter()
                .map(|&(x, y, yaw, l, w)| Box3::new(Point3::new(x, y, -1.0), [l, w, 1.5], yaw))
                .collect();
            let half = ClusterOccluders::from_boxes(all[..all.len() / 2].to_vec());
            let whole = ClusterOccluders::from_boxes(all);
            let v_half = half.visible_share([px, py, pz], &SHAPE);
            let v_whole = whole.visible_share([px, py, pz], &SHAPE);
            proptest::prop_assert!((0.0..=1.0).contains(&v_whole));
            proptest::prop_assert!(v_whole <= v_half);
        }
    }
}
