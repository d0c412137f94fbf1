//! The labelled multi-Bernoulli recursion with particle densities, independent of any sensor.
//!
//! [`LmbFilter::step`] runs one frame: predict → birth → gate → likelihoods → associate →
//! update → resample → prune → estimate. Sensors feed it [`Measurements`]; it never knows
//! where they came from.

pub mod association;
pub mod label;
pub mod particles;

pub use label::Label;
pub use particles::{Jitter, ParticleSet};
