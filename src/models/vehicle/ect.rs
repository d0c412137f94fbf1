//! The extended constant-turn model (Gostar et al. 2019) as a [`VehicleModel`]: its state is
//! the measured kinematics as they are, [X, Ẋ, Y, Ẏ, φ, φ̇].
//!
//! Not for: the model's equations (see [`crate::models::motion::ect`]).

use super::{VehicleModel, VehicleState};
use crate::models::ExtendedConstantTurn;
use crate::rng::FilterRng;
use nalgebra::Isometry3;

fn six(state: &[f64]) -> [f64; 6] {
    [state[0], state[1], state[2], state[3], state[4], state[5]]
}

impl VehicleModel for ExtendedConstantTurn {
    fn state_dim(&self) -> usize {
        6
    }

    fn state_of(&self, measured: &VehicleState) -> Vec<f64> {
        measured.to_array().to_vec()
    }

    fn sample_step(&self, state: &[f64], dt: f64, rng: &mut FilterRng, next: &mut [f64]) {
        next.copy_from_slice(&ExtendedConstantTurn::sample_step(
            self,
            &six(state),
            dt,
            rng,
        ));
    }

    fn mean_step(&self, state: &[f64], dt: f64, next: &mut [f64]) {
        next.copy_from_slice(&ExtendedConstantTurn::step_noiseless(&six(state), dt));
    }

    fn pose_of(&self, state: &[f64]) -> Isometry3<f64> {
        ExtendedConstantTurn::pose_of(&six(state))
    }

    fn sample_poses(
        &self,
        state: &[f64],
        dt: f64,
        rng: &mut FilterRng,
        poses: &mut [Isometry3<f64>],
    ) {
        let s = six(state);
        for p in poses {
            *p = ExtendedConstantTurn::pose_of(&ExtendedConstantTurn::sample_step(
                self, &s, dt, rng,
            ));
        }
    }
}
