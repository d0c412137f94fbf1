//! Plane segmentation and plane prediction for Python: `extract_planes` (the ground and
//! building walls of one scan, sequential RANSAC), `predict_planes_between` (the walls of
//! scan k moved into scan k + 1 and scored, seed 001's Algorithm 1) and
//! `predict_plane_pairs` (the same over every frame pair of a KITTI raw drive, tracking or
//! odometry sequence), with the prediction metrics.
//!
//! Options are keyword arguments named as the library's fields (`PlaneConfig`,
//! `PlanePredictionConfig`); unknown names are an error.
//!
//! Not for: the methods themselves (`smc_lmb::cloud::planes`,
//! `smc_lmb::pipeline::plane_prediction`).

use crate::convert::{fixed_rows, lib, pose, table, vec_array, vector};
use crate::vehicle::PyVehicleModel;
use numpy::ndarray::Array2;
use numpy::IntoPyArray;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use smc_lmb::cloud::planes::{self, PlaneConfig, PlaneDetection, WallQuality};
use smc_lmb::cloud::PointCloud;
use smc_lmb::geometry::PlanePatch;
use smc_lmb::metrics::{PlanePairError, PlanePredictionSummary};
use smc_lmb::models::{vehicle_model_by_name, ExtendedConstantTurn, SharedVehicleModel};
use smc_lmb::pipeline::plane_prediction::{self as pp, PairPrediction, PlanePredictionConfig};
use smc_lmb::recording::Recording;
use smc_lmb::rng::seeded;
use std::path::PathBuf;
use std::sync::Arc;

/// An `N × 3` (or wider: x, y, z first) array as a cloud.
fn cloud(points: &Bound<'_, PyAny>, what: &str) -> PyResult<PointCloud> {
    let t = table(points, what, 3)?;
    if t.cols < 3 {
        return Err(PyValueError::new_err(format!(
            "{what}: expected N × 3 or N × 4 (x, y, z[, reflectance]), got {} columns",
            t.cols
        )));
    }
    let col =
        |c: usize| -> Vec<f32> { (0..t.rows).map(|i| t.data[i * t.cols + c] as f32).collect() };
    let intensity = if t.cols > 3 {
        col(3)
    } else {
        vec![0.0; t.rows]
    };
    lib(PointCloud::from_columns(col(0), col(1), col(2), intensity))
}

/// Applies keyword overrides to a `PlaneConfig`; `wall_quality` is a bool (the building
/// facade test on or off).
fn plane_config(options: Option<&Bound<'_, PyDict>>) -> PyResult<PlaneConfig> {
    let mut c = PlaneConfig::default();
    let Some(options) = options else {
        return Ok(c);
    };
    for (k, v) in options.iter() {
        let key: String = k.extract()?;
        macro_rules! set {
            ($($f:ident),*) => {
                match key.as_str() {
                    $(stringify!($f) => c.$f = v.extract().map_err(|e| {
                        PyValueError::new_err(format!("plane option {key}: {e}"))
                    })?,)*
                    "wall_quality" => {
                        c.wall_quality = if v.is_truthy()? { Some(WallQuality::BUILDING) } else { None }
                    }
                    other => {
                        return Err(PyValueError::new_err(format!(
                            "unknown plane option `{other}`"
                        )))
                    }
                }
            };
        }
        set!(
            max_planes,
            min_points,
            hypotheses,
            score_sample,
            preemptive_sample,
            preemptive_keep,
            sample_cell,
            score_threshold,
            msse_t,
            min_threshold,
            max_threshold,
            max_ground_tilt,
            min_ground_depth,
            ground_clearance,
            max_wall_tilt,
            min_wall_area,
            min_wall_length,
            min_wall_height,
            walls_to_ground,
            grid_cell,
            min_cell_points
        );
    }
    lib(c.validate())?;
    Ok(c)
}

