//! A seeded simulator of walking people seen by a planar laser scanner on a moving robot,
//! with ground truth, written after the two simulated experiments of the ML-RANSAC paper
//! (seed 000, section 5.1).
//!
//! A [`PeopleScenario`] is plain data: the robot's motion (unicycle legs of constant speed
//! and turn rate, at most 2 m/s), the people (discs moving with piecewise-constant
//! velocities, entering and leaving at given times), the static scene (wall segments and
//! round pillars), the scanner and its mounting offset on the robot, and the odometry noise.
//! [`PeopleScenario::generate`] turns it into a [`People2dRun`]: one [`Scan`] per scanner
//! period, with a noisy odometry pose attached, plus the true robot and sensor poses, the
//! true people states and which people the scanner actually saw.
//!
//! Not for: tracking, segmentation or scoring (see [`crate::laser2d`] and
//! [`crate::metrics`]); people are rigid discs, not pairs of legs.
//!
//! # Geometry and frames
//!
//! Poses are `(x, y, θ)` in a fixed world frame, θ counter-clockwise from the x axis. The
//! sensor sits at the offset `(a, b)` in the robot frame (seed 000, eq. 11):
//! `x_s = x + a cos θ − b sin θ`, `y_s = y + a sin θ + b cos θ`, with the robot's heading.
//! Beam `i` of a scan has the nominal bearing `angle_min + i·angle_increment` in the sensor
//! frame, the fan being centred on the sensor's heading.
//!
//! # How a scan is made
//!
//! Each beam is cast as an exact ray from the true sensor pose, at its nominal bearing plus
//! a bearing error drawn from N(0, σ_b²); the nearest intersection with any person disc,
//! pillar disc or wall segment is the true range. A hit closer than `range_max` is reported
//! with additive range noise N(0, σ_r²), clipped below at 0 (noisy values that reach
//! `range_max` then count as "no return"); a beam that hits nothing within `range_max`
//! reports exactly `range_max`, which [`Scan`] treats as "no return". The scan always
//! reports the nominal bearing, as a real scanner does.
//!
//! A person is *visible* in a scan when at least three of the cast rays end on their disc
//! (nearest hit, within `range_max`); people hidden behind others or behind static objects,
//! outside the field of view or too far away to catch three beams are not.
//!
//! # Odometry
//!
//! The odometry starts at the true pose of scan 0. For every later scan the true increment
//! since the previous scan is expressed in the previous robot frame as `(dx, dy, dθ)` and
//! corrupted as `dx' = dx·(1 + e_t) + n_x`, `dy' = dy·(1 + e_t) + n_y`,
//! `dθ' = dθ·(1 + e_r) + n_θ`, with `e_t ~ N(0, σ_trel²)`, `n_x, n_y ~ N(0, σ_tabs²)`,
//! `e_r ~ N(0, σ_rrel²)` and `n_θ ~ N(0, σ_rabs²)` (see [`OdometryNoise`]); the noisy
//! increments are composed, so the odometry drifts. With all four set to zero it repeats
//! the truth (up to rounding).
//!
//! # Randomness
//!
//! Everything random in scan `k` (its odometry increment, then per beam a bearing and a
//! range error) comes from [`crate::rng::stream`]`(seed, k)`, so a run is a pure function
//! of the scenario and the seed. All draws are made even when a standard deviation is
//! zero, so changing one noise level leaves the others' draws unchanged.
//!
//! # The two scenarios
//!
//! The paper gives the five walking velocities of its first experiment and the scanner
//! (8 scans/s, 180° field of view, 30 m range, 0.2 m and 2° noise) but no positions, room or
//! robot path; the layouts here are this module's own and are documented on
//! [`PeopleScenario::one`] and [`PeopleScenario::two`].

use crate::error::{Error, Result};
use crate::geometry::Pose2;
use crate::geometry::{ray_circle, wrap_angle};
use crate::laser2d::Scan;
use crate::rng::{stream, FilterRng};
use rand_distr::{Distribution, StandardNormal};
use std::collections::HashSet;
use std::f64::consts::{FRAC_PI_2, PI};

/// Beams that must end on a person for the person to count as visible.
pub const MIN_VISIBLE_BEAMS: usize = 3;

/// One leg of the robot's motion: constant forward speed and turn rate for a duration.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RobotLeg {
    /// How long the leg lasts (s).
    pub duration: f64,
    /// Forward speed (m/s).
    pub speed: f64,
    /// Turn rate (rad/s), counter-clockwise positive.
    pub turn_rate: f64,
}

