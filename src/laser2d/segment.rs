//! Adaptive breakpoint segmentation of one scan (Borges & Aldon's detector, as used by the
//! ML-RANSAC paper, seed 000, eq. 15 and Algorithm 1): consecutive returns belong to the same
//! segment unless they are farther apart than a range-dependent threshold. Not for: deciding
//! what a segment is (person, wall, clutter), fitting lines or circles, or tracking.
//!
//! # The threshold
//!
//! Walking the beams in order, a point `P` at range `r_prev` is followed, one angular step
//! `Δθ` later, by the next point `Q`. Take the most grazing surface still accepted as one
//! object: a straight line leaving `P` at the angle `λ` to `P`'s beam, receding from the
//! sensor. In the triangle sensor–`P`–`Q` the angle at the sensor is `Δθ` and the angle at
//! `Q` is `λ − Δθ`, so by the law of sines `|PQ| = r_prev · sin Δθ / sin(λ − Δθ)`. Adding
//! three standard deviations of range noise gives
//!
//! `D_max = r_prev · sin(Δθ) / sin(λ − Δθ) + 3·σ_r`
//!
//! and a segment ends where the Cartesian distance between consecutive points exceeds it.
//! Defaults (seed 000): `λ = 20°`, `σ_r = 0.03 m`. `Δθ` is `|angle_increment|`, so
//! `λ` must exceed it.
//!
//! The seed writes the distance between the polar vectors `(r, θ)`; the Cartesian distance
//! between the two points is what the threshold is derived for and what is used here.
//!
//! "No return" beams (see [`Scan`]) belong to no segment and always end the current one.
//!
//! # What a segment reports
//!
//! Its beams and points, the *middle* point as its centre (as the seed does; for an even
//! number of points the mean of the two middle points), the first and last points, the
//! width (first-to-last distance) and, towards each neighbouring segment in beam order,
//! the Cartesian gap between the facing end points and the range step (neighbour's end
//! range minus own end range: positive when the neighbour lies farther away, i.e. this
//! segment stands in front of it). Neighbours are taken before filtering, across any
//! "no return" beams in between; there is none before the first or after the last segment.

use super::scan::Scan;
use crate::error::{Error, Result};
use std::ops::Range;

/// Parameters of the adaptive breakpoint detector and of the segment filter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BreakpointConfig {
    /// Grazing-angle parameter `λ` (rad); default 20° (0.349 rad). Must satisfy
    /// `|angle_increment| < λ < π`.
    pub lambda: f64,
    /// Range noise standard deviation `σ_r` (m); default 0.03 m.
    pub sigma_r: f64,
    /// Segments with fewer points are dropped; default 1 (keep every segment, including
    /// single isolated returns).
    pub min_points: usize,
    /// Segments wider than this (m) are dropped; default `+∞` (keep all).
    pub max_width: f64,
}

impl Default for BreakpointConfig {
    fn default() -> Self {
        BreakpointConfig {
            lambda: 20f64.to_radians(),
            sigma_r: 0.03,
            min_points: 1,
            max_width: f64::INFINITY,
        }
    }
}

impl BreakpointConfig {
    /// Checks the parameters: `0 < λ < π`, `σ_r ≥ 0` finite, `min_points ≥ 1`,
    /// `max_width > 0` (may be `+∞`).
    pub fn validate(&self) -> Result<()> {
        if !(self.lambda.is_finite() && self.lambda > 0.0 && self.lambda < std::f64::consts::PI) {
            return Err(Error::invalid(
                "BreakpointConfig::lambda",
                format!("{} (must lie in (0, π))", self.lambda),
            ));
        }
        if !(self.sigma_r.is_finite() && self.sigma_r >= 0.0) {
            return Err(Error::invalid(
                "BreakpointConfig::sigma_r",
                format!("{} (must be finite and ≥ 0)", self.sigma_r),
            ));
        }
        if self.min_points == 0 {
            return Err(Error::invalid(
                "BreakpointConfig::min_points",
                "0 (must be at least 1)",
            ));
        }
        if self.max_width.is_nan() || self.max_width <= 0.0 {
            return Err(Error::invalid(
                "BreakpointConfig::max_width",
                format!("{} (must be positive)", self.max_width),
            ));
        }
        Ok(())
    }

