//! Variations of a recorded scan for training the leg classifier ([`super::legs`]) on more
//! than the recordings show: the scene mirrored, the scene scaled, and the scan at a coarser
//! angular resolution. Each maps a scan onto another scan of the same scanner (same time)
//! and a point of the scene (an annotated leg) onto its place in the new scan, so that
//! candidates keep their labels.
//!
//! - [`Augmentation::Mirror`]: the scene mirrored about the scanner's x axis (`y → −y`); the
//!   beams run in the opposite order over the mirrored bearings, so the scanner's sense of
//!   rotation is kept and the beam order across the scene is reversed.
//! - [`Augmentation::Scale`]: every range times a factor (`p → s·p`): a scene of larger or
//!   smaller things, farther or nearer, seen with the same beams (a leg 20 % farther that is
//!   also 20 % thicker, with as many returns).
//! - [`Augmentation::Subsample`]: every `stride`th beam from `offset` on: the same scene at
//!   `stride` times the angular step.
//!
//! Not for: simulating a scanner's noise, or scenes that change over time.

use super::scan::Scan;
use crate::error::{Error, Result};
use crate::geometry::Pose2;

/// One variation of a scan (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Augmentation {
    /// The scan as recorded.
    Identity,
    /// The scene mirrored about the x axis, beams in reversed order.
    Mirror,
    /// Every range (and the range limits) times this factor (finite, > 0).
    Scale(f64),
    /// Every `stride`th beam (≥ 1) from beam `offset` (< `stride`) on.
    Subsample {
        /// Beams kept: one in this many.
        stride: usize,
        /// First beam kept.
        offset: usize,
    },
}

impl Augmentation {
    /// Checks the parameters: a finite positive scale, a stride ≥ 1 and an offset below it.
    pub fn validate(&self) -> Result<()> {
        match *self {
            Augmentation::Scale(s) if !(s.is_finite() && s > 0.0) => Err(Error::invalid(
                "scan augmentation",
                format!("scale {s} (must be finite and > 0)"),
            )),
            Augmentation::Subsample { stride, offset } if stride == 0 || offset >= stride => {
                Err(Error::invalid(
                    "scan augmentation",
                    format!("stride {stride}, offset {offset} (need 0 ≤ offset < stride)"),
                ))
            }
            _ => Ok(()),
        }
    }

    /// The varied scan. Errors on bad parameters, or when subsampling leaves no beam.
    pub fn apply(&self, scan: &Scan) -> Result<Scan> {
        self.validate()?;
        let n = scan.len();
        let mut out = match *self {
            Augmentation::Identity => scan.clone(),
            Augmentation::Mirror => {
                let mut ranges = scan.ranges.clone();
                ranges.reverse();
                Scan {
                    angle_min: -scan.angle_max(),
                    ranges,
                    odometry: scan.odometry.map(mirror_pose),
                    laser_pose: scan.laser_pose.map(mirror_pose),
                    ..scan.clone()
                }
            }
            Augmentation::Scale(s) => Scan {
                ranges: scan
                    .ranges
                    .iter()
                    .map(|&r| (f64::from(r) * s) as f32)
                    .collect(),
                range_min: scan.range_min * s,
                range_max: scan.range_max * s,
                ..scan.clone()
            },
            Augmentation::Subsample { stride, offset } => {
                if offset >= n {
                    return Err(Error::invalid(
                        "scan augmentation",
                        format!("offset {offset} beyond the scan's {n} beams"),
                    ));
                }
                Scan {
                    angle_min: scan.bearing(offset),
                    angle_increment: scan.angle_increment * stride as f64,
                    ranges: scan.ranges[offset..]
                        .iter()
                        .step_by(stride)
                        .copied()
                        .collect(),
                    ..scan.clone()
                }
            }
        };
        if let Augmentation::Scale(s) = *self {
            out.odometry = scan.odometry.map(|p| scale_pose(p, s));
            out.laser_pose = scan.laser_pose.map(|p| scale_pose(p, s));
        }
        out.validate()?;
        Ok(out)
    }