/// The robot's true motion: a start pose and unicycle legs, after which it stands still.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RobotSpec {
    /// Pose `[x, y, θ]` at time 0 (m, m, rad).
    pub start: [f64; 3],
    /// Legs in order, starting at time 0.
    pub legs: Vec<RobotLeg>,
}

impl RobotSpec {
    /// The true pose at time `t` (s), θ wrapped to (−π, π]. Before 0 the start pose, after
    /// the last leg the final pose. Arcs are integrated exactly.
    pub fn pose_at(&self, t: f64) -> Pose2 {
        let [mut x, mut y, mut th] = self.start;
        let mut remaining = t.max(0.0);
        for leg in &self.legs {
            if remaining <= 0.0 {
                break;
            }
            let tau = remaining.min(leg.duration);
            remaining -= tau;
            let (v, w) = (leg.speed, leg.turn_rate);
            if (w * tau).abs() < 1e-12 {
                x += v * tau * th.cos();
                y += v * tau * th.sin();
            } else {
                let th1 = th + w * tau;
                x += v / w * (th1.sin() - th.sin());
                y -= v / w * (th1.cos() - th.cos());
                th = th1;
            }
        }
        Pose2::new(x, y, wrap_angle(th))
    }

    /// Total duration of the legs (s).
    pub fn total_duration(&self) -> f64 {
        self.legs.iter().map(|l| l.duration).sum()
    }

    fn validate(&self) -> Result<()> {
        if !self.start.iter().all(|v| v.is_finite()) {
            return Err(Error::invalid(
                "robot start pose",
                format!("{:?} is not finite", self.start),
            ));
        }
        for (i, l) in self.legs.iter().enumerate() {
            let ok = l.duration.is_finite()
                && l.duration >= 0.0
                && l.speed.is_finite()
                && l.turn_rate.is_finite();
            if !ok {
                return Err(Error::invalid(
                    format!("robot leg {i}"),
                    format!("{l:?} (duration must be finite and ≥ 0, speed and turn rate finite)"),
                ));
            }
        }
        Ok(())
    }
}

/// One leg of a person's walk: a constant velocity for a duration.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PersonLeg {
    /// How long the leg lasts (s).
    pub duration: f64,
    /// Velocity `[vx, vy]` in the world frame (m/s).
    pub velocity: [f64; 2],
}

/// One walking person, modelled as a disc.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PersonSpec {
    /// Identity reported in the truth.
    pub id: u64,
    /// Disc radius (m).
    pub radius: f64,
    /// Time the person appears (s).
    pub enter: f64,
    /// Time the person disappears (s); `None`: stays to the end. Present on `[enter, leave)`.
    pub leave: Option<f64>,
    /// Centre `[x, y]` at the entry time (m).
    pub start: [f64; 2],
    /// Legs in order from the entry time; after the last one the person stands still.
    pub legs: Vec<PersonLeg>,
}

impl PersonSpec {
    /// Whether the person is in the scene at time `t`.
    pub fn present_at(&self, t: f64) -> bool {
        t >= self.enter && self.leave.is_none_or(|l| t < l)
    }

    /// Centre and velocity at time `t` when present. On a leg boundary the velocity is
    /// that of the leg starting there.
    pub fn state_at(&self, t: f64) -> Option<([f64; 2], [f64; 2])> {
        if !self.present_at(t) {
            return None;
        }
        let mut p = self.start;
        let mut remaining = t - self.enter;
        for leg in &self.legs {
            if remaining < leg.duration {
                p[0] += leg.velocity[0] * remaining;
                p[1] += leg.velocity[1] * remaining;
                return Some((p, leg.velocity));
            }
            p[0] += leg.velocity[0] * leg.duration;
            p[1] += leg.velocity[1] * leg.duration;
            remaining -= leg.duration;
        }
        Some((p, [0.0, 0.0]))
    }

    fn validate(&self) -> Result<()> {
        let what = || format!("person {}", self.id);
        if !(self.radius.is_finite() && self.radius > 0.0) {
            return Err(Error::invalid(
                what(),
                format!("radius {} (must be positive)", self.radius),
            ));
        }
        if !self.enter.is_finite() || !self.start.iter().all(|v| v.is_finite()) {
            return Err(Error::invalid(what(), "entry time or start is not finite"));
        }
        if let Some(l) = self.leave {
            if l.is_nan() || l <= self.enter {
                return Err(Error::invalid(
                    what(),
                    format!("leaves at {l}, not after entering at {}", self.enter),
                ));
            }
        }
        for (i, l) in self.legs.iter().enumerate() {
            let ok = l.duration.is_finite()
                && l.duration >= 0.0
                && l.velocity.iter().all(|v| v.is_finite());
            if !ok {
                return Err(Error::invalid(
                    format!("person {} leg {i}", self.id),
                    format!("{l:?} (duration must be finite and ≥ 0, velocity finite)"),
                ));
            }
        }
        Ok(())
    }
}

