#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

pub mod assignment;
pub mod atomic;
pub mod cloud;
pub mod config;
pub mod detections;
pub mod error;
pub mod filter;
pub mod geometry;
pub mod kitti;
pub mod laser2d;
pub mod metrics;
pub mod models;
pub(crate) mod numerics;
pub mod pipeline;
pub mod plot;
pub mod rng;
pub mod sim;
pub mod trackers;

pub use error::{Error, Result};
pub use filter::{Label, ParticleSet};
pub use rng::FilterRng;
