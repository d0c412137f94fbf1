//! A simulated street drive in the KITTI raw layout: an ego vehicle with an HDL-64E-like lidar
//! and an OXTS unit drives at about 10 m/s along a street with turns, between building walls,
//! past parked cars, moving cars and pedestrians. [`write_drive`] writes it as
//! `DIR/DATE/DATE_drive_NNNN_sync/` that [`crate::kitti::RawDrive`] opens unchanged, plus
//! `truth.json` ([`StreetTruth`]); [`write_tracking_sequence`] writes it in the KITTI tracking
//! layout with its cars and pedestrians as `label_02` labels; [`generate`] keeps it in memory
//! with per-point labels.
//!
//! The pieces: [`ego`] (the vehicle's motion), [`world`] (the scene), [`ground`] (the road
//! surface's relief), [`lidar`] (the ray
//! caster), [`truth`] (what is written as ground truth), [`writer`] (the raw layout's files),
//! [`tracking_writer`] (the tracking layout's).
//!
//! **Poses.** The OXTS unit rolls, pitches and heaves a little with the body (see [`body`]);
//! the
//! Velodyne pose follows from the IMU→Velodyne calibration exactly as the reader derives it
//! (W_velo = W_imu·T_velo_imu⁻¹, with the calibration as the reader parses it), and the
//! mounting height is that of the Velodyne origin. Latitude and longitude are the world x/y
//! (east/north) through the inverse of the devkit's Mercator projection whose scale is fixed by
//! the first packet, so the poses read back equal the simulated ones to rounding.
//!
//! **Randomness.** The scene comes from `rng::stream(seed, SCENE_KEY)`, scan k from its own
//! streams (see [`lidar`]): a drive is a pure function of the configuration, the frame count
//! and the seed, at any thread count. The scene depends on the frame count (objects are placed
//! near the ego's path during the drive).
//!
//! Not for: reading drives back (see [`crate::kitti`]) or scoring trackers against the truth.

pub mod body;
pub mod calib_files;
pub mod ego;
pub mod ground;
pub mod lidar;
pub mod tracking_writer;
pub mod truth;
pub mod world;
pub mod writer;

pub use body::{BodyMotion, BodyMotionConfig};
pub use ego::{EgoState, EgoTrajectory, LegSpec};
pub use ground::{Ground, GroundConfig, ReliefOctave};
pub use lidar::{LidarConfig, LidarScan, Surface};
pub use tracking_writer::{write_tracking_sequence, WrittenSequence};
pub use truth::{FrameTruth, ObjectState, ObjectTruth, PoseTruth, StreetTruth, WallTruth};
pub use world::{ObjectKind, Street};
pub use writer::{write_drive, WrittenDrive, TRUTH_FILE};

use crate::error::{ensure_non_negative, ensure_positive, Error, Result};
use crate::geometry::wrap_angle;
use crate::kitti::calib::{rigid_calib_from, CalibFile};
use crate::kitti::poses::{oxts_rotation, velodyne_pose_from_imu, Mercator};
use crate::kitti::{OxtsPacket, Timestamp};
use crate::rng::{mix64, stream};
use nalgebra::{Isometry3, Point3, Translation3};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Key of the scene's random stream.
const SCENE_KEY: u64 = 0x5743_4E45;
/// Key of the ground relief's hash.
const GROUND_KEY: u64 = 0x4752_4E44;
/// Key of the body motion's random stream.
const BODY_KEY: u64 = 0x424F_4459;
/// Standard gravity, m/s² (OXTS accelerations include it, as the real unit's do).
const GRAVITY: f64 = 9.80665;

/// Street cross-section and building walls. Lengths in metres.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StreetLayout {
    /// Distance from the centreline to the kerb.
    pub road_half_width: f64,
    /// Sidewalk width between kerb and walls.
    pub sidewalk_width: f64,
    /// Lane width.
    pub lane_width: f64,
    /// Lateral offset of the ego's path from the centreline (negative = right).
    pub ego_lane_offset: f64,
    /// Range of wall piece lengths.
    pub wall_length: [f64; 2],
    /// Range of gaps between wall pieces.
    pub wall_gap: [f64; 2],
    /// Range of wall heights.
    pub wall_height: [f64; 2],
    /// Shorter pieces left at segment ends are dropped.
    pub min_wall_piece: f64,
    /// The street starts this far behind the ego's start.
    pub behind_start: f64,
    /// The last street segment reaches this far beyond the ego's last position.
    pub beyond_end: f64,
}