/// A round static object (pillar, bin, plant pot).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Disc {
    /// Centre `[x, y]` (m).
    pub center: [f64; 2],
    /// Radius (m).
    pub radius: f64,
}

/// The simulated scanner.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ScannerSpec {
    /// Scans per second (Hz).
    pub rate_hz: f64,
    /// Field of view (rad), centred on the sensor's heading; at most 2π.
    pub fov: f64,
    /// Number of beams (at least 2), spread evenly from `−fov/2` to `+fov/2`.
    pub beams: usize,
    /// Ranges at or below this are "no return" (m).
    pub range_min: f64,
    /// Maximum range (m); beams without a hit report this value ("no return").
    pub range_max: f64,
    /// Range noise standard deviation σ_r (m).
    pub sigma_range: f64,
    /// Bearing noise standard deviation σ_b (rad), applied to the cast direction only.
    pub sigma_bearing: f64,
}

impl Default for ScannerSpec {
    /// The scanner of seed 000's simulations: 8 Hz, 180°, 30 m, σ_r = 0.2 m, σ_b = 2°, with
    /// 361 beams (0.5° apart) and `range_min` 0.
    fn default() -> Self {
        ScannerSpec {
            rate_hz: 8.0,
            fov: PI,
            beams: 361,
            range_min: 0.0,
            range_max: 30.0,
            sigma_range: 0.2,
            sigma_bearing: 2f64.to_radians(),
        }
    }
}

impl ScannerSpec {
    /// The same scanner without range or bearing noise.
    pub fn noise_free(self) -> Self {
        ScannerSpec {
            sigma_range: 0.0,
            sigma_bearing: 0.0,
            ..self
        }
    }

    /// Bearing of beam 0 in the sensor frame (rad).
    pub fn angle_min(&self) -> f64 {
        -0.5 * self.fov
    }

    /// Bearing step between neighbouring beams (rad).
    pub fn angle_increment(&self) -> f64 {
        self.fov / (self.beams as f64 - 1.0)
    }

    fn validate(&self) -> Result<()> {
        let bad = |field: &str, why: String| Err(Error::invalid(format!("scanner {field}"), why));
        if !(self.rate_hz.is_finite() && self.rate_hz > 0.0) {
            return bad("rate_hz", format!("{} (must be positive)", self.rate_hz));
        }
        if !(self.fov.is_finite() && self.fov > 0.0 && self.fov <= 2.0 * PI) {
            return bad("fov", format!("{} (must lie in (0, 2π])", self.fov));
        }
        if self.beams < 2 {
            return bad("beams", format!("{} (need at least 2)", self.beams));
        }
        if !(self.range_min.is_finite()
            && self.range_min >= 0.0
            && self.range_max.is_finite()
            && self.range_max > self.range_min)
        {
            return bad(
                "range limits",
                format!(
                    "[{}, {}] (need 0 ≤ range_min < range_max, finite)",
                    self.range_min, self.range_max
                ),
            );
        }
        for (name, s) in [
            ("sigma_range", self.sigma_range),
            ("sigma_bearing", self.sigma_bearing),
        ] {
            if !(s.is_finite() && s >= 0.0) {
                return bad(name, format!("{s} (must be finite and ≥ 0)"));
            }
        }
        Ok(())
    }
}

/// Noise on the odometry increments between consecutive scans (see the module
/// documentation for the formula).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct OdometryNoise {
    /// Relative translation error σ_trel (shared scale factor of dx and dy, unitless).
    pub sigma_trans_rel: f64,
    /// Additive translation error σ_tabs per component per step (m).
    pub sigma_trans_abs: f64,
    /// Relative rotation error σ_rrel (unitless).
    pub sigma_rot_rel: f64,
    /// Additive rotation error σ_rabs per step (rad).
    pub sigma_rot_abs: f64,
}

impl Default for OdometryNoise {
    /// 2 % scale error on translation and rotation, 5 mm and 0.2° per step additive.
    fn default() -> Self {
        OdometryNoise {
            sigma_trans_rel: 0.02,
            sigma_trans_abs: 0.005,
            sigma_rot_rel: 0.02,
            sigma_rot_abs: 0.2f64.to_radians(),
        }
    }
}

