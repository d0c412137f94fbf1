//! The ego vehicle's motion as a plug-in: how the vehicle that carries the sensor moves between
//! two frames ([`VehicleModel`]), and the measured planar kinematics a model starts from
//! ([`VehicleState`], e.g. from OXTS).
//!
//! A vehicle model has a state vector of its own layout. It tells its length, draws the next
//! state over a step, gives the noise-free (mean) step and the vehicle's pose for a state, and
//! builds its state from measured kinematics. That is all the plane transition of the filter
//! ([`crate::models::PlaneTransition`] with [`crate::models::plane::EgoSource::Predicted`])
//! and the Monte-Carlo plane prediction of Gostar et al. (2019, Algorithm 1;
//! `pipeline::plane_prediction`) need: both draw vehicle poses from a model and move planes
//! with the frame change they imply ([`crate::geometry::FrameChange::of_vehicle`], the vehicle
//! → sensor calibration included).
//!
//! Built in: [`ExtendedConstantTurn`] (the paper's model, the default), [`CoordinatedTurnVehicle`]
//! (the same turn without the heading in the state: the vehicle points along its velocity) and
//! [`KinematicBicycle`] (speed, heading and steering angle on a wheelbase). A user's type
//! implements the trait in a few lines (see `examples/own_vehicle_model.rs`); a model chosen at
//! run time is an `Arc<dyn VehicleModel>`, and [`vehicle_model_by_name`] builds a built-in one
//! from a name and parameters, as configuration files and the command line name them.
//!
//! Not for: the motion of tracked objects (that is [`crate::filter::TransitionModel`]), or
//! moving planes (that is [`crate::geometry::FrameChange`]).

mod bicycle;
mod ct;
mod ect;
mod state;

pub use bicycle::KinematicBicycle;
pub use ct::CoordinatedTurnVehicle;
pub use state::VehicleState;

use crate::error::{Error, Result};
use crate::filter::model_name;
use crate::models::ExtendedConstantTurn;
use crate::rng::FilterRng;
use nalgebra::Isometry3;
use std::sync::Arc;

/// How the ego vehicle moves: a state of [`VehicleModel::state_dim`] components (any layout the
/// model chooses), a random step, its mean, and the vehicle's pose.
///
/// The slices handed to the methods have exactly [`VehicleModel::state_dim`] components; the
/// library checks a state once ([`check_vehicle_state`]) before it draws from it, so a model
/// may index them freely. Methods that draw many poses at once work on a whole batch, so a
/// boxed model is dispatched once per particle set, not once per particle.
pub trait VehicleModel: Send + Sync {
    /// Length of the state vector.
    fn state_dim(&self) -> usize;

    /// The model's state for measured planar kinematics (position, velocity, heading, yaw
    /// rate in the levelled frame of the first frame; see [`VehicleState`]).
    fn state_of(&self, measured: &VehicleState) -> Vec<f64>;

    /// Writes a draw of the state after `dt` seconds into `next`.
    fn sample_step(&self, state: &[f64], dt: f64, rng: &mut FilterRng, next: &mut [f64]);

    /// Writes the noise-free (mean) step over `dt` seconds into `next`.
    fn mean_step(&self, state: &[f64], dt: f64, next: &mut [f64]);

    /// The vehicle's pose of a state: vehicle frame → world frame.
    fn pose_of(&self, state: &[f64]) -> Isometry3<f64>;

    /// The model's name in errors and reports; the type's name by default.
    fn name(&self) -> String {
        model_name::<Self>()
    }

    /// Draws `poses.len()` independent next states from `state` over `dt` and writes their
    /// poses, in order (one [`VehicleModel::sample_step`] each, with `rng` in turn).
    fn sample_poses(
        &self,
        state: &[f64],
        dt: f64,
        rng: &mut FilterRng,
        poses: &mut [Isometry3<f64>],
    ) {
        let mut next = vec![0.0; self.state_dim()];
        for p in poses {
            self.sample_step(state, dt, rng, &mut next);
            *p = self.pose_of(&next);
        }
    }
}

impl std::fmt::Debug for dyn VehicleModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.name())
    }
}

impl<T: VehicleModel + ?Sized> VehicleModel for Arc<T> {
    fn state_dim(&self) -> usize {
        (**self).state_dim()
    }
    fn state_of(&self, measured: &VehicleState) -> Vec<f64> {
        (**self).state_of(measured)
    }
    fn sample_step(&self, state: &[f64], dt: f64, rng: &mut FilterRng, next: &mut [f64]) {
        (**self).sample_step(state, dt, rng, next)
    }
    fn mean_step(&self, state: &[f64], dt: f64, next: &mut [f64]) {
        (**self).mean_step(state, dt, next)
    }
    fn pose_of(&self, state: &[f64]) -> Isometry3<f64> {
        (**self).pose_of(state)
    }
    fn name(&self) -> String {
        (**self).name()
    }
    fn sample_poses(
        &self,
        state: &[f64],
        dt: f64,
        rng: &mut FilterRng,
        poses: &mut [Isometry3<f64>],
    ) {
        (**self).sample_poses(state, dt, rng, poses)
    }
}

