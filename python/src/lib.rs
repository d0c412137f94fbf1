//! The `smc_lmb` Python module: the library's filter, KITTI readers, plane segmentation and
//! prediction, the drive tracker over whole recordings, and multi-object metrics, with NumPy arrays in and out. Every call that does
//! Rust work releases the GIL while it runs; library errors become Python exceptions carrying
//! the library's message (which names the file, line and field where there is one).
//!
//! Not for: any algorithm of its own. Each function here converts arguments, calls the
//! library, and converts the result; the meaning lives in `smc_lmb` (the Rust crate).

mod convert;
mod drives;
mod filter;
mod kitti;
mod metrics;
mod planes;
mod sim;
mod transition;
mod vehicle;

use pyo3::prelude::*;

/// Labelled multi-Bernoulli tracking with particle densities, KITTI readers and plane
/// segmentation, from the Rust library smc-lmb.
#[pymodule(name = "smc_lmb")]
fn smc_lmb_module(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    drives::register(m)?;
    filter::register(m)?;
    kitti::register(m)?;
    metrics::register(m)?;
    planes::register(m)?;
    sim::register(m)?;
    Ok(())
}
