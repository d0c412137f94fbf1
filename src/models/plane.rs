//! Planar landmarks (building walls, ground) as tracked objects: how a plane seen from a moving
//! vehicle moves between frames ([`PlaneTransition`]) and how a segmented plane is scored
//! against it ([`PlaneMeasurement`]).
//!
//! # State
//!
//! β = `[n_x, n_y, n_z, d]`: unit normal n and offset d of the plane n·p + d = 0, expressed in
//! the **sensor frame of the current step**. The landmark itself is static in the world; it
//! is the vehicle that moves, so the transition is a change of frame. The canonical sign
//! ([`crate::geometry::plane::canonical`]) makes d ≥ 0, i.e. the normal points from the plane
//! towards the sensor; the transition never flips signs, and the measurement model is
//! sign-free.
//!
//! # Transition (f)
//!
//! Every particle's plane is carried into the new sensor frame by a
//! [`FrameChange`] M (n' = R n, d' = d − n'·t, renormalised: the plane transition
//! β_{k+1}ᵀ = β_kᵀ R_k⁻¹ R_{k+1} of Gostar et al. 2019, see [`crate::geometry::frame_change`]).
//! Optional process noise then tilts the normal by a random small rotation (a tangent-plane
//! Gaussian with `sigma_angle` rad per tangent axis, followed by renormalisation) and adds
//! N(0, `sigma_offset`²) to d.
//!
//! Where M comes from is the [`EgoSource`]: the measured sensor poses of the step context
//! (one M for every particle), or per particle a draw of the next vehicle state from a
//! [`VehicleModel`] (Gostar et al. 2019, Algorithm 1), M = C (P_{k+1}⁻¹ P_k) C⁻¹ with the
//! vehicle → sensor calibration C ([`FrameChange::of_vehicle`]), so that the ego-motion
//! uncertainty spreads into the plane density.
//!
//! # Measurement (h, g)
//!
//! A segmented plane z = `[n_x, n_y, n_z, d]` is compared with a particle β sign-free: the
//! angle θ = ∠(±n_z, n_β) ∈ [0, π/2] and, after flipping β to the side of z,
//! Δd = d_z − s·d_β (s = sign(n_z·n_β)). Then
//!
//! ```text
//! log g(z | β) = −½ (θ/σ_θ)² − ½ (Δd/σ_d)² − ln(2π σ_θ σ_d)
//! ```
//!
//! a Gaussian in the angle and in the offset (h(β) = β up to sign). It is a density in (θ, d),
//! not on the sphere of normals; clutter intensities must be expressed in the same units.
//!
//! Not for: segmenting planes out of point clouds, plane patches (vertices, areas) or metrics.

use super::vehicle::{check_vehicle_state, VehicleModel};
use crate::error::{Error, Result};
use crate::filter::ParticleSet;
use crate::filter::{
    check_state_dim, MeasurementModel, StepContext, TrackSummary, TransitionModel,
};
use crate::geometry::FrameChange;
use crate::rng::FilterRng;
use nalgebra::{Isometry3, Vector3};
use rand_distr::{Distribution, StandardNormal};
use std::sync::Arc;

/// Where the sensor's motion to the new step comes from.
#[derive(Clone)]
pub enum EgoSource {
    /// The measured sensor poses of the step context: T_k = `ctx.previous_platform`,
    /// T_{k+1} = `ctx.platform` (a missing pose counts as the world origin). Every particle is
    /// moved by the same M = T_{k+1}⁻¹ T_k.
    Measured,
    /// Predicted (Gostar et al. 2019, Algorithm 1): each particle draws its own vehicle state
    /// at k + 1 from `vehicle` over `ctx.dt`, starting at `vehicle_state` (the state at k),
    /// and is moved by its own M = C (P_{k+1}⁻¹ P_k) C⁻¹, C = `vehicle_to_sensor`. (The paper
    /// draws one vehicle sample for all particles; one per particle is the Monte-Carlo
    /// marginal over the vehicle motion.) `ctx` poses are not used.
    Predicted {
        /// The vehicle motion model.
        vehicle: Arc<dyn VehicleModel>,
        /// The vehicle state at the previous step k, in the model's layout.
        vehicle_state: Vec<f64>,
        /// The vehicle (IMU) → sensor transform C: `p_sensor = C p_vehicle`.
        vehicle_to_sensor: Isometry3<f64>,
    },
}

