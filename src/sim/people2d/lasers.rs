//! Several lasers on one robot in the simulated people world: each laser at its own mounting
//! pose `(x, y, heading)` on the robot, with its own scanner (field of view, beams, noise), rate
//! and time offset, producing its own scans — in its own frame, at its own times — with the
//! truth of every scan. For measuring what fusing the lasers buys over any one of them, and for
//! testing mounting estimation ([`crate::laser2d::mounting`]) against known poses.
//!
//! # What is simulated
//!
//! The world, the robot's motion and the people are those of the [`PeopleScenario`]; its own
//! `scanner` and `mount` are not used by [`PeopleScenario::generate_lasers`] except to set the
//! odometry clock (below) and by [`LaserRig::single`]. Laser `j` takes scan `k` at
//! `time_offset_j + k / rate_hz_j` for every such time in `[0, duration)`; the sensor's true pose
//! is the true robot pose at that time composed with the mounting, and the scan is cast exactly
//! as [`PeopleScenario::generate`] casts one (same noise model, same visibility rule).
//!
//! # Odometry
//!
//! The robot has one odometry, not one per laser: it ticks at the scenario's scanner clock
//! (`k / scanner.rate_hz`, the same ticks and the same draws as [`PeopleScenario::generate`], so
//! both give the same [`MultiLaserRun::odometry`] poses), and a laser scan between two ticks gets
//! the odometry pose interpolated between them (the increment scaled linearly in x, y and
//! heading), after the last tick the last pose. [`Scan::laser_pose`] is that odometry pose
//! composed with the laser's mounting.
//!
//! # Randomness
//!
//! Odometry tick `k` draws from [`crate::rng::stream`]`(seed, k)` as in
//! [`PeopleScenario::generate`]; scan `k` of laser `j` draws its beam noise from its own stream
//! (`stream(seed ^ mix64(LASER_STREAM + j), k)`), so adding a laser or changing one laser's
//! rate leaves the other lasers' scans unchanged.
//!
//! Not for: scan skew within a sweep, lasers that see each other or the robot's body, or
//! clock drift between lasers; tracking and scoring are elsewhere.

use super::{PeopleScenario, PersonTruth, ScannerSpec};
use crate::error::{Error, Result};
use crate::geometry::pose2::{between, compose};
use crate::geometry::{wrap_angle, Pose2};
use crate::laser2d::{OdometryRecord, Scan};
use crate::rng::{mix64, stream};
use std::f64::consts::PI;

/// Key mixed into the seed of the lasers' beam-noise streams.
const LASER_STREAM: u64 = 0x4C41_5345_5253; // "LASERS"

/// One laser on the robot.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MountedLaser {
    /// The laser's name (the multi-sensor configuration's `[[sensors]]` `name`).
    pub name: String,
    /// Pose `[x, y, heading]` of the laser in the robot frame (m, m, rad): `x` forward, `y`
    /// left, heading counter-clockwise from the robot's forward axis.
    pub mounting: [f64; 3],
    /// The scanner (its `rate_hz` is this laser's rate; the fan is centred on the laser's
    /// heading).
    pub scanner: ScannerSpec,
    /// Time of the laser's first scan (s, ≥ 0).
    pub time_offset: f64,
}

impl MountedLaser {
    /// The mounting as a pose.
    pub fn mounting_pose(&self) -> Pose2 {
        Pose2::new(self.mounting[0], self.mounting[1], self.mounting[2])
    }

    /// Time of scan `k` (s).
    pub fn scan_time(&self, k: usize) -> f64 {
        self.time_offset + k as f64 / self.scanner.rate_hz
    }

    /// Number of scans in a run of `duration` seconds: every `k` with `scan_time(k) < duration`.
    pub fn num_scans(&self, duration: f64) -> usize {
        let n = ((duration - self.time_offset) * self.scanner.rate_hz - 1e-9).ceil();
        n.max(0.0) as usize
    }
}

/// The lasers of one robot.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LaserRig {
    /// The lasers, in the order their streams are returned.
    pub lasers: Vec<MountedLaser>,
}

impl LaserRig {
    /// The scenario's own laser as a rig of one: named `laser`, mounted at the scenario's
    /// `mount` facing forward, its scanner, no time offset.
    pub fn single(scenario: &PeopleScenario) -> Self {
        LaserRig {
            lasers: vec![MountedLaser {
                name: "laser".into(),
                mounting: [scenario.mount[0], scenario.mount[1], 0.0],
                scanner: scenario.scanner,
                time_offset: 0.0,
            }],
        }
    }

