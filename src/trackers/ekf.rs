//! Extended Kalman filter pieces for a point moving in the plane and seen in range and bearing
//! from a sensor with a mounting offset on a moving platform (seed 000, eqs. 6–8 and 10–11).
//!
//! States are `[x, ẋ, y, ẏ, …]` in the world frame (any further components, such as a turn
//! rate, are not measured). The measurement function is
//! [`RangeBearing::predict_measurement`]; with the sensor at (x_s, y_s) and
//! d = (p_x − x_s, p_y − y_s), ρ = |d|, its Jacobian on the position components is
//!
//! ```text
//! ∂ρ/∂p_x = d_x/ρ      ∂ρ/∂p_y = d_y/ρ
//! ∂θ/∂p_x = −d_y/ρ²    ∂θ/∂p_y = d_x/ρ²      (bearing from the x axis; negated from the y axis)
//! ```
//!
//! and zero elsewhere. Bearing innovations are wrapped to (−π, π]; the covariance update is the
//! Joseph form P⁺ = (I − KH) P (I − KH)ᵀ + K R Kᵀ, which stays symmetric and positive
//! semi-definite under rounding.
//!
//! Not for: data association or track management (see the trackers beside this module).

use crate::filter::StepContext;
use crate::geometry::wrap_angle;
use crate::models::{BearingConvention, RangeBearing};
use nalgebra::{Matrix2, Matrix4, SMatrix, SVector, Vector2, Vector4};

/// Closer than this (m) to the sensor a point has no usable bearing Jacobian.
const MIN_RANGE: f64 = 1e-6;

/// A Gaussian track density: mean and covariance of an `N`-component state.
#[derive(Clone, Debug, PartialEq)]
pub struct Gaussian<const N: usize> {
    /// Mean.
    pub mean: SVector<f64, N>,
    /// Covariance.
    pub cov: SMatrix<f64, N, N>,
}

impl<const N: usize> Gaussian<N> {
    /// The mean as a plain vector (for [`crate::filter::Estimate`]).
    pub fn mean_vec(&self) -> Vec<f64> {
        self.mean.iter().copied().collect()
    }

    /// The position `[x, y]` (components 0 and 2).
    pub fn position(&self) -> [f64; 2] {
        [self.mean[0], self.mean[2]]
    }
}

/// Constant-velocity transition F and process noise Q for a step `dt` (seed 000, eqs. 6–8;
/// the same matrices as [`crate::models::ConstantVelocity`] in two axes).
pub fn cv_matrices(dt: f64, sigma_accel: f64) -> (Matrix4<f64>, Matrix4<f64>) {
    let mut f = Matrix4::identity();
    f[(0, 1)] = dt;
    f[(2, 3)] = dt;
    let s2 = sigma_accel * sigma_accel;
    let (q_pp, q_pv, q_vv) = (s2 * dt.powi(4) / 4.0, s2 * dt.powi(3) / 2.0, s2 * dt * dt);
    let mut q = Matrix4::zeros();
    for p in [0, 2] {
        q[(p, p)] = q_pp;
        q[(p, p + 1)] = q_pv;
        q[(p + 1, p)] = q_pv;
        q[(p + 1, p + 1)] = q_vv;
    }
    (f, q)
}

impl Gaussian<4> {
    /// Constant-velocity prediction over `dt` with white acceleration noise `sigma_accel`.
    pub fn predict_cv(&mut self, dt: f64, sigma_accel: f64) {
        let (f, q) = cv_matrices(dt, sigma_accel);
        self.mean = f * self.mean;
        self.cov = f * self.cov * f.transpose() + q;
        symmetrise(&mut self.cov);
    }