fn patch_dict<'py>(py: Python<'py>, p: &PlanePatch) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let n = p.plane.normal;
    d.set_item("normal", vec_array(py, vec![n.x, n.y, n.z]))?;
    d.set_item("offset", p.plane.offset)?;
    d.set_item(
        "vertices",
        fixed_rows(py, p.vertices.iter().map(|v| [v.x, v.y, v.z])),
    )?;
    d.set_item("area", p.area)?;
    d.set_item("extent", (p.extent.0, p.extent.1))?;
    Ok(d)
}

fn detection_dict<'py>(py: Python<'py>, w: PlaneDetection) -> PyResult<Bound<'py, PyDict>> {
    let d = patch_dict(py, &w.patch)?;
    d.set_item("rms", w.rms)?;
    d.set_item("inliers", w.inliers.into_pyarray(py))?;
    Ok(d)
}

/// Segments the ground and building walls of one scan (`points`: `N × 3` or `N × 4`).
/// Returns `{"ground": plane or None, "walls": [plane, …], "remaining": indices, "rejected":
/// [(reason, points), …], "skipped": int}`, each plane a dict with `normal`, `offset`
/// (n·p + d = 0), `vertices` (4 × 3 patch corners), `area`, `extent`, `rms`, `inliers`.
/// Keyword options override `PlaneConfig` fields (e.g. `min_wall_area=10.0`,
/// `wall_quality=False`). Deterministic for a given `seed`.
#[pyfunction]
#[pyo3(signature = (points, seed=0, **options))]
fn extract_planes<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
    seed: u64,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let cloud = cloud(points, "points")?;
    let config = plane_config(options)?;
    let seg = lib(py.detach(|| planes::extract_planes(&cloud, &config, &mut seeded(seed))))?;
    let d = PyDict::new(py);
    d.set_item(
        "ground",
        seg.ground.map(|g| detection_dict(py, g)).transpose()?,
    )?;
    let walls = PyList::empty(py);
    for w in seg.walls {
        walls.append(detection_dict(py, w)?)?;
    }
    d.set_item("walls", walls)?;
    d.set_item("remaining", seg.remaining.into_pyarray(py))?;
    d.set_item(
        "rejected",
        seg.rejected
            .iter()
            .map(|r| (format!("{:?}", r.reason), r.points))
            .collect::<Vec<_>>(),
    )?;
    d.set_item("skipped", seg.skipped)?;
    Ok(d)
}

/// Keyword options of plane prediction: `PlanePredictionConfig`'s `dt`, its association gate's
/// `max_angle`, `max_plane_gap` and `min_overlap`, `use_vehicle_model`, the ECT's `sigma_accel` and
/// `sigma_turn_accel`, `vehicle_model` (a built-in model's name, or a callable: see
/// [`PyVehicleModel`]) and `planes` (a dict of `PlaneConfig` options). The Python vehicle
/// model, if any, comes back beside the configuration (for its exceptions).
fn prediction_config(
    py: Python<'_>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<(PlanePredictionConfig, Option<Arc<PyVehicleModel>>)> {
    let mut c = PlanePredictionConfig::default();
    let (mut sa, mut st) = (None, None);
    let mut user = None;
    if let Some(options) = options {
        for (k, v) in options.iter() {
            let key: String = k.extract()?;
            let bad =
                |e: PyErr| PyValueError::new_err(format!("plane prediction option {key}: {e}"));
            match key.as_str() {
                "dt" => c.dt = v.extract().map_err(bad)?,
                "max_angle" => c.gate.max_angle = v.extract().map_err(bad)?,
                "max_plane_gap" => c.gate.max_plane_gap = v.extract().map_err(bad)?,
                "min_overlap" => c.gate.min_overlap = v.extract().map_err(bad)?,
                "use_vehicle_model" => c.use_vehicle_model = v.is_truthy()?,
                "sigma_accel" => sa = Some(v.extract::<f64>().map_err(bad)?),
                "sigma_turn_accel" => st = Some(v.extract::<f64>().map_err(bad)?),
                "planes" => c.planes = plane_config(Some(v.cast::<PyDict>()?))?,
                "vehicle_model" => {
                    if let Ok(name) = v.extract::<String>() {
                        c.vehicle = SharedVehicleModel(lib(vehicle_model_by_name(&name, &[]))?);
                    } else {
                        let m = Arc::new(PyVehicleModel::new(py, v.clone().unbind())?);
                        c.vehicle = SharedVehicleModel(m.clone());
                        user = Some(m);
                    }
                }
                other => {
                    return Err(PyValueError::new_err(format!(
                        "unknown plane prediction option `{other}`"
                    )))
                }
            }
        }
    }
    if sa.is_some() || st.is_some() {
        if user.is_some() {
            return Err(PyValueError::new_err(
                "sigma_accel and sigma_turn_accel are the ECT's: a Python vehicle_model draws \
                 its own noise",
            ));
        }
        c.vehicle = SharedVehicleModel::new(lib(ExtendedConstantTurn::new(
            sa.unwrap_or(0.5),
            st.unwrap_or(0.1),
        ))?);
    }
    lib(c.validate())?;
    Ok((c, user))
}