    /// Where a point of the scene (sensor frame) lies in the varied scan.
    pub fn map_point(&self, p: [f64; 2]) -> [f64; 2] {
        match *self {
            Augmentation::Mirror => [p[0], -p[1]],
            Augmentation::Scale(s) => [s * p[0], s * p[1]],
            Augmentation::Identity | Augmentation::Subsample { .. } => p,
        }
    }
}

fn mirror_pose(p: Pose2) -> Pose2 {
    Pose2 {
        x: p.x,
        y: -p.y,
        theta: -p.theta,
    }
}

fn scale_pose(p: Pose2, s: f64) -> Pose2 {
    Pose2 {
        x: s * p.x,
        y: s * p.y,
        theta: p.theta,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::laser2d::legs::{leg_segments, LegDetectorConfig, NUM_LEG_FEATURES};
    use proptest::prelude::*;

    /// A wall at 4 m with leg-sized discs (radius 6 cm) at `discs`, `n` beams from −0.7 rad.
    fn scene(n: usize, inc: f64, discs: &[[f64; 2]]) -> Scan {
        let a0 = -0.7f64;
        let ranges = (0..n)
            .map(|i| {
                let b = a0 + inc * i as f64;
                let (dx, dy) = (b.cos(), b.sin());
                let mut r = 4.0 / dx;
                for &[cx, cy] in discs {
                    let t = cx * dx + cy * dy;
                    let d2 = cx * cx + cy * cy - t * t;
                    if d2 < 0.06 * 0.06 {
                        r = r.min(t - (0.06 * 0.06 - d2).sqrt());
                    }
                }
                if i % 97 == 5 {
                    f32::INFINITY
                } else {
                    r as f32
                }
            })
            .collect();
        Scan::new(1.5, a0, inc, ranges, 0.05, 30.0).unwrap()
    }

    fn points(s: &Scan) -> Vec<[f64; 2]> {
        s.points().map(|(_, p)| p).collect()
    }

    #[test]
    fn a_mirrored_scan_gives_the_mirrored_candidates_with_the_same_features() {
        let s = scene(401, 0.0035, &[[2.0, 0.0], [2.0, 0.25], [1.5, -0.6]]);
        let m = Augmentation::Mirror.apply(&s).unwrap();
        assert_eq!(m.len(), s.len());
        // Every return mirrored, in reversed order.
        let (p, mut q) = (points(&s), points(&m));
        q.reverse();
        assert_eq!(p.len(), q.len());
        for (a, b) in p.iter().zip(&q) {
            let back = Augmentation::Mirror.map_point(*b);
            assert!((a[0] - back[0]).abs() < 1e-9 && (a[1] - back[1]).abs() < 1e-9);
        }
        let cfg = LegDetectorConfig::default();
        let a = leg_segments(&s, &cfg, &|_| [0.0, 0.0]).unwrap();
        let mut b = leg_segments(&m, &cfg, &|_| [0.0, 0.0]).unwrap();
        b.reverse();
        assert_eq!(a.len(), b.len());
        assert!(a.len() >= 3, "{a:?}");
        for (x, y) in a.iter().zip(&b) {
            let c = Augmentation::Mirror.map_point(x.centroid);
            assert!((c[0] - y.centroid[0]).abs() < 1e-9 && (c[1] - y.centroid[1]).abs() < 1e-9);
            for k in 0..NUM_LEG_FEATURES {
                assert!(
                    (x.features[k] - y.features[k]).abs() < 1e-9,
                    "feature {k}: {} against {}",
                    x.features[k],
                    y.features[k]
                );
            }
        }
    }

    #[test]
    fn a_scaled_scan_scales_lengths_and_keeps_counts_and_angles() {
        let s = scene(401, 0.0035, &[[2.0, 0.0], [2.0, 0.25]]);
        let m = Augmentation::Scale(1.2).apply(&s).unwrap();
        assert_eq!(m.valid_count(), s.valid_count());
        let cfg = LegDetectorConfig::default();
        let a = leg_segments(&s, &cfg, &|_| [0.0, 0.0]).unwrap();
        let b = leg_segments(&m, &cfg, &|_| [0.0, 0.0]).unwrap();
        let near = |c: &[crate::laser2d::legs::LegCandidate], r: f64| {
            c.iter()
                .filter(|c| c.features[13] < r)
                .cloned()
                .collect::<Vec<_>>()
        };
        let (a, b) = (near(&a, 3.0), near(&b, 3.6));
        assert_eq!(a.len(), 2);
        assert_eq!(a.len(), b.len());
        for (x, y) in a.iter().zip(&b) {
            let c = Augmentation::Scale(1.2).map_point(x.centroid);
            assert!((c[0] - y.centroid[0]).abs() < 1e-5 && (c[1] - y.centroid[1]).abs() < 1e-5);
            // Points and mean angular difference unchanged; width, radius, range scaled.
            assert_eq!(x.features[0], y.features[0]);
            assert!((x.features[12] - y.features[12]).abs() < 1e-4);
            for k in [5, 8, 13] {
                assert!(
                    (1.2 * x.features[k] - y.features[k]).abs() < 1e-4,
                    "feature {k}"
                );
            }
        }
    }

    #[test]
    fn a_subsampled_scan_keeps_the_bearings_of_its_beams() {
        let s = scene(401, 0.0035, &[[2.0, 0.0]]);
        let h = Augmentation::Subsample {
            stride: 2,
            offset: 1,
        }
        .apply(&s)
        .unwrap();
        assert_eq!(h.len(), 200);
        for i in 0..h.len() {
            assert!((h.bearing(i) - s.bearing(2 * i + 1)).abs() < 1e-12);
            assert_eq!(h.ranges[i], s.ranges[2 * i + 1]);
        }
        assert!(Augmentation::Subsample {
            stride: 2,
            offset: 2
        }
        .apply(&s)
        .is_err());
        assert!(Augmentation::Scale(0.0).apply(&s).is_err());
        assert!(Augmentation::Scale(f64::NAN).apply(&s).is_err());
        assert_eq!(Augmentation::Identity.apply(&s).unwrap(), s);
    }

    proptest! {
        /// Mirroring twice gives the scan back, and its returns are the mirrored returns.
        #[test]
        fn mirroring_is_an_involution(
            ranges in prop::collection::vec(0.0f32..12.0, 3..60),
            a0 in -2.0f64..0.0,
            inc in 0.001f64..0.05,
            s in 0.5f64..2.0,
        ) {
            let scan = Scan::new(0.0, a0, inc, ranges, 0.05, 10.0).unwrap();
            let m = Augmentation::Mirror.apply(&scan).unwrap();
            let back = Augmentation::Mirror.apply(&m).unwrap();
            prop_assert_eq!(&back.ranges, &scan.ranges);
            prop_assert!((back.angle_min - scan.angle_min).abs() < 1e-9);
            let mut q = points(&m);
            q.reverse();
            let p = points(&scan);
            prop_assert_eq!(p.len(), q.len());
            for (a, b) in p.iter().zip(&q) {
                let b = Augmentation::Mirror.map_point(*b);
                prop_assert!((a[0] - b[0]).abs() < 1e-6 && (a[1] - b[1]).abs() < 1e-6);
            }
            // Scaling keeps which beams return and scales their points.
            let z = Augmentation::Scale(s).apply(&scan).unwrap();
            prop_assert_eq!(z.valid_count(), scan.valid_count());
            for ((i, a), (j, b)) in scan.points().zip(z.points()) {
                prop_assert_eq!(i, j);
                let a = Augmentation::Scale(s).map_point(a);
                prop_assert!((a[0] - b[0]).abs() < 1e-4 && (a[1] - b[1]).abs() < 1e-4);
            }
        }
    }
}