    /// A track started from one range-bearing measurement `z`: the measured point, the
    /// measurement noise carried to Cartesian coordinates, zero velocity with standard
    /// deviation `velocity_std` (m/s) per axis.
    pub fn from_measurement(
        z: [f64; 2],
        sensor: &RangeBearing,
        ctx: &StepContext,
        velocity_std: f64,
    ) -> Self {
        let [x, y] = sensor.to_cartesian(z, ctx);
        let (xs, ys, _) = sensor.sensor_pose(ctx);
        let alpha = (y - ys).atan2(x - xs);
        let (sa, ca) = alpha.sin_cos();
        let rho = z[0].max(0.0);
        let j = Matrix2::new(ca, -rho * sa, sa, rho * ca);
        let pos = j * measurement_noise(sensor) * j.transpose();
        let mut cov = Matrix4::zeros();
        for (a, ia) in [(0, 0), (1, 2)] {
            for (b, ib) in [(0, 0), (1, 2)] {
                cov[(ia, ib)] = pos[(a, b)];
            }
        }
        let v2 = velocity_std * velocity_std;
        cov[(1, 1)] = v2;
        cov[(3, 3)] = v2;
        Gaussian {
            mean: Vector4::new(x, 0.0, y, 0.0),
            cov,
        }
    }
}

/// R = diag(σ_ρ², σ_θ²).
pub fn measurement_noise(sensor: &RangeBearing) -> Matrix2<f64> {
    let (sr, sb) = sensor.noise();
    Matrix2::new(sr * sr, 0.0, 0.0, sb * sb)
}

/// The predicted measurement h(x) and its Jacobian H at `mean`, or `None` when the position is
/// not finite or (almost) at the sensor.
pub fn measurement_jacobian<const N: usize>(
    sensor: &RangeBearing,
    mean: &SVector<f64, N>,
    ctx: &StepContext,
) -> Option<(Vector2<f64>, SMatrix<f64, 2, N>)> {
    if N < 3 {
        return None;
    }
    let (xs, ys, _) = sensor.sensor_pose(ctx);
    let (dx, dy) = (mean[0] - xs, mean[2] - ys);
    let r2 = dx * dx + dy * dy;
    let rho = r2.sqrt();
    if !(rho.is_finite() && rho > MIN_RANGE) {
        return None;
    }
    let z = sensor.predict_measurement(&[mean[0], 0.0, mean[2]], ctx);
    let sign = match sensor.convention() {
        BearingConvention::FromXAxis => 1.0,
        BearingConvention::FromYAxis => -1.0,
    };
    let mut h = SMatrix::<f64, 2, N>::zeros();
    h[(0, 0)] = dx / rho;
    h[(0, 2)] = dy / rho;
    h[(1, 0)] = -sign * dy / r2;
    h[(1, 2)] = sign * dx / r2;
    Some((Vector2::new(z[0], z[1]), h))
}

/// A track's predicted measurement, linearised: h(x̂), H, S = H P Hᵀ + R and S⁻¹.
#[derive(Clone, Debug, PartialEq)]
pub struct Linearisation<const N: usize> {
    /// Predicted measurement [range, bearing].
    pub predicted: Vector2<f64>,
    /// Measurement Jacobian.
    pub h: SMatrix<f64, 2, N>,
    /// Innovation covariance.
    pub s: Matrix2<f64>,
    /// Its inverse.
    pub s_inv: Matrix2<f64>,
    /// ln det S.
    pub ln_det_s: f64,
}

impl<const N: usize> Linearisation<N> {
    /// Linearises the measurement of `g`; `None` when the track sits on the sensor or S is
    /// singular.
    pub fn new(g: &Gaussian<N>, sensor: &RangeBearing, ctx: &StepContext) -> Option<Self> {
        let (predicted, h) = measurement_jacobian(sensor, &g.mean, ctx)?;
        let mut s = h * g.cov * h.transpose() + measurement_noise(sensor);
        symmetrise(&mut s);
        let det = s.determinant();
        if !(det.is_finite() && det > 0.0) {
            return None;
        }
        let s_inv = s.try_inverse()?;
        Some(Linearisation {
            predicted,
            h,
            s,
            s_inv,
            ln_det_s: det.ln(),
        })
    }

    /// ν = z − h(x̂), the bearing wrapped to (−π, π].
    pub fn innovation(&self, z: &[f64]) -> Vector2<f64> {
        Vector2::new(
            z[0] - self.predicted[0],
            wrap_angle(z[1] - self.predicted[1]),
        )
    }

