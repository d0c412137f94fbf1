//! Tracking a whole KITTI recording (a raw drive, a tracking sequence or an odometry sequence)
//! with one LMB filter in which building walls and object clusters are both labelled objects
//! (the mixed state and models of [`mixed`], written for this pipeline alone).
//!
//! Per frame: read the Velodyne `.bin`, segment the ground and walls, cluster the points on
//! neither ([`detect`]), turn walls and cluster centroids into mixed measurements and step the
//! filter with the frame's pose ([`tracker`]); the MAP estimate becomes a
//! [`TrackedFrame`] of labelled planes and clusters ([`output`]). Walls are tracked in the
//! Velodyne frame and moved by the ego motion (the measured poses, or per particle by the
//! extended constant-turn vehicle model, [`EgoModel`]); clusters are tracked in the world
//! frame with constant velocity. The ground is not tracked (see [`detect`]).
//!
//! [`DriveTracker::step`] is the per-frame step on ready-made detections (for benchmarks);
//! [`track_recording`] runs a whole recording and hands every frame (cloud, detections,
//! report) to a callback, which is where a caller draws progress or writes labelled point
//! clouds ([`export`]).
//!
//! Not for: plane prediction scoring (see [`super::plane_prediction`]) or evaluation against
//! ground truth.

pub mod detect;
pub mod export;
pub mod kitti_out;
pub mod mixed;
pub mod occlusion;
pub mod output;
pub mod repeatability;
pub mod road_users;
pub mod source;
pub mod tracker;

pub use detect::{detect_objects, ClusterDetection, FrameDetections, WallDetection};
use detect::{segment_here, Segmented};
pub use export::point_labels;
#[cfg(feature = "plot")]
pub use export::{drive_plot, frame_plot};
pub use mixed::OwnModels;
pub use output::{
    DriveTracks, StageTimes, TrackedCluster, TrackedFrame, TrackedPlane, TrackingSummary,
};
pub use repeatability::tracked_wall_pairs;
pub use source::RecordingSource;
pub use tracker::{DriveTracker, DriveTrackerBuilder};

use crate::cloud::fragments::FragmentParams;
use crate::cloud::odometry::{LidarOdometry, OdometryConfig};
use crate::cloud::planes::PlaneConfig;
use crate::cloud::PointCloud;
use crate::error::{ensure_positive, ensure_probability, Error, Result};
use crate::filter::{Jitter, LmbConfig, SharedTransitionModel, TransitionModel};
use crate::models::{
    vehicle_model_by_name, ExtendedConstantTurn, SharedVehicleModel, VehicleModel,
};
use crate::recording::Recording;
use crate::rng::stream;
use nalgebra::Isometry3;
use std::ops::Range;
use std::sync::Arc;
use std::time::Instant;

/// How walls are moved between frames.
///
/// In a configuration file: `ego = { kind = "measured" }`, `ego = { kind = "ect",
/// sigma_accel = 0.5, sigma_turn_accel = 0.1 }`, or any built-in vehicle model by name,
/// `ego = { kind = "vehicle", model = "bicycle", parameters = { wheelbase = 2.9 } }` (see
/// [`vehicle_model_by_name`]). A user's own model is [`EgoModel::Custom`], set from code.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum EgoModel {
    /// By the measured OXTS poses (every particle alike).
    Measured,
    /// By a per-particle draw of the extended constant-turn vehicle model from the OXTS
    /// vehicle state of the previous frame (Gostar et al. 2019, Algorithm 1).
    Ect {
        /// Longitudinal acceleration noise (m/s²).
        sigma_accel: f64,
        /// Yaw acceleration noise (rad/s²).
        sigma_turn_accel: f64,
    },
    /// As `Ect`, with a built-in vehicle model chosen by name.
    Vehicle {
        /// `ect`, `ct` or `bicycle`.
        model: String,
        /// The model's parameters by name (the others keep their defaults).
        #[serde(default)]
        parameters: std::collections::BTreeMap<String, f64>,
    },
    /// As `Ect`, with a user's vehicle model (not in configuration files).
    #[serde(skip)]
    Custom(SharedVehicleModel),
}

impl EgoModel {
    /// A user's vehicle model.
    pub fn custom(model: impl VehicleModel + 'static) -> Self {
        EgoModel::Custom(SharedVehicleModel::new(model))
    }