impl Default for StreetLayout {
    fn default() -> Self {
        StreetLayout {
            road_half_width: 9.0,
            sidewalk_width: 3.0,
            lane_width: 3.5,
            ego_lane_offset: -1.75,
            wall_length: [20.0, 45.0],
            wall_gap: [3.0, 10.0],
            wall_height: [6.0, 15.0],
            min_wall_piece: 5.0,
            behind_start: 60.0,
            beyond_end: 80.0,
        }
    }
}

/// Cars and pedestrians.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TrafficConfig {
    /// Number of parked cars.
    pub parked_cars: usize,
    /// Number of moving cars.
    pub moving_cars: usize,
    /// Number of pedestrians.
    pub pedestrians: usize,
    /// Car length, width, height, metres.
    pub car_size: [f64; 3],
    /// Range of moving car speeds, m/s.
    pub car_speed: [f64; 2],
    /// Pedestrian radius, metres.
    pub pedestrian_radius: f64,
    /// Pedestrian height, metres.
    pub pedestrian_height: f64,
    /// Range of walking speeds, m/s.
    pub pedestrian_speed: [f64; 2],
    /// Objects keep this far from street corners (moving ones vanish there), metres.
    pub corner_clearance: f64,
    /// Objects start within this distance of the ego's path, metres.
    pub spawn_radius: f64,
}

impl Default for TrafficConfig {
    fn default() -> Self {
        TrafficConfig {
            parked_cars: 8,
            moving_cars: 5,
            pedestrians: 8,
            car_size: [4.5, 1.8, 1.5],
            car_speed: [5.0, 12.0],
            pedestrian_radius: 0.3,
            pedestrian_height: 1.75,
            pedestrian_speed: [1.2, 1.4],
            corner_clearance: 20.0,
            spawn_radius: 60.0,
        }
    }
}

/// Where and when the drive is recorded.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Recording {
    /// Latitude of the start, degrees (also the Mercator reference).
    pub latitude: f64,
    /// Longitude of the start, degrees.
    pub longitude: f64,
    /// Ground altitude, metres.
    pub altitude: f64,
    /// Date folder name, `YYYY_MM_DD`.
    pub date: String,
    /// Time of frame 0, `hh:mm:ss[.fraction]`.
    pub start_time: String,
    /// Drive number (`DATE_drive_NNNN_sync`).
    pub drive_number: u32,
}

impl Default for Recording {
    fn default() -> Self {
        Recording {
            latitude: 49.0,
            longitude: 8.43,
            altitude: 115.0,
            date: "2020_01_01".to_string(),
            start_time: "12:00:00.000000000".to_string(),
            drive_number: 1,
        }
    }
}

/// A whole simulated street drive as data (TOML/JSON); every field has a default.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct StreetConfig {
    /// Ego speed, m/s.
    pub speed: f64,
    /// Time between frames, seconds.
    pub frame_period: f64,
    /// Initial heading, degrees counter-clockwise from east.
    pub start_heading_deg: f64,
    /// The route: straight stretches and turns; straight on after the last.
    pub route: Vec<LegSpec>,
    /// Street geometry.
    pub street: StreetLayout,
    /// The ground's relief.
    pub ground: GroundConfig,
    /// The vehicle body's roll, pitch and heave.
    pub body: BodyMotionConfig,
    /// Cars and pedestrians.
    pub traffic: TrafficConfig,
    /// The lidar.
    pub lidar: LidarConfig,
    /// Place and time.
    pub recording: Recording,
}

