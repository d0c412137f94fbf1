//! Two kinds of object in one filter: building-wall planes and Euclidean point clusters
//! (cars, pedestrians, poles), each a labelled track of the same [`LmbFilter`].
//!
//! # State (6 components) and kind (a tag)
//!
//! | kind | state |
//! |---|---|
//! | plane | `[n_x, n_y, n_z, d, 0, 0]` in the **sensor frame of the current step** |
//! | cluster | `[x, ẋ, y, ẏ, z, ż]` in the **world frame** |
//!
//! The kind is not a state component: it is the particle set's tag
//! ([`crate::filter::ParticleSet::tag`], [`ObjectKind::tag`]), set by the birth sampler and
//! kept by everything the filter does to the set. Models read the kind of a set
//! ([`kind_of_set`]) and dispatch once per set, so the hot loops stay the plain
//! structure-of-arrays loops of the single-kind models.
//!
//! # Measurement (5 components)
//!
//! | kind | components 0–3 | component 4 |
//! |---|---|---|
//! | plane | segmented wall `[n_x, n_y, n_z, d]` (sensor frame, canonical) | 0 |
//! | cluster | centroid `[x, y, z, 0]` in the sensor frame | 1 |
//!
//! A measurement of one kind has likelihood 0 (log −∞) for a track of the other kind and the
//! gate rejects the pair, so planes and clusters are never associated with each other.
//!
//! # Models
//!
//! - [`MixedTransition`]: planes move by the ego motion with [`PlaneTransition`] (measured
//!   poses, or a per-particle draw of a vehicle model from the previous frame's vehicle
//!   state, [`VehicleStart`], which the frame brings in its step data);
//!   clusters move by 3-D [`ConstantVelocity`].
//! - [`MixedMeasurement`]: planes are scored by [`PlaneMeasurement`]; a cluster particle's
//!   world position p is taken into the sensor frame, s = T⁻¹ p with T = `ctx.platform`, and
//!   scored by an axis-aligned Gaussian of standard deviation σ per axis around the centroid.
//! - [`MixedDetection`], [`MixedClutter`]: a constant detection probability and a uniform
//!   clutter intensity per kind (the plane clutter density is in the (angle, offset) units
//!   of [`PlaneMeasurement`]; the cluster one per m³).
//! - [`MixedBirthSampler`]: the inverse measurement model for measurement-driven birth.
//! - [`MixedMergeDistance`]: duplicate cluster tracks merge ([`ScaledDistance`]); planes never
//!   do, because two stretches of one facade are one plane state, each measured by its own
//!   segment.
//!
//! The predicted option moves planes by the sensor motion the vehicle (IMU) draw implies, the
//! IMU → Velodyne calibration included ([`crate::geometry::FrameChange::of_vehicle`]), as the
//! plane prediction of Gostar et al. (2019, Algorithm 1) does.
//!
//! Not for: segmenting planes or clusters out of point clouds (see
//! [`crate::pipeline::drive_tracking`]).
//!
//! [`LmbFilter`]: crate::filter::LmbFilter

use super::occlusion::{ClusterOccluders, OcclusionShape};
use crate::error::{ensure_positive, ensure_probability, Error, Result};
use crate::filter::{
    check_state_dim, relative_from_logs, BirthSampler, LikelihoodFault, MergeDistance, ParticleSet,
    ScaledDistance,
};
use crate::filter::{
    ClutterModel, DetectionModel, MeasurementModel, StepContext, TrackSummary, TransitionModel,
};
use crate::geometry::plane::canonical;
use crate::models::plane::EgoSource;
use crate::models::{ConstantVelocity, PlaneMeasurement, PlaneTransition, VehicleModel};
use crate::numerics::exp::exp_in_place;
use crate::numerics::ln::ln_in_place;
use crate::rng::FilterRng;
use rand_distr::{Distribution, StandardNormal};
use std::sync::Arc;

/// Dimension of the mixed state.
pub const STATE_DIM: usize = 6;
/// Dimension of a mixed measurement.
pub const MEASUREMENT_DIM: usize = 5;
/// Index of the kind component in a measurement.
pub const MEASUREMENT_KIND: usize = 4;

/// The duplicate merge's distance for the mixed state: [`ScaledDistance`] between two
/// clusters; planes never merge (see the module documentation).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MixedMergeDistance;

impl MergeDistance for MixedMergeDistance {
    /// Untagged densities (not the tracker's): [`ScaledDistance`].
    fn distance2(&self, a: (&[f64], &[f64]), b: (&[f64], &[f64])) -> Option<f64> {
        ScaledDistance.distance2(a, b)
    }

    fn tagged_distance2(
        &self,
        a: (Option<u32>, &[f64], &[f64]),
        b: (Option<u32>, &[f64], &[f64]),
    ) -> Option<f64> {
        let cluster = Some(ObjectKind::Cluster.tag());
        if a.0 == cluster && b.0 == cluster {
            ScaledDistance.distance2((a.1, a.2), (b.1, b.2))
        } else {
            None
        }
    }
}

/// What a track or a measurement is.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ObjectKind {
    /// A building wall (plane).
    Plane,
    /// A Euclidean point cluster.
    Cluster,
}

impl ObjectKind {
    /// The particle-set tag of the kind ([`crate::filter::ParticleSet::tag`]); also its
    /// measurement code ([`ObjectKind::code`]) and its place in the per-kind arrays of the
    /// mixed models.
    pub fn tag(self) -> u32 {
        match self {
            ObjectKind::Plane => 0,
            ObjectKind::Cluster => 1,
        }
    }

    /// The kind of a particle-set tag.
    pub fn from_tag(tag: u32) -> Option<Self> {
        match tag {
            0 => Some(ObjectKind::Plane),
            1 => Some(ObjectKind::Cluster),
            _ => None,
        }
    }

    /// The value stored in a measurement's kind component: the tag.
    pub fn code(self) -> f64 {
        f64::from(self.tag())
    }

    /// The kind of a stored code (within 0.25 of a kind's, so tiny rounding drift does not
    /// matter); `None` for anything else.
    pub fn from_code(v: f64) -> Option<Self> {
        let nearest = v.round();
        if (v - nearest).abs() < 0.25 && (0.0..=f64::from(u32::MAX)).contains(&nearest) {
            ObjectKind::from_tag(nearest as u32)
        } else {
            None
        }
    }
}

/// The kind of a particle set, its tag (`None` when untagged or not a kind's tag).
pub fn kind_of_set(particles: &ParticleSet) -> Option<ObjectKind> {
    particles.tag().and_then(ObjectKind::from_tag)
}

/// The kind of a measurement.
pub fn kind_of_measurement(z: &[f64]) -> Option<ObjectKind> {
    z.get(MEASUREMENT_KIND)
        .copied()
        .and_then(ObjectKind::from_code)
}

/// A plane measurement row `[n, d, 0]` (canonical sign).
pub fn plane_measurement(beta: [f64; 4]) -> [f64; MEASUREMENT_DIM] {
    let b = canonical(&beta);
    [b[0], b[1], b[2], b[3], ObjectKind::Plane.code()]
}

/// A cluster measurement row `[x, y, z, 0, 1]` from a sensor-frame centroid.
pub fn cluster_measurement(centroid: [f64; 3]) -> [f64; MEASUREMENT_DIM] {
    [
        centroid[0],
        centroid[1],
        centroid[2],
        0.0,
        ObjectKind::Cluster.code(),
    ]
}