    /// Three lasers at the corners of a robot about 0.6 m × 0.4 m, each with a limited field of
    /// view so that each alone misses people the others see:
    ///
    /// | name | mounting `[x, y, heading]` | field of view | beams | rate | first scan |
    /// |---|---|---|---|---|---|
    /// | `front_left` | `[0.25, 0.18, +45°]` | 200° (−55° … 145° about the robot's axis) | 401 | `scanner.rate_hz` | 0 |
    /// | `front_right` | `[0.25, −0.18, −45°]` | 200° (−145° … 55°) | 401 | `scanner.rate_hz` | half a period |
    /// | `rear` | `[−0.3, 0.0, 180°]` | 140° (110° … 250°) | 281 | 5/8 of `scanner.rate_hz` | 0.03 s |
    ///
    /// Together they see all round (the front lasers overlap ahead over 110°, the rear one
    /// overlaps each front one over 35°); beams stay 0.5° apart; range limits and noise are
    /// `scanner`'s. With the default scanner the rates are 8, 8 and 5 Hz.
    pub fn three_lasers(scanner: ScannerSpec) -> Self {
        let with = |fov_deg: f64, rate: f64| ScannerSpec {
            fov: fov_deg.to_radians(),
            beams: (2.0 * fov_deg).round() as usize + 1,
            rate_hz: rate,
            ..scanner
        };
        let r = scanner.rate_hz;
        LaserRig {
            lasers: vec![
                MountedLaser {
                    name: "front_left".into(),
                    mounting: [0.25, 0.18, PI / 4.0],
                    scanner: with(200.0, r),
                    time_offset: 0.0,
                },
                MountedLaser {
                    name: "front_right".into(),
                    mounting: [0.25, -0.18, -PI / 4.0],
                    scanner: with(200.0, r),
                    time_offset: 0.5 / r,
                },
                MountedLaser {
                    name: "rear".into(),
                    mounting: [-0.3, 0.0, PI],
                    scanner: with(140.0, 0.625 * r),
                    time_offset: 0.03,
                },
            ],
        }
    }

    /// Checks every laser: a unique non-empty name, a finite mounting, a valid scanner and a
    /// finite time offset ≥ 0; at least one laser.
    pub fn validate(&self) -> Result<()> {
        if self.lasers.is_empty() {
            return Err(Error::invalid("laser rig", "no lasers"));
        }
        for (i, l) in self.lasers.iter().enumerate() {
            let what = || format!("laser {i} ({})", l.name);
            if l.name.is_empty() {
                return Err(Error::invalid(what(), "empty name"));
            }
            if self.lasers[..i].iter().any(|o| o.name == l.name) {
                return Err(Error::invalid(what(), "name used twice"));
            }
            if !l.mounting.iter().all(|v| v.is_finite()) {
                return Err(Error::invalid(
                    what(),
                    format!("mounting {:?} is not finite", l.mounting),
                ));
            }
            if !(l.time_offset.is_finite() && l.time_offset >= 0.0) {
                return Err(Error::invalid(
                    what(),
                    format!("time_offset {} (must be finite and ≥ 0)", l.time_offset),
                ));
            }
            l.scanner
                .validate()
                .map_err(|e| Error::invalid(what(), e.to_string()))?;
        }
        Ok(())
    }
}

/// A visible person as one laser sees it: the true centre in the laser's own frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LaserDetection {
    /// The person's id.
    pub id: u64,
    /// Centre `[x, y]` in the laser frame (m).
    pub position: [f64; 2],
    /// Range of the centre (m).
    pub range: f64,
    /// Bearing of the centre in the laser frame (rad).
    pub bearing: f64,
}

/// One laser's output; every vector has one entry per scan of this laser.
#[derive(Clone, Debug, PartialEq)]
pub struct LaserStream {
    /// The laser's name.
    pub name: String,
    /// The true mounting (robot frame).
    pub mounting: Pose2,
    /// The scans, in the laser's frame at the laser's times, with the (interpolated) noisy
    /// odometry in [`Scan::odometry`] and that pose composed with the mounting in
    /// [`Scan::laser_pose`].
    pub scans: Vec<Scan>,
    /// True robot poses at the scans' times.
    pub robot_truth: Vec<Pose2>,
    /// True sensor poses (robot pose ∘ mounting).
    pub sensor_truth: Vec<Pose2>,
    /// Everyone in the scene (world frame), by increasing id.
    pub people_truth: Vec<Vec<PersonTruth>>,
    /// Ids of the people at least [`super::MIN_VISIBLE_BEAMS`] beams of this laser ended on.
    pub visible: Vec<Vec<u64>>,
    /// The visible people's true centres in this laser's frame, by increasing id.
    pub detections: Vec<Vec<LaserDetection>>,
}

/// Output of [`PeopleScenario::generate_lasers`].
#[derive(Clone, Debug, PartialEq)]
pub struct MultiLaserRun {
    /// The robot's noisy odometry at its ticks (scenario scanner clock).
    pub odometry: Vec<OdometryRecord>,
    /// One stream per laser, in rig order.
    pub lasers: Vec<LaserStream>,
}

