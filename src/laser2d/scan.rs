//! One planar laser scan in polar form, the poses that travel with it, and the policy that
//! decides which beams carry a usable return.
//!
//! A [`Scan`] is a fan of beams: beam `i` points at bearing `angle_min + i·angle_increment`
//! (radians, counter-clockwise positive, in the sensor frame: x forward, y left) and measured
//! `ranges[i]` metres. Not for: reading files (see the CARMEN, ROS bag and CSV readers) or
//! grouping beams into objects (see the segmentation module).
//!
//! # "No return" beams
//!
//! A range is usable only when it is finite and lies strictly between `range_min` and
//! `range_max`. Everything else — NaN, ±∞, zero, anything `≤ range_min` or `≥ range_max`
//! (scanners report their maximum, or zero, when nothing reflected) — is a *no return* beam.
//! Such beams are kept in [`Scan::ranges`] untouched so that beam indices stay aligned with
//! bearings; [`Scan::range`], [`Scan::point`] and [`Scan::points`] skip them, and the
//! breakpoint segmentation breaks segments at them.

use crate::error::{Error, Result};
use crate::geometry::Pose2;

/// One odometry reading: a time-stamped platform pose and its velocities.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OdometryRecord {
    /// Time stamp (s).
    pub time: f64,
    /// The platform pose in the odometry frame.
    pub pose: Pose2,
    /// Forward (translational) velocity (m/s).
    pub linear_velocity: f64,
    /// Turn rate (rad/s).
    pub angular_velocity: f64,
}

/// One scan of a planar laser range finder. See the module documentation for the geometry
/// and for which beams count as returns.
#[derive(Clone, Debug, PartialEq)]
pub struct Scan {
    /// Time stamp (s).
    pub time: f64,
    /// Bearing of beam 0 (rad).
    pub angle_min: f64,
    /// Bearing step from one beam to the next (rad); negative for clockwise scanners.
    pub angle_increment: f64,
    /// Measured ranges (m), one per beam, including "no return" values.
    pub ranges: Vec<f32>,
    /// Ranges at or below this value are "no return" (m).
    pub range_min: f64,
    /// Ranges at or above this value are "no return" (m); may be `+∞`.
    pub range_max: f64,
    /// The platform's odometry pose at the scan, when the source logged one.
    pub odometry: Option<Pose2>,
    /// The sensor pose as logged by the source (for CARMEN, the pose written in the laser
    /// line), when present.
    pub laser_pose: Option<Pose2>,
}

impl Scan {
    /// A scan without poses; checks the header values with [`Scan::validate`].
    pub fn new(
        time: f64,
        angle_min: f64,
        angle_increment: f64,
        ranges: Vec<f32>,
        range_min: f64,
        range_max: f64,
    ) -> Result<Self> {
        let scan = Scan {
            time,
            angle_min,
            angle_increment,
            ranges,
            range_min,
            range_max,
            odometry: None,
            laser_pose: None,
        };
        scan.validate()?;
        Ok(scan)
    }

    /// Checks the header values: finite time, angle and increment, a non-zero increment,
    /// `0 ≤ range_min < range_max` (range_max may be `+∞`), at least one beam and finite
    /// poses. Ranges themselves are never rejected: unusable ones are "no return" beams.
    pub fn validate(&self) -> Result<()> {
        let what = "laser scan";
        if !self.time.is_finite() {
            return Err(Error::invalid(
                what,
                format!("time {} is not finite", self.time),
            ));
        }
        if !self.angle_min.is_finite() {
            return Err(Error::invalid(
                what,
                format!("angle_min {} is not finite", self.angle_min),
            ));
        }
        if !(self.angle_increment.is_finite() && self.angle_increment != 0.0) {
            return Err(Error::invalid(
                what,
                format!(
                    "angle_increment {} (must be finite and non-zero)",
                    self.angle_increment
                ),
            ));
        }
        if !(self.range_min.is_finite() && self.range_min >= 0.0) {
            return Err(Error::invalid(
                what,
                format!("range_min {} (must be finite and ≥ 0)", self.range_min),
            ));
        }
        if self.range_max.is_nan() || self.range_max <= self.range_min {
            return Err(Error::invalid(
                what,
                format!(
                    "range_max {} (must exceed range_min {})",
                    self.range_max, self.range_min
                ),
            ));
        }
        if self.ranges.is_empty() {
            return Err(Error::invalid(what, "no beams"));
        }
        for (name, pose) in [("odometry", self.odometry), ("laser_pose", self.laser_pose)] {
            if let Some(p) = pose {
                if !p.is_finite() {
                    return Err(Error::invalid(what, format!("{name} {p:?} is not finite")));
                }
            }
        }
        Ok(())
    }