fn pairs_dict<'py>(py: Python<'py>, pairs: &[PlanePairError]) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let col = |f: &dyn Fn(&PlanePairError) -> f64| vec_array(py, pairs.iter().map(f).collect());
    d.set_item(
        "frame",
        vec_array(py, pairs.iter().map(|p| p.frame as i64).collect()),
    )?;
    d.set_item("predicted_area", col(&|p| p.predicted_area))?;
    d.set_item("segmented_area", col(&|p| p.segmented_area))?;
    d.set_item(
        "vertex_distances",
        Array2::from_shape_vec(
            (pairs.len(), 4),
            pairs.iter().flat_map(|p| p.vertex_distances).collect(),
        )
        .expect("4 per pair")
        .into_pyarray(py),
    )?;
    d.set_item("normal_angle_rad", col(&|p| p.normal_angle_rad))?;
    d.set_item("normal_angle_deg", col(&|p| p.normal_angle_deg))?;
    Ok(d)
}

fn prediction_dict<'py>(py: Python<'py>, p: PairPrediction) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("frame", p.frame)?;
    d.set_item("predicted", p.predicted)?;
    d.set_item("segmented", p.segmented)?;
    d.set_item("prediction_ms", vec_array(py, p.prediction_ms))?;
    d.set_item("pairs", pairs_dict(py, &p.pairs)?)?;
    Ok(d)
}

fn summary_dict<'py>(py: Python<'py>, preds: &[PairPrediction]) -> PyResult<Bound<'py, PyDict>> {
    let pairs: Vec<PlanePairError> = preds.iter().flat_map(|p| p.pairs.clone()).collect();
    let ms: Vec<f64> = preds.iter().flat_map(|p| p.prediction_ms.clone()).collect();
    let s = PlanePredictionSummary::from_pairs(&pairs, &ms);
    let d = PyDict::new(py);
    d.set_item("median_normal_angle_deg", s.median_normal_angle_deg)?;
    d.set_item("p90_normal_angle_deg", s.p90_normal_angle_deg)?;
    d.set_item("median_vertex_distance_m", s.median_vertex_distance_m)?;
    d.set_item("p90_vertex_distance_m", s.p90_vertex_distance_m)?;
    d.set_item("mean_prediction_ms", s.mean_prediction_ms)?;
    d.set_item("pairs", s.pairs)?;
    Ok(d)
}