    /// The vehicle model that moves the walls, `None` for measured poses; an unknown name
    /// or parameter is an error.
    pub fn vehicle_model(&self) -> Result<Option<Arc<dyn VehicleModel>>> {
        Ok(match self {
            EgoModel::Measured => None,
            EgoModel::Ect {
                sigma_accel,
                sigma_turn_accel,
            } => Some(Arc::new(ExtendedConstantTurn::new(
                *sigma_accel,
                *sigma_turn_accel,
            )?)),
            EgoModel::Vehicle { model, parameters } => {
                let params: Vec<(String, f64)> =
                    parameters.iter().map(|(k, v)| (k.clone(), *v)).collect();
                Some(vehicle_model_by_name(model, &params)?)
            }
            EgoModel::Custom(m) => Some(m.0.clone()),
        })
    }

    /// Whether a vehicle model moves the walls (it then needs vehicle states).
    pub fn is_predicted(&self) -> bool {
        !matches!(self, EgoModel::Measured)
    }

    /// The suffix of the output's `ego` name: empty for measured poses, `+ect`, `+bicycle`, …,
    /// or `+` and a user's model's name.
    fn suffix(&self) -> String {
        match self {
            EgoModel::Measured => String::new(),
            EgoModel::Ect { .. } => "+ect".into(),
            EgoModel::Vehicle { model, .. } => format!("+{model}"),
            EgoModel::Custom(m) => format!("+{}", m.name()),
        }
    }
}

/// Where the sensor poses (frame k → first frame) come from.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PoseSource {
    /// The recording's own poses (OXTS, `poses/NN.txt`) when it has them, lidar odometry on
    /// the scans otherwise.
    #[default]
    Auto,
    /// The recording's own poses; a recording without them is an error.
    Recorded,
    /// Lidar odometry ([`crate::cloud::odometry::LidarOdometry`], default settings) on the
    /// scans, registered as they are read; poses are relative to the first tracked frame.
    Lidar,
    /// Every frame at the origin: a sensor that does not move.
    Static,
}

/// Wall models: process noise, measurement noise, detection, clutter and birth spread.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PlaneTuning {
    /// Normal-tilt process noise per step (rad). Default 0.5°.
    pub process_angle: f64,
    /// Offset process noise per step (m). Default 0.05.
    pub process_offset: f64,
    /// Measurement noise of the normal angle (rad). Default 2°.
    pub sigma_angle: f64,
    /// Measurement noise of the offset (m). Default 0.15.
    pub sigma_offset: f64,
    /// Gate width in multiples of (σ + spread). Default 4.
    pub gate: f64,
    /// Detection probability. Default 0.9.
    pub detection: f64,
    /// Expected false walls per frame. Default 0.5.
    pub clutter_rate: f64,
    /// Volume of the (angle, offset) space the false walls spread over (rad·m). Default
    /// π/2 · 50.
    pub clutter_volume: f64,
    /// Normal spread of a new wall (rad). Default 2°.
    pub birth_angle: f64,
    /// Offset spread of a new wall (m). Default 0.15.
    pub birth_offset: f64,
    /// A user's own wall measurement, detection or clutter model, used instead of the one the
    /// fields above tune (code only; see [`OwnModels`]). Default none.
    #[serde(skip)]
    pub own_models: OwnModels,
}

impl Default for PlaneTuning {
    fn default() -> Self {
        PlaneTuning {
            process_angle: 0.5f64.to_radians(),
            process_offset: 0.05,
            sigma_angle: 2f64.to_radians(),
            sigma_offset: 0.15,
            gate: 4.0,
            detection: 0.9,
            clutter_rate: 0.5,
            clutter_volume: std::f64::consts::FRAC_PI_2 * 50.0,
            birth_angle: 2f64.to_radians(),
            birth_offset: 0.15,
            own_models: OwnModels::default(),
        }
    }
}

