//! [`DriveTracker`]: one [`LmbFilter`] over the mixed plane/cluster state, stepped frame by
//! frame with a frame's detections and the sensor pose, and the per-frame report built from
//! its MAP estimate.
//!
//! The filter's estimates carry no shape, so the report borrows it from the detections: each
//! confirmed track is matched (greedy, nearest first, within a fixed gate) to one detection of
//! its kind in the frame; a wall takes that detection's rectangle projected onto the track's
//! plane and remembers it in the world frame for the frames where it is missed, a cluster
//! takes the detection's box size. The matches also give every detection (and so every
//! point) a track number for the labelled exports.
//!
//! Not for: reading drives or segmenting clouds (see [`super::detect`],
//! [`super::track_recording`]).

use super::detect::{detect_here, FrameDetections};
use super::occlusion::{ClusterOccluders, OcclusionShape};
use super::output::{OrientedBox, StageTimes, TrackedCluster, TrackedFrame, TrackedPlane};
use super::road_users::{contained_in_others, speed_evidence, travel_direction, RoadUserState};
use super::TrackingConfig;
use crate::cloud::classes::speed_log_likelihoods;
use crate::cloud::classes::ClassModel;
use crate::cloud::PointCloud;
use crate::error::Result;
use crate::filter::{AdaptiveBirth, Estimate, Frame, Label, LmbFilter, StepData, Track};
use crate::geometry::plane::canonical;
use crate::geometry::wrap_angle;
use crate::geometry::Plane;
use crate::models::plane::plane_residual;
use crate::models::{PlaneMeasurement, VehicleModel, VehicleState};
use crate::pipeline::drive_tracking::mixed::{
    kind_of_set, MixedBirthSampler, MixedClutter, MixedDetection, MixedMeasurement,
    MixedMergeDistance, MixedTransition, ObjectKind, VehicleStart,
};
use crate::rng::{seeded, FilterRng};
use nalgebra::{Isometry3, Point3, Vector3};
use std::collections::{HashMap, HashSet};
use std::sync::Arc;
use std::time::Instant;

/// Largest normal angle between a wall track and the detection it is matched to (rad).
const MATCH_ANGLE: f64 = 0.15;
/// Largest offset difference between a wall track and its matched detection (m).
const MATCH_OFFSET: f64 = 1.0;
/// Largest sensor-frame distance between a cluster track and its matched detection (m).
const MATCH_DISTANCE: f64 = 1.5;
/// Gap (m) between a wall track's remembered rectangle and a matched segment along their
/// plane that costs as much as `MATCH_OFFSET` of offset, and beyond which the segment is
/// another stretch of the same plane (a collinear facade) and does not replace the rectangle.
const MATCH_GAP: f64 = 2.0;

/// The gap between two rectangles in (nearly) one plane, along their longer sides: the
/// distance between their centres less half the sum of their lengths, 0 when they overlap.
fn rectangle_gap(a: &[Point3<f64>; 4], b: &[Point3<f64>; 4]) -> f64 {
    let centre =
        |r: &[Point3<f64>; 4]| Point3::from(r.iter().map(|p| p.coords).sum::<Vector3<f64>>() / 4.0);
    let length = |r: &[Point3<f64>; 4]| (r[1] - r[0]).norm().max((r[3] - r[0]).norm());
    ((centre(a) - centre(b)).norm() - 0.5 * (length(a) + length(b))).max(0.0)
}