/// The vehicle state (in the vehicle model's layout) that a predicted ego's plane transition
/// starts from, the previous frame's: handed with the step in [`crate::filter::Frame::data`].
#[derive(Clone, Debug, PartialEq)]
pub struct VehicleStart(pub Vec<f64>);

/// Plane transition or the road users' motion, chosen by the kind of the set.
#[derive(Clone)]
pub struct MixedTransition {
    plane: PlaneTransition,
    cluster: ConstantVelocity,
    /// A user's road-user model, used instead of `cluster` when set.
    road_users: Option<Arc<dyn TransitionModel>>,
}

impl std::fmt::Debug for MixedTransition {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MixedTransition")
            .field("plane", &self.plane)
            .field("cluster", &self.cluster)
            .field("road_users", &self.road_users.as_ref().map(|m| m.name()))
            .finish_non_exhaustive()
    }
}

impl MixedTransition {
    /// Planes moved by the measured poses with normal-tilt noise `plane_sigma_angle` (rad) and
    /// offset noise `plane_sigma_offset` (m); clusters by 3-D constant velocity with
    /// acceleration noise `cluster_sigma_accel` (m/s²).
    pub fn measured(
        plane_sigma_angle: f64,
        plane_sigma_offset: f64,
        cluster_sigma_accel: f64,
    ) -> Result<Self> {
        Ok(MixedTransition {
            plane: PlaneTransition::new(
                EgoSource::Measured,
                plane_sigma_angle,
                plane_sigma_offset,
            )?,
            cluster: ConstantVelocity::spatial(cluster_sigma_accel)?,
            road_users: None,
        })
    }

    /// As [`MixedTransition::measured`], but planes are moved by a per-particle draw of the
    /// vehicle motion from `vehicle`, starting at the step's [`VehicleStart`] (an error when
    /// the frame brings none), with the vehicle → sensor transform `vehicle_to_sensor`
    /// (Gostar et al. 2019, Algorithm 1).
    pub fn predicted(
        vehicle: Arc<dyn VehicleModel>,
        vehicle_to_sensor: nalgebra::Isometry3<f64>,
        plane_sigma_angle: f64,
        plane_sigma_offset: f64,
        cluster_sigma_accel: f64,
    ) -> Result<Self> {
        let state = vec![0.0; vehicle.state_dim()];
        let plane = PlaneTransition::new(
            EgoSource::Predicted {
                vehicle,
                vehicle_state: state,
                vehicle_to_sensor,
            },
            plane_sigma_angle,
            plane_sigma_offset,
        )?;
        Ok(MixedTransition {
            plane,
            cluster: ConstantVelocity::spatial(cluster_sigma_accel)?,
            road_users: None,
        })
    }
}

impl MixedTransition {
    /// The same transition whose clusters manoeuvre now and then
    /// ([`ConstantVelocity::with_manoeuvres`]).
    pub fn with_cluster_manoeuvres(mut self, probability: f64, scale: f64) -> Result<Self> {
        self.cluster = self.cluster.with_manoeuvres(probability, scale)?;
        Ok(self)
    }

    /// The same transition whose clusters move by `model` instead of constant velocity: it
    /// gets a cluster's state [x, ẋ, y, ẏ, z, ż] (a 4-component model moves the first four
    /// and leaves the height). A model of neither 4 nor 6 components is an error naming it.
    pub fn with_road_users(mut self, model: Arc<dyn TransitionModel>) -> Result<Self> {
        let d = model.state_dim();
        if d != 4 && d != 6 {
            return Err(Error::invalid(
                format!("road-user motion {}", model.name()),
                format!("moves states of {d} components; a cluster's state has 4 or 6"),
            ));
        }
        self.road_users = Some(model);
        Ok(self)
    }

    /// Whether planes move by a vehicle model's draw from the step's [`VehicleStart`].
    fn moves_by_vehicle(&self) -> bool {
        matches!(self.plane.ego(), EgoSource::Predicted { .. })
    }
}

impl TransitionModel for MixedTransition {
    fn state_dim(&self) -> usize {
        STATE_DIM
    }

    fn predict(
        &self,
        particles: &mut ParticleSet,
        ctx: &StepContext,
        rng: &mut FilterRng,
    ) -> Result<()> {
        check_state_dim(&self.name(), STATE_DIM, particles)?;
        if particles.is_empty() {
            return Ok(());
        }
        match kind_of_set(particles) {
            Some(ObjectKind::Plane) if self.moves_by_vehicle() => {
                let start = ctx.data.require::<VehicleStart>(&self.name())?;
                self.plane.predict_from(&start.0, particles, ctx, rng)
            }
            Some(ObjectKind::Plane) => self.plane.predict(particles, ctx, rng),
            Some(ObjectKind::Cluster) => match &self.road_users {
                None => self.cluster.predict(particles, ctx, rng),
                Some(m) => m.predict(particles, ctx, rng),
            },
            None => Err(Error::invalid(
                format!("particle set handed to {}", self.name()),
                format!(
                    "its tag {:?} is neither a wall's nor a cluster's kind",
                    particles.tag()
                ),
            )),
        }
    }
}

/// A user's own measurement, detection and clutter models for one kind of object (walls or
/// clusters), used by the drive tracker instead of its built-in ones (code only: a
/// configuration file tunes the built-in ones). Each gets the mixed layout of the module
/// documentation: the 6-component state (the kind is the particle set's tag, not a component)
/// and the 5-component measurement (the kind in component 4), and is only ever asked about its
/// own kind: a measurement of the other kind never reaches it.
#[derive(Clone, Default)]
pub struct OwnModels {
    /// The measurement model (its `measurement_dim` must be 5).
    pub measurement: Option<Arc<dyn MeasurementModel>>,
    /// The detection model.
    pub detection: Option<Arc<dyn DetectionModel>>,
    /// The clutter model (asked about measurements of its kind).
    pub clutter: Option<Arc<dyn ClutterModel>>,
}

impl OwnModels {
    /// The same with `m` as the measurement model.
    pub fn measurement(mut self, m: impl MeasurementModel + 'static) -> Self {
        self.measurement = Some(Arc::new(m));
        self
    }

    /// The same with `d` as the detection model.
    pub fn detection(mut self, d: impl DetectionModel + 'static) -> Self {
        self.detection = Some(Arc::new(d));
        self
    }

    /// The same with `c` as the clutter model.
    pub fn clutter(mut self, c: impl ClutterModel + 'static) -> Self {
        self.clutter = Some(Arc::new(c));
        self
    }

    /// Checks the measurement model's dimensions against the mixed layout; `what` names the
    /// kind (`wall`, `cluster`) in the error.
    pub fn check(&self, what: &str) -> Result<()> {
        if let Some(m) = &self.measurement {
            if m.measurement_dim() != MEASUREMENT_DIM {
                return Err(Error::invalid(
                    format!("{what} measurement model {}", m.name()),
                    format!(
                        "measures {} components; the drive tracker's measurements have \
                         {MEASUREMENT_DIM} (the kind last)",
                        m.measurement_dim()
                    ),
                ));
            }
            if let Some(d) = m.state_dim().filter(|&d| d > STATE_DIM) {
                return Err(Error::invalid(
                    format!("{what} measurement model {}", m.name()),
                    format!("reads states of {d} components; the drive tracker's have {STATE_DIM}"),
                ));
            }
        }
        Ok(())
    }
}

impl std::fmt::Debug for OwnModels {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("OwnModels")
            .field("measurement", &self.measurement.as_ref().map(|m| m.name()))
            .field("detection", &self.detection.is_some())
            .field("clutter", &self.clutter.is_some())
            .finish()
    }
}

