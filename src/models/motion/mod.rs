//! How objects move: transition models f(x' | x) that move a whole particle set one step.
//!
//! * [`cv`]: constant velocity in two or three dimensions (the linear benchmark's dynamics).
//! * [`ct`]: the planar coordinated turn with an unknown turn rate (the nonlinear benchmark).
//! * [`ect`]: the extended constant turn of a ground vehicle (seed 001, eq. 36), whose pose
//!   drives the plane transition of [`super::plane`].
//!
//! Not for: the transition trait itself (see [`crate::filter::TransitionModel`]) or the motion
//! of planes seen from a moving vehicle (see [`super::plane`]).

pub mod ct;
pub mod cv;
pub mod ect;

pub use ct::CoordinatedTurn;
pub use cv::ConstantVelocity;
pub use ect::ExtendedConstantTurn;