impl std::fmt::Debug for EgoSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            EgoSource::Measured => f.write_str("Measured"),
            EgoSource::Predicted {
                vehicle,
                vehicle_state,
                vehicle_to_sensor,
            } => f
                .debug_struct("Predicted")
                .field("vehicle", &vehicle.name())
                .field("vehicle_state", vehicle_state)
                .field("vehicle_to_sensor", vehicle_to_sensor)
                .finish(),
        }
    }
}

/// Default standard deviation of the normal-tilt process noise, radians (0.2°).
pub const DEFAULT_SIGMA_ANGLE: f64 = 0.2 * std::f64::consts::PI / 180.0;
/// Default standard deviation of the offset process noise, metres.
pub const DEFAULT_SIGMA_OFFSET: f64 = 0.02;

/// Plane transition driven by the vehicle's ego motion; state `[n_x, n_y, n_z, d]` in the
/// sensor frame (see the module documentation for the maths).
///
/// Particle sets with fewer than 4 components are an error.
#[derive(Clone, Debug)]
pub struct PlaneTransition {
    ego: EgoSource,
    sigma_angle: f64,
    sigma_offset: f64,
}

impl PlaneTransition {
    /// A transition with ego source `ego`, normal-tilt noise `sigma_angle` (rad) and offset
    /// noise `sigma_offset` (m), both finite and ≥ 0. A predicted source's vehicle state must
    /// fit its model ([`check_vehicle_state`]).
    pub fn new(ego: EgoSource, sigma_angle: f64, sigma_offset: f64) -> Result<Self> {
        for (name, v) in [("sigma_angle", sigma_angle), ("sigma_offset", sigma_offset)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::invalid(
                    format!("plane transition {name}"),
                    format!("{v} (must be finite and non-negative)"),
                ));
            }
        }
        if let EgoSource::Predicted {
            vehicle,
            vehicle_state,
            ..
        } = &ego
        {
            check_vehicle_state(&**vehicle, vehicle_state)?;
        }
        Ok(PlaneTransition {
            ego,
            sigma_angle,
            sigma_offset,
        })
    }

    /// Measured ego motion with the default small process noise
    /// ([`DEFAULT_SIGMA_ANGLE`], [`DEFAULT_SIGMA_OFFSET`]).
    pub fn measured() -> Self {
        PlaneTransition {
            ego: EgoSource::Measured,
            sigma_angle: DEFAULT_SIGMA_ANGLE,
            sigma_offset: DEFAULT_SIGMA_OFFSET,
        }
    }

    /// The ego source.
    pub fn ego(&self) -> &EgoSource {
        &self.ego
    }

    /// Standard deviation of the normal tilt, radians.
    pub fn sigma_angle(&self) -> f64 {
        self.sigma_angle
    }

    /// Standard deviation of the offset noise, metres.
    pub fn sigma_offset(&self) -> f64 {
        self.sigma_offset
    }

    /// The prediction with the vehicle state at the previous step given here instead of the
    /// one in [`EgoSource::Predicted`] (the drive tracker hands each step's state this way);
    /// the same as [`TransitionModel::predict`] for a measured source. A state that does not
    /// fit the model is an error.
    pub fn predict_from(
        &self,
        vehicle_state: &[f64],
        particles: &mut ParticleSet,
        ctx: &StepContext,
        rng: &mut FilterRng,
    ) -> Result<()> {
        check_state_dim("PlaneTransition", 4, particles)?;
        if particles.is_empty() {
            return Ok(());
        }
        match &self.ego {
            EgoSource::Measured => {
                let prev = ctx.previous_platform.unwrap_or_else(Isometry3::identity);
                let cur = ctx.platform.unwrap_or_else(Isometry3::identity);
                let m = FrameChange::between(&prev, &cur);
                let mut comps = particles.components_mut();
                if let [nx, ny, nz, d, ..] = comps.as_mut_slice() {
                    m.move_planes(nx, ny, nz, d);
                }
            }
            EgoSource::Predicted {
                vehicle,
                vehicle_to_sensor,
                ..
            } => {
                check_vehicle_state(&**vehicle, vehicle_state)?;
                let p0 = vehicle.pose_of(vehicle_state);
                // One batch of vehicle draws a set: one dispatch, one allocation.
                let mut next = vec![Isometry3::identity(); particles.len()];
                vehicle.sample_poses(vehicle_state, ctx.dt, rng, &mut next);
                let mut comps = particles.components_mut();
                let [nx, ny, nz, d, ..] = comps.as_mut_slice() else {
                    return Ok(());
                };
                for (i, p1) in next.iter().enumerate() {
                    let m = FrameChange::of_vehicle(&p0, p1, vehicle_to_sensor);
                    if !m.is_finite() {
                        return Err(Error::invalid(
                            format!("vehicle model {}", vehicle.name()),
                            format!(
                                "draw {i} from the state {vehicle_state:?} over {} s gave a \
                                 non-finite pose",
                                ctx.dt
                            ),
                        ));
                    }
                    let b = m.move_plane([nx[i], ny[i], nz[i], d[i]]);
                    nx[i] = b[0];
                    ny[i] = b[1];
                    nz[i] = b[2];
                    d[i] = b[3];
                }
            }
        }
        self.add_noise(particles, rng);
        Ok(())
    }

    fn add_noise(&self, particles: &mut ParticleSet, rng: &mut FilterRng) {
        if self.sigma_angle == 0.0 && self.sigma_offset == 0.0 {
            return;
        }
        let mut comps = particles.components_mut();
        let [nx, ny, nz, d, ..] = comps.as_mut_slice() else {
            return;
        };
        for i in 0..nx.len() {
            if self.sigma_angle > 0.0 {
                let n = Vector3::new(nx[i], ny[i], nz[i]);
                let e: Vector3<f64> = Vector3::new(
                    StandardNormal.sample(rng),
                    StandardNormal.sample(rng),
                    StandardNormal.sample(rng),
                );
                // tangent part of e: a 2-D isotropic Gaussian orthogonal to n
                let tangent = e - n * n.dot(&e);
                let m = n + tangent * self.sigma_angle;
                let inv = 1.0 / m.norm();
                nx[i] = m.x * inv;
                ny[i] = m.y * inv;
                nz[i] = m.z * inv;
            }
            if self.sigma_offset > 0.0 {
                let e: f64 = StandardNormal.sample(rng);
                d[i] += self.sigma_offset * e;
            }
        }
    }
}

