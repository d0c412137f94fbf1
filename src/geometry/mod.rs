//! Geometric primitives shared by detectors, transition models and metrics: infinite planes
//! in Hessian normal form and bounded rectangular plane patches.
//!
//! Not for: finding planes in point clouds (see [`crate::cloud::planes`]) or moving planes
//! with a vehicle model (see [`crate::models`]).

pub mod plane;

pub use plane::{Plane, PlanePatch};