    /// Number of beams (valid or not).
    pub fn len(&self) -> usize {
        self.ranges.len()
    }

    /// True when the scan has no beams.
    pub fn is_empty(&self) -> bool {
        self.ranges.is_empty()
    }

    /// Bearing of beam `i` (rad): `angle_min + i·angle_increment`. Defined for any `i`.
    pub fn bearing(&self, i: usize) -> f64 {
        self.angle_min + i as f64 * self.angle_increment
    }

    /// The beam whose bearing is nearest that of `p` (sensor frame; bearings taken modulo a
    /// full turn, so a scanner whose beams start anywhere on the circle is served), `None`
    /// outside the scan's beams or for a zero or non-finite increment. A return at `p` came
    /// from this beam: the scan reports its bearings without noise.
    pub fn beam_of(&self, p: [f64; 2]) -> Option<usize> {
        nearest_beam(
            self.angle_min,
            self.angle_increment,
            self.len(),
            p[1].atan2(p[0]),
        )
    }

    /// Bearing of the last beam (rad).
    pub fn angle_max(&self) -> f64 {
        self.bearing(self.len().saturating_sub(1))
    }

    /// True when beam `i` exists and carries a return (finite, `range_min < r < range_max`).
    pub fn is_valid(&self, i: usize) -> bool {
        self.range(i).is_some()
    }

    /// The range of beam `i` when it exists and carries a return.
    /// The limits are compared at the `f32` precision of the ranges, so a range written as
    /// `0.1` counts as equal to `range_min = 0.1`.
    pub fn range(&self, i: usize) -> Option<f64> {
        let r = *self.ranges.get(i)?;
        let usable = r.is_finite() && r > self.range_min as f32 && r < self.range_max as f32;
        usable.then_some(f64::from(r))
    }

    /// Number of beams that carry a return.
    pub fn valid_count(&self) -> usize {
        (0..self.len()).filter(|&i| self.is_valid(i)).count()
    }

    /// Cartesian point `[x, y]` of beam `i` in the sensor frame, when the beam carries a
    /// return.
    pub fn point(&self, i: usize) -> Option<[f64; 2]> {
        let r = self.range(i)?;
        let (s, c) = self.bearing(i).sin_cos();
        Some([r * c, r * s])
    }

    /// The range of every beam in beam order, `+∞` for a no-return beam.
    pub fn beam_ranges(&self) -> impl Iterator<Item = f64> + '_ {
        (0..self.len()).map(|i| self.range(i).unwrap_or(f64::INFINITY))
    }

    /// [`Scan::beam_ranges`] into `out` (cleared first).
    pub fn ranges_into(&self, out: &mut Vec<f64>) {
        out.clear();
        out.extend(self.beam_ranges());
    }

    /// All returns as `(beam index, [x, y])` in the sensor frame, in beam order; "no return"
    /// beams are left out.
    pub fn points(&self) -> impl Iterator<Item = (usize, [f64; 2])> + '_ {
        (0..self.len()).filter_map(move |i| self.point(i).map(|p| (i, p)))
    }
}

/// Sets each scan's [`Scan::odometry`] to the pose of the latest odometry record whose time
/// is not after the scan's time; scans earlier than every record keep their value. The
/// records need not be sorted (a time-sorted copy is used; among equal times the later one
/// in `odometry` wins). Records with a non-finite time or pose are ignored.
pub fn attach_odometry(scans: &mut [Scan], odometry: &[OdometryRecord]) {
    let mut sorted: Vec<&OdometryRecord> = odometry
        .iter()
        .filter(|o| o.time.is_finite() && o.pose.is_finite())
        .collect();
    sorted.sort_by(|a, b| a.time.total_cmp(&b.time));
    for scan in scans {
        let after = sorted.partition_point(|o| o.time <= scan.time);
        if after > 0 {
            scan.odometry = Some(sorted[after - 1].pose);
        }
    }
}