    /// The breakpoint distance `D_max` after a point at range `r_prev` for an angular
    /// step `delta_theta` (see the module documentation).
    pub fn threshold(&self, r_prev: f64, delta_theta: f64) -> f64 {
        breakpoint_threshold(r_prev, delta_theta, self.lambda, self.sigma_r)
    }
}

/// `D_max = r_prev · sin(Δθ) / sin(λ − Δθ) + 3·σ_r`: the largest Cartesian distance
/// between consecutive returns of one segment (see the module documentation).
pub fn breakpoint_threshold(r_prev: f64, delta_theta: f64, lambda: f64, sigma_r: f64) -> f64 {
    r_prev * delta_theta.sin() / (lambda - delta_theta).sin() + 3.0 * sigma_r
}

/// One segment of a scan: a run of consecutive returns without a breakpoint.
#[derive(Clone, Debug, PartialEq)]
pub struct Segment {
    /// The beams it spans (`start..end`, end exclusive); all of them carry returns.
    pub beams: Range<usize>,
    /// Its points `[x, y]` in the sensor frame, one per beam, in beam order.
    pub points: Vec<[f64; 2]>,
    /// The middle point (mean of the two middle points for an even count).
    pub center: [f64; 2],
    /// The first point.
    pub first: [f64; 2],
    /// The last point.
    pub last: [f64; 2],
    /// Distance from the first to the last point (m).
    pub width: f64,
    /// Distance from the last point of the previous segment to this one's first point (m).
    pub gap_prev: Option<f64>,
    /// Distance from this one's last point to the first point of the next segment (m).
    pub gap_next: Option<f64>,
    /// Range of the previous segment's last point minus range of this one's first point (m).
    pub range_step_prev: Option<f64>,
    /// Range of the next segment's first point minus range of this one's last point (m).
    pub range_step_next: Option<f64>,
}

impl Segment {
    /// Number of points.
    pub fn num_points(&self) -> usize {
        self.points.len()
    }

    /// Range of the centre from the sensor (m).
    pub fn center_range(&self) -> f64 {
        self.center[0].hypot(self.center[1])
    }

