//! Scenario generators with ground truth, for tests, examples and benchmarks.
//!
//! [`rfs_benchmark`] holds the two standard random-finite-set scenarios (a linear one with
//! constant-velocity targets and position measurements, a nonlinear one with coordinated-turn
//! targets and range-bearing measurements) as plain data, a seeded generator of noiseless
//! truth and noisy, cluttered measurements, and the matching filter-side models.
//!
//! Not for: reading recorded data sets or scoring estimates (see [`crate::metrics`]).

pub mod rfs_benchmark;

pub use rfs_benchmark::{
    ClutterSpec, DetectionSpec, DynamicsSpec, Scenario, ScenarioModels, SensorSpec, SimRun,
    TargetSpec, Truth,
};