/// The arc a vehicle at (`x`, `y`) with heading `heading` drives in `dt` seconds at speed `v`
/// along its heading and turn rate `w`: the new (x, y, heading). Written with the coordinated
/// turn's well-conditioned coefficients ([`crate::models::CoordinatedTurn::coefficients`]), so
/// a small `w` needs no division by it.
fn arc(x: f64, y: f64, heading: f64, v: f64, w: f64, dt: f64) -> (f64, f64, f64) {
    let (a, b, _, _) = crate::models::CoordinatedTurn::coefficients(w, dt);
    let (s, c) = heading.sin_cos();
    let (vx, vy) = (v * c, v * s);
    (x + a * vx - b * vy, y + b * vx + a * vy, heading + w * dt)
}

/// A white longitudinal acceleration of `sigma` over `dt` on a state [X, Y, heading, v, …]:
/// speed + σ T e, position + σ T²/2 e along `heading` (the heading at the start of the step).
fn accelerate(sigma: f64, heading: f64, dt: f64, rng: &mut FilterRng, next: &mut [f64]) {
    if sigma > 0.0 {
        use rand_distr::{Distribution, StandardNormal};
        let e: f64 = StandardNormal.sample(rng);
        let (s, c) = heading.sin_cos();
        let half = 0.5 * dt * dt;
        next[0] += sigma * half * e * c;
        next[1] += sigma * half * e * s;
        next[3] += sigma * dt * e;
    }
}

/// The planar pose of a state [X, Y, heading, …].
fn planar_pose(state: &[f64]) -> Isometry3<f64> {
    Isometry3::new(
        nalgebra::Vector3::new(state[0], state[1], 0.0),
        nalgebra::Vector3::new(0.0, 0.0, state[2]),
    )
}

/// A vehicle model held by a configuration: shared, compared by identity, shown by name.
#[derive(Clone)]
pub struct SharedVehicleModel(pub Arc<dyn VehicleModel>);

impl SharedVehicleModel {
    /// Shares `model`.
    pub fn new(model: impl VehicleModel + 'static) -> Self {
        SharedVehicleModel(Arc::new(model))
    }
}

impl std::ops::Deref for SharedVehicleModel {
    type Target = dyn VehicleModel;
    fn deref(&self) -> &Self::Target {
        &*self.0
    }
}

impl std::fmt::Debug for SharedVehicleModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.0.name())
    }
}