/// The tracker of one drive: the filter, its random state and what the report remembers.
pub struct DriveTracker {
    filter: LmbFilter,
    /// The vehicle model of a predicted ego and the last vehicle state handed to the tracker
    /// (its layout; zeros before the first), which each step hands the plane transition.
    vehicle: Option<(Arc<dyn VehicleModel>, Vec<f64>)>,
    rng: FilterRng,
    /// The report's id of each live label; a label the filter dropped never returns, and its
    /// entries here and in the maps below leave with it (see [`DriveTracker::forget_dropped`]).
    ids: HashMap<Label, u32>,
    /// Ids handed out so far.
    issued: u32,
    wall_corners: HashMap<Label, [Point3<f64>; 4]>,
    cluster_extent: HashMap<Label, [f64; 3]>,
    road_users: HashMap<Label, RoadUserState>,
    class_model: ClassModel,
    all_clusters: bool,
    /// Least existence of a reported road user (`TrackingConfig::report_min_existence`).
    report_min_existence: f64,
    /// Particle cap of unreported static clutter (`ClusterTuning::clutter_particles`).
    clutter_particles: Option<usize>,
    /// The road users reported in the last frame.
    reported: HashSet<Label>,
    /// The configuration, for the segmentation of [`DriveTracker::step_scan`].
    config: TrackingConfig,
    /// Time and sensor pose of a frame predicted by [`DriveTracker::predict_to`] and not yet
    /// updated.
    predicted: Option<(f64, Isometry3<f64>)>,
}

impl std::fmt::Debug for DriveTracker {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DriveTracker")
            .field("filter", &self.filter)
            .field("labels", &self.issued)
            .finish_non_exhaustive()
    }
}

/// Assembles a [`DriveTracker`] from a configuration and the recording's parts it does not
/// hold: the vehicle → sensor calibration a vehicle ego model moves walls with.
#[derive(Debug)]
pub struct DriveTrackerBuilder<'a> {
    config: &'a TrackingConfig,
    vehicle_to_sensor: Isometry3<f64>,
}

impl DriveTrackerBuilder<'_> {
    /// The vehicle (IMU) → sensor transform C, `p_sensor = C p_vehicle`, of the recording
    /// (KITTI: `calib_imu_to_velo.txt`, `Tr_imu_velo`); default the identity. Only a vehicle
    /// ego model ([`super::EgoModel`] other than `Measured`) uses it.
    pub fn vehicle_to_sensor(mut self, c: Isometry3<f64>) -> Self {
        self.vehicle_to_sensor = c;
        self
    }

    /// The tracker; `seed` drives the filter's randomness.
    pub fn build(self, seed: u64) -> Result<DriveTracker> {
        DriveTracker::assemble(self.config, self.vehicle_to_sensor, seed)
    }
}

impl DriveTracker {
    /// A tracker with the models and tuning of `config`; `seed` drives the filter's randomness.
    /// The same as [`DriveTracker::builder`] with the identity vehicle → sensor transform.
    pub fn new(config: &TrackingConfig, seed: u64) -> Result<Self> {
        Self::builder(config).build(seed)
    }