/// Segments the walls of two consecutive scans and predicts those of `points_k` into the
/// frame of `points_k1`: with the measured motion from the sensor poses `pose_k`, `pose_k1`
/// (4 × 4, sensor → world), or, given `vehicle_state` `[X, Ẋ, Y, Ẏ, φ, φ̇]` at k, with
/// `runs` Monte-Carlo draws of the vehicle model. Returns `{"frame", "predicted",
/// "segmented", "prediction_ms", "pairs": {arrays of the associated pairs' errors}}`.
#[pyfunction]
#[pyo3(signature = (points_k, points_k1, pose_k, pose_k1, vehicle_state=None, frame=0, runs=10, seed=0, **options))]
#[allow(clippy::too_many_arguments)]
fn predict_planes_between<'py>(
    py: Python<'py>,
    points_k: &Bound<'py, PyAny>,
    points_k1: &Bound<'py, PyAny>,
    pose_k: &Bound<'py, PyAny>,
    pose_k1: &Bound<'py, PyAny>,
    vehicle_state: Option<&Bound<'py, PyAny>>,
    frame: usize,
    runs: usize,
    seed: u64,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let (ck, ck1) = (cloud(points_k, "points_k")?, cloud(points_k1, "points_k1")?);
    let (pk, pk1) = (pose(pose_k, "pose_k")?, pose(pose_k1, "pose_k1")?);
    let state = match vehicle_state {
        None => None,
        Some(v) => {
            let v = vector(v, "vehicle_state")?;
            Some(<[f64; 6]>::try_from(v.as_slice()).map_err(|_| {
                PyValueError::new_err(format!(
                    "vehicle_state: expected 6 values [X, Ẋ, Y, Ẏ, φ, φ̇], got {}",
                    v.len()
                ))
            })?)
        }
    };
    let (config, user) = prediction_config(py, options)?;
    let p = py.detach(|| {
        pp::predict_planes_between(
            frame,
            &ck,
            &ck1,
            &pk,
            &pk1,
            state,
            &config,
            runs,
            &mut seeded(seed),
        )
    });
    match (p, user.as_ref().and_then(|m| m.take_error())) {
        (Ok(p), None) => prediction_dict(py, p),
        (_, Some(e)) => Err(e),
        (Err(e), None) => Err(crate::convert::to_py_err(e)),
    }
}

/// Plane prediction over consecutive frame pairs of a recording: `layout` is `"raw"` (`path` =
/// the drive folder), `"tracking"` or `"odometry"` (`path` = the benchmark root, with
/// `sequence`) or `"scans"` (`path` = a folder of `.bin` or `.pcd` scans with its `poses.txt`
/// in it). `frames = (start, end)` limits the pairs (k from start to end − 1). The
/// vehicle model (Algorithm 1) needs the vehicle's measured motion (OXTS: raw drives and
/// tracking sequences); other recordings are predicted with their poses.
/// Returns `{"frames": [per pair as predict_planes_between], "summary": {medians and 90th
/// percentiles of the normal angle (°) and vertex distance (m), mean prediction time (ms),
/// pair count}}`.
#[pyfunction]
#[pyo3(signature = (layout, path, sequence=None, frames=None, runs=10, seed=0, **options))]
#[allow(clippy::too_many_arguments)]
fn predict_plane_pairs<'py>(
    py: Python<'py>,
    layout: &str,
    path: PathBuf,
    sequence: Option<u32>,
    frames: Option<(usize, usize)>,
    runs: usize,
    seed: u64,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let (config, user) = prediction_config(py, options)?;
    let range = frames.map(|(a, b)| a..b);
    let mut rng = seeded(seed);
    // A Python vehicle model's exception replaces the library's error about its draw.
    let lib = |r: smc_lmb::Result<Vec<pp::PairPrediction>>| match (
        r,
        user.as_ref().and_then(|m| m.take_error()),
    ) {
        (Ok(v), None) => Ok(v),
        (_, Some(e)) => Err(e),
        (Err(e), None) => lib(Err(e)),
    };
    let source = crate::drives::recording_source(layout, path, sequence)?;
    let recording: Box<dyn Recording> = crate::convert::lib(source.open())?;
    // Algorithm 1 needs the vehicle's measured motion (OXTS); other recordings are predicted
    // with their poses.
    let mut config = config;
    config.use_vehicle_model &= recording.has_vehicle();
    let preds = lib(py.detach(|| pp::predict_pairs(&*recording, range, &config, runs, &mut rng)))?;
    let d = PyDict::new(py);
    d.set_item("summary", summary_dict(py, &preds)?)?;
    let list = PyList::empty(py);
    for p in preds {
        list.append(prediction_dict(py, p)?)?;
    }
    d.set_item("frames", list)?;
    Ok(d)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(extract_planes, m)?)?;
    m.add_function(wrap_pyfunction!(predict_planes_between, m)?)?;
    m.add_function(wrap_pyfunction!(predict_plane_pairs, m)?)?;
    Ok(())
}