/// Equal when they share the same models (compared by identity).
impl PartialEq for OwnModels {
    fn eq(&self, other: &Self) -> bool {
        fn same<T: ?Sized>(a: &Option<Arc<T>>, b: &Option<Arc<T>>) -> bool {
            match (a, b) {
                (None, None) => true,
                (Some(a), Some(b)) => Arc::ptr_eq(a, b),
                _ => false,
            }
        }
        same(&self.measurement, &other.measurement)
            && same(&self.detection, &other.detection)
            && same(&self.clutter, &other.clutter)
    }
}

/// The index of a kind in the per-kind arrays of the mixed models: its tag.
fn slot(kind: ObjectKind) -> usize {
    kind.tag() as usize
}

/// Plane likelihood or sensor-frame position likelihood, chosen by the kind of the set; −∞
/// for a measurement of the other kind. A user's model replaces either
/// ([`MixedMeasurement::with_own`]).
#[derive(Clone)]
pub struct MixedMeasurement {
    plane: PlaneMeasurement,
    cluster_sigma: f64,
    cluster_gate: f64,
    /// Weight ε and scale k of the wide component of the cluster likelihood (ε = 0: none).
    cluster_outliers: (f64, f64),
    /// A user's models for walls and clusters ([`slot`]).
    own: [Option<Arc<dyn MeasurementModel>>; 2],
}

impl std::fmt::Debug for MixedMeasurement {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MixedMeasurement")
            .field("plane", &self.plane)
            .field("cluster_sigma", &self.cluster_sigma)
            .field("cluster_gate", &self.cluster_gate)
            .field("cluster_outliers", &self.cluster_outliers)
            .field(
                "own",
                &self.own.each_ref().map(|m| m.as_ref().map(|m| m.name())),
            )
            .finish()
    }
}

impl MixedMeasurement {
    /// Planes scored by `plane`; cluster centroids by an isotropic Gaussian of standard
    /// deviation `cluster_sigma` (m), gated at `cluster_gate`·(σ + spread) per axis.
    pub fn new(plane: PlaneMeasurement, cluster_sigma: f64, cluster_gate: f64) -> Result<Self> {
        ensure_positive("cluster measurement sigma", cluster_sigma)?;
        ensure_positive("cluster measurement gate", cluster_gate)?;
        Ok(MixedMeasurement {
            plane,
            cluster_sigma,
            cluster_gate,
            cluster_outliers: (0.0, 1.0),
            own: [None, None],
        })
    }

    /// The same with a user's model for walls (`planes`) and for clusters (`clusters`) where
    /// given, each asked only about measurements of its kind.
    pub fn with_own(
        mut self,
        planes: Option<Arc<dyn MeasurementModel>>,
        clusters: Option<Arc<dyn MeasurementModel>>,
    ) -> Self {
        self.own = [planes, clusters];
        self
    }

    /// Scores cluster centres by a contaminated Gaussian instead: (1 − `weight`) of the
    /// isotropic Gaussian of σ and `weight` of one of `scale`·σ, so that a box centre now and
    /// then metres off (a class change of the box's visible-face extension, two objects
    /// merged for a frame, part of an object hidden) lowers a track's weight instead of
    /// handing its detection to a newborn track. Fails unless `weight` ∈ [0, 1) and `scale`
    /// ≥ 1.
    pub fn with_cluster_outliers(mut self, weight: f64, scale: f64) -> Result<Self> {
        if !(0.0..1.0).contains(&weight) {
            return Err(Error::invalid(
                "cluster outlier weight",
                format!("{weight} (must lie in [0, 1))"),
            ));
        }
        if !(scale >= 1.0 && scale.is_finite()) {
            return Err(Error::invalid(
                "cluster outlier scale",
                format!("{scale} (must be finite and at least 1)"),
            ));
        }
        self.cluster_outliers = (weight, scale);
        Ok(self)
    }

    /// World → sensor transform of the step (identity without a platform pose).
    fn world_to_sensor(ctx: &StepContext) -> nalgebra::Isometry3<f64> {
        ctx.platform
            .map(|p| p.inverse())
            .unwrap_or_else(nalgebra::Isometry3::identity)
    }

    /// The two weighted terms of the box centres' contaminated Gaussian as (ln of weight ×
    /// normalisation, 1 / (2 variance)): the core of standard deviation σ and the outliers'
    /// of kσ, so a term's logarithm is `norm − half · d²`.
    fn cluster_terms(&self) -> [(f64, f64); 2] {
        let (weight, scale) = self.cluster_outliers;
        let s2 = self.cluster_sigma * self.cluster_sigma;
        let w2 = s2 * scale * scale;
        [
            (ln_normal3(s2) + (1.0 - weight).ln(), 0.5 / s2),
            (ln_normal3(w2) + weight.ln(), 0.5 / w2),
        ]
    }
}

/// ln of the normalisation of an isotropic 3-D Gaussian of variance `var`.
fn ln_normal3(var: f64) -> f64 {
    -1.5 * (2.0 * std::f64::consts::PI * var).ln()
}

/// A particle's world position seen from the sensor, less a measured position: R p + t − z.
#[derive(Copy, Clone)]
struct SensorOffset {
    r: [[f64; 3]; 3],
    t: [f64; 3],
    z: [f64; 3],
}

impl SensorOffset {
    /// The step's world → sensor transform, less the measured position `z`.
    fn new(ctx: &StepContext, z: &[f64]) -> Self {
        let inv = MixedMeasurement::world_to_sensor(ctx);
        let r = inv.rotation.to_rotation_matrix().into_inner();
        let t = inv.translation.vector;
        SensorOffset {
            r: [
                [r[(0, 0)], r[(0, 1)], r[(0, 2)]],
                [r[(1, 0)], r[(1, 1)], r[(1, 2)]],
                [r[(2, 0)], r[(2, 1)], r[(2, 2)]],
            ],
            t: [t.x, t.y, t.z],
            z: [z[0], z[1], z[2]],
        }
    }

    /// The same transform less another measured position.
    fn toward(&self, z: &[f64]) -> Self {
        SensorOffset {
            z: [z[0], z[1], z[2]],
            ..*self
        }
    }

    /// |R p + t − z|², summed in a fixed order (the same value on every path).
    #[inline(always)]
    fn squared(&self, p: [f64; 3]) -> f64 {
        let [a, b, c] = self.r;
        let sx = a[0] * p[0] + a[1] * p[1] + a[2] * p[2] + self.t[0] - self.z[0];
        let sy = b[0] * p[0] + b[1] * p[1] + b[2] * p[2] + self.t[1] - self.z[1];
        let sz = c[0] * p[0] + c[1] * p[1] + c[2] * p[2] + self.t[2] - self.z[2];
        sx * sx + sy * sy + sz * sz
    }

    /// [`SensorOffset::squared`] of every particle `(x[i], y[i], z[i])` into `out`, a NaN as
    /// +∞ (such a particle explains nothing), and the smallest of them. The same values as
    /// one [`SensorOffset::squared`] a particle: on x86-64 with AVX2 the loop runs four lanes
    /// wide (the same operations, never fused), and the minimum is taken over four
    /// interleaved running minima, which is exact in any order (no NaN is left, and no value
    /// is −0).
    fn squared_into(&self, x: &[f64], y: &[f64], z: &[f64], out: &mut [f64]) -> f64 {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has just been found to support AVX2.
            return unsafe { self.squared_into_avx2(x, y, z, out) };
        }
        self.squared_into_lanes(x, y, z, out)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn squared_into_avx2(&self, x: &[f64], y: &[f64], z: &[f64], out: &mut [f64]) -> f64 {
        self.squared_into_lanes(x, y, z, out)
    }

