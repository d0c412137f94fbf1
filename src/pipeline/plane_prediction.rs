//! Plane prediction between consecutive LiDAR frames, scored as Gostar et al. (2019, Sec. 5,
//! Algorithm 1, Tables 1–6) score it, for any vehicle model.
//!
//! For a frame pair (k, k + 1):
//! 1. the building walls of both frames are segmented with
//!    [`crate::cloud::planes::extract_planes`];
//! 2. every wall patch of frame k is moved into the sensor frame of k + 1 with the frame change
//!    M ([`FrameChange`]). With [`EgoMotion::Measured`] M = T_{k+1}⁻¹ T_k comes from the
//!    measured poses. With [`EgoMotion::Sampled`] (Algorithm 1) each Monte-Carlo run draws
//!    the vehicle state at k + 1 from the state at k with the configured [`VehicleModel`](crate::models::VehicleModel)
//!    (extended constant turn by default) and moves the patches by
//!    M = C (P(s_{k+1})⁻¹ P(s_k)) C⁻¹ ([`FrameChange::of_vehicle`]), C the vehicle → sensor
//!    calibration;
//! 3. the predicted patches are associated with the segmented walls of k + 1
//!    ([`associate_planes`]) and each pair's errors are computed ([`PlanePairError`]).
//!
//! The prediction step (drawing the vehicle state and moving the patches) is timed per run
//! with [`std::time::Instant`]. Errors of a pair (predicted index, segmented index) are
//! averaged over the runs in which the pair was associated; pairs associated in fewer than
//! half of the runs are dropped.
//!
//! Not for: tracking planes over many frames (that is the filter with
//! [`PlaneTransition`](crate::models::PlaneTransition)).

use crate::cloud::planes::{extract_planes, PlaneConfig, PlaneDetection};
use crate::cloud::PointCloud;
use crate::error::{Error, Result};
use crate::geometry::{FrameChange, PlanePatch};
use crate::metrics::plane_prediction::{associate_planes, PlanePairError, WallGate};
use crate::models::vehicle::check_vehicle_state;
use crate::models::{ExtendedConstantTurn, SharedVehicleModel, VehicleState};
use crate::recording::Recording;
use crate::rng::FilterRng;
use nalgebra::Isometry3;
use std::collections::BTreeMap;
use std::time::Instant;

/// Parameters of plane prediction. Angles in radians, lengths in metres, times in seconds.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanePredictionConfig {
    /// Plane segmentation of every frame.
    pub planes: PlaneConfig,
    /// Vehicle motion model for the Monte-Carlo prediction (default: extended constant turn
    /// with σ_a = 0.5 m/s², σ_ω = 0.1 rad/s²); any [`VehicleModel`](crate::models::VehicleModel).
    pub vehicle: SharedVehicleModel,
    /// Step length used when no timestamps give it (s); KITTI records at 10 Hz.
    pub dt: f64,
    /// Vehicle (IMU) → sensor (Velodyne) transform C: `p_sensor = C p_vehicle`.
    pub vehicle_to_sensor: Isometry3<f64>,
    /// How a predicted wall is paired with a segmented one: by plane and overlap along the
    /// wall ([`WallGate`]).
    pub gate: WallGate,
    /// Whether the drive functions predict with the vehicle model (Algorithm 1) when vehicle
    /// states are available, instead of with the measured poses.
    pub use_vehicle_model: bool,
}

impl Default for PlanePredictionConfig {
    fn default() -> Self {
        PlanePredictionConfig {
            planes: PlaneConfig::default(),
            vehicle: SharedVehicleModel::new(
                ExtendedConstantTurn::new(0.5, 0.1)
                    .expect("constant noise levels are finite and non-negative"),
            ),
            dt: 0.1,
            vehicle_to_sensor: Isometry3::identity(),
            gate: WallGate::default(),
            use_vehicle_model: true,
        }
    }
}

impl PlanePredictionConfig {
    /// Checks the fields for usable values.
    pub fn validate(&self) -> Result<()> {
        self.planes.validate()?;
        for (name, v) in [
            ("dt", self.dt),
            ("gate.max_angle", self.gate.max_angle),
            ("gate.max_plane_gap", self.gate.max_plane_gap),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::invalid(
                    format!("plane prediction config field {name}"),
                    format!("must be finite and positive, got {v}"),
                ));
            }
        }
        if !(0.0..=1.0).contains(&self.gate.min_overlap) {
            return Err(Error::invalid(
                "plane prediction config field gate.min_overlap",
                format!("must lie in [0, 1], got {}", self.gate.min_overlap),
            ));
        }
        Ok(())
    }
}