impl OdometryNoise {
    /// No odometry noise: the odometry repeats the true poses.
    pub fn none() -> Self {
        OdometryNoise {
            sigma_trans_rel: 0.0,
            sigma_trans_abs: 0.0,
            sigma_rot_rel: 0.0,
            sigma_rot_abs: 0.0,
        }
    }

    fn validate(&self) -> Result<()> {
        for (name, s) in [
            ("sigma_trans_rel", self.sigma_trans_rel),
            ("sigma_trans_abs", self.sigma_trans_abs),
            ("sigma_rot_rel", self.sigma_rot_rel),
            ("sigma_rot_abs", self.sigma_rot_abs),
        ] {
            if !(s.is_finite() && s >= 0.0) {
                return Err(Error::invalid(
                    format!("odometry noise {name}"),
                    format!("{s} (must be finite and ≥ 0)"),
                ));
            }
        }
        Ok(())
    }
}

/// A complete people-tracking scenario: robot, people, static scene, scanner, odometry.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PeopleScenario {
    /// Short name.
    pub name: String,
    /// Length of the run (s); scans are taken at `k / rate_hz` for `k·(1/rate_hz) < duration`.
    pub duration: f64,
    /// True robot motion.
    pub robot: RobotSpec,
    /// The people.
    pub people: Vec<PersonSpec>,
    /// Static wall segments `[[x0, y0], [x1, y1]]` (m).
    pub walls: Vec<[[f64; 2]; 2]>,
    /// Static round objects.
    pub pillars: Vec<Disc>,
    /// The scanner.
    pub scanner: ScannerSpec,
    /// Sensor offset `[a, b]` in the robot frame (m): `a` forward, `b` left.
    pub mount: [f64; 2],
    /// Odometry noise.
    pub odometry_noise: OdometryNoise,
}

/// One person's truth in one scan: id, centre `[x, y]` and velocity `[vx, vy]` in the world
/// frame.
pub type PersonTruth = (u64, [f64; 2], [f64; 2]);

/// Output of [`PeopleScenario::generate`]; every vector has one entry per scan.
#[derive(Clone, Debug, PartialEq)]
pub struct People2dRun {
    /// The scans, with the noisy odometry pose in [`Scan::odometry`] and the sensor pose
    /// implied by it (odometry pose plus mounting offset) in [`Scan::laser_pose`].
    pub scans: Vec<Scan>,
    /// True robot poses.
    pub robot_truth: Vec<Pose2>,
    /// True sensor poses (robot pose plus mounting offset).
    pub sensor_truth: Vec<Pose2>,
    /// The people in the scene, by increasing id.
    pub people_truth: Vec<Vec<PersonTruth>>,
    /// Ids of the people at least [`MIN_VISIBLE_BEAMS`] beams ended on, increasing.
    pub visible: Vec<Vec<u64>>,
}

/// The sensor pose for a robot pose and a mounting offset `[a, b]` (seed 000, eq. 11).
pub fn sensor_pose(robot: Pose2, mount: [f64; 2]) -> Pose2 {
    let (s, c) = robot.theta.sin_cos();
    Pose2::new(
        robot.x + mount[0] * c - mount[1] * s,
        robot.y + mount[0] * s + mount[1] * c,
        robot.theta,
    )
}

/// Distance along the ray `origin + t·dir` (`dir` of unit length) to the segment `p`–`q`,
/// for `t > 0`; `None` when the ray misses or runs parallel to it.
pub fn ray_segment(origin: [f64; 2], dir: [f64; 2], p: [f64; 2], q: [f64; 2]) -> Option<f64> {
    let e = [q[0] - p[0], q[1] - p[1]];
    let denom = dir[0] * e[1] - dir[1] * e[0];
    if denom.abs() < 1e-15 {
        return None;
    }
    let w = [p[0] - origin[0], p[1] - origin[1]];
    let t = (w[0] * e[1] - w[1] * e[0]) / denom;
    let u = (w[0] * dir[1] - w[1] * dir[0]) / denom;
    (t > 0.0 && (0.0..=1.0).contains(&u)).then_some(t)
}

/// The four wall segments of an axis-aligned box `[x0, x1] × [y0, y1]`.
pub fn box_walls(x: [f64; 2], y: [f64; 2]) -> [[[f64; 2]; 2]; 4] {
    [
        [[x[0], y[0]], [x[1], y[0]]],
        [[x[1], y[0]], [x[1], y[1]]],
        [[x[1], y[1]], [x[0], y[1]]],
        [[x[0], y[1]], [x[0], y[0]]],
    ]
}