    #[inline(always)]
    fn squared_into_lanes(&self, x: &[f64], y: &[f64], z: &[f64], out: &mut [f64]) -> f64 {
        for (((d, &a), &b), &h) in out.iter_mut().zip(x).zip(y).zip(z) {
            let v = self.squared([a, b, h]);
            *d = if v.is_nan() { f64::INFINITY } else { v };
        }
        let n = out.len().min(x.len()).min(y.len()).min(z.len());
        let mut lanes = [f64::INFINITY; 4];
        let chunks = out[..n].chunks_exact(4);
        let rest = chunks.remainder();
        for c in chunks {
            for (m, &v) in lanes.iter_mut().zip(c) {
                *m = m.min(v);
            }
        }
        let nearest = lanes[0].min(lanes[1]).min(lanes[2].min(lanes[3]));
        rest.iter().fold(nearest, |m, &v| m.min(v))
    }
}

impl MeasurementModel for MixedMeasurement {
    fn measurement_dim(&self) -> usize {
        MEASUREMENT_DIM
    }

    fn state_dim(&self) -> Option<usize> {
        Some(STATE_DIM)
    }

    fn log_likelihood(
        &self,
        z: &[f64],
        particles: &ParticleSet,
        ctx: &StepContext,
        out: &mut [f64],
    ) {
        let n = particles.len();
        let kind = kind_of_set(particles);
        if kind.is_none() || kind != kind_of_measurement(z) {
            out[..n].fill(f64::NEG_INFINITY);
            return;
        }
        if let Some(m) = kind.and_then(|k| self.own[slot(k)].as_ref()) {
            m.log_likelihood(z, particles, ctx, out);
            return;
        }
        if kind == Some(ObjectKind::Plane) {
            self.plane.log_likelihood(&z[..4], particles, ctx, out);
            return;
        }
        // Cluster: s = R p + t, Gaussian around z per axis.
        let (x, y, zc) = (
            &particles.component(0)[..n],
            &particles.component(2)[..n],
            &particles.component(4)[..n],
        );
        let c = SensorOffset::new(ctx, z);
        let out = &mut out[..n];
        let points = || x.iter().zip(y).zip(zc).map(|((&a, &b), &c)| [a, b, c]);
        if self.cluster_outliers.0 == 0.0 {
            let s2 = self.cluster_sigma * self.cluster_sigma;
            let (norm, half_inv) = (ln_normal3(s2), 0.5 / s2);
            for (o, p) in out.iter_mut().zip(points()) {
                let l = norm - half_inv * c.squared(p);
                *o = if l.is_nan() { f64::NEG_INFINITY } else { l };
            }
            return;
        }
        // ln((1 − ε) N(d; σ) + ε N(d; kσ)) = b + ln(1 + e^(a − b)), a and b the two terms'
        // logarithms; a − b ≤ ln((1 − ε)/ε) + 3 ln k, so e^(a − b) stays finite. Three passes
        // over the particles, the transcendental ones on vector lanes.
        let [(norm_a, half_a), (norm_b, half_b)] = self.cluster_terms();
        // The squared distances once, for the first pass and the last (a NaN one as +∞: its
        // log-likelihood comes out −∞ all the same).
        let mut d2 = vec![0.0; n];
        c.squared_into(x, y, zc, &mut d2);
        for (o, &d) in out.iter_mut().zip(&d2) {
            *o = (norm_a - norm_b) - (half_a - half_b) * d;
        }
        exp_in_place(out);
        for o in out.iter_mut() {
            *o += 1.0;
        }
        ln_in_place(out);
        for (o, &d) in out.iter_mut().zip(&d2) {
            let l = *o + norm_b - half_b * d;
            *o = if l.is_nan() { f64::NEG_INFINITY } else { l };
        }
    }

    /// Box centres under the contaminated Gaussian in closed form: with a(d²) and b(d²) the
    /// logarithms of the two weighted terms, the largest likelihood is that of the smallest
    /// squared distance (both terms fall with d²), top = ln(e^a + e^b) there, and a
    /// particle's relative likelihood is e^(a − top) + e^(b − top): two exponentials a
    /// particle instead of the log path's exponential, logarithm and exponential. The same
    /// values up to rounding. Walls, and clusters without the outlier term, take the log path.
    fn relative_likelihood_batch(
        &self,
        zs: &[&[f64]],
        particles: &ParticleSet,
        ctx: &StepContext,
        out: &mut [Vec<f64>],
        tops: &mut [f64],
    ) -> std::result::Result<(), LikelihoodFault> {
        let n = particles.len();
        let kind = kind_of_set(particles);
        let own = kind.is_some_and(|k| self.own[slot(k)].is_some());
        if own || kind != Some(ObjectKind::Cluster) || self.cluster_outliers.0 == 0.0 {
            self.log_likelihood_batch(zs, particles, ctx, out);
            return relative_from_logs(out, tops);
        }
        let [(norm_a, half_a), (norm_b, half_b)] = self.cluster_terms();
        let offset = SensorOffset::new(ctx, &[0.0; 3]);
        let (x, y, zc) = (
            &particles.component(0)[..n],
            &particles.component(2)[..n],
            &particles.component(4)[..n],
        );
        let mut d2 = vec![0.0; n];
        let mut second = vec![0.0; n];
        for ((z, row), top_out) in zs.iter().zip(out.iter_mut()).zip(tops.iter_mut()) {
            *top_out = f64::NEG_INFINITY;
            if kind_of_measurement(z) != kind {
                continue;
            }
            // A particle whose distance is NaN explains nothing (as on the log path).
            let nearest = offset.toward(z).squared_into(x, y, zc, &mut d2);
            if !nearest.is_finite() {
                continue;
            }
            let (a, b) = (norm_a - half_a * nearest, norm_b - half_b * nearest);
            let top = a.max(b) + (a.min(b) - a.max(b)).exp().ln_1p();
            *top_out = top;
            let row = &mut row[..n];
            for ((o, s), &d) in row.iter_mut().zip(second.iter_mut()).zip(&d2) {
                *o = (norm_a - top) - half_a * d;
                *s = (norm_b - top) - half_b * d;
            }
            exp_in_place(row);
            exp_in_place(&mut second);
            for (o, s) in row.iter_mut().zip(&second) {
                *o += s;
            }
        }
        Ok(())
    }

    fn gate(&self, z: &[f64], track: &TrackSummary, ctx: &StepContext) -> bool {
        let track_kind = track.tag.and_then(ObjectKind::from_tag);
        let z_kind = kind_of_measurement(z);
        if track_kind.is_none() || track_kind != z_kind {
            return false;
        }
        if let Some(m) = track_kind.and_then(|k| self.own[slot(k)].as_ref()) {
            return m.gate(z, track, ctx);
        }
        if track_kind == Some(ObjectKind::Plane) {
            let summary = TrackSummary::new(track.mean[..4].to_vec(), track.std[..4].to_vec());
            return self.plane.gate(&z[..4], &summary, ctx);
        }
        // Cluster: compare in the world frame, per axis.
        let pose = ctx.platform.unwrap_or_else(nalgebra::Isometry3::identity);
        let w = pose * nalgebra::Point3::new(z[0], z[1], z[2]);
        [(w.x, 0), (w.y, 2), (w.z, 4)].iter().all(|&(v, c)| {
            (v - track.mean[c]).abs() <= self.cluster_gate * (self.cluster_sigma + track.std[c])
        })
    }
}