impl Default for StreetConfig {
    fn default() -> Self {
        StreetConfig {
            speed: 10.0,
            frame_period: 0.1,
            start_heading_deg: 30.0,
            route: vec![
                LegSpec {
                    straight: 25.0,
                    turn_deg: 45.0,
                    turn_seconds: 3.0,
                },
                LegSpec {
                    straight: 50.0,
                    turn_deg: -60.0,
                    turn_seconds: 4.0,
                },
                LegSpec {
                    straight: 60.0,
                    turn_deg: 30.0,
                    turn_seconds: 2.5,
                },
            ],
            street: StreetLayout::default(),
            ground: GroundConfig::default(),
            body: BodyMotionConfig::default(),
            traffic: TrafficConfig::default(),
            lidar: LidarConfig::default(),
            recording: Recording::default(),
        }
    }
}

fn ensure_range(what: &str, r: [f64; 2]) -> Result<()> {
    ensure_non_negative(what, r[0])?;
    ensure_non_negative(what, r[1])?;
    if r[1] < r[0] {
        return Err(Error::invalid(
            what,
            format!("[{}, {}] is decreasing", r[0], r[1]),
        ));
    }
    Ok(())
}

impl StreetConfig {
    /// Checks every field; errors name the field.
    pub fn validate(&self) -> Result<()> {
        ensure_positive("speed", self.speed)?;
        ensure_positive("frame_period", self.frame_period)?;
        crate::error::ensure_finite("start_heading_deg", &[self.start_heading_deg])?;
        for (i, leg) in self.route.iter().enumerate() {
            ensure_non_negative(&format!("route[{i}].straight"), leg.straight)?;
            ensure_positive(&format!("route[{i}].turn_seconds"), leg.turn_seconds)?;
            if !(leg.turn_deg.abs() >= 10.0 && leg.turn_deg.abs() <= 120.0) {
                return Err(Error::invalid(
                    format!("route[{i}].turn_deg"),
                    format!("{} (turns must be 10° to 120° either way)", leg.turn_deg),
                ));
            }
        }
        let s = &self.street;
        ensure_positive("street.road_half_width", s.road_half_width)?;
        ensure_positive("street.sidewalk_width", s.sidewalk_width)?;
        ensure_positive("street.lane_width", s.lane_width)?;
        if s.ego_lane_offset.is_nan() || s.ego_lane_offset.abs() >= s.road_half_width {
            return Err(Error::invalid(
                "street.ego_lane_offset",
                format!("{} is not inside the road", s.ego_lane_offset),
            ));
        }
        ensure_range("street.wall_length", s.wall_length)?;
        ensure_positive("street.wall_length", s.wall_length[0])?;
        ensure_range("street.wall_gap", s.wall_gap)?;
        ensure_range("street.wall_height", s.wall_height)?;
        ensure_positive("street.wall_height", s.wall_height[0])?;
        ensure_non_negative("street.min_wall_piece", s.min_wall_piece)?;
        ensure_non_negative("street.behind_start", s.behind_start)?;
        ensure_positive("street.beyond_end", s.beyond_end)?;
        self.ground.validate()?;
        self.body.validate()?;
        let t = &self.traffic;
        for (i, v) in t.car_size.iter().enumerate() {
            ensure_positive(&format!("traffic.car_size[{i}]"), *v)?;
        }
        ensure_range("traffic.car_speed", t.car_speed)?;
        ensure_positive("traffic.pedestrian_radius", t.pedestrian_radius)?;
        ensure_positive("traffic.pedestrian_height", t.pedestrian_height)?;
        ensure_range("traffic.pedestrian_speed", t.pedestrian_speed)?;
        ensure_non_negative("traffic.corner_clearance", t.corner_clearance)?;
        ensure_positive("traffic.spawn_radius", t.spawn_radius)?;
        let l = &self.lidar;
        if l.beams < 2 || !l.beams.is_multiple_of(2) || l.beams > 256 {
            return Err(Error::invalid(
                "lidar.beams",
                format!("{} (must be even, 2 to 256)", l.beams),
            ));
        }
        if !(l.elevation_top_deg < 90.0
            && l.elevation_top_deg > l.elevation_split_deg
            && l.elevation_split_deg > l.elevation_bottom_deg
            && l.elevation_bottom_deg > -90.0)
        {
            return Err(Error::invalid(
                "lidar elevations",
                "need 90 > top > split > bottom > -90 degrees",
            ));
        }
        if l.columns == 0 || l.columns > 100_000 {
            return Err(Error::invalid(
                "lidar.columns",
                format!("{} (must be 1 to 100000)", l.columns),
            ));
        }
        ensure_positive("lidar.max_range", l.max_range)?;
        ensure_non_negative("lidar.min_range", l.min_range)?;
        ensure_non_negative("lidar.range_noise", l.range_noise)?;
        ensure_positive("lidar.mount_height", l.mount_height)?;
        if !(0.0..1.0).contains(&l.dropout) {
            return Err(Error::invalid(
                "lidar.dropout",
                format!("{} (must be in [0, 1))", l.dropout),
            ));
        }
        let r = &self.recording;
        if !(r.latitude.abs() < 80.0 && r.longitude.abs() <= 180.0 && r.altitude.is_finite()) {
            return Err(Error::invalid(
                "recording latitude/longitude/altitude",
                format!("{} / {} / {}", r.latitude, r.longitude, r.altitude),
            ));
        }
        self.start_stamp()?;
        Ok(())
    }