/// Cluster models: motion, measurement noise, detection, clutter and birth spread.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ClusterTuning {
    /// Acceleration noise of the constant-velocity model (m/s²). Default 8: a white-noise
    /// acceleration has to cover a turn or a braking that lasts, not only its typical size
    /// (a car turning at 15 m/s on a 20 m radius accelerates at 11 m/s² for a second or two).
    pub sigma_accel: f64,
    /// Probability that a particle's acceleration in a step is drawn `manoeuvre_scale` times
    /// wider ([`crate::models::ConstantVelocity::with_manoeuvres`]): a fringe of the cloud that
    /// follows a car turning or braking where the core lags behind (on the simulated street a
    /// turning car's track fell behind and a newborn took the car). 0 turns it off. Default 0.1.
    pub manoeuvre_probability: f64,
    /// How much wider a manoeuvre step's acceleration is. Default 3.
    pub manoeuvre_scale: f64,
    /// Centroid measurement noise per axis (m). Default 0.3.
    pub sigma: f64,
    /// Gate width in multiples of (σ + spread). Default 4.
    pub gate: f64,
    /// Weight of the wide component of the measurement likelihood: a box centre is scored by
    /// (1 − this) of a Gaussian of σ and this much of one of `outlier_scale`·σ, so that a
    /// centre now and then metres off (the box's visible-face extension changing with the
    /// frame's class, two objects merged for a frame) does not cost the track its detection.
    /// 0 turns it off. Default 0.1.
    pub outlier_weight: f64,
    /// Standard deviation of the wide component in multiples of σ. Default 4.
    pub outlier_scale: f64,
    /// Detection probability. Default 0.8.
    pub detection: f64,
    /// Lower a track's detection probability by the share of it that nearer clusters of the
    /// frame hide ([`occlusion`]): a parked car behind others keeps its track through the
    /// frames it is not seen in. Default true.
    pub occlusion: bool,
    /// Expected false clusters per frame. Default 2.
    pub clutter_rate: f64,
    /// Volume they spread over (m³). Default 80 × 80 × 4.
    pub clutter_volume: f64,
    /// Position spread of a new cluster (m). Default 0.3.
    pub birth_position: f64,
    /// Horizontal velocity spread of a new cluster (m/s). Default 4.
    pub birth_velocity: f64,
    /// Vertical velocity spread of a new cluster (m/s). Default 0.3.
    pub birth_vertical: f64,
    /// Particles kept for a confirmed cluster that is not reported (static clutter of class
    /// `Other`), instead of `filter.particles`. Its filtered position and speed only decide
    /// whether it stays clutter; when it turns into a road user it gets its full count back at
    /// the next resampling. `None` (or `--all-clusters`) carries every track at full count.
    /// Default 400.
    pub clutter_particles: Option<usize>,
    /// How road users move. Default: 3-D constant velocity with `sigma_accel` and the
    /// manoeuvre fringe.
    #[serde(skip_serializing_if = "RoadUserMotion::is_default")]
    pub motion: RoadUserMotion,
    /// A user's own cluster measurement, detection or clutter model, used instead of the one
    /// the fields above tune (code only; see [`OwnModels`]). Default none.
    #[serde(skip)]
    pub own_models: OwnModels,
}

/// How the drive tracker's road users (clusters) move. A cluster's state is
/// [x, ẋ, y, ẏ, z, ż] in the world frame; a model moves its first 4 or all 6 components.
///
/// In a configuration file: `motion = { kind = "constant_velocity" }` (the default; its
/// parameters are `sigma_accel`, `manoeuvre_probability` and `manoeuvre_scale` beside it). A
/// user's own model is [`RoadUserMotion::Custom`], set from code (Rust or Python).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum RoadUserMotion {
    /// 3-D constant velocity ([`crate::models::ConstantVelocity`]) with the manoeuvre fringe.
    #[default]
    ConstantVelocity,
    /// A user's transition model (not in configuration files).
    #[serde(skip)]
    Custom(SharedTransitionModel),
}

impl RoadUserMotion {
    /// A user's road-user motion model.
    pub fn custom(model: impl TransitionModel + 'static) -> Self {
        RoadUserMotion::Custom(SharedTransitionModel::new(model))
    }

    fn is_default(&self) -> bool {
        *self == RoadUserMotion::ConstantVelocity
    }

    /// Checks that a user's model moves a cluster's state (4 or 6 components), naming it.
    fn validate(&self) -> Result<()> {
        if let RoadUserMotion::Custom(m) = self {
            let d = m.0.state_dim();
            if d != 4 && d != 6 {
                return Err(Error::invalid(
                    format!("road-user motion {}", m.0.name()),
                    format!(
                        "moves states of {d} components, but a cluster's state is \
                         [x, ẋ, y, ẏ, z, ż]: a model must move its first 4 or all 6"
                    ),
                ));
            }
        }
        Ok(())
    }
}

impl Default for ClusterTuning {
    fn default() -> Self {
        ClusterTuning {
            sigma_accel: 8.0,
            manoeuvre_probability: 0.1,
            manoeuvre_scale: 3.0,
            sigma: 0.3,
            gate: 4.0,
            outlier_weight: 0.1,
            outlier_scale: 4.0,
            detection: 0.8,
            occlusion: true,
            clutter_rate: 2.0,
            clutter_volume: 80.0 * 80.0 * 4.0,
            birth_position: 0.3,
            birth_velocity: 4.0,
            birth_vertical: 0.3,
            clutter_particles: Some(400),
            motion: RoadUserMotion::ConstantVelocity,
            own_models: OwnModels::default(),
        }
    }
}

