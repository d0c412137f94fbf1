//! The exponential map of SE(3): a 6-vector update `[ρ; ω]` (translation part first, as in
//! Sophus) to a rigid transform, for the Gauss–Newton steps of the registration.

use nalgebra::{Isometry3, Matrix3, Translation3, UnitQuaternion, Vector3, Vector6};

/// exp([ρ; ω]) = (exp(ω^), V(ω)·ρ) with V = I + (1 − cos θ)/θ² ω^ + (θ − sin θ)/θ³ ω^²,
/// θ = ‖ω‖ (series below θ = 1e-5).
pub fn exp(xi: &Vector6<f64>) -> Isometry3<f64> {
    let rho = Vector3::new(xi[0], xi[1], xi[2]);
    let omega = Vector3::new(xi[3], xi[4], xi[5]);
    let theta2 = omega.norm_squared();
    let theta = theta2.sqrt();
    let w = omega.cross_matrix();
    let (a, b) = if theta < 1e-5 {
        (0.5 - theta2 / 24.0, 1.0 / 6.0 - theta2 / 120.0)
    } else {
        (
            (1.0 - theta.cos()) / theta2,
            (theta - theta.sin()) / (theta2 * theta),
        )
    };
    let v = Matrix3::identity() + w * a + w * w * b;
    Isometry3::from_parts(
        Translation3::from(v * rho),
        UnitQuaternion::from_scaled_axis(omega),
    )
}

/// `pose` with its rotation quaternion scaled back to unit norm.
///
/// Products of unit quaternions drift off unit norm by rounding, and nalgebra inverts a unit
/// quaternion by conjugation, which keeps the excess: in the constant-velocity loop
/// (prediction = pose · delta, delta = pose⁻¹ · new pose) the excess then grows geometrically,
/// about ×2.4 a frame, until the rotations scale the scans (on KITTI drive 0005 the yaw ran
/// off from frame 37). Every pose that feeds back is renormalized.
pub fn renormalized(pose: &Isometry3<f64>) -> Isometry3<f64> {
    Isometry3::from_parts(
        pose.translation,
        UnitQuaternion::new_normalize(pose.rotation.into_inner()),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn pure_translation_and_pure_rotation() {
        let t = exp(&Vector6::new(1.0, 2.0, 3.0, 0.0, 0.0, 0.0));
        assert!((t.translation.vector - Vector3::new(1.0, 2.0, 3.0)).norm() < 1e-15);
        // A screw about z through the origin: ρ = 0 leaves the origin fixed.
        let r = exp(&Vector6::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.5));
        assert!(r.translation.vector.norm() < 1e-15);
        assert!((r.rotation.angle() - 0.5).abs() < 1e-12);
    }

    #[test]
    fn the_constant_velocity_loop_keeps_unit_quaternions() {
        // The pipeline's feedback: prediction, a small correction, the new delta.
        let step = exp(&Vector6::new(0.4, 0.01, 0.0, 0.0001, -0.0002, 0.012));
        let fix = exp(&Vector6::new(0.001, 0.0, 0.0, 0.0, 0.0, 0.0003));
        let (mut pose, mut delta) = (Isometry3::identity(), step);
        for _ in 0..500 {
            let predicted = renormalized(&(pose * delta));
            let new = renormalized(&(fix * predicted));
            delta = renormalized(&(pose.inverse() * new));
            pose = new;
        }
        assert!((pose.rotation.into_inner().norm() - 1.0).abs() < 1e-14);
        assert!((delta.rotation.into_inner().norm() - 1.0).abs() < 1e-14);
    }

    proptest! {
        #[test]
        fn exp_of_minus_xi_undoes_exp_of_xi(
            v in prop::array::uniform6(-2.0f64..2.0),
            scale in prop::sample::select(vec![1.0, 1e-3, 1e-7]),
        ) {
            let xi = Vector6::from_column_slice(&v) * scale;
            let id = exp(&xi) * exp(&-xi);
            prop_assert!(id.translation.vector.norm() < 1e-12);
            prop_assert!(id.rotation.angle() < 1e-12);
        }

        #[test]
        fn small_steps_move_points_like_the_linearisation(
            v in prop::array::uniform6(-1.0f64..1.0),
            p in prop::array::uniform3(-10.0f64..10.0),
        ) {
            // p' ≈ p + ρ + ω × p, the model behind the Jacobian [I, −p^].
            let xi = Vector6::from_column_slice(&v) * 1e-6;
            let p = Vector3::from_column_slice(&p);
            let moved = exp(&xi).transform_vector(&p) + exp(&xi).translation.vector;
            let lin = p + xi.fixed_rows::<3>(0) + xi.fixed_rows::<3>(3).cross(&p);
            prop_assert!((moved - lin).norm() < 1e-9);
        }
    }
}