    /// The time stamp of frame 0 from `recording.date` and `recording.start_time`.
    pub fn start_stamp(&self) -> Result<Timestamp> {
        let r = &self.recording;
        let ok = r.date.len() == 10 && r.date.bytes().all(|b| b.is_ascii_digit() || b == b'_');
        let text = format!("{} {}", r.date.replace('_', "-"), r.start_time);
        match Timestamp::parse(&text) {
            Ok(t) if ok => Ok(t),
            Ok(_) => Err(Error::invalid(
                "recording.date",
                format!("`{}` is not YYYY_MM_DD", r.date),
            )),
            Err(e) => Err(Error::invalid("recording date/start_time", e)),
        }
    }

    /// Drive folder name, `DATE_drive_NNNN_sync`.
    pub fn drive_name(&self) -> String {
        format!(
            "{}_drive_{:04}_sync",
            self.recording.date, self.recording.drive_number
        )
    }
}

/// A drive being simulated: the scene, the motion and the rig, frame by frame.
#[derive(Clone, Debug)]
pub struct StreetSimulator {
    config: StreetConfig,
    frames: usize,
    seed: u64,
    trajectory: EgoTrajectory,
    street: Street,
    ground: Ground,
    body: BodyMotion,
    t_velo_imu: Isometry3<f64>,
    imu_height: f64,
    mercator: Mercator,
    origin_xy: (f64, f64),
    start: Timestamp,
}

impl StreetSimulator {
    /// Builds the scene for `frames` frames. Errors: an invalid configuration (naming the
    /// field), `frames == 0`, or a route whose corners overlap.
    pub fn new(config: &StreetConfig, frames: usize, seed: u64) -> Result<StreetSimulator> {
        config.validate()?;
        if frames == 0 {
            return Err(Error::invalid("frame count", "0 (need at least one frame)"));
        }
        let start = config.start_stamp()?;
        if start
            .plus_seconds(frames as f64 * config.frame_period)
            .is_none()
        {
            return Err(Error::invalid(
                "frame count",
                format!("{frames} runs past year 9999"),
            ));
        }
        let calib = CalibFile::parse(Path::new("calib_imu_to_velo.txt"), calib_files::IMU_TO_VELO)
            .and_then(|f| rigid_calib_from(&f))?;
        let t_velo_imu = calib.isometry;
        // The Velodyne origin in IMU coordinates; the IMU is level, so its height follows.
        let velo_in_imu = t_velo_imu.inverse() * Point3::origin();
        let imu_height = config.lidar.mount_height - velo_in_imu.z;
        let trajectory = EgoTrajectory::new(
            0.0,
            0.0,
            config.start_heading_deg.to_radians(),
            config.speed,
            &config.route,
        );
        let times: Vec<f64> = (0..frames)
            .map(|k| k as f64 * config.frame_period)
            .collect();
        let ego: Vec<[f64; 2]> = times
            .iter()
            .map(|&t| {
                let s = trajectory.state_at(t);
                [s.x, s.y]
            })
            .collect();
        let mut rng = stream(seed, SCENE_KEY);
        let street =
            world::build_street(config, &trajectory.straight_lines(), &ego, &times, &mut rng)?;
        let ground = Ground::new(&config.ground, mix64(seed ^ mix64(GROUND_KEY)));
        let body = BodyMotion::new(&config.body, &mut stream(seed, BODY_KEY));
        let r = &config.recording;
        let mercator = Mercator::from_reference_latitude(r.latitude)?;
        let origin_xy = mercator.project(r.latitude, r.longitude);
        Ok(StreetSimulator {
            config: config.clone(),
            frames,
            seed,
            trajectory,
            street,
            ground,
            body,
            t_velo_imu,
            imu_height,
            mercator,
            origin_xy,
            start,
        })
    }