    /// Bearing of the centre in the sensor frame (rad).
    pub fn center_bearing(&self) -> f64 {
        self.center[1].atan2(self.center[0])
    }
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Splits `scan` into segments with the adaptive breakpoint detector and keeps those that
/// pass the filter of `config` (see the module documentation). Errors on an invalid scan
/// header or configuration, or when `|angle_increment| ≥ λ`.
pub fn segment_scan(scan: &Scan, config: &BreakpointConfig) -> Result<Vec<Segment>> {
    scan.validate()?;
    config.validate()?;
    let dtheta = scan.angle_increment.abs();
    if dtheta >= config.lambda {
        return Err(Error::invalid(
            "BreakpointConfig::lambda",
            format!(
                "{} must exceed the scan's angular step {dtheta}",
                config.lambda
            ),
        ));
    }
    // Runs of beams: (start, end exclusive, points, first and last range).
    let mut runs: Vec<(usize, Vec<[f64; 2]>, f64, f64)> = Vec::new();
    let mut current: Option<(usize, Vec<[f64; 2]>, f64, f64)> = None;
    for i in 0..scan.len() {
        let (Some(r), Some(p)) = (scan.range(i), scan.point(i)) else {
            runs.extend(current.take());
            continue;
        };
        match current.as_mut() {
            Some(run) => {
                let prev = *run.1.last().unwrap_or(&p);
                if dist(prev, p) > config.threshold(run.3, dtheta) {
                    runs.extend(current.replace((i, vec![p], r, r)));
                } else {
                    run.1.push(p);
                    run.3 = r;
                }
            }
            None => current = Some((i, vec![p], r, r)),
        }
    }
    runs.extend(current);

    let mut segments: Vec<Segment> = runs
        .iter()
        .map(|(start, points, _, _)| {
            let n = points.len();
            let first = points[0];
            let last = points[n - 1];
            let center = if n % 2 == 1 {
                points[n / 2]
            } else {
                let (a, b) = (points[n / 2 - 1], points[n / 2]);
                [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0]
            };
            Segment {
                beams: *start..start + n,
                points: points.clone(),
                center,
                first,
                last,
                width: dist(first, last),
                gap_prev: None,
                gap_next: None,
                range_step_prev: None,
                range_step_next: None,
            }
        })
        .collect();
    for k in 1..segments.len() {
        let gap = dist(segments[k - 1].last, segments[k].first);
        let step = runs[k - 1].3 - runs[k].2;
        segments[k].gap_prev = Some(gap);
        segments[k].range_step_prev = Some(step);
        segments[k - 1].gap_next = Some(gap);
        segments[k - 1].range_step_next = Some(-step);
    }
    segments.retain(|s| s.num_points() >= config.min_points && s.width <= config.max_width);
    Ok(segments)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Range along bearing `b` to the wall `x = wall` and, if hit, the disc (centre `c`,
    /// radius `rad`); the nearer one wins.
    fn ray(b: f64, wall: f64, c: [f64; 2], rad: f64) -> f64 {
        let (s, co) = b.sin_cos();
        let mut r = wall / co;
        // |t·u − c|² = rad²  →  t² − 2 t (u·c) + |c|² − rad² = 0
        let uc = co * c[0] + s * c[1];
        let disc = uc * uc - (c[0] * c[0] + c[1] * c[1] - rad * rad);
        if disc >= 0.0 {
            let t = uc - disc.sqrt();
            if t > 0.0 && t < r {
                r = t;
            }
        }
        r
    }

    fn wall_and_person(c: [f64; 2]) -> Scan {
        let inc = 1f64.to_radians();
        let amin = -30f64.to_radians();
        let ranges = (0..61)
            .map(|i| ray(amin + i as f64 * inc, 5.0, c, 0.2) as f32)
            .collect();
        Scan::new(0.0, amin, inc, ranges, 0.05, 30.0).unwrap()
    }

    #[test]
    fn threshold_hand_value() {
        // r = 5 m, Δθ = 1°, λ = 20°:
        // sin 1° = 0.0174524, sin 19° = 0.3255682,
        // 5 · 0.0174524 / 0.3255682 = 0.0872620 / 0.3255682 = 0.268030,
        // + 3 · 0.03 = 0.09  →  D_max = 0.358030 m.
        let d = BreakpointConfig::default().threshold(5.0, 1f64.to_radians());
        assert!((d - 0.358030).abs() < 1e-6, "{d}");
        assert!((BreakpointConfig::default().lambda - 0.349066).abs() < 1e-6);
    }

    #[test]
    fn wall_with_person_gives_three_segments() {
        // A disc of radius 0.2 m standing 1 m in front of a wall 5 m away, off the beam
        // grid (bearing ≈ 10.3°).
        let b = 0.18f64;
        let c = [4.0, 4.0 * b.tan()];
        let scan = wall_and_person(c);
        let segs = segment_scan(&scan, &BreakpointConfig::default()).unwrap();
        assert_eq!(segs.len(), 3, "{segs:#?}");
        let person = &segs[1];
        // The centre is a surface point: compare with the point of the disc nearest the
        // sensor, 0.2 m short of the disc centre along its bearing.
        let cn = c[0].hypot(c[1]);
        let near = [c[0] * (1.0 - 0.2 / cn), c[1] * (1.0 - 0.2 / cn)];
        assert!(
            dist(person.center, near) < 0.05,
            "{:?} vs {near:?}",
            person.center
        );
        assert!(person.num_points() >= 4 && person.width < 0.4);
        assert_eq!(segs[0].beams.start, 0);
        assert_eq!(segs[2].beams.end, 61);
        assert_eq!(segs[0].beams.end, person.beams.start);
        assert_eq!(person.beams.end, segs[2].beams.start);
        // The person stands about 1 m in front of both neighbours.
        let step = person.range_step_prev.unwrap();
        assert!(step > 0.8 && step < 1.3, "{step}");
        assert!(person.range_step_next.unwrap() > 0.8);
        assert!(person.gap_prev.unwrap() > 0.8);
        assert_eq!(segs[0].gap_prev, None);
        assert_eq!(segs[2].gap_next, None);
        assert_eq!(segs[0].gap_next, person.gap_prev);
        assert_eq!(segs[0].range_step_next, Some(-step));
        // The filter: a maximum width keeps only the person.
        let cfg = BreakpointConfig {
            max_width: 1.0,
            ..BreakpointConfig::default()
        };
        let only = segment_scan(&scan, &cfg).unwrap();
        assert_eq!(only.len(), 1);
        assert_eq!(only[0].beams, person.beams);
        let cfg = BreakpointConfig {
            min_points: 10,
            ..BreakpointConfig::default()
        };
        assert_eq!(segment_scan(&scan, &cfg).unwrap().len(), 2);
    }

    #[test]
    fn invalid_beams_split_segments() {
        let mut ranges = vec![2.0f32; 20];
        ranges[5] = f32::NAN;
        ranges[11] = 0.0;
        ranges[12] = 50.0; // ≥ range_max
        let scan = Scan::new(0.0, -PI / 4.0, PI / 2.0 / 19.0, ranges, 0.0, 30.0).unwrap();
        let segs = segment_scan(&scan, &BreakpointConfig::default()).unwrap();
        let beams: Vec<_> = segs.iter().map(|s| s.beams.clone()).collect();
        assert_eq!(beams, vec![0..5, 6..11, 13..20]);
        // Neighbours are linked across the gap; equal ranges give zero steps.
        assert_eq!(segs[1].range_step_prev, Some(0.0));
        assert!(segs[1].gap_prev.unwrap() > 0.0);
        // Odd counts: the centre is the middle point.
        let s = &segs[2];
        assert_eq!(s.num_points(), 7);
        assert_eq!(s.center, s.points[3]);
        assert!((s.center_range() - 2.0).abs() < 1e-6);
    }

    #[test]
    fn even_count_center_and_bad_input() {
        let scan = Scan::new(0.0, 0.0, 0.01, vec![1.0; 4], 0.0, 30.0).unwrap();
        let segs = segment_scan(&scan, &BreakpointConfig::default()).unwrap();
        assert_eq!(segs.len(), 1);
        let b = segs[0].center_bearing();
        assert!((b - 0.015).abs() < 1e-6, "{b}");
        let all_invalid = Scan::new(0.0, 0.0, 0.01, vec![0.0; 4], 0.0, 30.0).unwrap();
        assert!(segment_scan(&all_invalid, &BreakpointConfig::default())
            .unwrap()
            .is_empty());
        let coarse = Scan::new(0.0, 0.0, 0.5, vec![1.0; 4], 0.0, 30.0).unwrap();
        assert!(segment_scan(&coarse, &BreakpointConfig::default()).is_err());
        let bad = BreakpointConfig {
            sigma_r: -1.0,
            ..BreakpointConfig::default()
        };
        assert!(segment_scan(&scan, &bad).is_err());
        let bad = BreakpointConfig {
            min_points: 0,
            ..BreakpointConfig::default()
        };
        assert!(bad.validate().is_err());
    }
}