fn normal(rng: &mut FilterRng) -> f64 {
    StandardNormal.sample(rng)
}

/// What a ray hit first.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Hit {
    Person(u64),
    Static,
}

/// A person that only walks one velocity for the whole run.
fn walker(id: u64, start: [f64; 2], velocity: [f64; 2], duration: f64) -> PersonSpec {
    PersonSpec {
        id,
        radius: 0.2,
        enter: 0.0,
        leave: None,
        start,
        legs: vec![PersonLeg { duration, velocity }],
    }
}

/// A person entering at `enter` and walking `legs`; with `leaves` they disappear when the
/// last leg ends (they are then at a door), otherwise they stay.
fn visitor(
    id: u64,
    enter: f64,
    start: [f64; 2],
    legs: &[(f64, [f64; 2])],
    leaves: bool,
) -> PersonSpec {
    let total: f64 = legs.iter().map(|l| l.0).sum();
    PersonSpec {
        id,
        radius: 0.2,
        enter,
        leave: leaves.then_some(enter + total),
        start,
        legs: legs
            .iter()
            .map(|&(duration, velocity)| PersonLeg { duration, velocity })
            .collect(),
    }
}

fn robot_legs(legs: &[(f64, f64, f64)]) -> Vec<RobotLeg> {
    legs.iter()
        .map(|&(duration, speed, turn_rate)| RobotLeg {
            duration,
            speed,
            turn_rate,
        })
        .collect()
}

impl PeopleScenario {
    /// Seed 000's first experiment: five people crossing and occluding one another in open
    /// space, seen from a robot driving at up to 2 m/s.
    ///
    /// From the paper: the five velocities (0.625, 0.625), (0.625, 0), (−0.1, −0.75),
    /// (−0.25, −0.8) and (−0.75, 0.6) m/s, held constant, and the scanner (see
    /// [`ScannerSpec::default`]). The paper notes this experiment has no static objects, so
    /// there are no walls: beams that miss every person are "no return".
    ///
    /// Chosen here (the paper gives no positions): 30 s; the robot starts at the origin
    /// facing +x and drives 4 s at 0.5 m/s, 6 s at 1 m/s, 5 s at 2 m/s turning left at
    /// 0.1 rad/s, 5 s at 1 m/s turning right at 0.1 rad/s and 10 s at 0.5 m/s. People 1–5
    /// (radius 0.2 m) start at (9.9, −4.1), (13.4, 8), (24.15, 20.9), (28.1, 23.8) and
    /// (31.75, 1.7): seven of the ten pairs pass within 2 m of each other between 13 s and
    /// 20 s, 2–8 m ahead of the robot where they hide one another, but no two come closer
    /// than 0.9 m centre to centre (people pass, they do not walk through each other) and
    /// nobody comes within 1.5 m of the robot; people 3–5 start out of range and walk in,
    /// person 5 later leaves the field of view. Mount offset (0.2, 0) m; default odometry
    /// noise.
    pub fn one() -> Self {
        let duration = 30.0;
        let people = vec![
            walker(1, [9.9, -4.1], [0.625, 0.625], duration),
            walker(2, [13.4, 8.0], [0.625, 0.0], duration),
            walker(3, [24.15, 20.9], [-0.1, -0.75], duration),
            walker(4, [28.1, 23.8], [-0.25, -0.8], duration),
            walker(5, [31.75, 1.7], [-0.75, 0.6], duration),
        ];
        PeopleScenario {
            name: "people2d-one".into(),
            duration,
            robot: RobotSpec {
                start: [0.0, 0.0, 0.0],
                legs: robot_legs(&[
                    (4.0, 0.5, 0.0),
                    (6.0, 1.0, 0.0),
                    (5.0, 2.0, 0.1),
                    (5.0, 1.0, -0.1),
                    (10.0, 0.5, 0.0),
                ]),
            },
            people,
            walls: Vec::new(),
            pillars: Vec::new(),
            scanner: ScannerSpec::default(),
            mount: [0.2, 0.0],
            odometry_noise: OdometryNoise::default(),
        }
    }

