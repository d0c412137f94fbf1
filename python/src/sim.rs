//! The standard linear RFS benchmark for Python (`linear_scenario`): simulated measurements
//! and truth of the library's `Scenario::linear`, with the run configuration (the
//! `kitti-tools detections` format) of the filter that scenario prescribes, so the same filter
//! can be timed from Python and from Rust.
//!
//! Not for: simulating anything else (the library's `smc_lmb::sim` does).

use crate::convert::{lib, rows_array, vec_array};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use smc_lmb::config::{
    BirthConfig, ClutterConfig, DetectionConfig, MeasurementConfig, RunConfig, TransitionConfig,
};
use smc_lmb::filter::LmbConfig;
use smc_lmb::sim::{ClutterSpec, DetectionSpec, DynamicsSpec, Scenario, SensorSpec};

/// The linear scenario's filter as a run configuration.
fn linear_config(sc: &Scenario, seed: u64, particles: usize) -> PyResult<RunConfig> {
    let (DynamicsSpec::ConstantVelocity { sigma_accel }, SensorSpec::Position { sigma }) =
        (sc.dynamics, sc.sensor)
    else {
        return Err(PyValueError::new_err(
            "the linear scenario changed its models",
        ));
    };
    let (DetectionSpec::Constant { p }, ClutterSpec::Rectangle { rate, x, y }) =
        (sc.detection, sc.clutter)
    else {
        return Err(PyValueError::new_err(
            "the linear scenario changed its models",
        ));
    };
    Ok(RunConfig {
        seed,
        survival: sc.survival,
        filter: LmbConfig {
            particles,
            ..LmbConfig::default()
        },
        transition: TransitionConfig::ConstantVelocity {
            dims: 2,
            sigma_accel,
        },
        measurement: Some(MeasurementConfig::Position { sigma }),
        detection: Some(DetectionConfig::Constant { probability: p }),
        clutter: Some(ClutterConfig {
            rate,
            volume: (x[1] - x[0]) * (y[1] - y[0]),
        }),
        sensors: Vec::new(),
        fusion: None,
        // Sampled from the prior, as `rfs_benchmark` (Rust) samples it, so that the two time
        // the same filter.
        birth: BirthConfig::Static {
            terms: sc.birth.clone(),
            particles,
            measurement_proposal: false,
        },
        association: Default::default(),
    })
}

/// The linear RFS benchmark (constant velocity, position measurements σ = 10 m, p_D = 0.98,
/// 30 clutter points a scan on [−1000, 1000]², 12 targets over 100 scans of 1 s), simulated
/// with `seed`. Returns `{"config": run configuration dict (filter seed `seed`,
/// `particles` per track), "times", "measurements": [M_k × 2 arrays], "truth": [n_k × 4
/// arrays of [x, ẋ, y, ẏ]], "truth_ids": [n_k arrays], "ospa_cutoff", "ospa_order"}`.
#[pyfunction]
#[pyo3(signature = (seed=1, particles=1000))]
fn linear_scenario<'py>(
    py: Python<'py>,
    seed: u64,
    particles: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let sc = Scenario::linear();
    let run = lib(py.detach(|| sc.generate(seed)))?;
    let config = linear_config(&sc, seed, particles)?;
    let json = serde_json::to_string(&config)
        .map_err(|e| PyValueError::new_err(format!("config: {e}")))?;
    let d = PyDict::new(py);
    d.set_item(
        "config",
        py.import("json")?.getattr("loads")?.call1((json,))?,
    )?;
    d.set_item(
        "times",
        vec_array(
            py,
            (0..run.measurements.len())
                .map(|k| k as f64 * sc.period)
                .collect(),
        ),
    )?;
    let meas: Vec<_> = run
        .measurements
        .iter()
        .map(|z| rows_array(py, z.len(), 2, z.iter().flatten().copied().collect()))
        .collect();
    d.set_item("measurements", meas)?;
    let truth: Vec<_> = run
        .truth
        .iter()
        .map(|t| {
            rows_array(
                py,
                t.len(),
                4,
                t.iter().flat_map(|(_, s)| s.clone()).collect(),
            )
        })
        .collect();
    d.set_item("truth", truth)?;
    let ids: Vec<_> = run
        .truth
        .iter()
        .map(|t| vec_array(py, t.iter().map(|(id, _)| *id).collect()))
        .collect();
    d.set_item("truth_ids", ids)?;
    d.set_item("ospa_cutoff", sc.ospa_cutoff)?;
    d.set_item("ospa_order", sc.ospa_order)?;
    Ok(d)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(linear_scenario, m)?)?;
    Ok(())
}