    /// The squared Mahalanobis distance νᵀ S⁻¹ ν.
    pub fn mahalanobis2(&self, nu: &Vector2<f64>) -> f64 {
        (nu.transpose() * self.s_inv * nu)[(0, 0)]
    }

    /// ln N(ν; 0, S).
    pub fn log_likelihood(&self, nu: &Vector2<f64>) -> f64 {
        -0.5 * self.mahalanobis2(nu) - 0.5 * self.ln_det_s - (2.0 * std::f64::consts::PI).ln()
    }

    /// The Kalman gain K = P Hᵀ S⁻¹ for the density it was built from.
    pub fn gain(&self, g: &Gaussian<N>) -> SMatrix<f64, N, 2> {
        g.cov * self.h.transpose() * self.s_inv
    }
}

/// The EKF update of `g` with innovation `nu` (Joseph form).
pub fn update<const N: usize>(
    g: &mut Gaussian<N>,
    lin: &Linearisation<N>,
    nu: &Vector2<f64>,
    sensor: &RangeBearing,
) {
    let k = lin.gain(g);
    g.mean += k * nu;
    let i_kh = SMatrix::<f64, N, N>::identity() - k * lin.h;
    g.cov = i_kh * g.cov * i_kh.transpose() + k * measurement_noise(sensor) * k.transpose();
    symmetrise(&mut g.cov);
}

/// Replaces `m` by (m + mᵀ)/2.
pub fn symmetrise<const N: usize>(m: &mut SMatrix<f64, N, N>) {
    let t = m.transpose();
    *m = (*m + t) * 0.5;
}

