//! Planar landmarks (building walls, ground) as tracked objects: how a plane seen from a moving
//! vehicle moves between frames ([`PlaneTransition`]) and how a segmented plane is scored
//! against it ([`PlaneMeasurement`]).
//!
//! # State
//!
//! β = `[n_x, n_y, n_z, d]`: unit normal n and offset d of the plane n·p + d = 0, expressed in
//! the **vehicle (sensor) frame of the current step**. The landmark itself is static in the
//! world; it is the vehicle that moves, so the transition is a change of frame. The canonical
//! sign ([`canonical_plane`]) makes d ≥ 0, i.e. the normal points from the plane towards the
//! sensor; the transition never flips signs, and the measurement model is sign-free.
//!
//! # Transition (f)
//!
//! Let T_k, T_{k+1} be the world poses of the vehicle (vehicle → world) at steps k and k + 1.
//! A point fixed in the world has vehicle coordinates p_{k+1} = M p_k with
//! M = T_{k+1}⁻¹ T_k = (R, t), i.e. p_{k+1} = R p_k + t. Substituting p_k = Rᵀ(p_{k+1} − t)
//! into n·p_k + d = 0 gives (R n)·p_{k+1} + d − (R n)·t = 0, so
//!
//! ```text
//! n' = R n,    d' = d − n'·t        (homogeneous form: β'ᵀ = βᵀ M⁻¹)
//! ```
//!
//! which is eq. (35) of seed 001, β_{k+1}ᵀ = β_kᵀ R_k⁻¹ R_{k+1}, with R_k = T_k. The result is
//! renormalised (n' and d' divided by |n'|) so that rounding never lets |n| drift. Optional
//! process noise then tilts the normal by a random small rotation (a tangent-plane Gaussian
//! with `sigma_angle` rad per tangent axis, followed by renormalisation) and adds N(0,
//! `sigma_offset`²) to d.
//!
//! Where T_{k+1} comes from is the [`EgoSource`]: the measured poses of the step context, or a
//! per-particle prediction from an [`ExtendedConstantTurn`] vehicle model (seed 001, Alg. 1).
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

use super::ExtendedConstantTurn;
use crate::error::{Error, Result};
use crate::filter::ParticleSet;
use crate::filter::{MeasurementModel, StepContext, TrackSummary, TransitionModel};
use crate::rng::FilterRng;
use nalgebra::{Isometry3, Matrix3, Vector3};
use rand_distr::{Distribution, StandardNormal};

/// Where the vehicle pose at the new step comes from.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum EgoSource {
    /// Use the measured poses of the step context: T_k = `ctx.previous_platform`,
    /// T_{k+1} = `ctx.platform` (a missing pose counts as the world origin). Every particle is
    /// moved by the same M = T_{k+1}⁻¹ T_k.
    Measured,
    /// Predict the new vehicle pose (seed 001, Algorithm 1): T_k is the pose of
    /// `vehicle_state` (see [`ExtendedConstantTurn::pose_of`]); each particle draws its own
    /// vehicle state at k + 1 from the `ect` model over `ctx.dt` and is moved by its own
    /// M = T_{k+1}⁻¹ T_k. The ego-motion uncertainty thus spreads into the plane density.
    /// (The paper draws one vehicle sample for all particles; one per particle is the
    /// Monte-Carlo marginal over the vehicle motion.) `ctx` poses are ignored; update
    /// `vehicle_state` every step (e.g. with [`PlaneTransition::set_vehicle_state`]).
    Predicted {
        /// The vehicle motion model.
        ect: ExtendedConstantTurn,
        /// Vehicle state `[X, Ẋ, Y, Ẏ, φ, φ̇]` (world frame) at the previous step k.
        vehicle_state: [f64; 6],
    },
}

/// Default standard deviation of the normal-tilt process noise, radians (0.2°).
pub const DEFAULT_SIGMA_ANGLE: f64 = 0.2 * std::f64::consts::PI / 180.0;
/// Default standard deviation of the offset process noise, metres.
pub const DEFAULT_SIGMA_OFFSET: f64 = 0.02;

