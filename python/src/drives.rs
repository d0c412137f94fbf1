//! Whole recordings for Python: `track` runs the library's drive tracker (walls and clusters,
//! one LMB filter) over a KITTI raw drive, tracking or odometry sequence and returns its
//! summary, writing the per-frame tracks as JSON on request; `tracks_summary` reads that
//! summary back from such a file; `synth_street` writes the simulated street as a raw drive.
//! They are what a batch over many recordings (e.g. on Ray) needs.
//!
//! Not for: the tracker itself (`smc_lmb::pipeline::drive_tracking`).

use crate::convert::{lib, read_config_as};
use crate::filter::SharedModel;
use crate::transition::PyTransition;
use crate::vehicle::PyVehicleModel;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use smc_lmb::filter::SharedTransitionModel;
use smc_lmb::models::SharedVehicleModel;
use smc_lmb::pipeline::drive_tracking::{
    DriveTracks, EgoModel, RecordingSource, RoadUserMotion, TrackingConfig,
};
use smc_lmb::sim::street::{write_drive, StreetConfig};
use std::path::PathBuf;
use std::sync::Arc;

/// A run's summary as a dict: `name`, `frames`, `ego`, `walls_per_frame`,
/// `clusters_per_frame`, `wall_labels`, `cluster_labels`, `ms_per_frame` (read, planes,
/// clusters and filter) and `odometry_ms_per_frame`.
fn summary<'py>(py: Python<'py>, t: &DriveTracks) -> PyResult<Bound<'py, PyDict>> {
    let s = &t.summary;
    let d = PyDict::new(py);
    d.set_item("name", &t.drive)?;
    d.set_item("frames", s.frames)?;
    d.set_item("ego", &t.ego)?;
    d.set_item("walls_per_frame", s.mean_planes)?;
    d.set_item("clusters_per_frame", s.mean_clusters)?;
    d.set_item("wall_labels", s.plane_labels)?;
    d.set_item("cluster_labels", s.cluster_labels)?;
    d.set_item("ms_per_frame", s.mean_times.total_ms())?;
    d.set_item("odometry_ms_per_frame", s.mean_times.ego_ms)?;
    Ok(d)
}

/// The recording `layout` names at `path`: `"raw"` (a raw drive folder), `"tracking"` (a
/// tracking split folder, with `sequence`), `"odometry"` (an odometry root, with `sequence`)
/// or `"scans"` (a folder of `.bin` or `.pcd` scans, with its `poses.txt` and `times.txt`
/// when they are in it).
pub fn recording_source(
    layout: &str,
    path: PathBuf,
    sequence: Option<u32>,
) -> PyResult<RecordingSource> {
    let need_sequence = || {
        sequence.ok_or_else(|| {
            PyValueError::new_err(format!("layout \"{layout}\" needs a sequence number"))
        })
    };
    Ok(match layout {
        "raw" => RecordingSource::Raw(path),
        "tracking" => RecordingSource::Tracking(path, need_sequence()?),
        "odometry" => RecordingSource::Odometry(path, need_sequence()?),
        "scans" => {
            let beside = |name: &str| Some(path.join(name)).filter(|p| p.is_file());
            RecordingSource::Scans {
                poses: beside("poses.txt"),
                times: beside("times.txt"),
                sensor_height: None,
                dir: path,
            }
        }
        other => {
            return Err(PyValueError::new_err(format!(
                "layout \"{other}\": expected \"raw\", \"tracking\", \"odometry\" or \"scans\""
            )))
        }
    })
}

