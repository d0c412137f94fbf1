//! A simulated street drive in the KITTI raw layout: an ego vehicle with an HDL-64E-like lidar
//! and an OXTS unit drives at about 10 m/s along a street with turns, between building walls,
//! past parked cars, moving cars and pedestrians (and, on [`StreetConfig::urban`], vans,
//! trucks, cyclists, poles, tree trunks, hedges and low walls; on
//! [`StreetConfig::parked_rows`], kerbs lined with parked cars and vans nose to tail). [`write_drive`] writes it as
//! `DIR/DATE/DATE_drive_NNNN_sync/` that [`crate::kitti::RawDrive`] opens unchanged, plus
//! `truth.json` ([`StreetTruth`]); [`write_tracking_sequence`] writes it in the KITTI tracking
//! layout with its road users as `label_02` labels; [`generate`] keeps it in memory
//! with per-point labels.
//!
//! The pieces: [`ego`] (the vehicle's planar motion), [`body`] (its roll, pitch and heave),
//! [`world`] (the scene), [`clutter`] (street furniture and vegetation), [`ground`] (the road surface's relief), [`lidar`] (the ray caster),
//! [`truth`] (what is written as ground truth), [`writer`] (the raw layout's files),
//! [`tracking_writer`] (the tracking layout's).
//!
//! **Poses.** The OXTS unit rolls, pitches and heaves a little with the body around its
//! nominal height; the Velodyne pose follows from the IMU→Velodyne calibration exactly as the
//! reader derives it (W_velo = W_imu·T_velo_imu⁻¹, with the calibration as the reader parses
//! it), and the nominal mounting height is that of the Velodyne origin. Latitude and longitude
//! are the world x/y (east/north) through the inverse of the devkit's Mercator projection whose
//! scale is fixed by the first packet, so the poses read back equal the simulated ones to
//! rounding.
//!
//! **Randomness.** The scene comes from `rng::stream(seed, SCENE_KEY)`, the body motion from
//! `rng::stream(seed, BODY_KEY)`, the ground relief from a hash keyed by the seed and scan k
//! from its own streams (see [`lidar`]): a drive is a pure function of the configuration, the
//! frame count and the seed, at any thread count. The scene depends on the frame count (objects
//! are placed near the ego's path during the drive). With `ground.relief = []` and zero `body`
//! amplitudes the scans are those of the flat, level street this simulator first wrote.
//!
//! **Occlusion.** Each road user's state in the truth carries how many of the scan's rays meet
//! it and how many of those first hit something nearer, and from that KITTI's occlusion level
//! ([`occlusion_level`]); the tracking layout's labels carry the level.
//!
//! Not for: reading drives back (see [`crate::kitti`]) or scoring trackers against the truth.

pub mod body;
pub mod calib_files;
pub mod clutter;
pub mod config;
pub mod ego;
pub mod ground;
pub mod lidar;
pub mod tracking_writer;
pub mod truth;
pub mod world;
pub mod writer;

pub use body::{BodyMotion, BodyMotionConfig};
pub use clutter::{Clutter, ClutterConfig, ClutterKind};
pub use config::{ParkedRows, Recording, RowSides, StreetConfig, StreetLayout, TrafficConfig};
pub use ego::{EgoState, EgoTrajectory, LegSpec};
pub use ground::{Ground, GroundConfig, ReliefOctave};
pub use lidar::{LidarConfig, LidarScan, ObjectView, Surface};
pub use tracking_writer::{write_tracking_sequence, WrittenSequence};
pub use truth::{
    occlusion_level, FrameTruth, ObjectState, ObjectTruth, PoseTruth, StreetTruth, WallTruth,
};
pub use world::{ObjectKind, Street};
pub use writer::{write_drive, WrittenDrive, TRUTH_FILE};

use crate::error::{Error, Result};
use crate::geometry::wrap_angle;
use crate::kitti::calib::{rigid_calib_from, CalibFile};
use crate::kitti::poses::{oxts_rotation, velodyne_pose_from_imu, Mercator};
use crate::kitti::{OxtsPacket, Timestamp};
use crate::rng::{mix64, stream};
use nalgebra::{Isometry3, Point3, Translation3};
use std::path::Path;

/// Key of the scene's random stream.
const SCENE_KEY: u64 = 0x5743_4E45;
/// Key of the ground relief's hash.
const GROUND_KEY: u64 = 0x4752_4E44;
/// Key of the body motion's random stream.
const BODY_KEY: u64 = 0x424F_4459;
/// Standard gravity, m/s² (OXTS accelerations include it, as the real unit's do).
const GRAVITY: f64 = 9.80665;

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
        // The Velodyne origin in IMU coordinates; with the body level its height follows.
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

    /// The truth without point and ray counts (all zero, occlusion unknown); add them with
    /// [`record_scan`](Self::record_scan).
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
                            rays: 0,
                            hidden_rays: 0,
                            occluded: truth::OCCLUSION_UNKNOWN,
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
            clutter: self.street.clutter.clone(),
        }
    }

    /// Adds the point and ray counts and the occlusion levels of scan k to `truth`.
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
                Surface::Clutter(_) => {}
            }
        }
        for (w, n) in truth.walls.iter_mut().zip(walls) {
            w.points[k] = n;
        }
        for (o, n) in truth.objects.iter_mut().zip(objects) {
            if let Some(state) = o.states.iter_mut().find(|s| s.frame == k) {
                state.points = n;
                let view = scan.objects.iter().find(|v| v.id == o.id);
                state.rays = view.map_or(0, |v| v.rays as usize);
                state.hidden_rays = view.map_or(0, |v| v.hidden as usize);
                state.occluded = truth::occlusion_level(state.hidden_share());
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