/// The beam, of `len` beams at `angle_min + i·angle_increment`, whose bearing is nearest
/// `bearing` (rad, taken modulo a full turn: a scanner whose beams start anywhere on the
/// circle, or go round it whole, is served across the seam); `None` outside the beams or for
/// a zero or non-finite increment.
pub fn nearest_beam(
    angle_min: f64,
    angle_increment: f64,
    len: usize,
    bearing: f64,
) -> Option<usize> {
    let inc = angle_increment;
    if inc == 0.0 || !inc.is_finite() {
        return None;
    }
    let tau = std::f64::consts::TAU;
    let from_first = ((bearing - angle_min) * inc.signum()).rem_euclid(tau);
    let steps = (from_first / inc.abs()).round();
    let wrapped = ((from_first - tau) / inc.abs()).round();
    [steps, wrapped]
        .into_iter()
        .find(|s| *s >= 0.0 && (*s as usize) < len)
        .map(|s| s as usize)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scan(ranges: &[f32]) -> Scan {
        Scan::new(0.0, -0.5, 0.25, ranges.to_vec(), 0.1, 10.0).unwrap()
    }

    #[test]
    fn returns_map_back_to_their_beams() {
        use std::f64::consts::{FRAC_PI_2, PI};
        // 181 beams over 180°, counter-clockwise and clockwise, and 360 beams from 0 to
        // 359° (bearings past π wrap round).
        let ccw = Scan::new(0.0, -FRAC_PI_2, PI / 180.0, vec![5.0; 181], 0.0, 30.0).unwrap();
        let cw = Scan::new(0.0, FRAC_PI_2, -PI / 180.0, vec![5.0; 181], 0.0, 30.0).unwrap();
        for s in [&ccw, &cw] {
            for b in [0, 1, 90, 179, 180] {
                assert_eq!(s.beam_of(s.point(b).unwrap()), Some(b));
            }
            // Behind the scanner: no beam.
            assert_eq!(s.beam_of([-1.0, 0.0]), None);
        }
        let round = Scan::new(0.0, 0.0, PI / 180.0, vec![5.0; 360], 0.0, 30.0).unwrap();
        for b in [0, 90, 180, 270, 359] {
            assert_eq!(round.beam_of(round.point(b).unwrap()), Some(b));
        }
        // A scan whose increment was zeroed after checking has no beam for anything.
        let mut flat = ccw.clone();
        flat.angle_increment = 0.0;
        assert_eq!(flat.beam_of([1.0, 0.0]), None);
    }

    #[test]
    fn bearings_and_points() {
        let s = scan(&[1.0, 2.0, 3.0, 4.0, 5.0]);
        assert_eq!(s.len(), 5);
        assert!((s.bearing(2) - 0.0).abs() < 1e-15);
        assert!((s.angle_max() - 0.5).abs() < 1e-15);
        let p = s.point(2).unwrap();
        assert!((p[0] - 3.0).abs() < 1e-12 && p[1].abs() < 1e-12);
        let p = s.point(4).unwrap();
        assert!((p[0] - 5.0 * 0.5f64.cos()).abs() < 1e-12);
        assert!((p[1] - 5.0 * 0.5f64.sin()).abs() < 1e-12);
    }

    #[test]
    fn no_return_policy() {
        let s = scan(&[
            f32::NAN,
            f32::INFINITY,
            0.0,
            0.1,
            10.0,
            12.0,
            -1.0,
            0.11,
            9.99,
        ]);
        let valid: Vec<usize> = s.points().map(|(i, _)| i).collect();
        assert_eq!(valid, vec![7, 8]);
        assert_eq!(s.valid_count(), 2);
        assert!(!s.is_valid(100));
        assert_eq!(s.range(3), None);
        // The raw values stay in place.
        assert_eq!(s.ranges[5], 12.0);
    }

    #[test]
    fn header_validation() {
        assert!(Scan::new(0.0, 0.0, 0.0, vec![1.0], 0.0, 5.0).is_err());
        assert!(Scan::new(f64::NAN, 0.0, 0.1, vec![1.0], 0.0, 5.0).is_err());
        assert!(Scan::new(0.0, 0.0, 0.1, vec![1.0], -1.0, 5.0).is_err());
        assert!(Scan::new(0.0, 0.0, 0.1, vec![1.0], 5.0, 5.0).is_err());
        assert!(Scan::new(0.0, 0.0, 0.1, vec![], 0.0, 5.0).is_err());
        assert!(Scan::new(0.0, 0.0, -0.1, vec![1.0], 0.0, f64::INFINITY).is_ok());
    }

    #[test]
    fn odometry_attachment() {
        let mut scans = vec![scan(&[1.0]), scan(&[1.0]), scan(&[1.0])];
        scans[0].time = -1.0;
        scans[1].time = 1.0;
        scans[2].time = 2.5;
        let odo = |t: f64, x: f64| OdometryRecord {
            time: t,
            pose: Pose2::new(x, 0.0, 0.0),
            linear_velocity: 0.0,
            angular_velocity: 0.0,
        };
        // Deliberately unsorted.
        attach_odometry(&mut scans, &[odo(2.0, 2.0), odo(0.0, 0.0), odo(1.0, 1.0)]);
        assert_eq!(scans[0].odometry, None);
        assert_eq!(scans[1].odometry.unwrap().x, 1.0);
        assert_eq!(scans[2].odometry.unwrap().x, 2.0);
    }
}