/// Measured minus predicted position in the world frame, for the RMS prediction error.
pub fn position_error<const N: usize>(
    g: &Gaussian<N>,
    z: &[f64],
    sensor: &RangeBearing,
    ctx: &StepContext,
) -> [f64; 2] {
    let [x, y] = sensor.to_cartesian([z[0], z[1]], ctx);
    [x - g.mean[0], y - g.mean[2]]
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Isometry3, Vector3};
    use proptest::prelude::*;

    fn ctx(x: f64, y: f64, phi: f64) -> StepContext {
        let mut c = StepContext::new(1, 0.0, 0.125);
        c.platform = Some(Isometry3::new(
            Vector3::new(x, y, 0.0),
            Vector3::new(0.0, 0.0, phi),
        ));
        c
    }

    proptest! {
        #[test]
        fn jacobian_matches_finite_differences(
            px in -20.0f64..20.0, py in -20.0f64..20.0,
            rx in -5.0f64..5.0, ry in -5.0f64..5.0, phi in -3.1f64..3.1,
            a in -0.5f64..0.5, b in -0.5f64..0.5, from_y in proptest::bool::ANY,
        ) {
            let conv = if from_y { BearingConvention::FromYAxis } else { BearingConvention::FromXAxis };
            let sensor = RangeBearing::new(0.2, 0.03).unwrap().with_offset(a, b).unwrap().with_convention(conv);
            let c = ctx(rx, ry, phi);
            let (xs, ys, _) = sensor.sensor_pose(&c);
            prop_assume!((px - xs).hypot(py - ys) > 0.5);
            let mean = Vector4::new(px, 0.3, py, -0.2);
            let (z, h) = measurement_jacobian(&sensor, &mean, &c).unwrap();
            let eps = 1e-6;
            for col in 0..4 {
                let (mut up, mut down) = (mean, mean);
                up[col] += eps;
                down[col] -= eps;
                let zu = sensor.predict_measurement(up.as_slice(), &c);
                let zd = sensor.predict_measurement(down.as_slice(), &c);
                let dr = (zu[0] - zd[0]) / (2.0 * eps);
                let db = wrap_angle(zu[1] - zd[1]) / (2.0 * eps);
                prop_assert!((dr - h[(0, col)]).abs() < 1e-5, "range col {}: {} vs {}", col, dr, h[(0, col)]);
                prop_assert!((db - h[(1, col)]).abs() < 1e-5, "bearing col {}: {} vs {}", col, db, h[(1, col)]);
            }
            let direct = sensor.predict_measurement(mean.as_slice(), &c);
            prop_assert!((z[0] - direct[0]).abs() < 1e-12 && (z[1] - direct[1]).abs() < 1e-12);
        }

        #[test]
        fn joseph_update_keeps_covariance_symmetric_positive(
            px in 2.0f64..20.0, py in -10.0f64..10.0, zr in -0.5f64..0.5, zb in -0.05f64..0.05,
        ) {
            let sensor = RangeBearing::new(0.2, 0.035).unwrap().with_offset(0.2, 0.0).unwrap();
            let c = ctx(0.0, 0.0, 0.3);
            let z0 = sensor.predict_measurement(&[px, 0.0, py, 0.0], &c);
            let mut g = Gaussian::from_measurement(z0, &sensor, &c, 1.0);
            g.predict_cv(0.125, 1.0);
            let lin = Linearisation::new(&g, &sensor, &c).unwrap();
            let before = g.cov;
            let nu = lin.innovation(&[z0[0] + zr, z0[1] + zb]);
            update(&mut g, &lin, &nu, &sensor);
            prop_assert!((g.cov - g.cov.transpose()).norm() < 1e-12);
            let eig = g.cov.symmetric_eigenvalues();
            prop_assert!(eig.iter().all(|&e| e > 0.0));
            // information only shrinks the position variances
            prop_assert!(g.cov[(0, 0)] <= before[(0, 0)] + 1e-12 && g.cov[(2, 2)] <= before[(2, 2)] + 1e-12);
        }
    }

    #[test]
    fn cv_prediction_moves_the_mean_and_grows_the_covariance() {
        let mut g = Gaussian {
            mean: Vector4::new(1.0, 2.0, 3.0, -1.0),
            cov: Matrix4::identity(),
        };
        g.predict_cv(0.5, 2.0);
        assert_eq!(g.position(), [2.0, 2.5]);
        // P_xx = 1 + T²·1 + σ²T⁴/4 = 1 + 0.25 + 4·0.0625/4 = 1.3125
        assert!((g.cov[(0, 0)] - 1.3125).abs() < 1e-12);
    }

    #[test]
    fn initial_density_is_the_measured_point() {
        let sensor = RangeBearing::new(0.2, 0.035)
            .unwrap()
            .with_offset(0.2, 0.0)
            .unwrap();
        let c = ctx(1.0, 1.0, std::f64::consts::FRAC_PI_2);
        // sensor at (1, 1.2) facing +y; 5 m straight ahead → (1, 6.2)
        let g = Gaussian::from_measurement([5.0, 0.0], &sensor, &c, 1.0);
        assert!((g.mean[0] - 1.0).abs() < 1e-12 && (g.mean[2] - 6.2).abs() < 1e-12);
        // along the beam (y) the variance is σ_ρ², across it (x) (ρ σ_θ)²
        assert!((g.cov[(2, 2)] - 0.04).abs() < 1e-12);
        assert!((g.cov[(0, 0)] - (5.0f64 * 0.035).powi(2)).abs() < 1e-12);
    }

    #[test]
    fn bearing_innovation_wraps() {
        let sensor = RangeBearing::new(0.2, 0.035).unwrap();
        let c = ctx(0.0, 0.0, 0.0);
        // object just below the negative x axis: predicted bearing ≈ −π + 0.01
        let g = Gaussian {
            mean: Vector4::new(-10.0, 0.0, -0.1, 0.0),
            cov: Matrix4::identity() * 0.01,
        };
        let lin = Linearisation::new(&g, &sensor, &c).unwrap();
        // measured π − 0.01: 0.02 rad clockwise across the ±π cut, not 2π − 0.02
        let nu = lin.innovation(&[10.0, std::f64::consts::PI - 0.01]);
        let predicted = (-0.1f64).atan2(-10.0);
        assert!((predicted + std::f64::consts::PI - 0.01).abs() < 1e-4);
        assert!((nu[1] + 0.02).abs() < 1e-4, "{nu}");
    }
}
