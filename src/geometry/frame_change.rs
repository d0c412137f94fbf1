//! How the sensor's frame changes between two steps, and the one way a plane (or a point) is
//! carried into the new frame.
//!
//! Let T_k, T_{k+1} be the sensor's poses (sensor → world) at steps k and k + 1. A point fixed
//! in the world has sensor coordinates p_{k+1} = M p_k with M = T_{k+1}⁻¹ T_k = (R, t). A plane
//! n·p + d = 0 of frame k is, in frame k + 1,
//!
//! ```text
//! n' = R n,    d' = d − n'·t        (homogeneous form: β'ᵀ = βᵀ M⁻¹)
//! ```
//!
//! the plane transition β_{k+1}ᵀ = β_kᵀ R_k⁻¹ R_{k+1} of Gostar et al. (2019) with R_k = T_k.
//! The result is renormalised (n' and d' divided by |n'|) so that rounding never lets |n|
//! drift over many steps.
//!
//! A vehicle model gives the vehicle's (IMU's) poses P_k, P_{k+1}, not the sensor's; with C
//! the vehicle → sensor calibration (p_sensor = C p_vehicle), the sensor's frame changes by
//! M = C (P_{k+1}⁻¹ P_k) C⁻¹ ([`FrameChange::of_vehicle`]). Every place where a plane moves
//! with the ego motion — the filter's plane transition, the Monte-Carlo plane prediction and
//! its metrics, plane patches — goes through [`FrameChange`].
//!
//! Not for: where the poses come from (measured, or drawn from a
//! [`crate::models::vehicle::VehicleModel`]).

use nalgebra::{Isometry3, Matrix3, Point3, Vector3};

/// The change of sensor frame from one step to the next, p' = R p + t.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct FrameChange {
    r: Matrix3<f64>,
    t: Vector3<f64>,
}

impl FrameChange {
    /// No motion.
    pub fn identity() -> Self {
        FrameChange {
            r: Matrix3::identity(),
            t: Vector3::zeros(),
        }
    }

    /// The frame change `m` itself (points map as p' = m p).
    pub fn from_isometry(m: &Isometry3<f64>) -> Self {
        FrameChange {
            r: m.rotation.to_rotation_matrix().into_inner(),
            t: m.translation.vector,
        }
    }

    /// Between two sensor poses (sensor → world): M = T_{k+1}⁻¹ T_k.
    pub fn between(sensor_k: &Isometry3<f64>, sensor_k1: &Isometry3<f64>) -> Self {
        Self::from_isometry(&(sensor_k1.inverse() * sensor_k))
    }

    /// Between two vehicle poses (vehicle → world) of a sensor mounted by `vehicle_to_sensor`
    /// C (p_sensor = C p_vehicle): M = C (P_{k+1}⁻¹ P_k) C⁻¹.
    pub fn of_vehicle(
        vehicle_k: &Isometry3<f64>,
        vehicle_k1: &Isometry3<f64>,
        vehicle_to_sensor: &Isometry3<f64>,
    ) -> Self {
        Self::from_isometry(
            &(vehicle_to_sensor * (vehicle_k1.inverse() * vehicle_k) * vehicle_to_sensor.inverse()),
        )
    }

    /// The rotation R.
    pub fn rotation(&self) -> &Matrix3<f64> {
        &self.r
    }

    /// The translation t.
    pub fn translation(&self) -> &Vector3<f64> {
        &self.t
    }

    /// Whether every entry is finite (a vehicle model's draw may not be).
    pub fn is_finite(&self) -> bool {
        self.r.iter().chain(self.t.iter()).all(|v| v.is_finite())
    }

    /// A plane β = [n, d] (n·p + d = 0) of the old frame in the new one: n' = R n,
    /// d' = d − n'·t, divided by |n'|. A zero normal has no direction to move: it comes out
    /// non-finite. The sign is kept (see [`crate::geometry::plane::canonical`] for the
    /// canonical one).
    #[inline(always)]
    pub fn move_plane(&self, beta: [f64; 4]) -> [f64; 4] {
        let (r, t) = (&self.r, &self.t);
        let [x, y, z, d] = beta;
        let nx = r[(0, 0)] * x + r[(0, 1)] * y + r[(0, 2)] * z;
        let ny = r[(1, 0)] * x + r[(1, 1)] * y + r[(1, 2)] * z;
        let nz = r[(2, 0)] * x + r[(2, 1)] * y + r[(2, 2)] * z;
        let nd = d - (nx * t.x + ny * t.y + nz * t.z);
        let inv = 1.0 / (nx * nx + ny * ny + nz * nz).sqrt();
        [nx * inv, ny * inv, nz * inv, nd * inv]
    }