impl TransitionModel for PlaneTransition {
    fn state_dim(&self) -> usize {
        4
    }

    fn predict(
        &self,
        particles: &mut ParticleSet,
        ctx: &StepContext,
        rng: &mut FilterRng,
    ) -> Result<()> {
        let state: &[f64] = match &self.ego {
            EgoSource::Measured => &[],
            EgoSource::Predicted { vehicle_state, .. } => vehicle_state,
        };
        self.predict_from(state, particles, ctx, rng)
    }
}

/// Default gate width of [`PlaneMeasurement`], in multiples of (σ + spread).
pub const DEFAULT_PLANE_GATE: f64 = 4.0;

/// Likelihood of a segmented plane z = `[n_x, n_y, n_z, d]` (vehicle frame) given a plane
/// particle; sign-free (see the module documentation for g).
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PlaneMeasurement {
    sigma_angle: f64,
    sigma_offset: f64,
    gate: f64,
}

impl PlaneMeasurement {
    /// A model with angle noise `sigma_angle` (rad) and offset noise `sigma_offset` (m), both
    /// finite and > 0, and the default gate width [`DEFAULT_PLANE_GATE`].
    pub fn new(sigma_angle: f64, sigma_offset: f64) -> Result<Self> {
        for (name, v) in [("sigma_angle", sigma_angle), ("sigma_offset", sigma_offset)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::invalid(
                    format!("plane measurement {name}"),
                    format!("{v} (must be finite and positive)"),
                ));
            }
        }
        Ok(PlaneMeasurement {
            sigma_angle,
            sigma_offset,
            gate: DEFAULT_PLANE_GATE,
        })
    }

    /// The same model with gate width `k` (finite, > 0): a measurement is admitted when its
    /// angle to the track's mean normal is ≤ k·(σ_angle + angular spread) and its offset
    /// difference ≤ k·(σ_offset + offset spread).
    pub fn with_gate(mut self, k: f64) -> Result<Self> {
        if !(k.is_finite() && k > 0.0) {
            return Err(Error::invalid(
                "plane measurement gate",
                format!("{k} (must be finite and positive)"),
            ));
        }
        self.gate = k;
        Ok(self)
    }

    /// Standard deviation of the normal angle, radians.
    pub fn sigma_angle(&self) -> f64 {
        self.sigma_angle
    }

    /// Standard deviation of the offset, metres.
    pub fn sigma_offset(&self) -> f64 {
        self.sigma_offset
    }

    /// Gate width in multiples of (σ + spread).
    pub fn gate_width(&self) -> f64 {
        self.gate
    }
}

