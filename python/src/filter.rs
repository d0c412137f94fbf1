//! `LmbFilter` for Python: the library's filter built from a run configuration (the one
//! `kitti-tools detections` reads, as a dict or TOML text), optionally with a Python motion
//! model, stepped with NumPy measurement arrays.
//!
//! Not for: the recursion itself (`smc_lmb::filter`) or the configuration's meaning
//! (`smc_lmb::config::RunConfig`).

use crate::convert::{columns_array, lib, table, vec_array, Table};
use crate::transition::PyTransition;
use nalgebra::{Isometry3, Vector3};
use numpy::{PyArray1, PyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use smc_lmb::config::{RunConfig, TransitionConfig};
use smc_lmb::filter::{Estimate, Frame, LmbFilter, Measurements};
use smc_lmb::rng::seeded;
use smc_lmb::FilterRng;
use std::sync::Arc;
use std::time::Instant;

/// One track's estimate: label `(birth_step, index)`, existence probability, mean state and
/// age in steps.
#[pyclass(name = "Estimate", module = "smc_lmb", get_all, frozen)]
pub struct PyEstimate {
    label: (u32, u32),
    existence: f64,
    state: Py<PyArray1<f64>>,
    age: u32,
}

#[pymethods]
impl PyEstimate {
    fn __repr__(&self, py: Python<'_>) -> String {
        format!(
            "Estimate(label={:?}, existence={:.4}, state={}, age={})",
            self.label,
            self.existence,
            self.state
                .bind(py)
                .repr()
                .map(|r| r.to_string())
                .unwrap_or_default(),
            self.age
        )
    }
}

fn estimate(py: Python<'_>, e: Estimate) -> PyEstimate {
    PyEstimate {
        label: (e.label.birth_step, e.label.index),
        existence: e.existence,
        state: vec_array(py, e.state).unbind(),
        age: e.age,
    }
}

/// One track of the filter: label, existence, age, and its particle cloud (`particles`,
/// `N × d`) with normalised `weights` (`N`).
#[pyclass(name = "Track", module = "smc_lmb", get_all, frozen)]
pub struct PyTrack {
    label: (u32, u32),
    existence: f64,
    age: u32,
    particles: Py<PyArray2<f64>>,
    weights: Py<PyArray1<f64>>,
}

#[pymethods]
impl PyTrack {
    fn __repr__(&self, py: Python<'_>) -> String {
        let n = self.weights.bind(py).len().unwrap_or(0);
        format!(
            "Track(label={:?}, existence={:.4}, age={}, {n} particles)",
            self.label, self.existence, self.age
        )
    }
}

/// The labelled multi-Bernoulli filter with particle densities.
///
/// `LmbFilter(config, transition=None)`: `config` is the run configuration of
/// `kitti-tools detections` as a dict or as TOML text (models, `[filter]` tuning, `seed`).
/// `transition`, if given, is a callable `f(particles, dt, rng) -> particles` that replaces
/// the configured motion model and must keep its state layout (the birth and measurement
/// models read positions from it).
///
/// A step that raises (bad measurements, a library error, an exception of the motion model)
/// may leave the filter part-way through that step; `reset()` starts it over.
#[pyclass(name = "LmbFilter", module = "smc_lmb")]
pub struct PyLmbFilter {
    filter: LmbFilter,
    rng: FilterRng,
    config: RunConfig,
    user_model: Option<Arc<PyTransition>>,
    step_ms: Vec<f64>,
}

/// Reads a run configuration from a dict (through JSON) or TOML text.
fn read_config(config: &Bound<'_, PyAny>) -> PyResult<RunConfig> {
    crate::convert::read_config_as(config, "config")
}

fn state_dim(config: &RunConfig) -> usize {
    match config.transition {
        TransitionConfig::ConstantVelocity { dims, .. } => 2 * dims,
        TransitionConfig::CoordinatedTurn { .. } => 5,
    }
}

/// A planar sensor pose `[x, y, heading]` as the frame's platform pose.
fn platform(pose: Option<Vec<f64>>) -> PyResult<Option<Isometry3<f64>>> {
    match pose.as_deref() {
        None => Ok(None),
        Some(&[x, y, h]) => Ok(Some(Isometry3::new(
            Vector3::new(x, y, 0.0),
            Vector3::new(0.0, 0.0, h),
        ))),
        Some(other) => Err(PyValueError::new_err(format!(
            "sensor_pose: expected [x, y, heading], got {} values",
            other.len()
        ))),
    }
}

fn measurements_of(z: &Table) -> smc_lmb::Result<Measurements> {
    if z.rows == 0 {
        Ok(Measurements::empty(z.cols))
    } else {
        Measurements::from_rows(z.cols, &z.row_slices())
    }
}

fn frame(time: f64, z: &Table, pose: Option<Isometry3<f64>>) -> smc_lmb::Result<Frame> {
    let mut f = Frame::new(time, measurements_of(z)?);
    f.platform = pose;
    Ok(f)
}

impl PyLmbFilter {
    /// Runs frames with the GIL released; a Python model's exception replaces the library's
    /// error (which names the track and step, kept as a note on the exception).
    fn run_frames(&mut self, py: Python<'_>, frames: Vec<Frame>) -> PyResult<Vec<Vec<Estimate>>> {
        let (filter, rng, ms) = (&mut self.filter, &mut self.rng, &mut self.step_ms);
        let result = py.detach(|| {
            let mut out = Vec::with_capacity(frames.len());
            for f in &frames {
                let t0 = Instant::now();
                let est = filter.step(f, rng)?;
                ms.push(t0.elapsed().as_secs_f64() * 1e3);
                out.push(est);
            }
            Ok(out)
        });
        match (
            result,
            self.user_model.as_ref().and_then(|m| m.take_error()),
        ) {
            (Ok(out), None) => Ok(out),
            (result, Some(user)) => {
                // Python 3.11+ keeps the library's view (which track, which step) as a note.
                if let Err(e) = result {
                    let _ = user
                        .value(py)
                        .call_method1("add_note", (format!("in the filter: {e}"),));
                }
                Err(user)
            }
            (Err(e), None) => Err(crate::convert::to_py_err(e)),
        }
    }
}

#[pymethods]
impl PyLmbFilter {
    #[new]
    #[pyo3(signature = (config, transition=None))]
    fn new(
        py: Python<'_>,
        config: &Bound<'_, PyAny>,
        transition: Option<Py<PyAny>>,
    ) -> PyResult<Self> {
        let config = read_config(config)?;
        let (filter, user_model) = match transition {
            None => (lib(config.build())?, None),
            Some(f) => {
                let model = Arc::new(PyTransition::new(py, f, state_dim(&config))?);
                let builder = lib(config.builder())?.transition(SharedModel(model.clone()));
                (lib(builder.build())?, Some(model))
            }
        };
        Ok(PyLmbFilter {
            rng: seeded(config.seed),
            filter,
            config,
            user_model,
            step_ms: Vec::new(),
        })
    }

    /// Runs one frame: `measurements` is `M × d` (an empty array for none) or, for a filter
    /// configured with several `[[sensors]]`, a dict from sensor name to that sensor's
    /// `M × d` array (sensors left out did not report); `sensor_pose` the platform's planar
    /// pose `[x, y, heading]`. Returns the estimates (maximum a posteriori cardinality, most
    /// likely tracks).
    #[pyo3(signature = (time, measurements, sensor_pose=None))]
    fn step(
        &mut self,
        py: Python<'_>,
        time: f64,
        measurements: &Bound<'_, PyAny>,
        sensor_pose: Option<Vec<f64>>,
    ) -> PyResult<Vec<PyEstimate>> {
        let f = if let Ok(by_sensor) = measurements.cast::<PyDict>() {
            let mut f = Frame::at_time(time);
            f.platform = platform(sensor_pose)?;
            for (name, z) in by_sensor.iter() {
                let name: String = name.extract().map_err(|_| {
                    PyValueError::new_err("measurements: dict keys must be sensor names")
                })?;
                let Some(index) = self.filter.sensor_index(&name) else {
                    let known: Vec<String> = self
                        .filter
                        .sensors()
                        .iter()
                        .map(|s| format!("{:?}", s.name()))
                        .collect();
                    return Err(PyValueError::new_err(format!(
                        "measurements: no sensor named {name:?} (the filter's sensors: {})",
                        known.join(", ")
                    )));
                };
                let z = table(&z, &format!("measurements[{name:?}]"), 0)?;
                f = f.with_sensor(index, lib(measurements_of(&z))?);
            }
            f
        } else {
            let z = table(measurements, "measurements", 0)?;
            lib(frame(time, &z, platform(sensor_pose)?))?
        };
        let mut out = self.run_frames(py, vec![f])?;
        Ok(out
            .pop()
            .unwrap_or_default()
            .into_iter()
            .map(|e| estimate(py, e))
            .collect())
    }

    /// Runs many frames in one call (`times[k]`, `measurements[k]`, optional
    /// `sensor_poses[k]` as in `step`), the GIL released throughout; returns the estimates of
    /// every frame.
    #[pyo3(signature = (times, measurements, sensor_poses=None))]
    fn run(
        &mut self,
        py: Python<'_>,
        times: Vec<f64>,
        measurements: Vec<Bound<'_, PyAny>>,
        sensor_poses: Option<Vec<Option<Vec<f64>>>>,
    ) -> PyResult<Vec<Vec<PyEstimate>>> {
        let poses = sensor_poses.unwrap_or_else(|| vec![None; times.len()]);
        if times.len() != measurements.len() || times.len() != poses.len() {
            return Err(PyValueError::new_err(format!(
                "run: {} times, {} measurement arrays and {} sensor poses",
                times.len(),
                measurements.len(),
                poses.len()
            )));
        }
        let frames = times
            .iter()
            .zip(&measurements)
            .zip(poses)
            .enumerate()
            .map(|(k, ((&t, z), pose))| {
                let z = table(z, &format!("measurements[{k}]"), 0)?;
                lib(frame(t, &z, platform(pose)?))
            })
            .collect::<PyResult<Vec<_>>>()?;
        let out = self.run_frames(py, frames)?;
        Ok(out
            .into_iter()
            .map(|f| f.into_iter().map(|e| estimate(py, e)).collect())
            .collect())
    }

    /// The current tracks with their particle clouds.
    fn tracks(&self, py: Python<'_>) -> Vec<PyTrack> {
        self.filter
            .tracks()
            .iter()
            .map(|t| {
                let (n, d) = (t.particles.len(), t.particles.dim());
                PyTrack {
                    label: (t.label.birth_step, t.label.index),
                    existence: t.existence,
                    age: t.age,
                    particles: columns_array(py, n, d, t.particles.components().concat()).unbind(),
                    weights: vec_array(py, t.particles.weights().to_vec()).unbind(),
                }
            })
            .collect()
    }

    /// Milliseconds the library spent in each step so far (the GIL released), to tell the
    /// filter's own time from the cost of calling it from Python.
    fn step_times_ms<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vec_array(py, self.step_ms.clone())
    }

    /// Number of steps run.
    #[getter]
    fn steps(&self) -> u32 {
        self.filter.steps()
    }

    /// The state dimension of the configured motion model.
    #[getter]
    fn state_dim(&self) -> usize {
        state_dim(&self.config)
    }

    /// Forgets every track and restarts the random stream from the configured seed.
    fn reset(&mut self) {
        self.filter.reset();
        self.rng = seeded(self.config.seed);
        self.step_ms.clear();
    }

    fn __repr__(&self) -> String {
        format!(
            "LmbFilter({} tracks after {} steps, seed {})",
            self.filter.tracks().len(),
            self.filter.steps(),
            self.config.seed
        )
    }
}

/// Lets the filter own a model the wrapper also keeps a handle on (for its errors).
pub struct SharedModel(pub Arc<PyTransition>);

impl smc_lmb::filter::TransitionModel for SharedModel {
    fn state_dim(&self) -> usize {
        self.0.state_dim()
    }
    fn predict(
        &self,
        particles: &mut smc_lmb::filter::ParticleSet,
        ctx: &smc_lmb::filter::StepContext,
        rng: &mut FilterRng,
    ) -> smc_lmb::Result<()> {
        self.0.predict(particles, ctx, rng)
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyLmbFilter>()?;
    m.add_class::<PyEstimate>()?;
    m.add_class::<PyTrack>()?;
    Ok(())
}