    /// Seed 000's second experiment: a building lobby with static objects and ten people
    /// who enter, walk, turn around and leave, seen from a robot driving at up to 2 m/s.
    ///
    /// Chosen here (the paper shows only a figure): a 30 m × 20 m lobby `[0, 30] × [−10, 10]`
    /// with four doors (north wall gap x ∈ [13, 17], south wall gap x ∈ [8, 11], east wall
    /// gap y ∈ [−2, 2], west wall gap y ∈ [−1.5, 1.5]); four pillars of radius 0.3 m at
    /// (10, ±3) and (20, ±3); a reception desk, the box [22, 25] × [7, 8]; a bench, the box
    /// [4, 7] × [−9.5, −9]. The robot starts at (3, −6) facing +x and drives 6 s at 1.2 m/s,
    /// turns left 90° (3 s at 1 m/s), drives 4 s at 1.5 m/s, turns right 90°, drives 6 s at
    /// 2 m/s, turns left 180° and drives 5 s back at 1 m/s. Ten people (radius 0.2 m, 0.5 to
    /// 1.3 m/s) enter through doors between 0 s and 15 s; six of them turn around on the
    /// spot, six leave through a door before the end. Mount offset (0.2, 0) m; default
    /// odometry noise.
    pub fn two() -> Self {
        let mut walls: Vec<[[f64; 2]; 2]> = vec![
            // South wall with its door at x ∈ [8, 11].
            [[0.0, -10.0], [8.0, -10.0]],
            [[11.0, -10.0], [30.0, -10.0]],
            // East wall with its door at y ∈ [−2, 2].
            [[30.0, -10.0], [30.0, -2.0]],
            [[30.0, 2.0], [30.0, 10.0]],
            // North wall with its door at x ∈ [13, 17].
            [[30.0, 10.0], [17.0, 10.0]],
            [[13.0, 10.0], [0.0, 10.0]],
            // West wall with its door at y ∈ [−1.5, 1.5].
            [[0.0, 10.0], [0.0, 1.5]],
            [[0.0, -1.5], [0.0, -10.0]],
        ];
        walls.extend(box_walls([22.0, 25.0], [7.0, 8.0]));
        walls.extend(box_walls([4.0, 7.0], [-9.5, -9.0]));
        let pillars = [[10.0, 3.0], [20.0, 3.0], [10.0, -3.0], [20.0, -3.0]]
            .into_iter()
            .map(|center| Disc {
                center,
                radius: 0.3,
            })
            .collect();
        let people = vec![
            // From the north door to the middle and back out.
            visitor(
                1,
                0.0,
                [15.0, 9.5],
                &[(7.0, [0.0, -1.0]), (7.0, [0.0, 1.0])],
                true,
            ),
            // Across the lobby from the east door to the west door.
            visitor(2, 0.0, [29.5, 0.5], &[(24.0, [-1.2, 0.0])], true),
            // In through the south door, turns around, back out.
            visitor(
                3,
                10.0,
                [9.5, -9.5],
                &[(5.0, [0.1, 1.0]), (5.0, [-0.1, -1.0])],
                true,
            ),
            // In from the west, a long walk with a turn-around, then towards the north door.
            visitor(
                4,
                1.0,
                [0.5, -1.0],
                &[
                    (10.0, [1.0, 0.6]),
                    (8.0, [1.0, 0.0]),
                    (6.0, [-1.0, 0.0]),
                    (6.0, [0.3, 0.8]),
                ],
                true,
            ),
            // From the north door diagonally to the east door.
            visitor(
                5,
                4.0,
                [16.0, 9.5],
                &[(10.0, [0.9, -0.9]), (5.0, [0.9, 0.0])],
                true,
            ),
            // Pacing along the north wall, stays.
            visitor(
                6,
                0.0,
                [5.0, 8.0],
                &[(12.0, [0.5, 0.0]), (12.0, [-0.5, 0.0])],
                false,
            ),
            // In through the east door, waits, turns back.
            visitor(
                7,
                6.0,
                [29.5, -1.0],
                &[(8.0, [-1.0, -0.5]), (4.0, [0.0, 0.0]), (8.0, [1.0, 0.5])],
                true,
            ),
            // In through the south door towards the east door.
            visitor(
                8,
                8.0,
                [10.5, -9.5],
                &[(12.0, [1.0, 0.4]), (10.0, [0.6, 0.45])],
                true,
            ),
            // In from the west door, turns around, back out.
            visitor(
                9,
                12.0,
                [0.5, 1.0],
                &[(8.0, [1.2, -0.3]), (8.0, [-1.2, 0.3])],
                true,
            ),
            // In from the north door, turns around near the pillar, back.
            visitor(
                10,
                15.0,
                [16.5, 9.5],
                &[(9.0, [0.3, -1.0]), (9.0, [-0.3, 1.0])],
                true,
            ),
        ];
        PeopleScenario {
            name: "people2d-two".into(),
            duration: 30.0,
            robot: RobotSpec {
                start: [3.0, -6.0, 0.0],
                legs: robot_legs(&[
                    (6.0, 1.2, 0.0),
                    (3.0, 1.0, FRAC_PI_2 / 3.0),
                    (4.0, 1.5, 0.0),
                    (3.0, 1.0, -FRAC_PI_2 / 3.0),
                    (6.0, 2.0, 0.0),
                    (3.0, 1.0, PI / 3.0),
                    (5.0, 1.0, 0.0),
                ]),
            },
            people,
            walls,
            pillars,
            scanner: ScannerSpec::default(),
            mount: [0.2, 0.0],
            odometry_noise: OdometryNoise::default(),
        }
    }

