//! The models written for people tracking in planar scans, beside the pipeline that is their
//! only user: occlusion-aware detection against the current scan ([`occlusion`], reading the
//! scan through [`beam_view`]), detection lowered next to tracks the detector cannot resolve
//! ([`resolution`]), misses that come in runs ([`detectability`]), constant velocity with
//! occasional manoeuvres ([`manoeuvring`]), survival that forgets people outside the field of
//! view ([`view_survival`]). Their per-track shortcuts use the particle-cloud bounds of
//! [`crate::models::cloud_bounds`].
//!
//! Not for: the general built-in models (see [`crate::models`]) or the plug-in traits (see
//! [`crate::filter::model`]).

pub mod beam_view;
pub mod detectability;
pub mod manoeuvring;
pub mod occlusion;
pub mod resolution;
pub mod view_survival;

pub use detectability::{Detectability, DetectabilityDetection, DetectabilityTransition};
pub use manoeuvring::ManoeuvringVelocity;
pub use occlusion::{BeamView, OcclusionDetection};
pub use resolution::{Neighbours, ResolutionDetection, ResolutionLikelihood};
pub use view_survival::FieldOfViewSurvival;