/// How frame k is moved into the sensor frame of k + 1.
#[derive(Clone, Debug)]
pub enum EgoMotion {
    /// A fixed motion (sensor frame k → sensor frame k + 1).
    Measured(FrameChange),
    /// Monte-Carlo prediction from the vehicle state at k (Gostar et al. 2019, Algorithm 1).
    Sampled {
        /// Vehicle motion model.
        vehicle: SharedVehicleModel,
        /// Vehicle state at k, in the model's layout.
        vehicle_state: Vec<f64>,
        /// Step length (s).
        dt: f64,
        /// Vehicle → sensor transform C.
        vehicle_to_sensor: Isometry3<f64>,
    },
}

impl EgoMotion {
    /// One draw of the frame change (sensor frame k → sensor frame k + 1); a vehicle model
    /// whose draw is not finite is an error naming it.
    fn draw(&self, rng: &mut FilterRng) -> Result<FrameChange> {
        match self {
            EgoMotion::Measured(m) => Ok(*m),
            EgoMotion::Sampled {
                vehicle,
                vehicle_state,
                dt,
                vehicle_to_sensor,
            } => {
                let mut next = [Isometry3::identity()];
                vehicle.sample_poses(vehicle_state, *dt, rng, &mut next);
                let m = FrameChange::of_vehicle(
                    &vehicle.pose_of(vehicle_state),
                    &next[0],
                    vehicle_to_sensor,
                );
                if !m.is_finite() {
                    return Err(Error::invalid(
                        format!("vehicle model {}", vehicle.name()),
                        format!(
                            "a draw from the state {vehicle_state:?} over {dt} s gave a \
                             non-finite pose"
                        ),
                    ));
                }
                Ok(m)
            }
        }
    }
}

/// The result of predicting one frame pair.
#[derive(Clone, Debug, PartialEq)]
pub struct PairPrediction {
    /// Frame k + 1 (the frame predicted into).
    pub frame: usize,
    /// Errors of the associated pairs, averaged over the runs, by predicted index.
    pub pairs: Vec<PlanePairError>,
    /// Execution time of the prediction step of each run (ms).
    pub prediction_ms: Vec<f64>,
    /// Number of wall patches segmented in frame k (and predicted).
    pub predicted: usize,
    /// Number of wall patches segmented in frame k + 1.
    pub segmented: usize,
}

impl PairPrediction {
    /// Mean execution time of the prediction step (ms); NaN without runs.
    pub fn mean_prediction_ms(&self) -> f64 {
        if self.prediction_ms.is_empty() {
            return f64::NAN;
        }
        self.prediction_ms.iter().sum::<f64>() / self.prediction_ms.len() as f64
    }
}

/// The walls of one cloud.
pub fn segment_walls(
    cloud: &PointCloud,
    config: &PlaneConfig,
    rng: &mut FilterRng,
) -> Result<Vec<PlaneDetection>> {
    Ok(extract_planes(cloud, config, rng)?.walls)
}

/// Predicts the walls `walls_k` into frame `frame` (= k + 1) `runs` times (at least once) and
/// scores them against `walls_k1`. A vehicle model's non-finite draw is an error.
///
/// The walls' rectangles ([`PlaneDetection::patch`], a facade's span when the segmentation
/// trims low structure off it) are associated and give the vertex distances and normal
/// angle; the areas reported are those of the walls' whole rectangles
/// ([`PlaneDetection::whole`], which move with the same rigid motion and keep their area).
pub fn predict_walls(
    walls_k: &[PlaneDetection],
    walls_k1: &[PlaneDetection],
    ego: &EgoMotion,
    frame: usize,
    config: &PlanePredictionConfig,
    runs: usize,
    rng: &mut FilterRng,
) -> Result<PairPrediction> {
    let runs = runs.max(1);
    let mut per_pair: BTreeMap<(usize, usize), Vec<PlanePairError>> = BTreeMap::new();
    let mut prediction_ms = Vec::with_capacity(runs);
    let segmented: Vec<PlanePatch> = walls_k1.iter().map(|w| w.patch.clone()).collect();
    for _ in 0..runs {
        let start = Instant::now();
        let m = ego.draw(rng)?;
        let predicted: Vec<PlanePatch> = walls_k.iter().map(|w| w.patch.moved_by(&m)).collect();
        prediction_ms.push(start.elapsed().as_secs_f64() * 1e3);
        for (i, j) in associate_planes(&predicted, &segmented, &config.gate) {
            let mut e = PlanePairError::between(frame, &predicted[i], &segmented[j]);
            e.predicted_area = walls_k[i].whole.area;
            e.segmented_area = walls_k1[j].whole.area;
            per_pair.entry((i, j)).or_default().push(e);
        }
    }
    let pairs = per_pair
        .values()
        .filter(|errs| 2 * errs.len() >= runs)
        .filter_map(|errs| PlanePairError::mean(errs))
        .collect();
    Ok(PairPrediction {
        frame,
        pairs,
        prediction_ms,
        predicted: walls_k.len(),
        segmented: walls_k1.len(),
    })
}

