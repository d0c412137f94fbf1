//! The labelled multi-Bernoulli recursion with particle densities, independent of any sensor.
//!
//! [`LmbFilter::step`] runs one frame: predict → birth → gate → likelihoods → associate →
//! update → resample → prune → estimate. Sensors feed it [`Measurements`] in a [`Frame`]; it
//! never knows where they came from. Tracks ([`Track`]) carry a [`Label`], an existence
//! probability and a [`ParticleSet`].

pub mod association;
pub mod birth;
pub mod estimate;
pub mod groups;
pub mod label;
pub mod lmb;
pub mod measurements;
pub mod particles;
pub mod track;

pub use association::{AssociationMethod, Associator};
pub use birth::{
    AdaptiveBirth, BirthModel, BirthSampler, BirthTerm, BirthTrack, PositionBirthSampler,
    StaticBirth,
};
pub use label::Label;
pub use lmb::{Frame, LmbConfig, LmbFilter, LmbFilterBuilder, MostProbableMeasurement};
pub use measurements::Measurements;
pub use particles::{Jitter, ParticleSet};
pub use track::{Estimate, Track};
