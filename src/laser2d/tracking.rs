//! People tracking from planar scans with the particle LMB filter: each scan is segmented
//! (adaptive breakpoints), segments of person size become range-bearing measurements of the
//! person's centre, and the filter — constant velocity (seed 000, eqs. 6–8), range-bearing from
//! a sensor mounted at (a, b) on the robot's odometry pose (eqs. 10–11), a field-of-view
//! detection probability, adaptive birth — follows them with labels.
//!
//! Not for: deciding which segments belong to moving objects on a cluttered map (background
//! attenuation and shape learning), or the baseline trackers.

use super::{segment_scan, BreakpointConfig, Scan, Segment};
use crate::config::{
    BirthConfig, ClutterConfig, DetectionConfig, MeasurementConfig, RunConfig, TransitionConfig,
};
use crate::error::Result;
use crate::filter::{AssociationMethod, Estimate, Frame, LmbConfig, LmbFilter, Measurements};
use crate::models::BearingConvention;
use crate::rng::{seeded, FilterRng};
use nalgebra::{Isometry3, Vector3};

/// What counts as a person and how they are tracked.
#[derive(Clone, Debug, PartialEq)]
pub struct PeopleTrackerConfig {
    /// Scan segmentation.
    pub breakpoint: BreakpointConfig,
    /// Segments wider than this (m) are not people. Default 0.8 m.
    pub max_width: f64,
    /// Groups with fewer points are ignored. Default 2.
    pub min_points: usize,
    /// Neighbouring segments closer than this (m) are one group. Default 0.6 m.
    pub merge_gap: f64,
    /// A segment's middle point lies on the body surface; the centre is this much (m) farther
    /// along the beam. Default 0.2 m.
    pub body_radius: f64,
    /// The filter: models and tuning (state [x, ẋ, y, ẏ] in the world frame).
    pub filter: RunConfig,
}

impl PeopleTrackerConfig {
    /// Defaults for a scanner with range noise `sigma_range` (m), bearing noise
    /// `sigma_bearing` (rad), `max_range` (m), a field of view of ±`half_angle` (rad), mounted
    /// at `mount` = (a, b) on the robot.
    pub fn for_scanner(
        sigma_range: f64,
        sigma_bearing: f64,
        max_range: f64,
        half_angle: f64,
        mount: [f64; 2],
    ) -> Self {
        PeopleTrackerConfig {
            // Breakpoints at the scanner's own range noise, or a person's noisy outline splits.
            breakpoint: BreakpointConfig {
                sigma_r: sigma_range.max(BreakpointConfig::default().sigma_r),
                ..BreakpointConfig::default()
            },
            max_width: 0.8,
            min_points: 2,
            merge_gap: 0.6,
            body_radius: 0.2,
            filter: RunConfig {
                seed: 0,
                survival: 0.99,
                filter: LmbConfig {
                    particles: 500,
                    ..LmbConfig::default()
                },
                transition: TransitionConfig::ConstantVelocity {
                    dims: 2,
                    sigma_accel: 1.0,
                },
                measurement: MeasurementConfig::RangeBearing {
                    sigma_range: sigma_range.max(0.05),
                    sigma_bearing: sigma_bearing.max(0.005),
                    offset: mount,
                    convention: BearingConvention::FromXAxis,
                },
                detection: DetectionConfig::FieldOfView {
                    p_inside: 0.9,
                    p_outside: 0.0,
                    max_range,
                    half_angle,
                    offset: mount,
                },
                clutter: ClutterConfig {
                    rate: 1.0,
                    volume: 2.0 * half_angle * max_range,
                },
                birth: BirthConfig::Adaptive {
                    expected_births: 0.2,
                    max_existence: 0.2,
                    particles: 500,
                    position_std: 0.2,
                    velocity_std: 0.8,
                    turn_rate_std: 0.0,
                },
                association: AssociationMethod::default(),
            },
        }
    }
}

