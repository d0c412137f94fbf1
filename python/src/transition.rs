//! A user's motion model written in Python: a callable
//! `f(particles: ndarray[N, d], dt: float, rng: numpy.random.Generator) -> ndarray[N, d]`
//! that moves a whole particle set at once, so the cost of calling into Python is paid once
//! per track and step, not once per particle.
//!
//! The callable gets a NumPy generator seeded with one draw from the filter's per-track
//! stream, so a run is reproduced exactly by the same filter seed whatever the thread count.
//! The filter runs its tracks on worker threads with the GIL released; each call takes the
//! GIL for its own duration.
//!
//! Not for: the models built into the library (they stay in Rust).

use crate::convert::table;
use numpy::ndarray::{Array2, ShapeBuilder};
use numpy::IntoPyArray;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rand::Rng;
use smc_lmb::filter::{check_state_dim, ParticleSet, StepContext, TransitionModel};
use smc_lmb::FilterRng;
use std::sync::Mutex;

/// The Python callable as a [`TransitionModel`]. A failing call (an exception, or a result of
/// the wrong shape) is an error of the step, which names the track; the Python exception is
/// kept and raised instead by [`PyTransition::take_error`].
pub struct PyTransition {
    func: Py<PyAny>,
    dim: usize,
    generator: Py<PyAny>,
    bit_generator: Py<PyAny>,
    error: Mutex<Option<PyErr>>,
}

impl PyTransition {
    /// Wraps `func` for states of `dim` components.
    pub fn new(py: Python<'_>, func: Py<PyAny>, dim: usize) -> PyResult<Self> {
        if !func.bind(py).is_callable() {
            return Err(PyValueError::new_err(
                "transition: expected a callable f(particles, dt, rng) -> particles",
            ));
        }
        let random = py.import("numpy.random")?;
        Ok(PyTransition {
            func,
            dim,
            generator: random.getattr("Generator")?.unbind(),
            bit_generator: random.getattr("PCG64")?.unbind(),
            error: Mutex::new(None),
        })
    }

    /// The first exception raised by the callable since the last call, if any.
    pub fn take_error(&self) -> Option<PyErr> {
        self.error.lock().unwrap_or_else(|p| p.into_inner()).take()
    }

    fn call(
        &self,
        py: Python<'_>,
        particles: &mut ParticleSet,
        dt: f64,
        seed: u64,
    ) -> PyResult<()> {
        // The model's own components: a longer state (the drive tracker's kind tag after a
        // road user's [x, ẋ, y, ẏ, z, ż]) keeps the rest as it is.
        let (n, d) = (particles.len(), self.dim);
        // The set is stored column by column: one Fortran-order array, no reordering.
        let data: Vec<f64> = particles.components()[..d].concat();
        let arr = Array2::from_shape_vec((n, d).f(), data)
            .expect("n × d values")
            .into_pyarray(py);
        let rng = self
            .generator
            .bind(py)
            .call1((self.bit_generator.bind(py).call1((seed,))?,))?;
        let out = self.func.bind(py).call1((arr, dt, rng))?;
        let t = table(&out, "transition result", d)?;
        if t.rows != n || t.cols != d {
            return Err(PyValueError::new_err(format!(
                "transition: returned an array of shape ({}, {}), expected ({n}, {d})",
                t.rows, t.cols
            )));
        }
        for (c, col) in particles.components_mut().into_iter().take(d).enumerate() {
            for (i, v) in col.iter_mut().enumerate() {
                *v = t.data[i * d + c];
            }
        }
        Ok(())
    }
}

impl TransitionModel for PyTransition {
    fn state_dim(&self) -> usize {
        self.dim
    }

    fn predict(
        &self,
        particles: &mut ParticleSet,
        ctx: &StepContext,
        rng: &mut FilterRng,
    ) -> smc_lmb::Result<()> {
        check_state_dim("the Python transition", self.dim, particles)?;
        let seed = rng.next_u64();
        match Python::attach(|py| self.call(py, particles, ctx.dt, seed)) {
            Ok(()) => Ok(()),
            Err(e) => {
                let why = e.to_string();
                let mut slot = self.error.lock().unwrap_or_else(|p| p.into_inner());
                if slot.is_none() {
                    *slot = Some(e);
                }
                Err(smc_lmb::Error::invalid("the Python transition", why))
            }
        }
    }
}