/// Birth and survival.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BirthTuning {
    /// Expected new objects per frame, λ_B of the adaptive birth. Default 4.
    pub expected_births: f64,
    /// Largest existence of a birth. Default 0.1.
    pub max_existence: f64,
    /// Proposals of smaller existence are not born (nor any below `filter.prune_threshold`).
    /// A measurement that the tracks leave almost explained proposes a birth of tiny existence
    /// that costs a full particle set; on drive 0005 a dozen of the ~28 births a frame were
    /// below 0.01. Default 0.01.
    pub min_existence: f64,
    /// Survival probability per step. Default 0.95.
    pub survival: f64,
}

impl Default for BirthTuning {
    fn default() -> Self {
        BirthTuning {
            expected_births: 4.0,
            max_existence: 0.1,
            min_existence: 0.01,
            survival: 0.95,
        }
    }
}

/// How the points on neither ground nor wall are grouped into clusters.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ClusterMethod {
    /// Angle-criterion clustering on the scan's range image
    /// ([`crate::cloud::range_image::range_image_clusters`]), linear in the points. On real
    /// HDL-64E frames it splits about a quarter of the exact method's clusters (surfaces seen
    /// edge-on, sparse vegetation) and, with the image's build counted, is not faster; on the
    /// simulated street it doubled the label switches. Kept as an option.
    RangeImage,
    /// Exact Euclidean clustering with `tolerance` ([`crate::cloud::euclidean_clusters_of`]):
    /// the default.
    #[default]
    Euclidean,
}

/// Which point clusters become detections: every object-sized cluster within `max_range`.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ClusterDetectionConfig {
    /// Clustering method. Default `euclidean`.
    pub method: ClusterMethod,
    /// Neighbour distance of the Euclidean clustering; the range-image clustering joins image
    /// neighbours within it whatever their angle, and up to twice it when the angle criterion
    /// holds (m). Default 0.5.
    pub tolerance: f64,
    /// Smallest angle between beam and neighbour line that joins two range-image neighbours
    /// (degrees; Bogoslavskyi & Stachniss). Default 10.
    pub min_angle_deg: f64,
    /// Columns searched on either side for a range-image neighbour (bridges dropouts).
    /// Default 3.
    pub reach: usize,
    /// Fewest points of a cluster. Default 15.
    pub min_points: usize,
    /// Most points of a cluster. Default 20 000.
    pub max_points: usize,
    /// Points at most this high above the ground are not clustered (m). Default 0.3.
    pub ground_clearance: f64,
    /// Sensor height over the road, used when no ground plane was found (m). Default 1.73.
    pub sensor_height: f64,
    /// Horizontal range limit (m). Default 40.
    pub max_range: f64,
    /// Largest horizontal box side (m). Default 8.
    pub max_footprint: f64,
    /// Largest box height (m). Default 4.
    pub max_height: f64,
    /// Give a face seen at a grazing angle, clustered apart from its object, back to the
    /// cluster at its near end ([`crate::cloud::fragments`]). Default true.
    pub merge_fragments: bool,
    /// When a cluster is such a fragment.
    pub fragments: FragmentParams,
}

impl Default for ClusterDetectionConfig {
    fn default() -> Self {
        ClusterDetectionConfig {
            method: ClusterMethod::Euclidean,
            tolerance: 0.5,
            min_angle_deg: 10.0,
            reach: 3,
            min_points: 15,
            max_points: 20_000,
            ground_clearance: 0.3,
            sensor_height: 1.73,
            max_range: 40.0,
            max_footprint: 8.0,
            max_height: 4.0,
            merge_fragments: true,
            fragments: FragmentParams::default(),
        }
    }
}

/// The drive tracker's [`LmbConfig::merge_threshold`]: two tracks that claim one measurement
/// merge when their posterior means lie within a squared distance of 9 (3 standard deviations
/// of the two tracks' summed spread along one component, or less along several). Measured on
/// sequence 0000's frames 0–49 and the 22 simulated sequences against 4, 16, 36 and 100 (the
/// measurements in `docs/road_users.md`): 4 and 16 score about the same, from 36 up the simulated
/// pedestrians' HOTA falls (0.761 → 0.737 at 36) and at 100 distinct objects merge.
pub const DUPLICATE_MERGE_THRESHOLD: f64 = 9.0;

/// The default [`TrackingConfig::report_min_existence`]: 0.9. On sequence 0000's frames 0–49
/// and the 22 simulated sequences (`docs/road_users.md`) reporting every line of the MAP
/// estimate, or only those at 0.99, both scored lower.
pub const REPORT_MIN_EXISTENCE: f64 = 0.9;

