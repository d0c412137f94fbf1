#![cfg_attr(
    all(feature = "kitti", feature = "laser2d", feature = "plot"),
    doc = include_str!("../README.md")
)]
#![cfg_attr(
    not(all(feature = "kitti", feature = "laser2d", feature = "plot")),
    doc = "Labelled multi-Bernoulli tracking with particle densities (built without some of \
           the default features `kitti`, `laser2d`, `plot`; the README's examples need them all)."
)]
#![deny(missing_docs)]

pub mod assignment;
pub mod atomic;
#[cfg(feature = "kitti")]
pub mod cloud;
pub mod config;
pub mod detections;
pub mod error;
pub mod filter;
pub mod geometry;
#[cfg(feature = "kitti")]
pub mod kitti;
#[cfg(feature = "laser2d")]
pub mod laser2d;
pub mod metrics;
pub mod models;
pub(crate) mod numerics;
pub mod pipeline;
#[cfg(feature = "plot")]
pub mod plot;
#[cfg(feature = "kitti")]
pub mod recording;
pub mod rng;
pub mod sim;
pub mod trackers;

pub use error::{Error, Result};
pub use filter::{Label, ParticleSet};
pub use rng::FilterRng;