    /// The configuration.
    pub fn config(&self) -> &StreetConfig {
        &self.config
    }

    /// Number of frames.
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// The scene.
    pub fn street(&self) -> &Street {
        &self.street
    }

    /// The ground surface.
    pub fn ground(&self) -> &Ground {
        &self.ground
    }

    /// Time of frame k since frame 0, seconds.
    pub fn time(&self, k: usize) -> f64 {
        k as f64 * self.config.frame_period
    }

    /// Time stamp of frame k.
    pub fn timestamp(&self, k: usize) -> Timestamp {
        // Checked in `new` for the last frame.
        self.start.plus_seconds(self.time(k)).unwrap_or(self.start)
    }

    /// The ego state at frame k.
    pub fn ego(&self, k: usize) -> EgoState {
        self.trajectory.state_at(self.time(k))
    }

    /// The IMU→Velodyne calibration T_velo_imu as the reader parses it.
    pub fn imu_to_velo(&self) -> Isometry3<f64> {
        self.t_velo_imu
    }

    /// The IMU pose in the world at frame k (roll, pitch and heave of the body, heading
    /// wrapped as in the OXTS packet).
    pub fn imu_pose(&self, k: usize) -> Isometry3<f64> {
        let s = self.ego(k);
        let t = self.time(k);
        let (roll, pitch) = self.body.attitude(t);
        Isometry3::from_parts(
            Translation3::new(s.x, s.y, self.imu_height + self.body.heave(t)),
            oxts_rotation(roll, pitch, wrap_angle(s.yaw)),
        )
    }

    /// The Velodyne pose in the world at frame k.
    pub fn velodyne_pose(&self, k: usize) -> Isometry3<f64> {
        velodyne_pose_from_imu(&self.imu_pose(k), &self.t_velo_imu)
    }

    /// The Velodyne pose of frame k relative to frame 0 (what `RawDrive::poses()` gives).
    pub fn drive_pose(&self, k: usize) -> Isometry3<f64> {
        self.velodyne_pose(0).inverse() * self.velodyne_pose(k)
    }

    /// The OXTS packet of frame k.
    pub fn packet(&self, k: usize) -> OxtsPacket {
        let s = self.ego(k);
        let (lat, lon) = self
            .mercator
            .unproject(self.origin_xy.0 + s.x, self.origin_xy.1 + s.y);
        let (ve, vn) = s.velocity();
        let lateral = s.speed * s.yaw_rate;
        let t = self.time(k);
        let (roll, pitch) = self.body.attitude(t);
        let (roll_rate, pitch_rate) = self.body.attitude_rate(t);
        let (sy, cy) = s.yaw.sin_cos();
        OxtsPacket {
            lat,
            lon,
            alt: self.config.recording.altitude + self.imu_height + self.body.heave(t),
            roll,
            pitch,
            yaw: wrap_angle(s.yaw),
            vn,
            ve,
            vf: s.speed,
            vl: 0.0,
            vu: self.body.heave_rate(t),
            ax: 0.0,
            ay: lateral,
            az: GRAVITY,
            af: 0.0,
            al: lateral,
            au: GRAVITY,
            wx: cy * roll_rate - sy * pitch_rate,
            wy: sy * roll_rate + cy * pitch_rate,
            wz: s.yaw_rate,
            wf: roll_rate,
            wl: pitch_rate,
            wu: s.yaw_rate,
            pos_accuracy: 0.02,
            vel_accuracy: 0.01,
            navstat: 4,
            numsats: 11,
            posmode: 6,
            velmode: 6,
            orimode: 6,
        }
    }