    /// A builder for the tracker of `config`.
    pub fn builder(config: &TrackingConfig) -> DriveTrackerBuilder<'_> {
        DriveTrackerBuilder {
            config,
            vehicle_to_sensor: Isometry3::identity(),
        }
    }

    fn assemble(
        config: &TrackingConfig,
        vehicle_to_sensor: Isometry3<f64>,
        seed: u64,
    ) -> Result<Self> {
        config.validate()?;
        let p = &config.plane;
        let c = &config.cluster;
        let (transition, vehicle) = match config.ego.vehicle_model()? {
            None => (
                MixedTransition::measured(p.process_angle, p.process_offset, c.sigma_accel)?,
                None,
            ),
            Some(model) => {
                let t = MixedTransition::predicted(
                    model.clone(),
                    vehicle_to_sensor,
                    p.process_angle,
                    p.process_offset,
                    c.sigma_accel,
                )?;
                let start = vec![0.0; model.state_dim()];
                (t, Some((model, start)))
            }
        };
        let mut transition =
            transition.with_cluster_manoeuvres(c.manoeuvre_probability, c.manoeuvre_scale)?;
        if let super::RoadUserMotion::Custom(m) = &c.motion {
            transition = transition.with_road_users(m.0.clone())?;
        }
        let plane_meas = PlaneMeasurement::new(p.sigma_angle, p.sigma_offset)?.with_gate(p.gate)?;
        p.own_models.check("wall")?;
        c.own_models.check("cluster")?;
        let (po, co) = (&p.own_models, &c.own_models);
        let sampler = MixedBirthSampler {
            plane_sigma_angle: p.birth_angle,
            plane_sigma_offset: p.birth_offset,
            cluster_sigma_position: c.birth_position,
            cluster_sigma_velocity: c.birth_velocity,
            cluster_sigma_vertical: c.birth_vertical,
        };
        sampler.validate()?;
        let mut birth = AdaptiveBirth::new(
            sampler,
            config.birth.expected_births,
            config.birth.max_existence,
            config.filter.particles,
        )?;
        // A proposal below the pruning threshold would be pruned right after its first update.
        birth.min_existence = config
            .filter
            .prune_threshold
            .max(config.birth.min_existence)
            .max(birth.min_existence);
        let filter = LmbFilter::builder()
            .transition(transition)
            .measurement(
                MixedMeasurement::new(plane_meas, c.sigma, c.gate)?
                    .with_cluster_outliers(c.outlier_weight, c.outlier_scale)?
                    .with_own(po.measurement.clone(), co.measurement.clone()),
            )
            .detection(
                {
                    let d = MixedDetection::new(p.detection, c.detection)?;
                    match c.occlusion {
                        true => d.with_occlusion(OcclusionShape::default())?,
                        false => d,
                    }
                }
                .with_own(po.detection.clone(), co.detection.clone()),
            )
            .clutter(
                MixedClutter::new(
                    p.clutter_rate,
                    p.clutter_volume,
                    c.clutter_rate,
                    c.clutter_volume,
                )?
                .with_own(po.clutter.clone(), co.clutter.clone()),
            )
            .survival(crate::filter::ConstantSurvival(config.birth.survival))
            .birth(birth)
            .merge_distance(MixedMergeDistance)
            .config(config.filter.clone())
            .build()?;
        Ok(DriveTracker {
            filter,
            vehicle,
            rng: seeded(seed),
            ids: HashMap::new(),
            issued: 0,
            wall_corners: HashMap::new(),
            cluster_extent: HashMap::new(),
            road_users: HashMap::new(),
            class_model: ClassModel::default(),
            all_clusters: config.all_clusters,
            report_min_existence: config.report_min_existence,
            clutter_particles: c.clutter_particles,
            reported: HashSet::new(),
            config: config.clone(),
            predicted: None,
        })
    }

    /// The filter (tracks, configuration).
    pub fn filter(&self) -> &LmbFilter {
        &self.filter
    }

    /// Runs one frame: `pose` is the sensor pose (sensor → world) at `time` (s);
    /// `vehicle_state` the planar vehicle state `[X, Ẋ, Y, Ẏ, φ, φ̇]` of the *previous* frame,
    /// needed only by the ECT ego model (the first frame may pass any). Returns the frame's
    /// report; `times.read_ms` is left 0 for the caller, `planes_ms` and `clusters_ms` are
    /// copied from `detections`.
    pub fn step(
        &mut self,
        frame: usize,
        time: f64,
        pose: Isometry3<f64>,
        vehicle_state: Option<[f64; 6]>,
        detections: &FrameDetections,
    ) -> Result<TrackedFrame> {
        // On one of rayon's threads (see `detect_objects`).
        rayon::scope(|_| self.step_here(frame, time, pose, vehicle_state, detections))
    }

    /// Runs one frame from its scan: segments `cloud` (sensor frame) with the tracker's
    /// configuration and `segment_rng` while the filter predicts its tracks to `time` beside
    /// it, then updates them with the detections. The same detections, tracks and report as
    /// [`detect_objects`](super::detect_objects) with that generator followed by
    /// [`DriveTracker::step`]; only the times differ (`times.overlap_ms`). After an error the
    /// tracker is not to be stepped again.
    pub fn step_scan(
        &mut self,
        frame: usize,
        time: f64,
        pose: Isometry3<f64>,
        vehicle_state: Option<[f64; 6]>,
        cloud: &PointCloud,
        segment_rng: &mut FilterRng,
    ) -> Result<(FrameDetections, TrackedFrame)> {
        let config = self.config.clone();
        let start = Instant::now();
        let (detections, predict_ms) = rayon::scope(|_| {
            let (detections, predicted) = rayon::join(
                || detect_here(cloud, &config, segment_rng),
                || {
                    let start = Instant::now();
                    self.predict_to(time, pose, vehicle_state)
                        .map(|()| start.elapsed().as_secs_f64() * 1e3)
                },
            );
            Ok::<_, crate::error::Error>((detections?, predicted?))
        })?;
        let side_by_side_ms = start.elapsed().as_secs_f64() * 1e3;
        let mut tracked = self.update_with(frame, &detections)?;
        let t = &mut tracked.times;
        t.filter_ms += predict_ms;
        t.overlap_ms = (t.planes_ms + t.clusters_ms + predict_ms - side_by_side_ms).max(0.0);
        Ok((detections, tracked))
    }

    /// The first half of a step: the filter's tracks predicted to `time`, the sensor at
    /// `pose` (`vehicle_state` as for [`DriveTracker::step`]). Needs no detections, so a
    /// caller can run it while the scan is segmented; [`DriveTracker::update_with`] completes
    /// the frame. An error when a frame is predicted and not yet updated.
    pub fn predict_to(
        &mut self,
        time: f64,
        pose: Isometry3<f64>,
        vehicle_state: Option<[f64; 6]>,
    ) -> Result<()> {
        rayon::scope(|_| {
            let data = self.step_data(vehicle_state);
            self.filter
                .predict_step(time, Some(pose), data, &mut self.rng)
        })?;
        self.predicted = Some((time, pose));
        Ok(())
    }

    /// The second half of a step predicted by [`DriveTracker::predict_to`]: the update with the
    /// frame's `detections` and the frame's report (`times.filter_ms` counts this half only).
    /// An error when no frame is predicted.
    pub fn update_with(
        &mut self,
        frame: usize,
        detections: &FrameDetections,
    ) -> Result<TrackedFrame> {
        let Some((time, pose)) = self.predicted else {
            return Err(crate::error::Error::invalid(
                format!("update of frame {frame}"),
                "the frame was not predicted (call predict_to first)",
            ));
        };
        rayon::scope(|_| {
            let start = Instant::now();
            let measurements = detections.measurements()?;
            let estimates = self
                .filter
                .update_step_with(&measurements, occluders(detections))?;
            self.predicted = None;
            self.finish(frame, time, pose, detections, &estimates, start)
        })
    }

    /// The step's data for the models: for a vehicle ego model the state of the previous
    /// frame ([`VehicleStart`]), built from the measured kinematics `[X, Ẋ, Y, Ẏ, φ, φ̇]`
    /// ([`VehicleModel::state_of`]) or, without them, the last state handed over.
    fn step_data(&mut self, measured: Option<[f64; 6]>) -> StepData {
        let Some((model, last)) = &mut self.vehicle else {
            return StepData::new();
        };
        if let Some([x, vx, y, vy, heading, yaw_rate]) = measured {
            *last = model.state_of(&VehicleState {
                x,
                vx,
                y,
                vy,
                heading,
                yaw_rate,
            });
        }
        StepData::new().with(VehicleStart(last.clone()))
    }

    fn step_here(
        &mut self,
        frame: usize,
        time: f64,
        pose: Isometry3<f64>,
        vehicle_state: Option<[f64; 6]>,
        detections: &FrameDetections,
    ) -> Result<TrackedFrame> {
        let start = Instant::now();
        let mut data = self.step_data(vehicle_state);
        data.extend(occluders(detections));
        let measurements = detections.measurements()?;
        let estimates = self.filter.step(
            &Frame::new(time, measurements).at(pose).with_data(data),
            &mut self.rng,
        )?;
        self.finish(frame, time, pose, detections, &estimates, start)
    }

    /// The frame's report from the filter's estimates; `start` is when the filter's work
    /// began.
    fn finish(
        &mut self,
        frame: usize,
        time: f64,
        pose: Isometry3<f64>,
        detections: &FrameDetections,
        estimates: &[Estimate],
        start: Instant,
    ) -> Result<TrackedFrame> {
        let (planes, clusters) = self.report(estimates, &pose, detections)?;
        self.forget_dropped();
        let filter_ms = start.elapsed().as_secs_f64() * 1e3;
        let (_, _, yaw) = pose.rotation.euler_angles();
        let t = pose.translation.vector;
        Ok(TrackedFrame {
            frame,
            time,
            ego_position: [t.x, t.y, t.z],
            ego_yaw: yaw,
            detected_planes: detections.walls.len(),
            detected_clusters: detections.clusters.len(),
            planes,
            clusters,
            times: StageTimes {
                read_ms: 0.0,
                ego_ms: 0.0,
                planes_ms: detections.planes_ms,
                clusters_ms: detections.clusters_ms,
                filter_ms,
                overlap_ms: 0.0,
            },
        })
    }

    fn id_of(&mut self, label: Label) -> u32 {
        let issued = &mut self.issued;
        *self.ids.entry(label).or_insert_with(|| {
            *issued += 1;
            *issued
        })
    }

    /// Drops what the report remembers of labels that are no longer tracks: the filter
    /// never brings a pruned or merged label back, so over a long drive these maps hold only
    /// the live tracks instead of every label ever reported.
    fn forget_dropped(&mut self) {
        let live: HashSet<Label> = self.filter.tracks().iter().map(|t| t.label).collect();
        self.ids.retain(|l, _| live.contains(l));
        self.wall_corners.retain(|l, _| live.contains(l));
        self.cluster_extent.retain(|l, _| live.contains(l));
        self.road_users.retain(|l, _| live.contains(l));
    }

    /// The frame's report: the filter's estimates split into walls and clusters, each matched
    /// to this frame's detections and reported ([`Self::report_walls`],
    /// [`Self::report_clusters`]).
    fn report(
        &mut self,
        estimates: &[Estimate],
        pose: &Isometry3<f64>,
        det: &FrameDetections,
    ) -> Result<(Vec<TrackedPlane>, Vec<TrackedCluster>)> {
        let mut planes: Vec<(&Estimate, [f64; 4])> = Vec::new();
        let mut clusters: Vec<(&Estimate, Point3<f64>)> = Vec::new();
        // the kind of each track: its particle set's tag
        let kinds: HashMap<Label, ObjectKind> = self
            .filter
            .tracks()
            .iter()
            .filter_map(|t| kind_of_set(&t.particles).map(|k| (t.label, k)))
            .collect();
        for e in estimates {
            match kinds.get(&e.label).copied() {
                Some(ObjectKind::Plane) => {
                    let s = &e.state;
                    planes.push((e, canonical(&[s[0], s[1], s[2], s[3]])));
                }
                Some(ObjectKind::Cluster) => {
                    let w = Point3::new(e.state[0], e.state[2], e.state[4]);
                    clusters.push((e, w));
                }
                None => {}
            }
        }
        let out_planes = self.report_walls(&planes, pose, det);
        let out_clusters = self.report_clusters(&clusters, pose, det)?;
        Ok((out_planes, out_clusters))
    }

    /// The wall estimates (`(estimate, canonical β)`), each matched to at most one of the
    /// frame's walls (greedy, cheapest pair first) and reported with the rectangle it
    /// remembers: a matched wall's rectangle replaces it when it lies on the same stretch of
    /// facade.
    fn report_walls(
        &mut self,
        planes: &[(&Estimate, [f64; 4])],
        pose: &Isometry3<f64>,
        det: &FrameDetections,
    ) -> Vec<TrackedPlane> {
        let inv = pose.inverse();
        let mut plane_pairs: Vec<(f64, usize, usize)> = Vec::new();
        for (i, (_, beta)) in planes.iter().enumerate() {
            // The remembered rectangle in the sensor frame: of several segments of one plane,
            // the one on the same stretch of facade is preferred.
            let remembered = self
                .wall_corners
                .get(&planes[i].0.label)
                .map(|world| world.map(|v| inv * v));
            for (j, w) in det.walls.iter().enumerate() {
                let (angle, dd) = plane_residual(beta, &w.patch.plane.as_vector());
                if angle <= MATCH_ANGLE && dd.abs() <= MATCH_OFFSET {
                    let gap = remembered.map_or(0.0, |r| rectangle_gap(&r, &w.patch.vertices));
                    let cost = angle / MATCH_ANGLE + dd.abs() / MATCH_OFFSET + gap / MATCH_GAP;
                    plane_pairs.push((cost, i, j));
                }
            }
        }
        let plane_match = greedy(plane_pairs, planes.len(), det.walls.len());
        let mut out_planes = Vec::with_capacity(planes.len());
        for ((e, beta), m) in planes.iter().zip(plane_match) {
            let plane = Plane::new(Vector3::new(beta[0], beta[1], beta[2]), beta[3]).ok();
            if let (Some(j), Some(_)) = (m, &plane) {
                let corners = det.walls[j].patch.vertices.map(|v| pose * v);
                let same_stretch = self
                    .wall_corners
                    .get(&e.label)
                    .is_none_or(|old| rectangle_gap(old, &corners) <= MATCH_GAP);
                if same_stretch {
                    self.wall_corners.insert(e.label, corners);
                }
            }
            let sensor = match (&plane, self.wall_corners.get(&e.label)) {
                (Some(pl), Some(world)) => Some(world.map(|v| pl.project(&(inv * v)))),
                _ => None,
            };
            let area = sensor.map_or(0.0, |v| rectangle_area(&v));
            let id = self.id_of(e.label);
            out_planes.push(TrackedPlane {
                id,
                label: e.label,
                normal: [beta[0], beta[1], beta[2]],
                offset: beta[3],
                vertices: sensor.map(|v| v.map(|p| [p.x, p.y, p.z])),
                vertices_world: sensor.map(|v| {
                    v.map(|p| {
                        let w = pose * p;
                        [w.x, w.y, w.z]
                    })
                }),
                area,
                existence: e.existence,
                detection: m,
            });
        }
        out_planes
    }

    /// The cluster estimates (`(estimate, world position)`), each matched to at most one of
    /// the frame's clusters (nearest first): a matched one's road-user state takes in the
    /// detection's shape, and the road users are reported (every confirmed cluster with
    /// `all_clusters`). Static clutter that is not reported gets the particle cap of
    /// `ClusterTuning::clutter_particles`.
    fn report_clusters(
        &mut self,
        clusters: &[(&Estimate, Point3<f64>)],
        pose: &Isometry3<f64>,
        det: &FrameDetections,
    ) -> Result<Vec<TrackedCluster>> {
        let inv = pose.inverse();
        let mut cluster_pairs: Vec<(f64, usize, usize)> = Vec::new();
        for (i, (_, w)) in clusters.iter().enumerate() {
            let s = inv * w;
            for (j, c) in det.clusters.iter().enumerate() {
                let d = (s - Point3::from(c.position())).norm();
                if d <= MATCH_DISTANCE {
                    cluster_pairs.push((d, i, j));
                }
            }
        }
        let cluster_match = greedy(cluster_pairs, clusters.len(), det.clusters.len());
        let ego_yaw = yaw_of(pose);
        let mut out_clusters = Vec::with_capacity(clusters.len());
        // Static clutter that is not reported is carried with fewer particles (see
        // `ClusterTuning::clutter_particles`).
        let clutter_particles = self.clutter_particles;
        let mut caps = HashMap::new();
        // The speed evidence of the tracks whose class is updated below.
        let tracks: HashMap<Label, &Track> =
            self.filter.tracks().iter().map(|t| (t.label, t)).collect();
        let mut speed_lls = HashMap::new();
        for ((e, _), m) in clusters.iter().zip(&cluster_match) {
            if m.is_some() {
                let ll = match tracks.get(&e.label) {
                    Some(t) => speed_evidence(&t.particles)?,
                    None => speed_log_likelihoods([(e.state[1].hypot(e.state[3]), 1.0)])?,
                };
                speed_lls.insert(e.label, ll);
            }
        }
        drop(tracks);
        for ((e, w), m) in clusters.iter().zip(cluster_match) {
            let velocity = [e.state[1], e.state[3], e.state[5]];
            let speed = velocity[0].hypot(velocity[1]);
            if let Some(j) = m {
                let c = &det.clusters[j];
                self.cluster_extent
                    .insert(e.label, std::array::from_fn(|a| c.max[a] - c.min[a]));
                if let Some(shape) = &c.shape {
                    let world_yaw = wrap_angle(shape.bbox.yaw + ego_yaw);
                    let speed_ll = &speed_lls[&e.label];
                    match self.road_users.get_mut(&e.label) {
                        Some(state) => {
                            let travel = travel_direction([velocity[0], velocity[1]], e.age)
                                .map(|t| wrap_angle(t - ego_yaw));
                            state.update(shape, world_yaw, speed_ll, travel, &self.class_model)?
                        }
                        None => {
                            let state =
                                RoadUserState::new(shape, world_yaw, speed_ll, &self.class_model)?;
                            self.road_users.insert(e.label, state);
                        }
                    }
                }
            }
            let state = self.road_users.get(&e.label);
            let road_user = state.is_none_or(|st| st.is_road_user(speed));
            if !road_user && !self.all_clusters {
                if let Some(n) = clutter_particles {
                    caps.insert(e.label, n);
                }
                continue;
            }
            if e.existence < self.report_min_existence && !self.all_clusters {
                continue;
            }
            let s = inv * w;
            let (class, class_probability, box_world, box_sensor) = match state {
                Some(st) => {
                    let (class, p) = st.class();
                    let yaw = st.heading([velocity[0], velocity[1]]);
                    let world = OrientedBox {
                        center: [w.x, w.y, w.z],
                        size: st.size(),
                        yaw,
                    };
                    let sensor = OrientedBox {
                        center: [s.x, s.y, s.z],
                        size: st.size(),
                        yaw: wrap_angle(yaw - ego_yaw),
                    };
                    (Some(class.name().to_string()), p, Some(world), Some(sensor))
                }
                None => (None, 0.0, None, None),
            };
            let id = self.id_of(e.label);
            out_clusters.push(TrackedCluster {
                id,
                label: e.label,
                position_world: [w.x, w.y, w.z],
                position_sensor: [s.x, s.y, s.z],
                velocity,
                extent: self.cluster_extent.get(&e.label).copied(),
                existence: e.existence,
                detection: m,
                class,
                class_probability,
                box_world,
                box_sensor,
                road_user,
            });
        }
        self.drop_fragments(&mut out_clusters);
        self.reported = out_clusters
            .iter()
            .filter(|c| c.road_user)
            .map(|c| c.label)
            .collect();
        if !self.all_clusters {
            out_clusters.retain(|c| c.road_user);
        }
        self.filter.set_particle_caps(caps);
        Ok(out_clusters)
    }

    /// A road user inside a more certain one's footprint is a fragment of it: it is no road
    /// user ([`contained_in_others`]).
    fn drop_fragments(&self, out_clusters: &mut [TrackedCluster]) {
        let users: Vec<usize> = (0..out_clusters.len())
            .filter(|&i| out_clusters[i].road_user && out_clusters[i].box_world.is_some())
            .collect();
        let boxes: Vec<_> = users
            .iter()
            .filter_map(|&i| {
                let c = &out_clusters[i];
                c.box_world.as_ref().map(|b| (b.to_box3(), c.existence))
            })
            .collect();
        let incumbent: Vec<bool> = users
            .iter()
            .map(|&i| self.reported.contains(&out_clusters[i].label))
            .collect();
        for (&i, contained) in users.iter().zip(contained_in_others(&boxes, &incumbent)) {
            if contained {
                out_clusters[i].road_user = false;
            }
        }
    }
}