/// A constant detection probability per kind, for clusters lowered by the share of the track
/// that the step's [`ClusterOccluders`] hide when occlusion is on
/// ([`MixedDetection::with_occlusion`]); or a user's model for a kind
/// ([`MixedDetection::with_own`]).
#[derive(Clone)]
pub struct MixedDetection {
    plane: f64,
    cluster: f64,
    occlusion: Option<OcclusionShape>,
    own: [Option<Arc<dyn DetectionModel>>; 2],
}

impl std::fmt::Debug for MixedDetection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MixedDetection")
            .field("plane", &self.plane)
            .field("cluster", &self.cluster)
            .field("occlusion", &self.occlusion)
            .field("own", &self.own.each_ref().map(|m| m.is_some()))
            .finish()
    }
}

impl MixedDetection {
    /// p_D of planes and of clusters, each in [0, 1].
    pub fn new(plane: f64, cluster: f64) -> Result<Self> {
        ensure_probability("plane detection probability", plane)?;
        ensure_probability("cluster detection probability", cluster)?;
        Ok(MixedDetection {
            plane,
            cluster,
            occlusion: None,
            own: [None, None],
        })
    }

    /// The same with the cluster p_D lowered by the hidden share of each track's silhouette
    /// `shape` ([`super::occlusion`]), in steps whose data hold the frame's
    /// [`ClusterOccluders`] and whose context has the platform pose. Fails on a floor outside
    /// [0, 1] or a silhouette side that is not positive.
    pub fn with_occlusion(mut self, shape: OcclusionShape) -> Result<Self> {
        ensure_probability("occlusion floor", shape.floor)?;
        ensure_positive("occlusion half-width", shape.half_width)?;
        ensure_positive("occlusion half-height", shape.half_height)?;
        ensure_positive("occlusion depth", shape.depth)?;
        self.occlusion = Some(shape);
        Ok(self)
    }

    /// The same with a user's model for walls and for clusters where given.
    pub fn with_own(
        mut self,
        planes: Option<Arc<dyn DetectionModel>>,
        clusters: Option<Arc<dyn DetectionModel>>,
    ) -> Self {
        self.own = [planes, clusters];
        self
    }
}

impl DetectionModel for MixedDetection {
    fn detection_probability(&self, particles: &ParticleSet, ctx: &StepContext, out: &mut [f64]) {
        let kind = kind_of_set(particles);
        if let Some(m) = kind.and_then(|k| self.own[slot(k)].as_ref()) {
            m.detection_probability(particles, ctx, out);
            return;
        }
        let p = match kind {
            Some(ObjectKind::Plane) => self.plane,
            Some(ObjectKind::Cluster) => self.cluster * self.visible_factor(particles, ctx),
            None => 0.0,
        };
        out[..particles.len()].fill(p);
    }
}

impl MixedDetection {
    /// f + (1 − f) · the visible share of a cluster set's mean position (module
    /// [`super::occlusion`]); 1 without occlusion, occluders or platform pose.
    fn visible_factor(&self, particles: &ParticleSet, ctx: &StepContext) -> f64 {
        let (Some(shape), Some(occluders), Some(pose)) = (
            self.occlusion.as_ref(),
            ctx.data.get::<ClusterOccluders>(),
            ctx.platform.as_ref(),
        ) else {
            return 1.0;
        };
        if particles.is_empty() || particles.dim() < 6 {
            return 1.0;
        }
        let mut mean = [0.0; STATE_DIM];
        particles.mean_into(&mut mean);
        let s = pose.inverse_transform_point(&nalgebra::Point3::new(mean[0], mean[2], mean[4]));
        shape.floor + (1.0 - shape.floor) * occluders.visible_share([s.x, s.y, s.z], shape)
    }
}

/// A uniform clutter intensity per kind: κ = rate / volume; or a user's model for a kind
/// ([`MixedClutter::with_own`]).
#[derive(Clone)]
pub struct MixedClutter {
    log_plane: f64,
    log_cluster: f64,
    own: [Option<Arc<dyn ClutterModel>>; 2],
}

impl std::fmt::Debug for MixedClutter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MixedClutter")
            .field("log_plane", &self.log_plane)
            .field("log_cluster", &self.log_cluster)
            .field("own", &self.own.each_ref().map(|m| m.is_some()))
            .finish()
    }
}

impl MixedClutter {
    /// Expected false planes per frame spread over `plane_volume` (rad·m) and expected false
    /// clusters per frame spread over `cluster_volume` (m³); all positive.
    pub fn new(
        plane_rate: f64,
        plane_volume: f64,
        cluster_rate: f64,
        cluster_volume: f64,
    ) -> Result<Self> {
        for (name, v) in [
            ("plane clutter rate", plane_rate),
            ("plane clutter volume", plane_volume),
            ("cluster clutter rate", cluster_rate),
            ("cluster clutter volume", cluster_volume),
        ] {
            ensure_positive(name, v)?;
        }
        Ok(MixedClutter {
            log_plane: (plane_rate / plane_volume).ln(),
            log_cluster: (cluster_rate / cluster_volume).ln(),
            own: [None, None],
        })
    }

    /// The same with a user's model for false walls and for false clusters where given.
    pub fn with_own(
        mut self,
        planes: Option<Arc<dyn ClutterModel>>,
        clusters: Option<Arc<dyn ClutterModel>>,
    ) -> Self {
        self.own = [planes, clusters];
        self
    }
}

impl ClutterModel for MixedClutter {
    fn log_intensity(&self, z: &[f64], ctx: &StepContext) -> f64 {
        // a measurement of no known kind counts as a wall's
        let kind = kind_of_measurement(z).unwrap_or(ObjectKind::Plane);
        if let Some(m) = &self.own[slot(kind)] {
            return m.log_intensity(z, ctx);
        }
        match kind {
            ObjectKind::Cluster => self.log_cluster,
            ObjectKind::Plane => self.log_plane,
        }
    }
}

/// Draws the particles of a new track from one mixed measurement of the step in `ctx`.
///
/// Planes: each normal component gets N(0, σ_angle²) and the normal is renormalised (a tilt
/// of about σ_angle per tangent axis), the offset gets N(0, σ_offset²). Clusters: the
/// centroid is taken into the world with `ctx.platform`, position ~ N(world centroid,
/// σ_position²) per axis, horizontal velocity ~ N(0, σ_velocity²), vertical velocity ~
/// N(0, σ_vertical²).
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MixedBirthSampler {
    /// Normal spread of a plane birth (rad).
    pub plane_sigma_angle: f64,
    /// Offset spread of a plane birth (m).
    pub plane_sigma_offset: f64,
    /// Position spread of a cluster birth (m).
    pub cluster_sigma_position: f64,
    /// Horizontal velocity spread of a cluster birth (m/s).
    pub cluster_sigma_velocity: f64,
    /// Vertical velocity spread of a cluster birth (m/s).
    pub cluster_sigma_vertical: f64,
}

impl MixedBirthSampler {
    /// Checks that every spread is finite and non-negative.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("plane_sigma_angle", self.plane_sigma_angle),
            ("plane_sigma_offset", self.plane_sigma_offset),
            ("cluster_sigma_position", self.cluster_sigma_position),
            ("cluster_sigma_velocity", self.cluster_sigma_velocity),
            ("cluster_sigma_vertical", self.cluster_sigma_vertical),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::invalid(
                    format!("birth sampler {name}"),
                    format!("{v} (must be finite and non-negative)"),
                ));
            }
        }
        Ok(())
    }
}

