//! The kinematic bicycle as a vehicle model: state [X, Y, ψ, v, δ] — the rear axle's
//! position, the heading, the speed and the front wheel's steering angle, on a wheelbase L.
//!
//! At constant speed and steering angle the vehicle turns at ω = v tan δ / L and drives an
//! arc, integrated exactly as the coordinated turn's ([`crate::models::CoordinatedTurn::coefficients`]).
//! Noise: a white longitudinal acceleration σ_a (speed + σ_a T e₁, position + σ_a T²/2 e₁
//! along the heading) and a white steering rate σ_δ (δ + σ_δ T e₂), which turns the vehicle
//! from the next step on. Steering is what a car does, so its heading changes only as fast as
//! its speed and wheelbase allow: a parked car does not turn on the spot.
//!
//! Not for: tyre slip or dynamics (it is kinematic), tracked objects.

use super::{accelerate, arc, planar_pose, VehicleModel, VehicleState};
use crate::error::{ensure_non_negative, ensure_positive, Result};
use crate::rng::FilterRng;
use nalgebra::Isometry3;
use rand_distr::{Distribution, StandardNormal};

/// Below this speed (m/s) the steering angle of measured kinematics is taken as 0: the yaw
/// rate of a car that barely moves says nothing about its wheels.
const MIN_STEER_SPEED: f64 = 0.5;

/// The largest steering angle (rad) a state of measured kinematics is given (about 35°).
const MAX_STEER: f64 = 0.6;

/// Kinematic bicycle, state [X, Y, ψ, v, δ].
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct KinematicBicycle {
    wheelbase: f64,
    sigma_accel: f64,
    sigma_steer_rate: f64,
}

impl KinematicBicycle {
    /// A bicycle with wheelbase `wheelbase` (m, > 0), longitudinal acceleration noise
    /// `sigma_accel` (m/s², ≥ 0) and steering-rate noise `sigma_steer_rate` (rad/s, ≥ 0).
    pub fn new(wheelbase: f64, sigma_accel: f64, sigma_steer_rate: f64) -> Result<Self> {
        ensure_positive("kinematic bicycle wheelbase", wheelbase)?;
        ensure_non_negative("kinematic bicycle sigma_accel", sigma_accel)?;
        ensure_non_negative("kinematic bicycle sigma_steer_rate", sigma_steer_rate)?;
        Ok(KinematicBicycle {
            wheelbase,
            sigma_accel,
            sigma_steer_rate,
        })
    }

    /// The wheelbase, metres.
    pub fn wheelbase(&self) -> f64 {
        self.wheelbase
    }

    /// The arc of a step at constant speed and steering angle.
    fn step(&self, state: &[f64], dt: f64, next: &mut [f64]) {
        let (v, delta) = (state[3], state[4]);
        let w = v * delta.tan() / self.wheelbase;
        let (x, y, psi) = arc(state[0], state[1], state[2], v, w, dt);
        next.copy_from_slice(&[x, y, psi, v, delta]);
    }
}

impl VehicleModel for KinematicBicycle {
    fn state_dim(&self) -> usize {
        5
    }

    fn state_of(&self, m: &VehicleState) -> Vec<f64> {
        let (s, c) = m.heading.sin_cos();
        let v = m.vx * c + m.vy * s;
        let delta = if v.abs() < MIN_STEER_SPEED {
            0.0
        } else {
            (m.yaw_rate * self.wheelbase / v)
                .atan()
                .clamp(-MAX_STEER, MAX_STEER)
        };
        vec![m.x, m.y, m.heading, v, delta]
    }

    fn sample_step(&self, state: &[f64], dt: f64, rng: &mut FilterRng, next: &mut [f64]) {
        self.step(state, dt, next);
        accelerate(self.sigma_accel, state[2], dt, rng, next);
        if self.sigma_steer_rate > 0.0 {
            let e: f64 = StandardNormal.sample(rng);
            next[4] += self.sigma_steer_rate * dt * e;
        }
    }

    fn mean_step(&self, state: &[f64], dt: f64, next: &mut [f64]) {
        self.step(state, dt, next);
    }

    fn pose_of(&self, state: &[f64]) -> Isometry3<f64> {
        planar_pose(state)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn turns_on_the_circle_its_wheelbase_and_steering_give() {
        // L = 2.5 m, δ = 0.3 rad: radius L / tan δ; after a quarter of the circle's length the
        // heading has turned by π/2 and the rear axle is (R, R) from where it started.
        let m = KinematicBicycle::new(2.5, 0.0, 0.0).unwrap();
        let r = 2.5 / 0.3f64.tan();
        let v = 2.0;
        let t = std::f64::consts::FRAC_PI_2 * r / v;
        let mut next = [0.0; 5];
        m.mean_step(&[0.0, 0.0, 0.0, v, 0.3], t, &mut next);
        assert!(
            (next[0] - r).abs() < 1e-9 && (next[1] - r).abs() < 1e-9,
            "{next:?}"
        );
        assert!((next[2] - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    }

    #[test]
    fn measured_yaw_rate_becomes_a_steering_angle() {
        let m = KinematicBicycle::new(2.5, 0.0, 0.0).unwrap();
        let measured = VehicleState {
            vx: 5.0,
            yaw_rate: 0.2,
            ..VehicleState::default()
        };
        let s = m.state_of(&measured);
        // ω = v tan δ / L gives back the measured yaw rate
        assert!((5.0 * s[4].tan() / 2.5 - 0.2).abs() < 1e-12, "{s:?}");
        // standing still: no steering from the yaw rate
        let still = VehicleState {
            yaw_rate: 0.2,
            ..VehicleState::default()
        };
        assert_eq!(m.state_of(&still)[4], 0.0);
        assert!(KinematicBicycle::new(0.0, 0.1, 0.1).is_err());
    }
}