/// Assigns each row at most one column and each column at most one row, taking pairs in
/// ascending cost (ties: lower row, then lower column).
fn greedy(mut pairs: Vec<(f64, usize, usize)>, rows: usize, cols: usize) -> Vec<Option<usize>> {
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
    let mut row = vec![None; rows];
    let mut used = vec![false; cols];
    for (_, i, j) in pairs {
        if row[i].is_none() && !used[j] {
            row[i] = Some(j);
            used[j] = true;
        }
    }
    row
}

/// Heading (rad) of a pose's x axis about z.
fn yaw_of(pose: &Isometry3<f64>) -> f64 {
    let x = pose.rotation * Vector3::x();
    x.y.atan2(x.x)
}

/// Area of the rectangle v0 v1 v2 v3.
fn rectangle_area(v: &[Point3<f64>; 4]) -> f64 {
    (v[1] - v[0]).norm() * (v[3] - v[0]).norm()
}

/// The step data the update's models read of the frame's detections: its clusters as
/// occluders ([`ClusterOccluders`]).
fn occluders(detections: &FrameDetections) -> StepData {
    StepData::new().with(ClusterOccluders::of(detections))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn greedy_takes_cheapest_pairs_first() {
        let m = greedy(vec![(1.0, 0, 0), (0.5, 1, 0), (2.0, 0, 1)], 3, 2);
        assert_eq!(m, vec![Some(1), Some(0), None]);
    }

    #[test]
    fn gap_between_stretches_of_one_facade() {
        // Upright 10 m × 4 m rectangles in the plane y = 5, starting at x0.
        let rect = |x0: f64, len: f64| {
            [
                Point3::new(x0, 5.0, 0.0),
                Point3::new(x0 + len, 5.0, 0.0),
                Point3::new(x0 + len, 5.0, 4.0),
                Point3::new(x0, 5.0, 4.0),
            ]
        };
        assert_eq!(rectangle_gap(&rect(0.0, 10.0), &rect(4.0, 10.0)), 0.0);
        assert_eq!(rectangle_gap(&rect(0.0, 10.0), &rect(2.0, 4.0)), 0.0);
        assert!((rectangle_gap(&rect(0.0, 10.0), &rect(25.0, 10.0)) - 15.0).abs() < 1e-12);
        assert!((rectangle_gap(&rect(0.0, 10.0), &rect(-13.0, 10.0)) - 3.0).abs() < 1e-12);
    }

    /// A real frame seen for a few frames, then nothing: every track dies, and with them
    /// what the report remembered of their labels; ids keep counting.
    #[test]
    fn labels_the_filter_dropped_are_forgotten() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(
            "tests/data/kitti/2011_09_26/2011_09_26_drive_UNKNOWN_sync/velodyne_points/data/\
             0000000000.bin",
        );
        let cloud = crate::cloud::read_kitti_bin(&path).unwrap();
        let config = TrackingConfig {
            all_clusters: true,
            ..TrackingConfig::default()
        };
        let seen = crate::pipeline::drive_tracking::detect_objects(
            &cloud,
            &config,
            &mut crate::rng::seeded(2),
        )
        .unwrap();
        let empty = FrameDetections {
            walls: Vec::new(),
            clusters: Vec::new(),
            ground: Vec::new(),
            planes_ms: 0.0,
            clusters_ms: 0.0,
        };
        let mut tracker = DriveTracker::new(&config, 3).unwrap();
        let pose = Isometry3::identity();
        for k in 0..60 {
            let det = if k < 5 { &seen } else { &empty };
            tracker.step(k, k as f64 * 0.1, pose, None, det).unwrap();
            if k == 4 {
                assert!(!tracker.ids.is_empty() && !tracker.cluster_extent.is_empty());
            }
        }
        assert!(tracker.filter.tracks().is_empty(), "every track died");
        assert!(tracker.issued > 0);
        assert!(tracker.ids.is_empty() && tracker.road_users.is_empty());
        assert!(tracker.cluster_extent.is_empty() && tracker.wall_corners.is_empty());
    }
}