/// Segments two consecutive clouds and predicts the walls of `cloud_k` into the frame of
/// `cloud_k1` (frame number `frame_k + 1`).
///
/// `pose_k`, `pose_k1` are the sensor poses (sensor → world) of the two frames. Given the
/// measured vehicle kinematics `vehicle_state_k` ([X, Ẋ, Y, Ẏ, φ, φ̇], see [`VehicleState`]),
/// the prediction follows Algorithm 1 with `config.vehicle`, `config.dt` and
/// `config.vehicle_to_sensor` over `runs` Monte-Carlo runs and the poses are not used;
/// otherwise the measured motion T_{k+1}⁻¹ T_k is applied (the runs then only repeat the
/// timing).
#[allow(clippy::too_many_arguments)]
pub fn predict_planes_between(
    frame_k: usize,
    cloud_k: &PointCloud,
    cloud_k1: &PointCloud,
    pose_k: &Isometry3<f64>,
    pose_k1: &Isometry3<f64>,
    vehicle_state_k: Option<[f64; 6]>,
    config: &PlanePredictionConfig,
    runs: usize,
    rng: &mut FilterRng,
) -> Result<PairPrediction> {
    config.validate()?;
    let walls_k = segment_walls(cloud_k, &config.planes, rng)?;
    let walls_k1 = segment_walls(cloud_k1, &config.planes, rng)?;
    let ego = ego_for(pose_k, pose_k1, vehicle_state_k, config.dt, config)?;
    predict_walls(&walls_k, &walls_k1, &ego, frame_k + 1, config, runs, rng)
}

/// The ego motion of a frame pair: the vehicle model's draws from the state it builds of the
/// measured kinematics, or the measured frame change.
fn ego_for(
    pose_k: &Isometry3<f64>,
    pose_k1: &Isometry3<f64>,
    vehicle_state_k: Option<[f64; 6]>,
    dt: f64,
    config: &PlanePredictionConfig,
) -> Result<EgoMotion> {
    Ok(match vehicle_state_k {
        Some([x, vx, y, vy, heading, yaw_rate]) => {
            let measured = VehicleState {
                x,
                vx,
                y,
                vy,
                heading,
                yaw_rate,
            };
            let vehicle_state = config.vehicle.state_of(&measured);
            check_vehicle_state(&*config.vehicle, &vehicle_state)?;
            EgoMotion::Sampled {
                vehicle: config.vehicle.clone(),
                vehicle_state,
                dt,
                vehicle_to_sensor: config.vehicle_to_sensor,
            }
        }
        None => EgoMotion::Measured(FrameChange::between(pose_k, pose_k1)),
    })
}