    /// Moves the planes of structure-of-arrays columns (normal x, y, z and offset, of equal
    /// length) in place, without allocating: the hot loop of the plane transition.
    pub fn move_planes(&self, nx: &mut [f64], ny: &mut [f64], nz: &mut [f64], d: &mut [f64]) {
        let n = nx.len();
        let (ny, nz, d) = (&mut ny[..n], &mut nz[..n], &mut d[..n]);
        for i in 0..n {
            let b = self.move_plane([nx[i], ny[i], nz[i], d[i]]);
            nx[i] = b[0];
            ny[i] = b[1];
            nz[i] = b[2];
            d[i] = b[3];
        }
    }

    /// A point of the old frame in the new one: R p + t.
    pub fn move_point(&self, p: &Point3<f64>) -> Point3<f64> {
        Point3::from(self.r * p.coords + self.t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

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

    proptest! {
        /// The moved point lies on the moved plane, for sensor poses and for vehicle poses
        /// with a mounting; the normal stays unit; the conjugated change equals the change
        /// between the sensor poses P C⁻¹ it implies.
        #[test]
        fn moved_points_lie_on_moved_planes(
            t0 in prop::array::uniform3(-50.0f64..50.0), r0 in prop::array::uniform3(-3.0f64..3.0),
            t1 in prop::array::uniform3(-50.0f64..50.0), r1 in prop::array::uniform3(-3.0f64..3.0),
            tc in prop::array::uniform3(-2.0f64..2.0), rc in prop::array::uniform3(-0.5f64..0.5),
            nv in prop::array::uniform3(-1.0f64..1.0), d in -30.0f64..30.0,
            u in -20.0f64..20.0, v in -20.0f64..20.0,
        ) {
            prop_assume!(Vector3::from(nv).norm() > 0.1);
            let beta = unit_plane(nv, d);
            let (p0, p1, c) = (pose(t0, r0), pose(t1, r1), pose(tc, rc));
            for m in [FrameChange::between(&p0, &p1), FrameChange::of_vehicle(&p0, &p1, &c)] {
                let q = m.move_point(&point_on(&beta, u, v));
                let b = m.move_plane(beta);
                let resid = b[0] * q.x + b[1] * q.y + b[2] * q.z + b[3];
                prop_assert!(resid.abs() < 1e-9, "residual {resid}");
                let n = (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]).sqrt();
                prop_assert!((n - 1.0).abs() < 1e-12);
            }
            // sensor poses are vehicle poses times C⁻¹
            let (s0, s1) = (p0 * c.inverse(), p1 * c.inverse());
            let a = FrameChange::of_vehicle(&p0, &p1, &c).move_plane(beta);
            let b = FrameChange::between(&s0, &s1).move_plane(beta);
            for (x, y) in a.iter().zip(b) {
                prop_assert!((x - y).abs() < 1e-9, "{a:?} vs {b:?}");
            }
        }

        #[test]
        fn two_steps_compose(
            t0 in prop::array::uniform3(-20.0f64..20.0), r0 in prop::array::uniform3(-3.0f64..3.0),
            t1 in prop::array::uniform3(-20.0f64..20.0), r1 in prop::array::uniform3(-3.0f64..3.0),
            t2 in prop::array::uniform3(-20.0f64..20.0), r2 in prop::array::uniform3(-3.0f64..3.0),
            nv in prop::array::uniform3(-1.0f64..1.0), d in -30.0f64..30.0,
        ) {
            prop_assume!(Vector3::from(nv).norm() > 0.1);
            let beta = unit_plane(nv, d);
            let (p0, p1, p2) = (pose(t0, r0), pose(t1, r1), pose(t2, r2));
            let two = FrameChange::between(&p1, &p2)
                .move_plane(FrameChange::between(&p0, &p1).move_plane(beta));
            let direct = FrameChange::between(&p0, &p2).move_plane(beta);
            for (a, b) in two.iter().zip(direct) {
                prop_assert!((a - b).abs() < 1e-9, "{two:?} vs {direct:?}");
            }
        }
    }

    #[test]
    fn forward_motion_brings_a_wall_closer_and_a_zero_normal_is_not_finite() {
        // wall x = 10 seen with n = (−1, 0, 0), d = 10; the sensor moves 1 m forward
        let m = FrameChange::between(
            &Isometry3::identity(),
            &Isometry3::translation(1.0, 0.0, 0.0),
        );
        assert_eq!(m.move_plane([-1.0, 0.0, 0.0, 10.0]), [-1.0, 0.0, 0.0, 9.0]);
        assert!(m
            .move_plane([0.0, 0.0, 0.0, 5.0])
            .iter()
            .all(|v| !v.is_finite()));
        let (mut x, mut y, mut z, mut d) = (vec![-1.0], vec![0.0], vec![0.0], vec![10.0]);
        m.move_planes(&mut x, &mut y, &mut z, &mut d);
        assert_eq!([x[0], y[0], z[0], d[0]], [-1.0, 0.0, 0.0, 9.0]);
        assert!(FrameChange::identity().is_finite());
    }
}