/// Sign-free comparison of two planes: (angle between normals in [0, π/2], offset difference
/// d_a − s·d_b after aligning b's normal with a's). Normals need not be unit.
pub fn plane_residual(a: &[f64; 4], b: &[f64; 4]) -> (f64, f64) {
    let na = Vector3::new(a[0], a[1], a[2]);
    let nb = Vector3::new(b[0], b[1], b[2]);
    let (la, lb) = (na.norm(), nb.norm());
    let dot = na.dot(&nb);
    let s = if dot < 0.0 { -1.0 } else { 1.0 };
    let angle = na.cross(&nb).norm().atan2(dot.abs());
    (angle, a[3] / la - s * b[3] / lb)
}

impl MeasurementModel for PlaneMeasurement {
    fn measurement_dim(&self) -> usize {
        4
    }

    fn state_dim(&self) -> Option<usize> {
        Some(4)
    }

    fn log_likelihood(
        &self,
        z: &[f64],
        particles: &ParticleSet,
        _ctx: &StepContext,
        out: &mut [f64],
    ) {
        let n = particles.len();
        if z.len() < 4 || particles.dim() < 4 || z[..4].iter().any(|v| !v.is_finite()) {
            out[..n].fill(f64::NEG_INFINITY);
            return;
        }
        let zb = [z[0], z[1], z[2], z[3]];
        let norm = -(2.0 * std::f64::consts::PI * self.sigma_angle * self.sigma_offset).ln();
        let (ia, io) = (1.0 / self.sigma_angle, 1.0 / self.sigma_offset);
        let (bx, by, bz, bd) = (
            particles.component(0),
            particles.component(1),
            particles.component(2),
            particles.component(3),
        );
        for i in 0..n {
            let (angle, dd) = plane_residual(&zb, &[bx[i], by[i], bz[i], bd[i]]);
            let (ea, eo) = (angle * ia, dd * io);
            let l = norm - 0.5 * (ea * ea + eo * eo);
            out[i] = if l.is_nan() { f64::NEG_INFINITY } else { l };
        }
    }