    /// Checks every part of the scenario: positive finite duration, valid robot legs,
    /// people (positive radius, unique ids, leave after enter), finite walls and pillars with
    /// positive radii, scanner limits and non-negative noise levels.
    pub fn validate(&self) -> Result<()> {
        if !(self.duration.is_finite() && self.duration > 0.0) {
            return Err(Error::invalid(
                "scenario duration",
                format!("{} (must be positive)", self.duration),
            ));
        }
        self.robot.validate()?;
        let mut ids = HashSet::new();
        for p in &self.people {
            p.validate()?;
            if !ids.insert(p.id) {
                return Err(Error::invalid(
                    format!("person {}", p.id),
                    "id used twice".to_string(),
                ));
            }
        }
        for (i, w) in self.walls.iter().enumerate() {
            if !w.iter().flatten().all(|v| v.is_finite()) {
                return Err(Error::invalid(
                    format!("wall {i}"),
                    format!("{w:?} is not finite"),
                ));
            }
        }
        for (i, d) in self.pillars.iter().enumerate() {
            if !(d.center.iter().all(|v| v.is_finite()) && d.radius.is_finite() && d.radius > 0.0) {
                return Err(Error::invalid(
                    format!("pillar {i}"),
                    format!("{d:?} (finite centre, positive radius)"),
                ));
            }
        }
        if !self.mount.iter().all(|v| v.is_finite()) {
            return Err(Error::invalid(
                "mount offset",
                format!("{:?} is not finite", self.mount),
            ));
        }
        self.scanner.validate()?;
        self.odometry_noise.validate()
    }

    /// Number of scans in a run.
    pub fn num_scans(&self) -> usize {
        let n = (self.duration * self.scanner.rate_hz - 1e-9).ceil();
        (n.max(1.0)) as usize
    }

    /// Time stamp of scan `k` (s).
    pub fn scan_time(&self, k: usize) -> f64 {
        k as f64 / self.scanner.rate_hz
    }

    /// The people present at time `t`, by increasing id.
    pub fn people_at(&self, t: f64) -> Vec<PersonTruth> {
        let mut out: Vec<PersonTruth> = self
            .people
            .iter()
            .filter_map(|p| p.state_at(t).map(|(pos, vel)| (p.id, pos, vel)))
            .collect();
        out.sort_by_key(|e| e.0);
        out
    }

    /// Nearest hit along a ray among people discs, pillars and walls.
    fn cast(
        &self,
        origin: [f64; 2],
        dir: [f64; 2],
        people: &[(u64, [f64; 2], f64)],
    ) -> Option<(f64, Hit)> {
        let mut best: Option<(f64, Hit)> = None;
        let mut consider = |t: Option<f64>, hit: Hit| {
            if let Some(t) = t {
                if best.is_none_or(|(b, _)| t < b) {
                    best = Some((t, hit));
                }
            }
        };
        for &(id, c, r) in people {
            consider(ray_circle(origin, dir, c, r), Hit::Person(id));
        }
        for d in &self.pillars {
            consider(ray_circle(origin, dir, d.center, d.radius), Hit::Static);
        }
        for w in &self.walls {
            consider(ray_segment(origin, dir, w[0], w[1]), Hit::Static);
        }
        best
    }