impl MultiLaserRun {
    /// Every scan of every laser as `(time, laser, scan index)`, by time, ties by laser
    /// order: the order a multi-sensor filter takes them in.
    pub fn frames(&self) -> Vec<(f64, usize, usize)> {
        let mut out: Vec<(f64, usize, usize)> = self
            .lasers
            .iter()
            .enumerate()
            .flat_map(|(j, l)| l.scans.iter().enumerate().map(move |(k, s)| (s.time, j, k)))
            .collect();
        out.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        out
    }
}

/// The odometry pose at time `t` from the ticks (interpolated between the two around it).
fn odometry_at(odometry: &[OdometryRecord], t: f64) -> Pose2 {
    let after = odometry.partition_point(|o| o.time <= t);
    if after == 0 {
        return odometry[0].pose;
    }
    let a = &odometry[after - 1];
    let Some(b) = odometry.get(after) else {
        return a.pose;
    };
    let alpha = (t - a.time) / (b.time - a.time);
    if alpha <= 0.0 {
        return a.pose;
    }
    let d = between(a.pose, b.pose);
    compose(
        a.pose,
        Pose2::new(alpha * d.x, alpha * d.y, alpha * wrap_angle(d.theta)),
    )
}

impl PeopleScenario {
    /// Simulates one run seen by every laser of `rig` (see [`lasers`](self)); errors when the
    /// scenario or the rig is invalid. A pure function of the scenario, the rig and the seed.
    pub fn generate_lasers(&self, rig: &LaserRig, seed: u64) -> Result<MultiLaserRun> {
        self.validate()?;
        rig.validate()?;
        // The odometry ticks, drawn exactly as `generate` draws them.
        let n = self.num_scans();
        let mut odometry = Vec::with_capacity(n);
        let mut odom = self.robot.pose_at(0.0);
        let mut prev_truth = odom;
        let dt = 1.0 / self.scanner.rate_hz;
        for k in 0..n {
            let t = self.scan_time(k);
            let truth = self.robot.pose_at(t);
            let last = odom;
            if k > 0 {
                let mut rng = stream(seed, k as u64);
                odom = self.odometry_step(odom, prev_truth, truth, &mut rng);
            }
            prev_truth = truth;
            let inc = between(last, odom);
            odometry.push(OdometryRecord {
                time: t,
                pose: odom,
                linear_velocity: inc.x.hypot(inc.y) / dt,
                angular_velocity: inc.theta / dt,
            });
        }
        let mut lasers = Vec::with_capacity(rig.lasers.len());
        for (j, laser) in rig.lasers.iter().enumerate() {
            let mount = laser.mounting_pose();
            let sc = &laser.scanner;
            let m = laser.num_scans(self.duration);
            let laser_seed = seed ^ mix64(LASER_STREAM.wrapping_add(j as u64));
            let mut out = LaserStream {
                name: laser.name.clone(),
                mounting: mount,
                scans: Vec::with_capacity(m),
                robot_truth: Vec::with_capacity(m),
                sensor_truth: Vec::with_capacity(m),
                people_truth: Vec::with_capacity(m),
                visible: Vec::with_capacity(m),
                detections: Vec::with_capacity(m),
            };
            for k in 0..m {
                let t = laser.scan_time(k);
                let truth = self.robot.pose_at(t);
                let sensor = compose(truth, mount);
                let present = self.people_at(t);
                let mut rng = stream(laser_seed, k as u64);
                let (ranges, visible) = self.cast_scan(sensor, sc, &present, &mut rng);
                let mut scan = Scan::new(
                    t,
                    sc.angle_min(),
                    sc.angle_increment(),
                    ranges,
                    sc.range_min,
                    sc.range_max,
                )?;
                let odo = odometry_at(&odometry, t);
                scan.odometry = Some(odo);
                scan.laser_pose = Some(compose(odo, mount));
                let (s, c) = sensor.theta.sin_cos();
                let detections = present
                    .iter()
                    .filter(|p| visible.contains(&p.0))
                    .map(|&(id, pos, _)| {
                        let (dx, dy) = (pos[0] - sensor.x, pos[1] - sensor.y);
                        let position = [c * dx + s * dy, -s * dx + c * dy];
                        LaserDetection {
                            id,
                            position,
                            range: position[0].hypot(position[1]),
                            bearing: position[1].atan2(position[0]),
                        }
                    })
                    .collect();
                out.scans.push(scan);
                out.robot_truth.push(truth);
                out.sensor_truth.push(sensor);
                out.people_truth.push(present);
                out.visible.push(visible);
                out.detections.push(detections);
            }
            lasers.push(out);
        }
        Ok(MultiLaserRun { odometry, lasers })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rig_of_the_scenario_laser_repeats_generate_without_noise() {
        let mut sc = PeopleScenario::two();
        sc.scanner = sc.scanner.noise_free();
        let run = sc.generate(5).unwrap();
        let multi = sc.generate_lasers(&LaserRig::single(&sc), 5).unwrap();
        let l = &multi.lasers[0];
        assert_eq!(l.scans.len(), run.scans.len());
        for k in 0..run.scans.len() {
            assert_eq!(l.scans[k].ranges, run.scans[k].ranges, "scan {k}");
            assert_eq!(l.scans[k].time, run.scans[k].time);
            assert_eq!(l.visible[k], run.visible[k]);
            assert_eq!(l.people_truth[k], run.people_truth[k]);
            assert_eq!(multi.odometry[k].pose, run.scans[k].odometry.unwrap());
            // Scans on the ticks get the tick's odometry.
            assert_eq!(l.scans[k].odometry, run.scans[k].odometry);
            let (a, b) = (l.sensor_truth[k], run.sensor_truth[k]);
            assert!((a.x - b.x).abs() < 1e-12 && (a.y - b.y).abs() < 1e-12);
        }
    }

    #[test]
    fn three_lasers_see_in_their_own_frames_at_their_own_rates() {
        let sc = PeopleScenario::two();
        let rig = LaserRig::three_lasers(sc.scanner);
        let run = sc.generate_lasers(&rig, 3).unwrap();
        assert_eq!(run.lasers.len(), 3);
        let counts: Vec<usize> = run.lasers.iter().map(|l| l.scans.len()).collect();
        // 30 s at 8, 8 and 5 Hz (the rear laser starts at 0.03 s).
        assert_eq!(counts, vec![240, 240, 150]);
        assert_eq!(run.lasers[1].scans[0].time, 0.0625);
        let frames = run.frames();
        assert_eq!(frames.len(), 630);
        assert!(frames.windows(2).all(|w| w[0].0 <= w[1].0));
        for l in &run.lasers {
            for k in 0..l.scans.len() {
                let sensor = l.sensor_truth[k];
                let truth = compose(l.robot_truth[k], l.mounting);
                assert!((sensor.x - truth.x).abs() < 1e-12);
                for d in &l.detections[k] {
                    // Back to the world: the person's true centre.
                    let (_, pos, _) = l.people_truth[k].iter().find(|p| p.0 == d.id).unwrap();
                    let w = crate::geometry::pose2::transform_point(sensor, d.position);
                    assert!((w[0] - pos[0]).abs() < 1e-9 && (w[1] - pos[1]).abs() < 1e-9);
                    // Inside the laser's field of view (plus a person's radius).
                    assert!(d.bearing.abs() <= l.scans[k].angle_max() + 0.3, "{d:?}");
                }
            }
        }
        // Each laser alone misses people that another one sees.
        let seen = |j: usize| -> std::collections::BTreeSet<(usize, u64)> {
            let l = &run.lasers[j];
            (0..l.scans.len())
                .flat_map(|k| {
                    let slot = (l.scans[k].time * 4.0) as usize; // quarter-second slots
                    l.visible[k].iter().map(move |&id| (slot, id))
                })
                .collect()
        };
        let all: Vec<_> = (0..3).map(seen).collect();
        for j in 0..3 {
            let others: std::collections::BTreeSet<_> = (0..3)
                .filter(|&i| i != j)
                .flat_map(|i| all[i].iter().copied())
                .collect();
            let missed = others.difference(&all[j]).count();
            assert!(
                missed > 20,
                "laser {j} misses only {missed} (slot, person) pairs"
            );
        }
    }

    #[test]
    fn adding_a_laser_leaves_the_others_unchanged_and_bad_rigs_are_errors() {
        let sc = PeopleScenario::one();
        let mut rig = LaserRig::three_lasers(sc.scanner);
        let a = sc.generate_lasers(&rig, 9).unwrap();
        rig.lasers.truncate(2);
        let b = sc.generate_lasers(&rig, 9).unwrap();
        assert_eq!(a.lasers[..2], b.lasers[..]);
        assert_eq!(a.odometry, b.odometry);
        let mut bad = rig.clone();
        bad.lasers[1].name = bad.lasers[0].name.clone();
        assert!(sc.generate_lasers(&bad, 1).is_err());
        let mut bad = rig.clone();
        bad.lasers[0].mounting[2] = f64::NAN;
        assert!(sc.generate_lasers(&bad, 1).is_err());
        let mut bad = rig.clone();
        bad.lasers[0].time_offset = -0.1;
        assert!(sc.generate_lasers(&bad, 1).is_err());
        let mut bad = rig;
        bad.lasers[0].scanner.beams = 1;
        assert!(sc.generate_lasers(&bad, 1).is_err());
        assert!(sc.generate_lasers(&LaserRig { lasers: vec![] }, 1).is_err());
    }
}