    /// Scan of frame k, in the Velodyne frame, with what each point hit.
    pub fn scan(&self, k: usize) -> LidarScan {
        let shapes = self.street.shapes_at(self.time(k));
        let seed = mix64(self.seed ^ mix64(0x5CA4_0000 + k as u64));
        lidar::cast_scan(
            &shapes,
            &self.ground,
            &self.velodyne_pose(k),
            &self.config.lidar,
            seed,
        )
    }

    /// The truth without point counts (all zero); add them with [`record_scan`](Self::record_scan).
    pub fn truth(&self) -> StreetTruth {
        let frames = (0..self.frames)
            .map(|k| FrameTruth {
                index: k,
                time: self.time(k),
                velodyne_pose: PoseTruth::from_isometry(&self.velodyne_pose(k)),
                drive_pose: PoseTruth::from_isometry(&self.drive_pose(k)),
                imu_pose: PoseTruth::from_isometry(&self.imu_pose(k)),
                ego: self.ego(k),
                points: 0,
                ground_points: 0,
            })
            .collect();
        let walls = self
            .street
            .walls
            .iter()
            .map(|w| WallTruth {
                id: w.id,
                vertices: w.vertices(),
                normal: [w.normal[0], w.normal[1], 0.0],
                offset: w.offset(),
                width: w.length,
                height: w.height,
                points: vec![0; self.frames],
            })
            .collect();
        let segments = &self.street.segments;
        let objects = self
            .street
            .objects
            .iter()
            .map(|o| ObjectTruth {
                id: o.id,
                kind: o.kind,
                size: o.size,
                states: (0..self.frames)
                    .filter_map(|k| {
                        let (p, v) = o.state_at(segments, self.time(k))?;
                        Some(ObjectState {
                            frame: k,
                            position: [p[0], p[1], 0.0],
                            velocity: [v[0], v[1], 0.0],
                            yaw: o.yaw,
                            points: 0,
                        })
                    })
                    .collect(),
            })
            .collect();
        StreetTruth {
            drive: self.config.drive_name(),
            seed: self.seed,
            config: self.config.clone(),
            world_from_drive: PoseTruth::from_isometry(&self.velodyne_pose(0)),
            imu_to_velo: PoseTruth::from_isometry(&self.t_velo_imu),
            frames,
            walls,
            objects,
        }
    }

    /// Adds the point counts of scan k to `truth`.
    pub fn record_scan(&self, truth: &mut StreetTruth, k: usize, scan: &LidarScan) {
        let frame = &mut truth.frames[k];
        frame.points = scan.surfaces.len();
        let mut walls = vec![0usize; truth.walls.len()];
        let mut objects = vec![0usize; truth.objects.len()];
        for s in &scan.surfaces {
            match *s {
                Surface::Ground => frame.ground_points += 1,
                Surface::Wall(i) => walls[i as usize] += 1,
                Surface::Object(i) => objects[i as usize] += 1,
            }
        }
        for (w, n) in truth.walls.iter_mut().zip(walls) {
            w.points[k] = n;
        }
        for (o, n) in truth.objects.iter_mut().zip(objects) {
            if let Some(state) = o.states.iter_mut().find(|s| s.frame == k) {
                state.points = n;
            }
        }
    }
}

/// A drive simulated in memory.
#[derive(Clone, Debug)]
pub struct StreetRun {
    /// Ground truth, point counts included.
    pub truth: StreetTruth,
    /// One scan per frame, with per-point surfaces.
    pub scans: Vec<LidarScan>,
    /// One OXTS packet per frame.
    pub packets: Vec<OxtsPacket>,
}

/// Simulates `frames` frames in memory. Errors as [`StreetSimulator::new`].
pub fn generate(config: &StreetConfig, frames: usize, seed: u64) -> Result<StreetRun> {
    let sim = StreetSimulator::new(config, frames, seed)?;
    let mut truth = sim.truth();
    let mut scans = Vec::with_capacity(frames);
    for k in 0..frames {
        let scan = sim.scan(k);
        sim.record_scan(&mut truth, k, &scan);
        scans.push(scan);
    }
    let packets = (0..frames).map(|k| sim.packet(k)).collect();
    Ok(StreetRun {
        truth,
        scans,
        packets,
    })
}

#[cfg(test)]
mod tests;