/// Everything [`track_recording`] needs besides the recording and the seed. Every field has a
/// default; a JSON or TOML file may set any subset (in `planes` too: the fields it leaves out
/// keep [`PlaneConfig::default`]'s values).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TrackingConfig {
    /// Filter tuning (particles per track, resampling, pruning). Default: the filter's
    /// defaults with room for 200 tracks, particles that follow existence (at least 200,
    /// 1000 for a certain track: a real street proposes a hundred unlikely tracks a frame),
    /// duplicate tracks merged ([`DUPLICATE_MERGE_THRESHOLD`]) and no jitter after
    /// resampling: every component of both kinds of state gets process noise in the next
    /// prediction (a wall's normal tilts by 0.5° and its offset by 5 cm a step; a cluster's
    /// acceleration noise moves its position by about 4 cm and its velocity by about 0.8 m/s),
    /// far more than the regularised kernel's tenth of the posterior spread, so copies of one
    /// particle part there anyway.
    pub filter: LmbConfig,
    /// How walls follow the ego motion. Default: measured poses.
    pub ego: EgoModel,
    /// Where the poses come from. Default: the recording's, else lidar odometry.
    pub poses: PoseSource,
    /// Wall models.
    pub plane: PlaneTuning,
    /// Cluster models.
    pub cluster: ClusterTuning,
    /// Birth and survival.
    pub birth: BirthTuning,
    /// Cluster detection.
    pub clusters: ClusterDetectionConfig,
    /// Frame interval when the drive has no Velodyne timestamps (s). Default 0.1.
    pub dt: f64,
    /// Report every confirmed cluster, not only road users (see
    /// [`road_users::RoadUserState::is_road_user`]: static clusters of class `Other` are left
    /// out by default).
    pub all_clusters: bool,
    /// A road user is reported in the frames where its track's existence probability is at
    /// least this (the MAP estimate alone also reports the young tracks and those coasting
    /// for a frame or two after their object left, at existence 0.5–0.9). Not applied with
    /// `all_clusters`. Default [`REPORT_MIN_EXISTENCE`].
    pub report_min_existence: f64,
    /// Plane segmentation. Default: [`PlaneConfig::default`]. The tracker never computes the
    /// ground's rectangle (it uses the ground's plane and inliers only), whatever
    /// `ground_outline` says.
    pub planes: PlaneConfig,
}

impl Default for TrackingConfig {
    fn default() -> Self {
        TrackingConfig {
            filter: LmbConfig {
                max_tracks: 200,
                min_particles: Some(200),
                jitter: Jitter::None,
                merge_threshold: Some(DUPLICATE_MERGE_THRESHOLD),
                ..LmbConfig::default()
            },
            ego: EgoModel::Measured,
            poses: PoseSource::Auto,
            plane: PlaneTuning::default(),
            cluster: ClusterTuning::default(),
            birth: BirthTuning::default(),
            clusters: ClusterDetectionConfig::default(),
            dt: 0.1,
            all_clusters: false,
            report_min_existence: REPORT_MIN_EXISTENCE,
            planes: PlaneConfig::default(),
        }
    }
}

impl TrackingConfig {
    /// Checks the fields the models do not check themselves.
    pub fn validate(&self) -> Result<()> {
        self.filter.validate()?;
        self.planes.validate()?;
        self.ego.vehicle_model()?;
        self.cluster.motion.validate()?;
        ensure_positive("tracking config field dt", self.dt)?;
        ensure_probability("tracking config field birth.survival", self.birth.survival)?;
        ensure_probability(
            "tracking config field birth.min_existence",
            self.birth.min_existence,
        )?;
        if self.birth.min_existence > self.birth.max_existence {
            return Err(Error::invalid(
                "tracking config field birth.min_existence",
                format!(
                    "{} is above birth.max_existence {}: nothing would be born",
                    self.birth.min_existence, self.birth.max_existence
                ),
            ));
        }
        ensure_probability(
            "tracking config field report_min_existence",
            self.report_min_existence,
        )?;
        let w = self.cluster.outlier_weight;
        if !(0.0..1.0).contains(&w) {
            return Err(Error::invalid(
                "tracking config field cluster.outlier_weight",
                format!("{w} (must lie in [0, 1); 0 turns the wide component off)"),
            ));
        }
        let k = self.cluster.outlier_scale;
        if !(k >= 1.0 && k.is_finite()) {
            return Err(Error::invalid(
                "tracking config field cluster.outlier_scale",
                format!("{k} (must be finite and at least 1)"),
            ));
        }
        ensure_probability(
            "tracking config field cluster.manoeuvre_probability",
            self.cluster.manoeuvre_probability,
        )?;
        let k = self.cluster.manoeuvre_scale;
        if !(k >= 1.0 && k.is_finite()) {
            return Err(Error::invalid(
                "tracking config field cluster.manoeuvre_scale",
                format!("{k} (must be finite and at least 1)"),
            ));
        }
        if self.cluster.clutter_particles == Some(0) {
            return Err(Error::invalid(
                "tracking config field cluster.clutter_particles",
                "must be at least 1 (leave it out to keep every track at full count)",
            ));
        }
        let c = &self.clusters;
        c.fragments.validate()?;
        for (name, v) in [
            ("clusters.tolerance", c.tolerance),
            ("clusters.max_range", c.max_range),
            ("clusters.max_footprint", c.max_footprint),
            ("clusters.max_height", c.max_height),
        ] {
            ensure_positive(&format!("tracking config field {name}"), v)?;
        }
        if !(c.ground_clearance.is_finite() && c.sensor_height.is_finite()) {
            return Err(Error::invalid(
                "tracking config field clusters.ground_clearance / sensor_height",
                "must be finite",
            ));
        }
        Ok(())
    }
}

