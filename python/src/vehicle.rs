//! A user's vehicle model written in Python: a callable
//! `g(kinematics: ndarray[6], dt: float, n: int, rng: numpy.random.Generator) -> ndarray[n, 3]`
//! that draws `n` poses (X, Y, φ) of the vehicle after `dt` seconds from its measured
//! kinematics [X, Ẋ, Y, Ẏ, φ, φ̇] (the OXTS state of the frame). It is called once per batch
//! of draws, so the cost of calling into Python is paid once per frame pair (plane
//! prediction) or per wall and step (tracking), not once per draw.
//!
//! The model's state is the measured kinematics; a step keeps the velocities and turn rate
//! and takes the drawn pose. Its mean step is one draw (the library's pipelines only draw).
//! The callable gets a NumPy generator seeded with one draw from the library's stream, so a
//! run is reproduced by the same seed.
//!
//! Not for: the built-in vehicle models (they stay in Rust, by name).

use crate::convert::table;
use nalgebra::{Isometry3, Vector3};
use numpy::IntoPyArray;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rand::Rng;
use smc_lmb::models::{VehicleModel, VehicleState};
use smc_lmb::FilterRng;
use std::sync::Mutex;

/// The Python callable as a [`VehicleModel`]. A failing call (an exception, a result of the
/// wrong shape or with a NaN) gives non-finite poses, which the pipelines turn into an error
/// naming the model; the Python exception is kept and raised instead by
/// [`PyVehicleModel::take_error`].
pub struct PyVehicleModel {
    func: Py<PyAny>,
    generator: Py<PyAny>,
    bit_generator: Py<PyAny>,
    error: Mutex<Option<PyErr>>,
}

impl PyVehicleModel {
    /// Wraps `func`.
    pub fn new(py: Python<'_>, func: Py<PyAny>) -> PyResult<Self> {
        if !func.bind(py).is_callable() {
            return Err(PyValueError::new_err(
                "vehicle_model: expected a name (\"ect\", \"ct\", \"bicycle\") or a callable \
                 g(kinematics, dt, n, rng) -> poses of shape (n, 3)",
            ));
        }
        let random = py.import("numpy.random")?;
        Ok(PyVehicleModel {
            func,
            generator: random.getattr("Generator")?.unbind(),
            bit_generator: random.getattr("PCG64")?.unbind(),
            error: Mutex::new(None),
        })
    }

    /// The first exception raised by (or about) the callable since the last call, if any.
    pub fn take_error(&self) -> Option<PyErr> {
        self.error.lock().unwrap_or_else(|p| p.into_inner()).take()
    }

    fn call(
        &self,
        py: Python<'_>,
        state: &[f64],
        dt: f64,
        seed: u64,
        poses: &mut [Isometry3<f64>],
    ) -> PyResult<()> {
        let n = poses.len();
        let rng = self
            .generator
            .bind(py)
            .call1((self.bit_generator.bind(py).call1((seed,))?,))?;
        let kin = state.to_vec().into_pyarray(py);
        let out = self.func.bind(py).call1((kin, dt, n, rng))?;
        let t = table(&out, "vehicle_model result", 3)?;
        if t.rows != n || t.cols != 3 {
            return Err(PyValueError::new_err(format!(
                "vehicle_model: returned an array of shape ({}, {}), expected ({n}, 3) poses \
                 (X, Y, heading)",
                t.rows, t.cols
            )));
        }
        if let Some(i) = t.data.iter().position(|v| !v.is_finite()) {
            return Err(PyValueError::new_err(format!(
                "vehicle_model: pose {} has a non-finite value ({})",
                i / 3,
                t.data[i]
            )));
        }
        for (p, row) in poses.iter_mut().zip(t.data.chunks(3)) {
            *p = planar(row[0], row[1], row[2]);
        }
        Ok(())
    }

    fn remember(&self, e: PyErr) {
        let mut slot = self.error.lock().unwrap_or_else(|p| p.into_inner());
        if slot.is_none() {
            *slot = Some(e);
        }
    }
}

fn planar(x: f64, y: f64, heading: f64) -> Isometry3<f64> {
    Isometry3::new(Vector3::new(x, y, 0.0), Vector3::new(0.0, 0.0, heading))
}

impl VehicleModel for PyVehicleModel {
    fn state_dim(&self) -> usize {
        6
    }

    fn state_of(&self, measured: &VehicleState) -> Vec<f64> {
        measured.to_array().to_vec()
    }

    fn sample_step(&self, state: &[f64], dt: f64, rng: &mut FilterRng, next: &mut [f64]) {
        let mut pose = [Isometry3::identity()];
        self.sample_poses(state, dt, rng, &mut pose);
        let (_, _, heading) = pose[0].rotation.euler_angles();
        let t = pose[0].translation.vector;
        next.copy_from_slice(state);
        next[0] = t.x;
        next[2] = t.y;
        next[4] = heading;
    }

    fn mean_step(&self, state: &[f64], dt: f64, next: &mut [f64]) {
        let mut rng = smc_lmb::rng::seeded(0);
        self.sample_step(state, dt, &mut rng, next);
    }

    fn pose_of(&self, state: &[f64]) -> Isometry3<f64> {
        planar(state[0], state[2], state[4])
    }

    fn name(&self) -> String {
        "PythonVehicleModel".into()
    }

    fn sample_poses(
        &self,
        state: &[f64],
        dt: f64,
        rng: &mut FilterRng,
        poses: &mut [Isometry3<f64>],
    ) {
        let seed = rng.next_u64();
        if let Err(e) = Python::attach(|py| self.call(py, state, dt, seed, poses)) {
            self.remember(e);
            let nan = planar(f64::NAN, f64::NAN, f64::NAN);
            poses.iter_mut().for_each(|p| *p = nan);
        }
    }
}
