//! The measured planar kinematics of the ego vehicle that vehicle models start from.
//!
//! Not for: a model's own state (each [`super::VehicleModel`] has its layout).

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

/// Measured planar kinematics of the vehicle (the OXTS unit), in the order of the extended
/// constant-turn state [X, Ẋ, Y, Ẏ, φ, φ̇]; every [`super::VehicleModel`] builds its own state
/// from it ([`super::VehicleModel::state_of`]).
///
/// As KITTI's OXTS packets give it (`crate::kitti::vehicle_states`): the planar frame ("levelled first frame") has its origin at the first packet's position, its
/// x axis along the first packet's heading projected on the horizontal, and z up; roll and pitch
/// are ignored. Per packet k:
/// - X, Y: the projected (Mercator) position minus the first one, rotated by −yaw₀;
/// - φ: yaw_k − yaw₀, unwrapped along the drive (continuous, may leave (−π, π]);
/// - Ẋ, Ẏ: the east/north velocities (`ve`, `vn`) rotated by −yaw₀ — the measured ground
///   velocity, side slip included. The alternative, (`vf`, `vl`) turned by the heading, has the
///   same magnitude but not quite the same direction: on drive 2011_09_26_0001 the (`ve`, `vn`)
///   direction stays within 0.42° of the track of the projected positions, while heading +
///   atan(vl/vf) is off by up to 1.3°, so (`ve`, `vn`) is the one consistent with X and Y;
/// - φ̇: `wu`, the angular rate about the upward axis of the earth-levelled frame, which is the
///   rate of change of heading (`wz` is about the body's z axis and differs by roll/pitch).
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct VehicleState {
    /// X position, metres.
    pub x: f64,
    /// Ẋ, m/s.
    pub vx: f64,
    /// Y position, metres.
    pub y: f64,
    /// Ẏ, m/s.
    pub vy: f64,
    /// Heading φ, rad.
    pub heading: f64,
    /// Heading rate φ̇, rad/s.
    pub yaw_rate: f64,
}

impl VehicleState {
    /// The state as [X, Ẋ, Y, Ẏ, φ, φ̇].
    pub fn to_array(&self) -> [f64; 6] {
        [
            self.x,
            self.vx,
            self.y,
            self.vy,
            self.heading,
            self.yaw_rate,
        ]
    }

    /// Speed over ground √(Ẋ² + Ẏ²), m/s.
    pub fn speed(&self) -> f64 {
        self.vx.hypot(self.vy)
    }

    /// The planar pose: rotation φ about z, translation (X, Y, 0).
    pub fn planar_pose(&self) -> Isometry3<f64> {
        Isometry3::from_parts(
            Translation3::new(self.x, self.y, 0.0),
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), self.heading),
        )
    }
}