/// Plane transition driven by the vehicle's ego motion; state `[n_x, n_y, n_z, d]` in the
/// vehicle frame (see the module documentation for the maths).
///
/// Particle sets with fewer than 4 components are left unchanged.
#[derive(Copy, Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PlaneTransition {
    ego: EgoSource,
    sigma_angle: f64,
    sigma_offset: f64,
}

impl PlaneTransition {
    /// A transition with ego source `ego`, normal-tilt noise `sigma_angle` (rad) and offset
    /// noise `sigma_offset` (m), both finite and ≥ 0.
    pub fn new(ego: EgoSource, sigma_angle: f64, sigma_offset: f64) -> Result<Self> {
        for (name, v) in [("sigma_angle", sigma_angle), ("sigma_offset", sigma_offset)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::invalid(
                    format!("plane transition {name}"),
                    format!("{v} (must be finite and non-negative)"),
                ));
            }
        }
        if let EgoSource::Predicted { vehicle_state, .. } = &ego {
            if vehicle_state.iter().any(|v| !v.is_finite()) {
                return Err(Error::invalid(
                    "plane transition vehicle_state",
                    format!("{vehicle_state:?} (must be finite)"),
                ));
            }
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

    /// Replaces the vehicle state at the previous step (only meaningful for
    /// [`EgoSource::Predicted`]; a no-op otherwise).
    pub fn set_vehicle_state(&mut self, state: [f64; 6]) {
        if let EgoSource::Predicted { vehicle_state, .. } = &mut self.ego {
            *vehicle_state = state;
        }
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

/// M = T_{k+1}⁻¹ T_k: maps vehicle-frame coordinates at step k to those at step k + 1.
pub fn relative_motion(previous: &Isometry3<f64>, current: &Isometry3<f64>) -> Isometry3<f64> {
    current.inverse() * previous
}

/// Applies n' = R n, d' = d − n'·t (then divides by |n'|) to one plane.
#[inline(always)]
fn move_plane(r: &Matrix3<f64>, t: &Vector3<f64>, b: [f64; 4]) -> [f64; 4] {
    let [x, y, z, d] = b;
    let nx = r[(0, 0)] * x + r[(0, 1)] * y + r[(0, 2)] * z;
    let ny = r[(1, 0)] * x + r[(1, 1)] * y + r[(1, 2)] * z;
    let nz = r[(2, 0)] * x + r[(2, 1)] * y + r[(2, 2)] * z;
    let nd = d - (nx * t.x + ny * t.y + nz * t.z);
    let inv = 1.0 / (nx * nx + ny * ny + nz * nz).sqrt();
    [nx * inv, ny * inv, nz * inv, nd * inv]
}

/// Moves one plane β = `[n, d]` by the frame change `m` = T_{k+1}⁻¹ T_k (n' = R n,
/// d' = d − n'·t, renormalised). A zero normal has no direction to move: it comes out
/// non-finite, and a particle left so makes the filter step fail with an error naming its
/// track (see `LmbFilter::step`) rather than be carried on.
pub fn transform_plane(beta: &[f64; 4], m: &Isometry3<f64>) -> [f64; 4] {
    let r = m.rotation.to_rotation_matrix().into_inner();
    move_plane(&r, &m.translation.vector, *beta)
}

/// Moves every particle's plane (components 0–3) by the same frame change `m` =
/// T_{k+1}⁻¹ T_k, in place over the structure-of-arrays columns, without allocating per
/// particle. This is the hot loop of the plane prediction. Sets with fewer than 4 components
/// are left unchanged.
pub fn transform_planes(states: &mut ParticleSet, m: &Isometry3<f64>) {
    if states.dim() < 4 || states.is_empty() {
        return;
    }
    let r = m.rotation.to_rotation_matrix().into_inner();
    let t = m.translation.vector;
    let mut comps = states.components_mut();
    let [nx, ny, nz, d, ..] = comps.as_mut_slice() else {
        return;
    };
    let n = nx.len();
    let (nx, ny, nz, d) = (&mut nx[..n], &mut ny[..n], &mut nz[..n], &mut d[..n]);
    for i in 0..n {
        let b = move_plane(&r, &t, [nx[i], ny[i], nz[i], d[i]]);
        nx[i] = b[0];
        ny[i] = b[1];
        nz[i] = b[2];
        d[i] = b[3];
    }
}

/// The canonical representative of a plane: unit normal and d ≥ 0 (normal towards the
/// origin of the frame); for a plane through the origin, the first non-zero normal component
/// is made positive. A zero or non-finite normal is returned unchanged.
pub fn canonical_plane(beta: &[f64; 4]) -> [f64; 4] {
    let [x, y, z, d] = *beta;
    let norm = (x * x + y * y + z * z).sqrt();
    if !(norm.is_finite() && norm > 0.0) {
        return *beta;
    }
    let mut s = 1.0 / norm;
    let flip = if d != 0.0 {
        d < 0.0
    } else if x != 0.0 {
        x < 0.0
    } else if y != 0.0 {
        y < 0.0
    } else {
        z < 0.0
    };
    if flip {
        s = -s;
    }
    [x * s, y * s, z * s, d * s]
}

impl TransitionModel for PlaneTransition {
    fn state_dim(&self) -> usize {
        4
    }

    fn predict(&self, particles: &mut ParticleSet, ctx: &StepContext, rng: &mut FilterRng) {
        if particles.dim() < 4 || particles.is_empty() {
            return;
        }
        match &self.ego {
            EgoSource::Measured => {
                let prev = ctx.previous_platform.unwrap_or_else(Isometry3::identity);
                let cur = ctx.platform.unwrap_or_else(Isometry3::identity);
                transform_planes(particles, &relative_motion(&prev, &cur));
            }
            EgoSource::Predicted { ect, vehicle_state } => {
                let dt = ctx.dt;
                let [x0, _, y0, _, phi0, _] = *vehicle_state;
                let mut comps = particles.components_mut();
                let [nx, ny, nz, d, ..] = comps.as_mut_slice() else {
                    return;
                };
                for i in 0..nx.len() {
                    let v = ect.sample_step(vehicle_state, dt, rng);
                    // M = T_{k+1}⁻¹ T_k for planar poses: R = Rz(φ_k − φ_{k+1}),
                    // t = Rz(−φ_{k+1}) (X_k − X_{k+1}, Y_k − Y_{k+1}, 0).
                    let (s1, c1) = v[4].sin_cos();
                    let (sr, cr) = (phi0 - v[4]).sin_cos();
                    let (dx, dy) = (x0 - v[0], y0 - v[2]);
                    let r = Matrix3::new(cr, -sr, 0.0, sr, cr, 0.0, 0.0, 0.0, 1.0);
                    let t = Vector3::new(c1 * dx + s1 * dy, -s1 * dx + c1 * dy, 0.0);
                    let b = move_plane(&r, &t, [nx[i], ny[i], nz[i], d[i]]);
                    nx[i] = b[0];
                    ny[i] = b[1];
                    nz[i] = b[2];
                    d[i] = b[3];
                }
            }
        }
        self.add_noise(particles, rng);
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
    use crate::rng::seeded;
    use nalgebra::{Point3, Translation3, UnitQuaternion};
    use proptest::prelude::*;

    fn ctx_with(prev: Isometry3<f64>, cur: Isometry3<f64>, dt: f64) -> StepContext {
        StepContext {
            step: 1,
            time: dt,
            dt,
            platform: Some(cur),
            previous_platform: Some(prev),
        }
    }

    fn one(beta: [f64; 4]) -> ParticleSet {
        ParticleSet::from_rows(&[beta.to_vec()], &[1.0]).unwrap()
    }

    fn pose(t: [f64; 3], axis_angle: [f64; 3]) -> Isometry3<f64> {
        Isometry3::new(Vector3::from(t), Vector3::from(axis_angle))
    }

    /// A point on the plane: −d n plus an in-plane offset built from (u, v).
    fn point_on(beta: &[f64; 4], u: f64, v: f64) -> Point3<f64> {
        let n = Vector3::new(beta[0], beta[1], beta[2]);
        let helper = if n.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        };
        let e1 = n.cross(&helper).normalize();
        let e2 = n.cross(&e1);
        Point3::from(-beta[3] * n + u * e1 + v * e2)
    }

    fn unit_plane(v: [f64; 3], d: f64) -> [f64; 4] {
        let n = Vector3::from(v).normalize();
        [n.x, n.y, n.z, d]
    }

    #[test]
    fn zero_normal_comes_out_non_finite() {
        let m = Isometry3::from_parts(
            Translation3::new(1.0, 2.0, 0.0),
            UnitQuaternion::from_euler_angles(0.0, 0.0, 0.3),
        );
        let moved = transform_plane(&[0.0, 0.0, 0.0, 5.0], &m);
        assert!(moved.iter().all(|v| !v.is_finite()), "{moved:?}");
        let fine = transform_plane(&[1.0, 0.0, 0.0, 5.0], &m);
        assert!(fine.iter().all(|v| v.is_finite()), "{fine:?}");
    }

    proptest! {
        #[test]
        fn moved_point_lies_on_moved_plane(
            t0 in prop::array::uniform3(-50.0f64..50.0), r0 in prop::array::uniform3(-3.0f64..3.0),
            t1 in prop::array::uniform3(-50.0f64..50.0), r1 in prop::array::uniform3(-3.0f64..3.0),
            nv in prop::array::uniform3(-1.0f64..1.0), d in -30.0f64..30.0,
            u in -20.0f64..20.0, v in -20.0f64..20.0,
        ) {
            prop_assume!(Vector3::from(nv).norm() > 0.1);
            let beta = unit_plane(nv, d);
            let m = relative_motion(&pose(t0, r0), &pose(t1, r1));
            let p1 = m * point_on(&beta, u, v);
            let b1 = transform_plane(&beta, &m);
            let resid = b1[0] * p1.x + b1[1] * p1.y + b1[2] * p1.z + b1[3];
            prop_assert!(resid.abs() < 1e-9, "residual {resid}");
            let n1 = (b1[0] * b1[0] + b1[1] * b1[1] + b1[2] * b1[2]).sqrt();
            prop_assert!((n1 - 1.0).abs() < 1e-12);
            // the SoA loop agrees with the single-plane function
            let mut set = one(beta);
            transform_planes(&mut set, &m);
            prop_assert_eq!(set.state(0), b1.to_vec());
        }

        #[test]
        fn composition_of_steps(
            t0 in prop::array::uniform3(-20.0f64..20.0), r0 in prop::array::uniform3(-3.0f64..3.0),
            t1 in prop::array::uniform3(-20.0f64..20.0), r1 in prop::array::uniform3(-3.0f64..3.0),
            t2 in prop::array::uniform3(-20.0f64..20.0), r2 in prop::array::uniform3(-3.0f64..3.0),
            nv in prop::array::uniform3(-1.0f64..1.0), d in -30.0f64..30.0,
        ) {
            prop_assume!(Vector3::from(nv).norm() > 0.1);
            let beta = unit_plane(nv, d);
            let (p0, p1, p2) = (pose(t0, r0), pose(t1, r1), pose(t2, r2));
            let two = transform_plane(&transform_plane(&beta, &relative_motion(&p0, &p1)),
                                      &relative_motion(&p1, &p2));
            let direct = transform_plane(&beta, &relative_motion(&p0, &p2));
            for (a, b) in two.iter().zip(direct) {
                prop_assert!((a - b).abs() < 1e-9, "{two:?} vs {direct:?}");
            }
        }
    }

    #[test]
    fn forward_translation_brings_wall_closer() {
        // wall x = 10, canonical form n = (−1, 0, 0), d = 10 (normal towards the sensor)
        let beta = canonical_plane(&[1.0, 0.0, 0.0, -10.0]);
        assert_eq!(beta, [-1.0, 0.0, 0.0, 10.0]);
        let prev = Isometry3::identity();
        let cur =
            Isometry3::from_parts(Translation3::new(1.0, 0.0, 0.0), UnitQuaternion::identity());
        let model = PlaneTransition::new(EgoSource::Measured, 0.0, 0.0).unwrap();
        let mut set = one(beta);
        model.predict(&mut set, &ctx_with(prev, cur, 0.1), &mut seeded(1));
        assert_eq!(set.state(0), vec![-1.0, 0.0, 0.0, 9.0]);
    }

    #[test]
    fn missing_poses_leave_planes_unchanged() {
        let model = PlaneTransition::new(EgoSource::Measured, 0.0, 0.0).unwrap();
        let beta = unit_plane([0.3, -0.4, 0.8], 5.0);
        let mut set = one(beta);
        model.predict(&mut set, &StepContext::new(1, 0.1, 0.1), &mut seeded(1));
        for (a, b) in set.state(0).iter().zip(beta) {
            assert!((a - b).abs() < 1e-15);
        }
    }

    #[test]
    fn predicted_ego_without_noise_equals_measured() {
        let vehicle = [12.0, 8.0, -3.0, 2.0, 0.4, 0.15];
        let dt = 0.1;
        let next = ExtendedConstantTurn::step_noiseless(&vehicle, dt);
        let prev_pose = ExtendedConstantTurn::pose_of(&vehicle);
        let cur_pose = ExtendedConstantTurn::pose_of(&next);
        let measured = PlaneTransition::new(EgoSource::Measured, 0.0, 0.0).unwrap();
        let predicted = PlaneTransition::new(
            EgoSource::Predicted {
                ect: ExtendedConstantTurn::noiseless(),
                vehicle_state: vehicle,
            },
            0.0,
            0.0,
        )
        .unwrap();
        let rows: Vec<Vec<f64>> = (0..20)
            .map(|i| {
                let a = i as f64 * 0.3;
                unit_plane([a.cos(), a.sin(), 0.2 * a - 1.0], 2.0 + a).to_vec()
            })
            .collect();
        let mut a = ParticleSet::from_rows(&rows, &vec![1.0; rows.len()]).unwrap();
        let mut b = a.clone();
        let ctx = ctx_with(prev_pose, cur_pose, dt);
        measured.predict(&mut a, &ctx, &mut seeded(1));
        predicted.predict(&mut b, &StepContext::new(1, dt, dt), &mut seeded(2));
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
        let vehicle = [0.0, 10.0, 0.0, 0.0, 0.0, 0.0];
        let model = PlaneTransition::new(
            EgoSource::Predicted {
                ect: ExtendedConstantTurn::new(1.0, 0.1).unwrap(),
                vehicle_state: vehicle,
            },
            0.0,
            0.0,
        )
        .unwrap();
        let n = 5_000;
        let rows = vec![vec![-1.0, 0.0, 0.0, 10.0]; n];
        let mut set = ParticleSet::from_rows(&rows, &vec![1.0; n]).unwrap();
        model.predict(&mut set, &StepContext::new(1, 0.1, 0.1), &mut seeded(3));
        let mean = set.mean();
        // the vehicle drives 1 m towards the wall on average
        assert!((mean[3] - 9.0).abs() < 0.01, "{mean:?}");
        let cov = set.covariance();
        assert!(cov[(3, 3)] > 0.0 && cov[(1, 1)] > 0.0);
    }

    #[test]
    fn process_noise_keeps_normals_unit_and_has_the_right_spread() {
        let model = PlaneTransition::new(EgoSource::Measured, 0.01, 0.05).unwrap();
        let n = 20_000;
        let rows = vec![vec![0.0, 0.0, 1.0, 2.0]; n];
        let mut set = ParticleSet::from_rows(&rows, &vec![1.0; n]).unwrap();
        model.predict(&mut set, &StepContext::new(1, 0.1, 0.1), &mut seeded(4));
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
        let rot = transform_plane(&beta, &pose([0.0; 3], [0.0, 0.0, 0.05]));
        m.log_likelihood(&rot, &set, &ctx, &mut out);
        assert!((out[0] - (want - 0.5)).abs() < 1e-9, "{out:?}");
    }

    #[test]
    fn measurement_gate() {
        let m = PlaneMeasurement::new(0.05, 0.2).unwrap();
        let track = TrackSummary {
            mean: vec![-1.0, 0.0, 0.0, 10.0],
            std: vec![0.0, 0.01, 0.0, 0.1],
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
