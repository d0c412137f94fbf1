//! The labelled multi-Bernoulli recursion with particle densities, independent of any sensor.
//!
//! [`LmbFilter::step`] runs one frame: predict → birth → gate → likelihoods → associate →
//! update → resample → prune → estimate. Sensors feed it [`Measurements`] in a [`Frame`]; it
//! never knows where they came from. Tracks ([`Track`]) carry a [`Label`], an existence
//! probability and a [`ParticleSet`].
//!
//! A filter may have several [`Sensor`]s, each with its own measurement, detection and clutter
//! models; a frame carries a [`Scan`] of any of them, and [`Fusion`] says how their updates
//! combine ([`fusion`]).
//!
//! The filter's contract with its models lives here too: the plug-in traits of [`model`]
//! ([`TransitionModel`], [`SurvivalModel`], [`MeasurementModel`], [`DetectionModel`],
//! [`ClutterModel`]), [`BirthModel`], [`Associator`] and the duplicate merge's
//! [`MergeDistance`]. The built-in models implementing them are in [`crate::models`] (and next
//! to the applications that need their own).
//!
//! Not for: sensor hardware, detectors or models of particular objects.

pub mod association;
pub mod birth;
pub mod estimate;
pub mod fusion;
pub mod groups;
pub mod label;
pub mod lmb;
pub mod measurements;
pub mod merge;
pub mod model;
pub mod particles;
pub mod sensor;
pub mod smoothing;
pub mod step_data;
pub mod survival;
pub mod track;
mod update;

pub use association::{AssociationMethod, Associator};
pub use birth::{
    AdaptiveBirth, BirthModel, BirthProposal, BirthSampler, BirthTerm, BirthTrack,
    CurrentMeasurements, PositionBirthSampler, StaticBirth,
};
pub use fusion::{Fusion, FusionMethod};
pub use label::Label;
pub use lmb::{
    Frame, LmbConfig, LmbFilter, LmbFilterBuilder, MostProbableMeasurement, MAX_PARTICLES,
    MAX_SMOOTHING_LAG, MAX_TRACKS,
};
pub use measurements::Measurements;
pub use merge::{MergeDistance, ScaledDistance};
pub use model::{
    check_state_dim, model_name, relative_from_logs, ClutterModel, DetectionModel, LikelihoodFault,
    MeasurementModel, SharedTransitionModel, StepContext, SurvivalModel, TrackSummary,
    TransitionModel,
};
pub use particles::{Jitter, ParticleSet};
pub use sensor::{Mounting, Scan, Sensor, DEFAULT_SENSOR};
pub use smoothing::FixedLagSmoother;
pub use step_data::StepData;
pub use survival::ConstantSurvival;
pub use track::{Estimate, Track};