fn root(owner: &mut [usize], mut i: usize) -> usize {
    while owner[i] != i {
        owner[i] = owner[owner[i]];
        i = owner[i];
    }
    i
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Turns scans into labelled people estimates.
#[derive(Debug)]
pub struct PeopleTracker {
    config: PeopleTrackerConfig,
    filter: LmbFilter,
    rng: FilterRng,
}

impl PeopleTracker {
    /// A tracker; the filter's random stream is seeded from `config.filter.seed`.
    pub fn new(config: PeopleTrackerConfig) -> Result<Self> {
        let filter = config.filter.build()?;
        let rng = seeded(config.filter.seed);
        Ok(PeopleTracker {
            config,
            filter,
            rng,
        })
    }

    /// The point groups of `scan` that look like people (see [`person_segments`]).
    pub fn person_segments(&self, scan: &Scan) -> Result<Vec<Vec<[f64; 2]>>> {
        person_segments(&self.config, scan)
    }

    /// Range-bearing measurements of the people's centres (see [`person_measurements`]).
    pub fn measurements(&self, scan: &Scan) -> Result<Measurements> {
        person_measurements(&self.config, scan)
    }

    /// One scan: segment, measure, filter. The robot pose is the scan's odometry (the world
    /// origin when the scan has none).
    pub fn step(&mut self, scan: &Scan) -> Result<Vec<Estimate>> {
        let measurements = self.measurements(scan)?;
        let platform = scan
            .odometry
            .map(|p| Isometry3::new(Vector3::new(p.x, p.y, 0.0), Vector3::new(0.0, 0.0, p.theta)));
        self.filter.step(
            &Frame {
                time: scan.time,
                measurements,
                platform,
            },
            &mut self.rng,
        )
    }

    /// The underlying filter.
    pub fn filter(&self) -> &LmbFilter {
        &self.filter
    }
}

// Scan → measurements, shared by the filter above and by the baseline trackers
// (`crate::trackers`), which must see exactly the same measurements.

/// The point groups of `scan` that look like people: breakpoint segments, with
/// neighbouring segments merged while their gap is below `merge_gap` and the merged group
/// stays within `max_width` (range noise splits a person's outline into pieces), then
/// filtered by size.
pub fn person_segments(config: &PeopleTrackerConfig, scan: &Scan) -> Result<Vec<Vec<[f64; 2]>>> {
    let mut groups: Vec<Vec<[f64; 2]>> = Vec::new();
    let mut previous: Option<Segment> = None;
    for s in segment_scan(scan, &config.breakpoint)? {
        let merge = match (&previous, groups.last()) {
            (Some(p), Some(g)) => {
                p.beams.end + 1 >= s.beams.start
                    && dist(p.last, s.first) <= config.merge_gap
                    && dist(g[0], s.last) <= config.max_width
            }
            _ => false,
        };
        if merge {
            groups
                .last_mut()
                .expect("merging into a group")
                .extend_from_slice(&s.points);
        } else {
            groups.push(s.points.clone());
        }
        previous = Some(s);
    }
    Ok(groups
        .into_iter()
        .filter(|g| g.len() >= config.min_points && dist(g[0], g[g.len() - 1]) <= config.max_width)
        .collect())
}

/// Range-bearing measurements (sensor frame, bearing from the sensor's x axis) of the
/// people's centres. Groups whose point means lie within `merge_gap` of each other are one
/// person (single linkage: noise can split an outline into pieces that are not neighbours
/// in the scan when another person's beams fall between them); each person's centre is the
/// mean of its points pushed `body_radius` farther along the beam.
pub fn person_measurements(config: &PeopleTrackerConfig, scan: &Scan) -> Result<Measurements> {
    let groups = person_segments(config, scan)?;
    let stats: Vec<(f64, f64, f64)> = groups
        .iter()
        .map(|g| {
            let n = g.len() as f64;
            let (x, y) = g
                .iter()
                .fold((0.0, 0.0), |(sx, sy), p| (sx + p[0] / n, sy + p[1] / n));
            (x, y, n)
        })
        .collect();
    let mut owner: Vec<usize> = (0..stats.len()).collect();
    for i in 0..stats.len() {
        for j in 0..i {
            if dist([stats[i].0, stats[i].1], [stats[j].0, stats[j].1]) <= config.merge_gap {
                let (a, b) = (root(&mut owner, i), root(&mut owner, j));
                owner[a.max(b)] = a.min(b);
            }
        }
    }
    let mut merged: Vec<(f64, f64, f64)> = vec![(0.0, 0.0, 0.0); stats.len()];
    for (i, &(x, y, n)) in stats.iter().enumerate() {
        let m = &mut merged[root(&mut owner, i)];
        *m = (m.0 + x * n, m.1 + y * n, m.2 + n);
    }
    let rows: Vec<[f64; 2]> = merged
        .into_iter()
        .filter(|m| m.2 > 0.0)
        .map(|(sx, sy, n)| {
            let (x, y) = (sx / n, sy / n);
            [x.hypot(y) + config.body_radius, y.atan2(x)]
        })
        .collect();
    Measurements::from_rows(2, &rows)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::laser2d::Pose2;

    /// A person (disc of radius 0.2 m) walking across in front of a static scanner, rendered
    /// exactly into 361 beams over 180°.
    fn scan_with_person(t: f64, px: f64, py: f64) -> Scan {
        let n = 361;
        let inc = std::f64::consts::PI / (n - 1) as f64;
        let ranges: Vec<f32> = (0..n)
            .map(|i| {
                let a = -std::f64::consts::FRAC_PI_2 + i as f64 * inc;
                let (dx, dy) = (a.cos(), a.sin());
                // ray–circle: |s·d − p|² = r²
                let b = dx * px + dy * py;
                let c = px * px + py * py - 0.04;
                let disc = b * b - c;
                if disc >= 0.0 && b - disc.sqrt() > 0.0 {
                    (b - disc.sqrt()) as f32
                } else {
                    30.0
                }
            })
            .collect();
        let mut s = Scan::new(t, -std::f64::consts::FRAC_PI_2, inc, ranges, 0.05, 30.0).unwrap();
        s.odometry = Some(Pose2 {
            x: 0.0,
            y: 0.0,
            theta: 0.0,
        });
        s
    }

    #[test]
    fn a_walking_person_gets_one_label_and_the_right_velocity() {
        let cfg = PeopleTrackerConfig::for_scanner(
            0.02,
            0.005,
            30.0,
            std::f64::consts::FRAC_PI_2,
            [0.0, 0.0],
        );
        let mut tracker = PeopleTracker::new(cfg).unwrap();
        let mut last = Vec::new();
        let mut labels = std::collections::BTreeSet::new();
        for k in 0..40 {
            let t = k as f64 * 0.125;
            let est = tracker
                .step(&scan_with_person(t, 5.0, -2.0 + 0.8 * t))
                .unwrap();
            if k >= 5 {
                assert_eq!(est.len(), 1, "step {k}: {est:?}");
                labels.insert(est[0].label);
            }
            last = est;
        }
        assert_eq!(labels.len(), 1);
        let e = &last[0];
        let t = 39.0 * 0.125;
        assert!(
            (e.state[0] - 5.0).abs() < 0.1 && (e.state[2] - (-2.0 + 0.8 * t)).abs() < 0.15,
            "{e:?}"
        );
        assert!(
            (e.state[3] - 0.8).abs() < 0.25 && e.state[1].abs() < 0.25,
            "velocity {e:?}"
        );
    }
}