    fn gate(&self, z: &[f64], track: &TrackSummary, _ctx: &StepContext) -> bool {
        if z.len() < 4 || track.mean.len() < 4 || track.std.len() < 4 {
            return true;
        }
        let m = &track.mean;
        let mean_norm = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
        if mean_norm.is_nan() || mean_norm <= 1e-9 {
            return true;
        }
        let (angle, dd) = plane_residual(&[z[0], z[1], z[2], z[3]], &[m[0], m[1], m[2], m[3]]);
        let s = &track.std;
        // spread of a unit normal's components, in radians for small spreads
        let angle_spread = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt() / mean_norm;
        angle <= self.gate * (self.sigma_angle + angle_spread)
            && dd.abs() <= self.gate * (self.sigma_offset + s[3])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::plane::canonical;
    use crate::models::ExtendedConstantTurn;
    use crate::rng::seeded;
    use nalgebra::Translation3;
    use nalgebra::UnitQuaternion;

    fn ctx_with(prev: Isometry3<f64>, cur: Isometry3<f64>, dt: f64) -> StepContext {
        StepContext {
            step: 1,
            time: dt,
            dt,
            platform: Some(cur),
            previous_platform: Some(prev),
            data: crate::filter::StepData::new(),
        }
    }

    fn one(beta: [f64; 4]) -> ParticleSet {
        ParticleSet::from_rows(&[beta.to_vec()], &[1.0]).unwrap()
    }

    fn pose(t: [f64; 3], axis_angle: [f64; 3]) -> Isometry3<f64> {
        Isometry3::new(Vector3::from(t), Vector3::from(axis_angle))
    }

    fn unit_plane(v: [f64; 3], d: f64) -> [f64; 4] {
        let n = Vector3::from(v).normalize();
        [n.x, n.y, n.z, d]
    }

    fn predicted(
        vehicle: Arc<dyn VehicleModel>,
        state: Vec<f64>,
        mounting: Isometry3<f64>,
    ) -> PlaneTransition {
        PlaneTransition::new(
            EgoSource::Predicted {
                vehicle,
                vehicle_state: state,
                vehicle_to_sensor: mounting,
            },
            0.0,
            0.0,
        )
        .unwrap()
    }

    #[test]
    fn forward_translation_brings_wall_closer() {
        // wall x = 10, canonical form n = (−1, 0, 0), d = 10 (normal towards the sensor)
        let beta = canonical(&[1.0, 0.0, 0.0, -10.0]);
        assert_eq!(beta, [-1.0, 0.0, 0.0, 10.0]);
        let prev = Isometry3::identity();
        let cur =
            Isometry3::from_parts(Translation3::new(1.0, 0.0, 0.0), UnitQuaternion::identity());
        let model = PlaneTransition::new(EgoSource::Measured, 0.0, 0.0).unwrap();
        let mut set = one(beta);
        model
            .predict(&mut set, &ctx_with(prev, cur, 0.1), &mut seeded(1))
            .unwrap();
        assert_eq!(set.state(0), vec![-1.0, 0.0, 0.0, 9.0]);
    }

    #[test]
    fn missing_poses_leave_planes_unchanged() {
        let model = PlaneTransition::new(EgoSource::Measured, 0.0, 0.0).unwrap();
        let beta = unit_plane([0.3, -0.4, 0.8], 5.0);
        let mut set = one(beta);
        model
            .predict(&mut set, &StepContext::new(1, 0.1, 0.1), &mut seeded(1))
            .unwrap();
        for (a, b) in set.state(0).iter().zip(beta) {
            assert!((a - b).abs() < 1e-15);
        }
    }

    /// A noise-free vehicle model moves every particle as the measured poses of its mean step
    /// do, the mounting included: the sensor poses are P C⁻¹.
    #[test]
    fn predicted_ego_without_noise_equals_measured() {
        let vehicle = [12.0, 8.0, -3.0, 2.0, 0.4, 0.15];
        let dt = 0.1;
        let next = ExtendedConstantTurn::step_noiseless(&vehicle, dt);
        let mounting = pose([0.8, -0.3, 1.7], [0.01, -0.02, 0.03]);
        let prev_pose = ExtendedConstantTurn::pose_of(&vehicle) * mounting.inverse();
        let cur_pose = ExtendedConstantTurn::pose_of(&next) * mounting.inverse();
        let measured = PlaneTransition::new(EgoSource::Measured, 0.0, 0.0).unwrap();
        let model = predicted(
            Arc::new(ExtendedConstantTurn::noiseless()),
            vehicle.to_vec(),
            mounting,
        );
        let rows: Vec<Vec<f64>> = (0..20)
            .map(|i| {
                let a = i as f64 * 0.3;
                unit_plane([a.cos(), a.sin(), 0.2 * a - 1.0], 2.0 + a).to_vec()
            })
            .collect();
        let mut a = ParticleSet::from_rows(&rows, &vec![1.0; rows.len()]).unwrap();
        let mut b = a.clone();
        let ctx = ctx_with(prev_pose, cur_pose, dt);
        measured.predict(&mut a, &ctx, &mut seeded(1)).unwrap();
        model
            .predict(&mut b, &StepContext::new(1, dt, dt), &mut seeded(2))
            .unwrap();
        for i in 0..rows.len() {
            for (x, y) in a.state(i).iter().zip(b.state(i)) {
                assert!(
                    (x - y).abs() < 1e-12,
                    "{:?} vs {:?}",
                    a.state(i),
                    b.state(i)
                );
            }
        }
    }

    #[test]
    fn predicted_ego_noise_spreads_planes() {
        let model = predicted(
            Arc::new(ExtendedConstantTurn::new(1.0, 0.1).unwrap()),
            vec![0.0, 10.0, 0.0, 0.0, 0.0, 0.0],
            Isometry3::identity(),
        );
        let n = 5_000;
        let rows = vec![vec![-1.0, 0.0, 0.0, 10.0]; n];
        let mut set = ParticleSet::from_rows(&rows, &vec![1.0; n]).unwrap();
        model
            .predict(&mut set, &StepContext::new(1, 0.1, 0.1), &mut seeded(3))
            .unwrap();
        let mean = set.mean();
        // the vehicle drives 1 m towards the wall on average
        assert!((mean[3] - 9.0).abs() < 0.01, "{mean:?}");
        let cov = set.covariance();
        assert!(cov[(3, 3)] > 0.0 && cov[(1, 1)] > 0.0);
    }

    #[test]
    fn a_vehicle_state_that_does_not_fit_its_model_is_an_error() {
        let ect: Arc<dyn VehicleModel> = Arc::new(ExtendedConstantTurn::noiseless());
        let e = PlaneTransition::new(
            EgoSource::Predicted {
                vehicle: ect.clone(),
                vehicle_state: vec![0.0; 5],
                vehicle_to_sensor: Isometry3::identity(),
            },
            0.0,
            0.0,
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("ExtendedConstantTurn") && e.contains("5 components"),
            "{e}"
        );
        let model = predicted(ect, vec![0.0; 6], Isometry3::identity());
        let mut set = one([1.0, 0.0, 0.0, 3.0]);
        let ctx = StepContext::new(1, 0.1, 0.1);
        assert!(model
            .predict_from(
                &[0.0, f64::NAN, 0.0, 0.0, 0.0, 0.0],
                &mut set,
                &ctx,
                &mut seeded(1)
            )
            .is_err());
        assert_eq!(set.state(0), vec![1.0, 0.0, 0.0, 3.0]);
    }

    #[test]
    fn process_noise_keeps_normals_unit_and_has_the_right_spread() {
        let model = PlaneTransition::new(EgoSource::Measured, 0.01, 0.05).unwrap();
        let n = 20_000;
        let rows = vec![vec![0.0, 0.0, 1.0, 2.0]; n];
        let mut set = ParticleSet::from_rows(&rows, &vec![1.0; n]).unwrap();
        model
            .predict(&mut set, &StepContext::new(1, 0.1, 0.1), &mut seeded(4))
            .unwrap();
        for i in 0..n {
            let s = set.state(i);
            assert!(((s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt() - 1.0).abs() < 1e-12);
        }
        let cov = set.covariance();
        for (c, want) in [(0, 1e-4), (1, 1e-4), (3, 0.0025)] {
            assert!(
                (cov[(c, c)] - want).abs() / want < 0.05,
                "{c}: {}",
                cov[(c, c)]
            );
        }
    }

    #[test]
    fn measurement_hand_value_and_sign_free() {
        let m = PlaneMeasurement::new(0.05, 0.2).unwrap();
        let beta = unit_plane([0.6, -0.8, 0.0], 7.0);
        let neg = [-beta[0], -beta[1], -beta[2], -beta[3]];
        let set = ParticleSet::from_rows(&[beta.to_vec(), neg.to_vec()], &[1.0, 1.0]).unwrap();
        let ctx = StepContext::new(1, 0.1, 0.1);
        let mut out = vec![0.0; 2];
        m.log_likelihood(&beta, &set, &ctx, &mut out);
        let want = -(2.0 * std::f64::consts::PI * 0.05 * 0.2).ln();
        assert!((out[0] - want).abs() < 1e-12, "{out:?} vs {want}");
        assert_eq!(out[0], out[1]);
        // a negated measurement scores the same
        let mut out2 = vec![0.0; 2];
        m.log_likelihood(&neg, &set, &ctx, &mut out2);
        assert_eq!(out, out2);
        // an offset residual of one σ costs ½
        let shifted = [beta[0], beta[1], beta[2], beta[3] + 0.2];
        m.log_likelihood(&shifted, &set, &ctx, &mut out);
        assert!((out[0] - (want - 0.5)).abs() < 1e-12);
        assert!((out[1] - (want - 0.5)).abs() < 1e-12);
        // an angle residual of one σ costs ½
        let rot = FrameChange::from_isometry(&pose([0.0; 3], [0.0, 0.0, 0.05])).move_plane(beta);
        m.log_likelihood(&rot, &set, &ctx, &mut out);
        assert!((out[0] - (want - 0.5)).abs() < 1e-9, "{out:?}");
    }

    #[test]
    fn measurement_gate() {
        let m = PlaneMeasurement::new(0.05, 0.2).unwrap();
        let track = TrackSummary {
            mean: vec![-1.0, 0.0, 0.0, 10.0],
            std: vec![0.0, 0.01, 0.0, 0.1],
            tag: None,
        };
        let ctx = StepContext::new(1, 0.1, 0.1);
        assert!(m.gate(&[1.0, 0.0, 0.0, -10.5], &track, &ctx));
        assert!(!m.gate(&[-1.0, 0.0, 0.0, 12.0], &track, &ctx));
        assert!(!m.gate(&unit_plane([-1.0, 1.0, 0.0], 10.0), &track, &ctx));
        assert!(m.gate(&unit_plane([-1.0, 0.1, 0.0], 10.0), &track, &ctx));
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(PlaneTransition::new(EgoSource::Measured, -1.0, 0.0).is_err());
        assert!(PlaneMeasurement::new(0.0, 1.0).is_err());
        assert!(PlaneMeasurement::new(0.1, 1.0)
            .unwrap()
            .with_gate(0.0)
            .is_err());
    }
}