impl PartialEq for SharedVehicleModel {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

/// Checks a vehicle state for `model`: exactly [`VehicleModel::state_dim`] components, all
/// finite. The error names the model and what is wrong.
pub fn check_vehicle_state(model: &dyn VehicleModel, state: &[f64]) -> Result<()> {
    let what = || format!("vehicle state of {}", model.name());
    if state.len() != model.state_dim() {
        return Err(Error::invalid(
            what(),
            format!(
                "{} components, but the model's states have {}",
                state.len(),
                model.state_dim()
            ),
        ));
    }
    if let Some(c) = state.iter().position(|v| !v.is_finite()) {
        return Err(Error::invalid(
            what(),
            format!("component {c} is {} (must be finite)", state[c]),
        ));
    }
    Ok(())
}

/// A built-in vehicle model by name, as configuration files and the command line write it:
/// `ect` (default parameters `sigma_accel` 0.5 m/s², `sigma_turn_accel` 0.1 rad/s²), `ct`
/// (the same two) or `bicycle` (`wheelbase` 2.7 m, `sigma_accel` 0.5 m/s², `sigma_steer_rate`
/// 0.05 rad/s). `params` sets any of the named model's parameters; an unknown name or
/// parameter is an error naming it and the ones there are.
pub fn vehicle_model_by_name(
    name: &str,
    params: &[(String, f64)],
) -> Result<Arc<dyn VehicleModel>> {
    let known: &[(&str, &[(&str, f64)])] = &[
        ("ect", &[("sigma_accel", 0.5), ("sigma_turn_accel", 0.1)]),
        ("ct", &[("sigma_accel", 0.5), ("sigma_turn_accel", 0.1)]),
        (
            "bicycle",
            &[
                ("wheelbase", 2.7),
                ("sigma_accel", 0.5),
                ("sigma_steer_rate", 0.05),
            ],
        ),
    ];
    let Some((_, defaults)) = known.iter().find(|(n, _)| *n == name) else {
        let names: Vec<&str> = known.iter().map(|(n, _)| *n).collect();
        return Err(Error::invalid(
            "vehicle model",
            format!("unknown name {name:?} (built in: {})", names.join(", ")),
        ));
    };
    let mut values: Vec<f64> = defaults.iter().map(|(_, v)| *v).collect();
    for (key, value) in params {
        let Some(i) = defaults.iter().position(|(k, _)| k == key) else {
            let names: Vec<&str> = defaults.iter().map(|(k, _)| *k).collect();
            return Err(Error::invalid(
                format!("vehicle model {name}"),
                format!("unknown parameter {key:?} (it has {})", names.join(", ")),
            ));
        };
        values[i] = *value;
    }
    Ok(match name {
        "ect" => Arc::new(ExtendedConstantTurn::new(values[0], values[1])?),
        "ct" => Arc::new(CoordinatedTurnVehicle::new(values[0], values[1])?),
        _ => Arc::new(KinematicBicycle::new(values[0], values[1], values[2])?),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::seeded;

    #[test]
    fn names_build_models_and_unknown_ones_are_errors() {
        let ect = vehicle_model_by_name("ect", &[]).unwrap();
        assert_eq!(ect.name(), "ExtendedConstantTurn");
        assert_eq!(ect.state_dim(), 6);
        let b = vehicle_model_by_name("bicycle", &[("wheelbase".into(), 3.0)]).unwrap();
        assert_eq!(b.name(), "KinematicBicycle");
        assert_eq!(vehicle_model_by_name("ct", &[]).unwrap().state_dim(), 5);
        let e = vehicle_model_by_name("unicycle", &[])
            .unwrap_err()
            .to_string();
        assert!(e.contains("unicycle") && e.contains("bicycle"), "{e}");
        let e = vehicle_model_by_name("ect", &[("wheelbase".into(), 3.0)])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("wheelbase") && e.contains("sigma_turn_accel"),
            "{e}"
        );
        assert!(vehicle_model_by_name("bicycle", &[("wheelbase".into(), -1.0)]).is_err());
    }

    #[test]
    fn a_state_of_the_wrong_length_or_not_finite_is_refused() {
        let m = ExtendedConstantTurn::new(0.5, 0.1).unwrap();
        let e = check_vehicle_state(&m, &[0.0; 4]).unwrap_err().to_string();
        assert!(
            e.contains("ExtendedConstantTurn") && e.contains("4 components"),
            "{e}"
        );
        let e = check_vehicle_state(&m, &[0.0, 1.0, f64::NAN, 0.0, 0.0, 0.0])
            .unwrap_err()
            .to_string();
        assert!(e.contains("component 2"), "{e}");
        check_vehicle_state(&m, &[0.0; 6]).unwrap();
    }

    /// Every built-in model: its state of measured kinematics has its length, reproduces the
    /// measured pose, and its draws scatter about the mean step (noise-free models equal it).
    #[test]
    fn built_in_models_keep_their_contract() {
        let measured = VehicleState {
            x: 3.0,
            vx: 4.0,
            y: -2.0,
            vy: 3.0,
            heading: 3f64.atan2(4.0),
            yaw_rate: 0.2,
        };
        for name in ["ect", "ct", "bicycle"] {
            let m = vehicle_model_by_name(name, &[]).unwrap();
            let s = m.state_of(&measured);
            assert_eq!(s.len(), m.state_dim(), "{name}");
            let p = m.pose_of(&s);
            let (_, _, yaw) = p.rotation.euler_angles();
            assert!((p.translation.vector.x - 3.0).abs() < 1e-12, "{name}");
            assert!((p.translation.vector.y + 2.0).abs() < 1e-12, "{name}");
            assert!((yaw - measured.heading).abs() < 1e-12, "{name}: {yaw}");
            let mut mean = vec![0.0; s.len()];
            m.mean_step(&s, 0.1, &mut mean);
            let mean_pose = m.pose_of(&mean);
            // 5 m/s along the heading for 0.1 s: about 0.5 m
            let moved = (mean_pose.translation.vector - p.translation.vector).norm();
            assert!((moved - 0.5).abs() < 0.01, "{name}: {moved}");
            let mut rng = seeded(7);
            let mut poses = vec![Isometry3::identity(); 4000];
            m.sample_poses(&s, 0.1, &mut rng, &mut poses);
            let n = poses.len() as f64;
            let cx = poses.iter().map(|q| q.translation.vector.x).sum::<f64>() / n;
            let cy = poses.iter().map(|q| q.translation.vector.y).sum::<f64>() / n;
            let spread = poses
                .iter()
                .map(|q| (q.translation.vector.x - cx).powi(2))
                .sum::<f64>()
                / n;
            assert!(spread > 0.0, "{name}: draws do not scatter");
            assert!(
                (cx - mean_pose.translation.vector.x).abs() < 2e-3
                    && (cy - mean_pose.translation.vector.y).abs() < 2e-3,
                "{name}: mean of draws ({cx}, {cy}) vs {:?}",
                mean_pose.translation.vector
            );
        }
    }
}