/// What [`track_recording`] hands its callback for every frame.
#[derive(Debug)]
pub struct FrameView<'a> {
    /// The frame's cloud (sensor frame).
    pub cloud: &'a PointCloud,
    /// The frame's detections.
    pub detections: &'a FrameDetections,
    /// The frame's report.
    pub tracked: &'a TrackedFrame,
    /// Frames done so far (including this one) and frames in the run.
    pub progress: (usize, usize),
}

/// Stream key of the plane segmentation random stream of a frame.
const KEY_SEGMENT: u64 = 0x5E6 << 48;

/// The random stream the segmentation of frame `frame` draws from in a run seeded `seed`
/// ([`track_recording`]): [`detect_objects`] with it gives that frame's
/// detections again.
pub fn segment_rng(seed: u64, frame: usize) -> crate::rng::FilterRng {
    stream(seed, KEY_SEGMENT ^ frame as u64)
}

/// The pose source's name with `+ect` when the ECT ego model moves the walls.
fn ego_name(source: &str, config: &TrackingConfig) -> String {
    format!("{source}{}", config.ego.suffix())
}

/// The poses of a recording (`None`: lidar odometry) and their source's name.
fn choose_poses(
    config: &TrackingConfig,
    rec: &dyn Recording,
) -> Result<(Option<Vec<Isometry3<f64>>>, String)> {
    let n = rec.frame_count();
    match (config.poses, rec.has_poses()) {
        (PoseSource::Static, _) => Ok((Some(vec![Isometry3::identity(); n]), "none".into())),
        (PoseSource::Lidar, _) | (PoseSource::Auto, false) => Ok((None, ego_name("lidar", config))),
        (PoseSource::Recorded, false) => Err(Error::invalid(
            rec.describe(),
            "has no recorded poses (OXTS or a poses file); use lidar odometry or a static sensor",
        )),
        (_, true) => Ok((Some(rec.poses()?), ego_name(rec.pose_source(), config))),
    }
}

/// Tracks walls and clusters over `frames` (default: all) of a recording: a KITTI raw drive,
/// tracking or odometry sequence, a folder of scans ([`crate::recording::ScanDirectory`]) or
/// a user's own [`Recording`].
///
/// Poses come from the recording when it has them (`config.poses` decides: recorded, lidar
/// odometry on the scans, or a static sensor); a vehicle ego model (`config.ego`) needs the
/// recording's measured vehicle motion ([`Recording::vehicle`]: OXTS). Frame times come from
/// the recording when it has them, else frame k is at k·`config.dt`. Frames without a scan
/// are left out and the next is predicted to over the longer step. `on_frame` sees every
/// frame as it is done; its error stops the run. The output is named [`Recording::name`].
pub fn track_recording(
    rec: &dyn Recording,
    frames: Option<Range<usize>>,
    config: &TrackingConfig,
    seed: u64,
    on_frame: impl FnMut(&FrameView<'_>) -> Result<()>,
) -> Result<DriveTracks> {
    config.validate()?;
    let with_height;
    let config = match rec.sensor_height() {
        Some(h) if h != config.clusters.sensor_height => {
            with_height = TrackingConfig {
                clusters: ClusterDetectionConfig {
                    sensor_height: h,
                    ..config.clusters.clone()
                },
                ..config.clone()
            };
            &with_height
        }
        _ => config,
    };
    let what = rec.describe();
    let n = rec.frame_count();
    if n == 0 {
        let reason = match rec.scan_dir() {
            Some(dir) => format!("has no scans in {}", dir.display()),
            None => "has no scans".to_string(),
        };
        return Err(Error::invalid(what, reason));
    }
    check_frame_range(frames.as_ref(), n, &what)?;
    // A recording without vehicle motion says so in its own words, before any pose is read.
    let vehicle = if config.ego.is_predicted() {
        let v = rec.vehicle()?;
        let measured: Vec<[f64; 6]> = v.states.iter().map(|s| s.to_array()).collect();
        Some((measured, v.vehicle_to_sensor))
    } else {
        None
    };
    let (poses, ego) = choose_poses(config, rec)?;
    let times = match rec.times()? {
        Some(t) => t,
        None => (0..n).map(|k| k as f64 * config.dt).collect(),
    };
    track_frames(
        rec, &ego, poses, vehicle, &times, frames, config, seed, on_frame,
    )
}

/// Where the tracking loop takes each frame's sensor pose from.
enum Ego<'a> {
    /// The recording's poses, one per frame.
    Recorded(&'a [Isometry3<f64>]),
    /// Lidar odometry on the scans as they are read (boxed: its map is large).
    Lidar(Box<LidarOdometry>),
}

impl Ego<'_> {
    /// The pose of frame `k`, whose scan is `cloud`, `steps` frames after the scan before it
    /// (more than one after dropped scans), and the milliseconds the odometry took.
    fn pose(
        &mut self,
        k: usize,
        steps: usize,
        cloud: &PointCloud,
        name: &str,
    ) -> Result<(Isometry3<f64>, f64)> {
        match self {
            Ego::Recorded(poses) => Ok((poses[k], 0.0)),
            Ego::Lidar(odometry) => {
                let start = Instant::now();
                let registered = odometry.register_after(cloud, steps).map_err(|e| {
                    Error::invalid(
                        format!("lidar odometry on frame {k} of {name}"),
                        e.to_string(),
                    )
                })?;
                Ok((registered.pose, start.elapsed().as_secs_f64() * 1e3))
            }
        }
    }
}

