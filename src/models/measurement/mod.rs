//! How objects are seen: single-object likelihoods g(z | x) with their gates.
//!
//! * [`position`]: a noisy position in two or three dimensions.
//! * [`range_bearing`]: range and bearing from a sensor mounted on a moving platform.
//!
//! Not for: the measurement trait itself (see [`crate::filter::MeasurementModel`]) or the
//! measurement of planes (see [`super::plane`]).

pub mod position;
pub mod range_bearing;

pub use position::PositionMeasurement;
pub use range_bearing::{BearingConvention, RangeBearing};