/// Runs the prediction over consecutive frame pairs `(k, k + 1)` for `k` in `frames`, given a
/// frame loader, sensor poses, optional vehicle states and step lengths. Each frame is
/// segmented once. A pair one of whose frames has no scan (`has_scan`: KITTI drops a scan
/// now and then) is left out.
#[allow(clippy::too_many_arguments)]
fn predict_sequence(
    frames: std::ops::Range<usize>,
    has_scan: &dyn Fn(usize) -> bool,
    load: &dyn Fn(usize) -> Result<PointCloud>,
    poses: &[Isometry3<f64>],
    states: Option<&[[f64; 6]]>,
    dts: &[f64],
    config: &PlanePredictionConfig,
    runs: usize,
    rng: &mut FilterRng,
) -> Result<Vec<PairPrediction>> {
    config.validate()?;
    let mut out = Vec::new();
    let mut previous: Option<(usize, Vec<PlaneDetection>)> = None;
    let pairs: Vec<usize> = frames
        .clone()
        .filter(|&k| has_scan(k) && has_scan(k + 1))
        .collect();
    if pairs.is_empty() && !frames.is_empty() {
        return Err(Error::invalid(
            format!("frame pairs {}..{}", frames.start, frames.end),
            "none has a scan in both frames (dropped scans)",
        ));
    }
    for k in pairs {
        let walls_k = match previous.take() {
            Some((f, w)) if f == k => w,
            _ => segment_walls(&load(k)?, &config.planes, rng)?,
        };
        let walls_k1 = segment_walls(&load(k + 1)?, &config.planes, rng)?;
        let dt = dts
            .get(k)
            .copied()
            .filter(|d| d.is_finite() && *d > 0.0)
            .unwrap_or(config.dt);
        let state = states.map(|s| s[k]);
        let ego = ego_for(&poses[k], &poses[k + 1], state, dt, config)?;
        out.push(predict_walls(
            &walls_k,
            &walls_k1,
            &ego,
            k + 1,
            config,
            runs,
            rng,
        )?);
        previous = Some((k + 1, walls_k1));
    }
    Ok(out)
}

/// Checks that `frames` (pairs `(k, k + 1)`) fit in `count` frames, naming `source`.
fn check_range(frames: &std::ops::Range<usize>, count: usize, source: &str) -> Result<()> {
    if frames.start < frames.end && frames.end + 1 > count {
        return Err(Error::invalid(
            format!("frame pairs {}..{} of {source}", frames.start, frames.end),
            format!("need frames up to {}, but there are {count}", frames.end),
        ));
    }
    Ok(())
}

/// Plane prediction over the consecutive frame pairs `(k, k + 1)`, `k ∈ frames`, of a
/// recording (a KITTI raw drive, tracking or odometry sequence, a folder of scans with a pose
/// file, a user's own [`Recording`]); `None` means every pair. Uses the recording's sensor
/// poses. With `config.use_vehicle_model` the prediction follows Algorithm 1 from the
/// recording's measured vehicle motion ([`Recording::vehicle`]: the OXTS states, their step
/// lengths and the vehicle → sensor calibration, which overrides `config.vehicle_to_sensor`);
/// a recording without it is an error then. Pairs with a frame that has no scan are left out.
pub fn predict_pairs(
    rec: &dyn Recording,
    frames: Option<std::ops::Range<usize>>,
    config: &PlanePredictionConfig,
    runs: usize,
    rng: &mut FilterRng,
) -> Result<Vec<PairPrediction>> {
    let poses = rec.poses()?;
    let count = rec.frame_count().min(poses.len());
    let frames = frames.unwrap_or(0..count.saturating_sub(1));
    check_range(&frames, count, &rec.describe())?;
    let mut config = config.clone();
    let (states, dts) = if config.use_vehicle_model {
        let vehicle = rec.vehicle()?;
        let states: Vec<[f64; 6]> = vehicle.states.iter().map(|s| s.to_array()).collect();
        config.vehicle_to_sensor = vehicle.vehicle_to_sensor;
        (Some(states), vehicle.intervals)
    } else {
        (None, Vec::new())
    };
    predict_sequence(
        frames,
        &|k| rec.has_scan(k),
        &|k| rec.scan(k),
        &poses,
        states.as_deref(),
        &dts,
        &config,
        runs,
        rng,
    )
}

/// Plane prediction over the consecutive frame pairs `(k, k + 1)`, `k ∈ frames`, of any
/// recording, with the measured motion between the given sensor `poses` (sensor → world, one
/// per frame; e.g. from [`crate::cloud::odometry`] when the recording has no poses of its
/// own). Pairs with a frame for which `has_scan` is false (a dropped scan) are left out.
/// `source` names the recording in errors.
#[allow(clippy::too_many_arguments)]
pub fn predict_pairs_with_poses(
    frames: std::ops::Range<usize>,
    has_scan: &dyn Fn(usize) -> bool,
    load: &dyn Fn(usize) -> Result<PointCloud>,
    poses: &[Isometry3<f64>],
    source: &str,
    config: &PlanePredictionConfig,
    runs: usize,
    rng: &mut FilterRng,
) -> Result<Vec<PairPrediction>> {
    check_range(&frames, poses.len(), source)?;
    predict_sequence(frames, has_scan, load, poses, None, &[], config, runs, rng)
}
