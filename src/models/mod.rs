//! The built-in models, grouped by the role they play in the filter:
//!
//! * [`motion`]: transition models — constant velocity, coordinated turn, extended constant
//!   turn (vehicle).
//! * [`measurement`]: likelihoods — position, range-bearing.
//! * [`detection`]: detection probabilities — constant, Gaussian fall-off, field of view.
//! * [`clutter`]: clutter intensities — uniform.
//! * [`cloud_bounds`]: a particle cloud's box and polar bounds, for per-track shortcuts that
//!   equal the per-particle answer (field of view here, occlusion and resolution in people
//!   tracking).
//! * [`vehicle`]: the ego vehicle's motion ([`VehicleModel`]): extended constant turn,
//!   coordinated turn, kinematic bicycle, or a user's own.
//! * [`plane`]: planar landmarks (walls) as objects: their transition, driven by the ego
//!   motion, and their measurement. One file because both sides share the plane's state
//!   convention and its helpers.
//!
//! Every model here implements one of the filter's plug-in traits ([`crate::filter::model`]);
//! the traits, [`crate::filter::StepContext`] and the default survival
//! ([`crate::filter::ConstantSurvival`]) live with the filter. The built-in models read the
//! position from components 0, 2 (and 4) of the state, see [`crate::filter::model`].
//!
//! Not for: the plug-in traits, or models written for one application: the mixed wall/cluster
//! models of drive tracking live in [`crate::pipeline::drive_tracking`], the people models
//! (occlusion, resolution, detectability, manoeuvring, view-dependent survival) in
//! [`crate::pipeline::people_tracking`].

pub mod cloud_bounds;
pub mod clutter;
pub mod detection;
pub mod measurement;
pub mod motion;
pub mod plane;
pub mod vehicle;

pub use cloud_bounds::{CloudBox, PolarBounds};
pub use clutter::UniformClutter;
pub use detection::{ConstantDetection, FieldOfViewDetection, GaussianRangeDetection};
pub use measurement::{BearingConvention, PositionMeasurement, RangeBearing};
pub use motion::{ConstantVelocity, CoordinatedTurn, ExtendedConstantTurn};
pub use plane::{EgoSource, PlaneMeasurement, PlaneTransition};
pub use vehicle::{
    vehicle_model_by_name, CoordinatedTurnVehicle, KinematicBicycle, SharedVehicleModel,
    VehicleModel, VehicleState,
};