impl BirthSampler for MixedBirthSampler {
    fn sample(&self, z: &[f64], ctx: &StepContext, n: usize, rng: &mut FilterRng) -> ParticleSet {
        let Some(kind) = kind_of_measurement(z) else {
            return ParticleSet::zeroed(STATE_DIM, 0);
        };
        let mut set = ParticleSet::zeroed(STATE_DIM, n).with_tag(kind.tag());
        let mut comps = set.components_mut();
        let [c0, c1, c2, c3, c4, c5] = comps.as_mut_slice() else {
            unreachable!("a mixed set has {STATE_DIM} components");
        };
        let mut g = || -> f64 { StandardNormal.sample(rng) };
        match kind {
            ObjectKind::Plane => {
                let b = canonical(&[z[0], z[1], z[2], z[3]]);
                for i in 0..n {
                    let nx = b[0] + self.plane_sigma_angle * g();
                    let ny = b[1] + self.plane_sigma_angle * g();
                    let nz = b[2] + self.plane_sigma_angle * g();
                    let inv = 1.0 / (nx * nx + ny * ny + nz * nz).sqrt();
                    c0[i] = nx * inv;
                    c1[i] = ny * inv;
                    c2[i] = nz * inv;
                    c3[i] = b[3] + self.plane_sigma_offset * g();
                }
            }
            ObjectKind::Cluster => {
                let pose = ctx.platform.unwrap_or_else(nalgebra::Isometry3::identity);
                let w = pose * nalgebra::Point3::new(z[0], z[1], z[2]);
                let (sp, sv, sz) = (
                    self.cluster_sigma_position,
                    self.cluster_sigma_velocity,
                    self.cluster_sigma_vertical,
                );
                for i in 0..n {
                    c0[i] = w.x + sp * g();
                    c1[i] = sv * g();
                    c2[i] = w.y + sp * g();
                    c3[i] = sv * g();
                    c4[i] = w.z + sp * g();
                    c5[i] = sz * g();
                }
            }
        }
        drop(comps);
        set
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::seeded;
    use nalgebra::{Isometry3, Vector3};

    fn ctx(platform: Isometry3<f64>) -> StepContext {
        StepContext {
            platform: Some(platform),
            previous_platform: Some(Isometry3::identity()),
            ..StepContext::new(1, 0.1, 0.1)
        }
    }

    /// Equally weighted cluster particles of `rows`.
    fn cluster_set(rows: &[Vec<f64>]) -> ParticleSet {
        ParticleSet::from_rows(rows, &vec![1.0; rows.len()])
            .unwrap()
            .with_tag(ObjectKind::Cluster.tag())
    }

    /// Equally weighted wall particles of `rows`.
    fn plane_set(rows: &[Vec<f64>]) -> ParticleSet {
        ParticleSet::from_rows(rows, &vec![1.0; rows.len()])
            .unwrap()
            .with_tag(ObjectKind::Plane.tag())
    }

    fn sampler() -> MixedBirthSampler {
        MixedBirthSampler {
            plane_sigma_angle: 0.0,
            plane_sigma_offset: 0.0,
            cluster_sigma_position: 0.0,
            cluster_sigma_velocity: 0.0,
            cluster_sigma_vertical: 0.0,
        }
    }

    proptest::proptest! {
        #[test]
        fn squared_distances_on_lanes_match_one_particle_at_a_time(
            pts in proptest::collection::vec(
                (-80.0f64..80.0, -80.0f64..80.0, -3.0f64..5.0), 0..23),
            nan_at in proptest::collection::vec(proptest::bool::weighted(0.1), 23),
            yaw in -3.2f64..3.2,
            z in (-40.0f64..40.0, -40.0f64..40.0, -2.0f64..2.0),
        ) {
            let pose = Isometry3::new(Vector3::new(3.0, -2.0, 0.5), Vector3::new(0.0, 0.0, yaw));
            let c = SensorOffset::new(&ctx(pose), &[z.0, z.1, z.2]);
            let x: Vec<f64> = pts
                .iter()
                .zip(&nan_at)
                .map(|(p, &nan)| if nan { f64::NAN } else { p.0 })
                .collect();
            let y: Vec<f64> = pts.iter().map(|p| p.1).collect();
            let h: Vec<f64> = pts.iter().map(|p| p.2).collect();
            let mut out = vec![0.0; x.len()];
            let nearest = c.squared_into(&x, &y, &h, &mut out);
            let want: Vec<f64> = (0..x.len())
                .map(|i| {
                    let v = c.squared([x[i], y[i], h[i]]);
                    if v.is_nan() { f64::INFINITY } else { v }
                })
                .collect();
            proptest::prop_assert_eq!(&out, &want);
            let smallest = want.iter().fold(f64::INFINITY, |m, &v| m.min(v));
            proptest::prop_assert_eq!(nearest.to_bits(), smallest.to_bits());
        }
    }

    #[test]
    fn kinds_never_score_each_other() {
        let c = ctx(Isometry3::identity());
        let m = MixedMeasurement::new(PlaneMeasurement::new(0.05, 0.2).unwrap(), 0.3, 4.0).unwrap();
        let plane_z = plane_measurement([-1.0, 0.0, 0.0, 10.0]);
        let cluster_z = cluster_measurement([5.0, 1.0, 0.0]);
        let planes = sampler().sample(&plane_z, &c, 3, &mut seeded(1));
        let clusters = sampler().sample(&cluster_z, &c, 3, &mut seeded(1));
        let mut out = [0.0; 3];
        m.log_likelihood(&cluster_z, &planes, &c, &mut out);
        assert!(out.iter().all(|v| *v == f64::NEG_INFINITY));
        m.log_likelihood(&plane_z, &clusters, &c, &mut out);
        assert!(out.iter().all(|v| *v == f64::NEG_INFINITY));
        m.log_likelihood(&plane_z, &planes, &c, &mut out);
        assert!(out.iter().all(|v| v.is_finite()));
        let summary = TrackSummary::of;
        assert!(!m.gate(&cluster_z, &summary(&planes), &c));
        assert!(!m.gate(&plane_z, &summary(&clusters), &c));
        assert!(m.gate(&plane_z, &summary(&planes), &c));
        assert!(m.gate(&cluster_z, &summary(&clusters), &c));
    }

    /// A user's cluster measurement model: a constant log-likelihood of −1 that refuses every
    /// gate. It scores cluster sets only; walls keep the built-in model.
    #[derive(Debug)]
    struct Flat;

    impl MeasurementModel for Flat {
        fn measurement_dim(&self) -> usize {
            MEASUREMENT_DIM
        }
        fn log_likelihood(&self, _: &[f64], p: &ParticleSet, _: &StepContext, out: &mut [f64]) {
            out[..p.len()].fill(-1.0);
        }
        fn gate(&self, _: &[f64], _: &TrackSummary, _: &StepContext) -> bool {
            false
        }
    }

    #[test]
    fn a_users_model_scores_its_own_kind_only() {
        let c = ctx(Isometry3::identity());
        let built_in =
            MixedMeasurement::new(PlaneMeasurement::new(0.05, 0.2).unwrap(), 0.3, 4.0).unwrap();
        let m = built_in.clone().with_own(None, Some(Arc::new(Flat)));
        let plane_z = plane_measurement([-1.0, 0.0, 0.0, 10.0]);
        let cluster_z = cluster_measurement([5.0, 1.0, 0.0]);
        let planes = sampler().sample(&plane_z, &c, 3, &mut seeded(1));
        let clusters = sampler().sample(&cluster_z, &c, 3, &mut seeded(1));
        let (mut out, mut want) = ([0.0; 3], [0.0; 3]);
        m.log_likelihood(&cluster_z, &clusters, &c, &mut out);
        assert_eq!(out, [-1.0; 3]);
        m.log_likelihood(&plane_z, &clusters, &c, &mut out);
        assert_eq!(out, [f64::NEG_INFINITY; 3]);
        m.log_likelihood(&plane_z, &planes, &c, &mut out);
        built_in.log_likelihood(&plane_z, &planes, &c, &mut want);
        assert_eq!(out, want);
        let summary = TrackSummary::of;
        assert!(!m.gate(&cluster_z, &summary(&clusters), &c));
        assert!(m.gate(&plane_z, &summary(&planes), &c));
        // the relative likelihoods of a cluster set: every particle as likely as the best
        let zs: Vec<&[f64]> = vec![&cluster_z, &plane_z];
        let (mut rows, mut tops) = (vec![vec![0.0; 3]; 2], [0.0; 2]);
        m.relative_likelihood_batch(&zs, &clusters, &c, &mut rows, &mut tops)
            .unwrap();
        assert_eq!((rows[0].clone(), tops[0]), (vec![1.0; 3], -1.0));
        assert_eq!(tops[1], f64::NEG_INFINITY);
        let own = OwnModels::default().measurement(Flat);
        assert!(own.check("cluster").is_ok());
    }

    #[test]
    fn cluster_likelihood_uses_the_platform_pose() {
        // Sensor 10 m east of the origin, turned 90° left: world (10, 5, 0) is 5 m ahead.
        let pose = Isometry3::new(
            Vector3::new(10.0, 0.0, 0.0),
            Vector3::new(0.0, 0.0, std::f64::consts::FRAC_PI_2),
        );
        let c = ctx(pose);
        let set = cluster_set(&[vec![10.0, 0.0, 5.0, 0.0, 0.0, 0.0]]);
        let m = MixedMeasurement::new(PlaneMeasurement::new(0.05, 0.2).unwrap(), 0.5, 4.0).unwrap();
        let mut out = [0.0];
        m.log_likelihood(&cluster_measurement([5.0, 0.0, 0.0]), &set, &c, &mut out);
        let peak = -1.5 * (2.0 * std::f64::consts::PI * 0.25).ln();
        assert!((out[0] - peak).abs() < 1e-9, "{out:?} vs {peak}");
        // one σ off along the sensor's y axis costs ½
        m.log_likelihood(&cluster_measurement([5.0, 0.5, 0.0]), &set, &c, &mut out);
        assert!((out[0] - (peak - 0.5)).abs() < 1e-9);
    }

    /// The closed-form relative likelihoods of box centres are the mixture written out by hand
    /// relative to its largest value over the particles, with that largest as `top`; a
    /// particle whose state is NaN explains nothing, a wall measurement nothing of a cluster
    /// track, and a moved sensor is accounted for.
    #[test]
    fn relative_cluster_likelihoods_match_the_mixture_by_hand() {
        let pose = Isometry3::new(Vector3::new(2.0, -1.0, 0.3), Vector3::new(0.0, 0.0, 0.4));
        let c = ctx(pose);
        let offsets = [0.2, 0.7, 1.0, 2.5, 8.0, 40.0, f64::NAN];
        let rows: Vec<Vec<f64>> = offsets
            .iter()
            .map(|&d| vec![7.0 + d, 0.0, 3.0, 0.0, -1.0, 0.0])
            .collect();
        let set = cluster_set(&rows);
        let m = MixedMeasurement::new(PlaneMeasurement::new(0.05, 0.2).unwrap(), 0.3, 4.0)
            .unwrap()
            .with_cluster_outliers(0.1, 4.0)
            .unwrap();
        // The measurement: the world point (7, 3, −1) seen from the sensor.
        let seen = pose.inverse() * nalgebra::Point3::new(7.0, 3.0, -1.0);
        let z = cluster_measurement([seen.x, seen.y, seen.z]);
        let wall = plane_measurement([-1.0, 0.0, 0.0, 10.0]);
        let mut out = vec![vec![0.0; 7]; 2];
        let mut tops = [0.0; 2];
        m.relative_likelihood_batch(&[&z, &wall], &set, &c, &mut out, &mut tops)
            .unwrap();
        let n3 = |d: f64, s: f64| {
            (-0.5 * d * d / (s * s)).exp() / (2.0 * std::f64::consts::PI * s * s).powf(1.5)
        };
        let g = |d: f64| 0.9 * n3(d, 0.3) + 0.1 * n3(d, 1.2);
        assert!((tops[0] - g(0.2).ln()).abs() < 1e-9, "{}", tops[0]);
        for (k, &d) in offsets.iter().enumerate() {
            let want = if d.is_nan() { 0.0 } else { g(d) / g(0.2) };
            assert!(
                (out[0][k] - want).abs() <= 1e-12 * want.max(1e-300) + 1e-300,
                "d = {d}: {} vs {want}",
                out[0][k]
            );
        }
        assert_eq!(tops[1], f64::NEG_INFINITY);
        // The log path's rows, exponentiated relative to their largest, agree.
        let mut logs = vec![vec![0.0; 7]; 1];
        m.log_likelihood_batch(&[&z], &set, &c, &mut logs);
        let mut log_tops = [0.0];
        relative_from_logs(&mut logs, &mut log_tops).unwrap();
        assert!((log_tops[0] - tops[0]).abs() < 1e-12);
        for (a, b) in logs[0].iter().zip(&out[0]) {
            assert!((a - b).abs() <= 1e-12 * a.abs().max(1e-300), "{a} vs {b}");
        }
    }

    #[test]
    fn contaminated_cluster_likelihood_matches_the_mixture_by_hand() {
        let c = ctx(Isometry3::identity());
        let rows: Vec<Vec<f64>> = [0.0, 0.3, 1.0, 2.5, 8.0]
            .iter()
            .map(|&d| vec![5.0 + d, 0.0, 0.0, 0.0, 0.0, 0.0])
            .collect();
        let set = cluster_set(&rows);
        let plane = PlaneMeasurement::new(0.05, 0.2).unwrap();
        let m = MixedMeasurement::new(plane, 0.3, 4.0)
            .unwrap()
            .with_cluster_outliers(0.1, 4.0)
            .unwrap();
        let mut out = [0.0; 5];
        m.log_likelihood(&cluster_measurement([5.0, 0.0, 0.0]), &set, &c, &mut out);
        // (1 − ε)·N₃(d; 0.3²) + ε·N₃(d; 1.2²), the isotropic 3-D normal written out.
        let n3 = |d: f64, s: f64| {
            (-0.5 * d * d / (s * s)).exp() / (2.0 * std::f64::consts::PI * s * s).powf(1.5)
        };
        for (k, d) in [0.0, 0.3, 1.0, 2.5, 8.0].into_iter().enumerate() {
            let want = (0.9 * n3(d, 0.3) + 0.1 * n3(d, 1.2)).ln();
            assert!(
                (out[k] - want).abs() < 1e-12,
                "d = {d}: {} vs {want}",
                out[k]
            );
        }
        // Far out the wide component carries the likelihood: 8 m off is e^−29 of the peak
        // instead of the narrow Gaussian's e^−356.
        assert!(out[4] - out[0] > -30.0);
        // Without outliers it is the plain Gaussian.
        let plain = MixedMeasurement::new(plane, 0.3, 4.0).unwrap();
        plain.log_likelihood(&cluster_measurement([5.0, 0.0, 0.0]), &set, &c, &mut out);
        assert!((out[1] - n3(0.3, 0.3).ln()).abs() < 1e-12);
        assert!(MixedMeasurement::new(plane, 0.3, 4.0)
            .unwrap()
            .with_cluster_outliers(1.0, 4.0)
            .is_err());
        assert!(MixedMeasurement::new(plane, 0.3, 4.0)
            .unwrap()
            .with_cluster_outliers(0.1, 0.5)
            .is_err());
    }

    #[test]
    fn births_carry_the_kind_and_land_in_the_world() {
        let pose = Isometry3::new(Vector3::new(3.0, 4.0, 0.0), Vector3::zeros());
        let c = ctx(pose);
        let s = MixedBirthSampler {
            cluster_sigma_velocity: 2.0,
            ..sampler()
        };
        let set = s.sample(
            &cluster_measurement([1.0, 2.0, 0.5]),
            &c,
            500,
            &mut seeded(3),
        );
        assert_eq!(kind_of_set(&set), Some(ObjectKind::Cluster));
        let mean = set.mean();
        for (got, want) in [(mean[0], 4.0), (mean[2], 6.0), (mean[4], 0.5)] {
            assert!((got - want).abs() < 1e-9, "{mean:?}");
        }
        assert!(set.std_dev()[1] > 1.5);
        let planes = s.sample(
            &plane_measurement([1.0, 0.0, 0.0, -7.0]),
            &c,
            10,
            &mut seeded(3),
        );
        assert_eq!(kind_of_set(&planes), Some(ObjectKind::Plane));
        assert_eq!(&planes.state(0)[..4], &[-1.0, 0.0, 0.0, 7.0]);
    }

    #[test]
    fn transition_dispatches_by_kind() {
        let mv = Isometry3::new(Vector3::new(1.0, 0.0, 0.0), Vector3::zeros());
        let c = ctx(mv);
        let t = MixedTransition::measured(0.0, 0.0, 0.0).unwrap();
        let mut plane = plane_set(&[vec![-1.0, 0.0, 0.0, 10.0, 0.0, 0.0]]);
        t.predict(&mut plane, &c, &mut seeded(1)).unwrap();
        assert_eq!(plane.state(0), vec![-1.0, 0.0, 0.0, 9.0, 0.0, 0.0]);
        let mut cluster = cluster_set(&[vec![0.0, 2.0, 0.0, -1.0, 0.0, 0.0]]);
        t.predict(&mut cluster, &c, &mut seeded(1)).unwrap();
        let s = cluster.state(0);
        assert!((s[0] - 0.2).abs() < 1e-12 && (s[2] + 0.1).abs() < 1e-12);
        assert_eq!(kind_of_set(&cluster), Some(ObjectKind::Cluster));
        // an untagged set is neither kind: an error naming the model
        let mut bare = ParticleSet::from_rows(&[vec![0.0; 6]], &[1.0]).unwrap();
        let e = t
            .predict(&mut bare, &c, &mut seeded(1))
            .unwrap_err()
            .to_string();
        assert!(e.contains("MixedTransition") && e.contains("tag"), "{e}");
    }

    /// A vehicle-model ego moves walls from the vehicle state the frame brings, and a step
    /// whose frame brings none is an error naming the model and the missing type.
    #[test]
    fn a_predicted_ego_takes_the_vehicle_state_from_the_step() {
        let ect = crate::models::ExtendedConstantTurn::new(0.5, 0.1).unwrap();
        let t = MixedTransition::predicted(Arc::new(ect), Isometry3::identity(), 0.0, 0.0, 0.0)
            .unwrap();
        let wall = || plane_set(&[vec![-1.0, 0.0, 0.0, 10.0, 0.0, 0.0]]);
        let bare = StepContext::new(1, 0.1, 0.1);
        let e = t
            .predict(&mut wall(), &bare, &mut seeded(1))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("MixedTransition") && e.contains("VehicleStart"),
            "{e}"
        );
        // clusters need no vehicle state
        let mut cluster = cluster_set(&[vec![0.0, 2.0, 0.0, -1.0, 0.0, 0.0]]);
        t.predict(&mut cluster, &bare, &mut seeded(1)).unwrap();
        // 10 m/s along x for 0.1 s: the wall 10 m ahead (normal −x) comes about 1 m nearer
        let start = VehicleStart(vec![0.0, 10.0, 0.0, 0.0, 0.0, 0.0]);
        let moving = bare
            .clone()
            .with_data(crate::filter::StepData::new().with(start));
        let mut w = wall();
        t.predict(&mut w, &moving, &mut seeded(1)).unwrap();
        let d = w.state(0)[3];
        assert!((d - 9.0).abs() < 0.05, "{d}");
    }

