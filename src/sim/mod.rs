//! Scenario generators with ground truth, for tests, examples and benchmarks.
//!
//! [`rfs_benchmark`] holds the two standard random-finite-set scenarios (a linear one with
//! constant-velocity targets and position measurements, a nonlinear one with coordinated-turn
//! targets and range-bearing measurements) as plain data, a seeded generator of noiseless
//! truth and noisy, cluttered measurements, and the matching filter-side models.
//!
//! [`people2d`] simulates walking people (discs) seen by a planar laser scanner on a moving
//! robot, in the two scenarios of the ML-RANSAC paper, with exact ray casting, noisy
//! odometry and per-scan ground truth and visibility; [`people2d::lasers`] puts several lasers
//! on the robot, each at its own mounting pose, field of view and rate.
//!
//! [`street`] simulates a KITTI-style street drive (HDL-64E-like lidar, OXTS) with walls, cars
//! and pedestrians, written in the KITTI raw layout with a ground-truth file.
//!
//! Not for: reading recorded data sets or scoring estimates (see [`crate::metrics`]).

#[cfg(feature = "laser2d")]
pub mod people2d;
pub mod rfs_benchmark;
#[cfg(feature = "kitti")]
pub mod street;

#[cfg(feature = "laser2d")]
pub use people2d::{
    OdometryNoise, People2dRun, PeopleScenario, PersonLeg, PersonSpec, RobotLeg, RobotSpec,
    ScannerSpec,
};
pub use rfs_benchmark::{
    ClutterSpec, DetectionSpec, DynamicsSpec, Scenario, ScenarioModels, SensorSpec, SimRun,
    TargetSpec, Truth,
};