/// A frame segmented and predicted, waiting for its update in the next round of the loop.
struct Held {
    frame: usize,
    cloud: PointCloud,
    /// The frame's walls and clusters, until the filter's side gives the clusters their
    /// shapes.
    segmented: Option<Segmented>,
    read_ms: f64,
    ego_ms: f64,
    /// The filter's prediction to this frame.
    predict_ms: f64,
    /// What ran side by side with this frame's segmentation (see [`StageTimes::overlap_ms`]).
    overlap_ms: f64,
}

impl Held {
    /// The frame's finished detections ([`Segmented::finish`]); an error the second time.
    fn finish(&mut self, config: &TrackingConfig) -> Result<FrameDetections> {
        match self.segmented.take() {
            Some(s) => s.finish(&self.cloud, config),
            None => Err(Error::invalid(
                format!("detections of frame {}", self.frame),
                "they were finished already",
            )),
        }
    }
}

/// Completes a held frame's report with its times, hands it to `on_frame` and keeps it.
fn emit(
    h: Held,
    detections: &FrameDetections,
    mut tracked: TrackedFrame,
    out: &mut Vec<TrackedFrame>,
    total: usize,
    on_frame: &mut impl FnMut(&FrameView<'_>) -> Result<()>,
) -> Result<()> {
    let t = &mut tracked.times;
    t.read_ms = h.read_ms;
    t.ego_ms = h.ego_ms;
    t.filter_ms += h.predict_ms;
    t.overlap_ms = h.overlap_ms;
    on_frame(&FrameView {
        cloud: &h.cloud,
        detections,
        tracked: &tracked,
        progress: (out.len() + 1, total),
    })?;
    out.push(tracked);
    Ok(())
}

/// Fails when `frames` is empty or reaches beyond `n` frames of `what`.
fn check_frame_range(frames: Option<&Range<usize>>, n: usize, what: &str) -> Result<()> {
    let range = frames.cloned().unwrap_or(0..n);
    if range.start >= range.end || range.end > n {
        return Err(Error::invalid(
            format!("frame range of {what}"),
            format!(
                "{}..{} is empty or beyond its {n} frames",
                range.start, range.end
            ),
        ));
    }
    Ok(())
}

/// The tracking loop over a recording's frames: `poses` one per frame (`None`: lidar
/// odometry), `vehicle` the measured kinematics of every frame and the vehicle → sensor
/// transform for a vehicle ego model, `times` one per frame.
#[allow(clippy::too_many_arguments)]
fn track_frames(
    rec: &dyn Recording,
    ego_name: &str,
    poses: Option<Vec<Isometry3<f64>>>,
    vehicle_motion: Option<(Vec<[f64; 6]>, Isometry3<f64>)>,
    times: &[f64],
    frames: Option<Range<usize>>,
    config: &TrackingConfig,
    seed: u64,
    mut on_frame: impl FnMut(&FrameView<'_>) -> Result<()>,
) -> Result<DriveTracks> {
    let name = &rec.name();
    let range = frames.unwrap_or(0..rec.frame_count());
    // The frames of the range that have a scan.
    let scans: Vec<usize> = range.clone().filter(|&k| rec.has_scan(k)).collect();
    if scans.is_empty() {
        return Err(Error::invalid(
            format!("frames {}..{} of {name}", range.start, range.end),
            "hold no scan",
        ));
    }
    let vehicle = vehicle_motion.as_ref().map(|(states, _)| states);
    let mut tracker = DriveTracker::builder(config)
        .vehicle_to_sensor(
            vehicle_motion
                .as_ref()
                .map_or_else(Isometry3::identity, |v| v.1),
        )
        .build(seed)?;
    let mut ego = match &poses {
        Some(p) => Ego::Recorded(p),
        None => Ego::Lidar(Box::new(LidarOdometry::new(OdometryConfig::default())?)),
    };
    let mut out = Vec::with_capacity(scans.len());
    let total = scans.len();
    // Frames overlap: the scan of frame k is segmented while the filter updates frame k − 1
    // with its detections and predicts to frame k, on the pool's other thread; that side
    // also gives frame k − 1's clusters their boxes and classes, just before its update, so
    // that the two sides take about as long. Each half runs in the order of a frame-by-frame
    // loop, so the tracks are the same.
    let mut held: Option<Held> = None;
    // Scan k + 1 is read beside the segmentation of scan k too.
    let read = |k: usize| -> Result<(PointCloud, f64)> {
        let start = Instant::now();
        let cloud = rec.scan(k)?;
        Ok((cloud, start.elapsed().as_secs_f64() * 1e3))
    };
    let mut next = Some(read(scans[0])?);
    for (i, &k) in scans.iter().enumerate() {
        let (cloud, read_ms) = next.take().expect("each scan is read before its round");
        let previous_state = vehicle.map(|v| v[scans[i.saturating_sub(1)]]);
        let following = scans.get(i + 1).copied();
        let steps = if i == 0 { 1 } else { k - scans[i - 1] };
        let (pose, ego_ms) = ego.pose(k, steps, &cloud, name)?;
        let start = Instant::now();
        let earlier = held.take();
        type Earlier = Option<(Held, FrameDetections, TrackedFrame, f64)>;
        type Beside = (Earlier, f64, Option<(PointCloud, f64)>);
        let (segmented, beside) = rayon::join(
            || segment_here(&cloud, config, &mut segment_rng(seed, k)),
            || -> Result<Beside> {
                let earlier = match earlier {
                    Some(mut h) => {
                        let start = Instant::now();
                        let detections = h.finish(config)?;
                        let shapes_ms = start.elapsed().as_secs_f64() * 1e3;
                        let tracked = tracker.update_with(h.frame, &detections)?;
                        Some((h, detections, tracked, shapes_ms))
                    }
                    None => None,
                };
                let start = Instant::now();
                tracker.predict_to(times[k], pose, previous_state)?;
                let predict_ms = start.elapsed().as_secs_f64() * 1e3;
                let next = match following {
                    Some(f) => Some(read(f)?),
                    None => None,
                };
                Ok((earlier, predict_ms, next))
            },
        );
        let side_by_side_ms = start.elapsed().as_secs_f64() * 1e3;
        let (segmented, (earlier, predict_ms, read_next)) = (segmented?, beside?);
        next = read_next;
        let beside_ms = predict_ms
            + earlier
                .as_ref()
                .map_or(0.0, |(_, _, t, shapes_ms)| t.times.filter_ms + shapes_ms)
            + next.as_ref().map_or(0.0, |(_, ms)| *ms);
        let (planes_ms, clusters_ms) = segmented.times();
        let overlap_ms = (planes_ms + clusters_ms + beside_ms - side_by_side_ms).max(0.0);
        if let Some((h, detections, tracked, _)) = earlier {
            emit(h, &detections, tracked, &mut out, total, &mut on_frame)?;
        }
        held = Some(Held {
            frame: k,
            cloud,
            segmented: Some(segmented),
            read_ms,
            ego_ms,
            predict_ms,
            overlap_ms,
        });
    }
    if let Some(mut h) = held.take() {
        let detections = h.finish(config)?;
        let tracked = tracker.update_with(h.frame, &detections)?;
        emit(h, &detections, tracked, &mut out, total, &mut on_frame)?;
    }
    let mut summary = TrackingSummary::of(&out);
    summary.ego_fallbacks = match &ego {
        Ego::Recorded(_) => 0,
        Ego::Lidar(o) => o.fallbacks().values().sum(),
    };
    Ok(DriveTracks {
        drive: name.to_string(),
        seed,
        particles: config.filter.particles,
        ego: ego_name.to_string(),
        frames: out,
        summary,
    })
}