    /// One scan's ranges from the true `sensor` pose among the people `present` (and the
    /// static scene), with the noise of `sc` drawn from `rng` (per beam a bearing, then a range
    /// error), and the ids of the people at least [`MIN_VISIBLE_BEAMS`] rays ended on.
    pub(crate) fn cast_scan(
        &self,
        sensor: Pose2,
        sc: &ScannerSpec,
        present: &[PersonTruth],
        rng: &mut FilterRng,
    ) -> (Vec<f32>, Vec<u64>) {
        let radius_of = |id: u64| {
            self.people
                .iter()
                .find(|p| p.id == id)
                .map_or(0.0, |p| p.radius)
        };
        let discs: Vec<(u64, [f64; 2], f64)> = present
            .iter()
            .map(|&(id, pos, _)| (id, pos, radius_of(id)))
            .collect();
        let mut hits = vec![0usize; discs.len()];
        let mut ranges = Vec::with_capacity(sc.beams);
        let origin = [sensor.x, sensor.y];
        for i in 0..sc.beams {
            let bearing_noise = sc.sigma_bearing * normal(rng);
            let range_noise = sc.sigma_range * normal(rng);
            let angle =
                sensor.theta + sc.angle_min() + i as f64 * sc.angle_increment() + bearing_noise;
            let dir = [angle.cos(), angle.sin()];
            let range = match self.cast(origin, dir, &discs) {
                Some((d, hit)) if d < sc.range_max => {
                    if let Hit::Person(id) = hit {
                        if let Some(j) = discs.iter().position(|e| e.0 == id) {
                            hits[j] += 1;
                        }
                    }
                    (d + range_noise).clamp(0.0, sc.range_max)
                }
                _ => sc.range_max,
            };
            ranges.push(range as f32);
        }
        let visible: Vec<u64> = discs
            .iter()
            .zip(&hits)
            .filter(|(_, &h)| h >= MIN_VISIBLE_BEAMS)
            .map(|(d, _)| d.0)
            .collect();
        (ranges, visible)
    }

    /// The noisy odometry increment from the true pose `prev` to `next` (see the module
    /// documentation), five draws from `rng`, composed onto `odom`.
    pub(crate) fn odometry_step(
        &self,
        odom: Pose2,
        prev: Pose2,
        next: Pose2,
        rng: &mut FilterRng,
    ) -> Pose2 {
        let on = &self.odometry_noise;
        let (s, c) = prev.theta.sin_cos();
        let (dxw, dyw) = (next.x - prev.x, next.y - prev.y);
        let dx = c * dxw + s * dyw;
        let dy = -s * dxw + c * dyw;
        let dth = wrap_angle(next.theta - prev.theta);
        let e_t = on.sigma_trans_rel * normal(rng);
        let n_x = on.sigma_trans_abs * normal(rng);
        let n_y = on.sigma_trans_abs * normal(rng);
        let e_r = on.sigma_rot_rel * normal(rng);
        let n_th = on.sigma_rot_abs * normal(rng);
        let (lx, ly) = (dx * (1.0 + e_t) + n_x, dy * (1.0 + e_t) + n_y);
        let lth = dth * (1.0 + e_r) + n_th;
        let (so, co) = odom.theta.sin_cos();
        Pose2::new(
            odom.x + co * lx - so * ly,
            odom.y + so * lx + co * ly,
            wrap_angle(odom.theta + lth),
        )
    }

    /// Simulates one run (see the module documentation); errors when the scenario is
    /// invalid.
    pub fn generate(&self, seed: u64) -> Result<People2dRun> {
        self.validate()?;
        let n = self.num_scans();
        let sc = &self.scanner;
        let mut run = People2dRun {
            scans: Vec::with_capacity(n),
            robot_truth: Vec::with_capacity(n),
            sensor_truth: Vec::with_capacity(n),
            people_truth: Vec::with_capacity(n),
            visible: Vec::with_capacity(n),
        };
        let mut odom = self.robot.pose_at(0.0);
        let mut prev_truth = odom;
        for k in 0..n {
            let t = self.scan_time(k);
            let mut rng = stream(seed, k as u64);
            let truth = self.robot.pose_at(t);
            if k > 0 {
                odom = self.odometry_step(odom, prev_truth, truth, &mut rng);
            }
            prev_truth = truth;
            let sensor = sensor_pose(truth, self.mount);
            let present = self.people_at(t);
            let (ranges, visible) = self.cast_scan(sensor, sc, &present, &mut rng);
            let mut scan = Scan::new(
                t,
                sc.angle_min(),
                sc.angle_increment(),
                ranges,
                sc.range_min,
                sc.range_max,
            )?;
            scan.odometry = Some(odom);
            scan.laser_pose = Some(sensor_pose(odom, self.mount));
            run.scans.push(scan);
            run.robot_truth.push(truth);
            run.sensor_truth.push(sensor);
            run.people_truth.push(present);
            run.visible.push(visible);
        }
        Ok(run)
    }
}

pub mod lasers;

#[cfg(test)]
mod tests;