    #[test]
    fn clutter_and_detection_follow_the_kind() {
        let cl = MixedClutter::new(1.0, 10.0, 2.0, 1000.0).unwrap();
        let c = StepContext::new(0, 0.0, 0.0);
        assert!(
            (cl.log_intensity(&plane_measurement([1.0, 0.0, 0.0, 1.0]), &c) - 0.1f64.ln()).abs()
                < 1e-12
        );
        assert!(
            (cl.log_intensity(&cluster_measurement([0.0; 3]), &c) - 0.002f64.ln()).abs() < 1e-12
        );
        let d = MixedDetection::new(0.9, 0.7).unwrap();
        let set = cluster_set(&[vec![0.0; 6]]);
        let mut out = [0.0];
        d.detection_probability(&set, &c, &mut out);
        assert_eq!(out, [0.7]);
        assert!(MixedDetection::new(1.2, 0.5).is_err());
    }

    #[test]
    fn occluded_clusters_keep_the_floor_of_their_detection_probability() {
        use super::super::occlusion::{ClusterOccluders, OcclusionShape};
        use crate::geometry::Box3;
        let shape = OcclusionShape::default();
        let d = MixedDetection::new(0.9, 0.8)
            .unwrap()
            .with_occlusion(shape)
            .unwrap();
        // The sensor 5 m along world x: a car 10 m ahead of it hides a cluster 20 m ahead.
        let pose = Isometry3::translation(5.0, 0.0, 0.0);
        let front = Box3::new(
            nalgebra::Point3::new(10.0, 0.0, -0.98),
            [3.9, 1.6, 1.5],
            0.0,
        );
        let mut ctx = StepContext::new(1, 0.1, 0.1)
            .with_data(crate::filter::StepData::new().with(ClusterOccluders::from_boxes([front])));
        ctx.platform = Some(pose);
        let hidden = cluster_set(&[vec![25.0, 0.0, 0.0, 0.0, -0.98, 0.0]]);
        let beside = cluster_set(&[vec![25.0, 0.0, 12.0, 0.0, -0.98, 0.0]]);
        let mut out = [0.0];
        d.detection_probability(&hidden, &ctx, &mut out);
        assert!((out[0] - 0.8 * shape.floor).abs() < 1e-12, "{out:?}");
        d.detection_probability(&beside, &ctx, &mut out);
        assert_eq!(out, [0.8]);
        // Without the frame's occluders, or with occlusion off, the constant.
        let mut bare = StepContext::new(1, 0.1, 0.1);
        bare.platform = Some(pose);
        d.detection_probability(&hidden, &bare, &mut out);
        assert_eq!(out, [0.8]);
        MixedDetection::new(0.9, 0.8)
            .unwrap()
            .detection_probability(&hidden, &ctx, &mut out);
        assert_eq!(out, [0.8]);
        let bad = OcclusionShape {
            floor: 1.5,
            ..shape
        };
        assert!(MixedDetection::new(0.9, 0.8)
            .unwrap()
            .with_occlusion(bad)
            .is_err());
    }
}