/// Tracks walls and clusters over a whole recording with one LMB filter and returns the run's
/// summary (see `tracks_summary`). `layout` and `path` name the recording as
/// `predict_plane_pairs` takes them: `"raw"` (`path` a raw drive folder), `"tracking"` (`path`
/// a tracking split folder, with `sequence`), `"odometry"` (`path` an odometry root, with
/// `sequence`) or `"scans"` (`path` a folder of scans, its `poses.txt` and `times.txt` used
/// when present). `config` is the tracking configuration (`TrackingConfig`:
/// a dict or TOML text; default: the library's); `particles` overrides its particles per
/// track. With `out`, the per-frame tracks are written there as JSON (atomically), as
/// `kitti-tools track --out` writes them. The GIL is released while it runs.
///
/// `transition`, a callable `f(particles: ndarray[N, 6], dt, rng) -> ndarray[N, 6]` as
/// `LmbFilter(config, transition=f)` takes, moves the road users (clusters, state
/// [x, ẋ, y, ẏ, z, ż] in the world frame) instead of constant velocity. `vehicle_model`, a
/// built-in model's name (`"ect"`, `"ct"`, `"bicycle"`) or a callable
/// `g(kinematics, dt, n, rng) -> poses (n, 3)` (see `predict_plane_pairs`), moves the walls by
/// per-particle draws of the vehicle's motion instead of the measured poses. A callable's
/// exception is raised as it is.
#[pyfunction]
#[pyo3(signature = (path, layout = "raw", sequence = None, out = None, config = None, seed = 1, particles = None, transition = None, vehicle_model = None))]
#[allow(clippy::too_many_arguments)]
fn track<'py>(
    py: Python<'py>,
    path: PathBuf,
    layout: &str,
    sequence: Option<u32>,
    out: Option<PathBuf>,
    config: Option<&Bound<'py, PyAny>>,
    seed: u64,
    particles: Option<usize>,
    transition: Option<Py<PyAny>>,
    vehicle_model: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let mut cfg: TrackingConfig = match config {
        Some(c) => read_config_as(c, "tracking config")?,
        None => TrackingConfig::default(),
    };
    if let Some(n) = particles {
        cfg.filter.particles = n;
    }
    let road_users = match transition {
        None => None,
        Some(f) => {
            let m = Arc::new(PyTransition::new(py, f, 6)?);
            cfg.cluster.motion =
                RoadUserMotion::Custom(SharedTransitionModel(Arc::new(SharedModel(m.clone()))));
            Some(m)
        }
    };
    let vehicle = match vehicle_model {
        None => None,
        Some(v) => {
            if let Ok(name) = v.extract::<String>() {
                cfg.ego = EgoModel::Vehicle {
                    model: name,
                    parameters: Default::default(),
                };
                None
            } else {
                let m = Arc::new(PyVehicleModel::new(py, v.clone().unbind())?);
                cfg.ego = EgoModel::Custom(SharedVehicleModel(m.clone()));
                Some(m)
            }
        }
    };
    lib(cfg.validate())?;
    let source = recording_source(layout, path, sequence)?;
    let tracks = py.detach(|| source.track(None, &cfg, seed, |_| Ok(())));
    let user_error = road_users
        .as_ref()
        .and_then(|m| m.take_error())
        .or_else(|| vehicle.as_ref().and_then(|m| m.take_error()));
    if let Some(e) = user_error {
        return Err(e);
    }
    let tracks = lib(tracks)?;
    if let Some(out) = &out {
        lib(py.detach(|| tracks.write_json(out)))?;
    }
    summary(py, &tracks)
}

/// The summary (as `track` returns it) of a tracks file written by `track(out=...)` or
/// `kitti-tools track --out`.
#[pyfunction]
fn tracks_summary<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyDict>> {
    let tracks = lib(py.detach(|| DriveTracks::read_json(&path)))?;
    summary(py, &tracks)
}

/// Writes the simulated street (the library's default street: walls, parked and moving cars,
/// pedestrians) as a KITTI raw drive under `out` (`out/DATE/DATE_drive_NNNN_sync`, with OXTS,
/// calibration and `truth.json`) and returns the drive folder. `drive` is the drive number
/// NNNN, so that several streets can share one `out`.
#[pyfunction]
#[pyo3(signature = (out, frames = 40, seed = 1, drive = 1))]
fn synth_street(
    py: Python<'_>,
    out: PathBuf,
    frames: usize,
    seed: u64,
    drive: u32,
) -> PyResult<String> {
    let mut config = StreetConfig::default();
    config.recording.drive_number = drive;
    let written = lib(py.detach(|| write_drive(&out, &config, frames, seed, |_| {})))?;
    Ok(written.dir.display().to_string())
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(track, m)?)?;
    m.add_function(wrap_pyfunction!(tracks_summary, m)?)?;
    m.add_function(wrap_pyfunction!(synth_street, m)?)?;
    Ok(())
}
