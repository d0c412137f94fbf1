//! KITTI readers for Python: Velodyne `.bin` scans as `N × 4` float32 arrays (x, y, z,
//! reflectance), and the three layouts — raw drives (`RawDrive`), the odometry benchmark
//! (`OdometrySequence`) and the tracking benchmark (`TrackingSequence`, with its `label_02`
//! labels) — giving scans, poses (`K × 4 × 4`, Velodyne frame k → frame 0), times and labels
//! as arrays.
//!
//! Not for: parsing (the library's `smc_lmb::kitti` and `smc_lmb::cloud` do it, and their
//! errors name the file).

use crate::convert::{fixed_rows, lib, poses_array, vec_array};
use numpy::ndarray::{Array2, ShapeBuilder};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use smc_lmb::cloud::{read_kitti_bin as read_bin, PointCloud};
use smc_lmb::kitti::{self, OdometrySequence, RawDrive, TrackingLabel, TrackingSequence};
use smc_lmb::recording::Recording;
use std::path::PathBuf;

/// A cloud as an `N × 4` float32 array (x, y, z, reflectance), columns copied once.
pub fn cloud_array<'py>(py: Python<'py>, cloud: PointCloud) -> Bound<'py, PyArray2<f32>> {
    let n = cloud.len();
    let (x, y, z, i) = cloud.into_columns();
    let data = [x, y, z, i].concat();
    Array2::from_shape_vec((n, 4).f(), data)
        .expect("4 columns of n")
        .into_pyarray(py)
}

/// Reads one KITTI Velodyne scan (`.bin`: float32 x, y, z, reflectance per point) as an
/// `N × 4` float32 array.
#[pyfunction]
fn read_kitti_bin<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let cloud = lib(py.detach(|| read_bin(&path)))?;
    Ok(cloud_array(py, cloud))
}

/// Tracking labels (`label_02/NNNN.txt`) as a dict of arrays, one entry per label line:
/// `frame`, `track_id`, `type` (list of str), `truncated`, `occluded`, `alpha`, `bbox`
/// (`n × 4`: left, top, right, bottom), `dimensions` (`n × 3`: height, width, length),
/// `location` (`n × 3`, camera coordinates), `rotation_y`, `score` (NaN where absent).
fn labels_dict<'py>(py: Python<'py>, labels: &[TrackingLabel]) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let col = |f: &dyn Fn(&TrackingLabel) -> f64| labels.iter().map(f).collect::<Vec<f64>>();
    d.set_item(
        "frame",
        vec_array(py, labels.iter().map(|l| l.frame as i64).collect()),
    )?;
    d.set_item(
        "track_id",
        vec_array(py, labels.iter().map(|l| l.track_id).collect()),
    )?;
    d.set_item(
        "type",
        labels
            .iter()
            .map(|l| l.object_type.name())
            .collect::<Vec<_>>(),
    )?;
    d.set_item("truncated", vec_array(py, col(&|l| l.truncated)))?;
    d.set_item(
        "occluded",
        vec_array(py, labels.iter().map(|l| l.occluded as i64).collect()),
    )?;
    d.set_item("alpha", vec_array(py, col(&|l| l.alpha)))?;
    d.set_item("bbox", fixed_rows(py, labels.iter().map(|l| l.bbox)))?;
    d.set_item(
        "dimensions",
        fixed_rows(py, labels.iter().map(|l| l.dimensions)),
    )?;
    d.set_item(
        "location",
        fixed_rows(py, labels.iter().map(|l| l.location)),
    )?;
    d.set_item("rotation_y", vec_array(py, col(&|l| l.rotation_y)))?;
    d.set_item(
        "score",
        vec_array(py, col(&|l| l.score.unwrap_or(f64::NAN))),
    )?;
    Ok(d)
}

/// Reads a tracking label file (`label_02/NNNN.txt`); see `TrackingSequence.labels`.
#[pyfunction]
fn read_tracking_labels<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyDict>> {
    let labels = lib(py.detach(|| kitti::read_tracking_labels(&path)))?;
    labels_dict(py, &labels)
}

/// A KITTI raw drive: `RawDrive("…/2011_09_26/2011_09_26_drive_0005_sync")`.
#[pyclass(name = "RawDrive", module = "smc_lmb", frozen)]
struct PyRawDrive(RawDrive);

#[pymethods]
impl PyRawDrive {
    #[new]
    fn new(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        Ok(PyRawDrive(lib(py.detach(|| RawDrive::open(&path)))?))
    }
    /// The drive's name (its folder).
    #[getter]
    fn name(&self) -> String {
        self.0.name()
    }
    /// Number of frames, dropped scans inside the numbering included (see `has_scan`).
    #[getter]
    fn frame_count(&self) -> usize {
        self.0.frame_count()
    }
    /// Whether frame `k` has a scan (KITTI drops one now and then, e.g. drive 0009's 177–180).
    fn has_scan(&self, k: usize) -> bool {
        self.0.has_scan(k)
    }
    /// Velodyne scan `k` as an `N × 4` float32 array.
    fn velodyne<'py>(&self, py: Python<'py>, k: usize) -> PyResult<Bound<'py, PyArray2<f32>>> {
        let cloud = lib(py.detach(|| self.0.scan(k)))?;
        Ok(cloud_array(py, cloud))
    }
    /// Velodyne poses (`K × 4 × 4`): pose k maps frame-k Velodyne coordinates to frame 0.
    fn poses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<f64>>> {
        let poses = lib(py.detach(|| self.0.poses()))?;
        Ok(poses_array(py, &poses))
    }
    /// Velodyne time stamps, seconds since the first.
    fn times<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let t = lib(py.detach(|| self.0.timestamps()))?;
        Ok(vec_array(py, t.seconds))
    }
    /// Planar vehicle states `[X, Ẋ, Y, Ẏ, φ, φ̇]` from OXTS (`K × 6`).
    fn vehicle_states<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let s = lib(py.detach(|| self.0.vehicle_states()))?;
        Ok(fixed_rows(py, s.iter().map(|s| s.to_array())))
    }
    fn __repr__(&self) -> String {
        format!(
            "RawDrive({:?}, {} frames)",
            self.0.dir(),
            self.0.frame_count()
        )
    }
}

/// A KITTI odometry sequence: `OdometrySequence(root, 0)` for `root/sequences/00`.
#[pyclass(name = "OdometrySequence", module = "smc_lmb", frozen)]
struct PyOdometrySequence(OdometrySequence);

#[pymethods]
impl PyOdometrySequence {
    #[new]
    fn new(py: Python<'_>, root: PathBuf, sequence: u32) -> PyResult<Self> {
        Ok(PyOdometrySequence(lib(
            py.detach(|| OdometrySequence::open(&root, sequence))
        )?))
    }
    /// The sequence's name (`00`, …).
    #[getter]
    fn name(&self) -> String {
        self.0.name().to_string()
    }
    /// Number of frames.
    #[getter]
    fn frame_count(&self) -> usize {
        self.0.frame_count()
    }
    /// Velodyne scan `k` as an `N × 4` float32 array.
    fn velodyne<'py>(&self, py: Python<'py>, k: usize) -> PyResult<Bound<'py, PyArray2<f32>>> {
        let cloud = lib(py.detach(|| self.0.scan(k)))?;
        Ok(cloud_array(py, cloud))
    }
    /// Ground-truth Velodyne poses (`K × 4 × 4`, frame k → frame 0; sequences 00–10).
    fn poses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<f64>>> {
        let poses = lib(py.detach(|| self.0.velodyne_poses()))?;
        Ok(poses_array(py, &poses))
    }
    /// Frame times (`times.txt`), seconds.
    fn times<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let t = lib(py.detach(|| self.0.times()))?;
        Ok(vec_array(py, t))
    }
}

/// A KITTI tracking sequence: `TrackingSequence(root, 0)` for `root/velodyne/0000`,
/// `root/oxts/0000.txt`, `root/calib/0000.txt`, `root/label_02/0000.txt`.
#[pyclass(name = "TrackingSequence", module = "smc_lmb", frozen)]
struct PyTrackingSequence(TrackingSequence);

#[pymethods]
impl PyTrackingSequence {
    #[new]
    fn new(py: Python<'_>, root: PathBuf, sequence: u32) -> PyResult<Self> {
        Ok(PyTrackingSequence(lib(
            py.detach(|| TrackingSequence::open(&root, sequence))
        )?))
    }
    /// The sequence's name (`0000`, …).
    #[getter]
    fn name(&self) -> String {
        self.0.name().to_string()
    }
    /// Number of frames, dropped scans inside the numbering included (see `has_scan`).
    #[getter]
    fn frame_count(&self) -> usize {
        self.0.frame_count()
    }
    /// Whether frame `k` has a scan (sequence 0001 has none for frames 177–180).
    fn has_scan(&self, k: usize) -> bool {
        self.0.has_scan(k)
    }
    /// Velodyne scan `k` as an `N × 4` float32 array.
    fn velodyne<'py>(&self, py: Python<'py>, k: usize) -> PyResult<Bound<'py, PyArray2<f32>>> {
        let cloud = lib(py.detach(|| self.0.scan(k)))?;
        Ok(cloud_array(py, cloud))
    }
    /// Velodyne poses from OXTS (`K × 4 × 4`, frame k → frame 0).
    fn poses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<f64>>> {
        let poses = lib(py.detach(|| self.0.poses()))?;
        Ok(poses_array(py, &poses))
    }
    /// Frame times, seconds (k × 0.1: the layout keeps no stamps).
    fn times<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        vec_array(py, self.0.times())
    }
    /// The sequence's `label_02` labels as a dict of arrays (see `read_tracking_labels`).
    fn labels<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let labels = lib(py.detach(|| self.0.labels()))?;
        labels_dict(py, &labels)
    }
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(read_kitti_bin, m)?)?;
    m.add_function(wrap_pyfunction!(read_tracking_labels, m)?)?;
    m.add_class::<PyRawDrive>()?;
    m.add_class::<PyOdometrySequence>()?;
    m.add_class::<PyTrackingSequence>()?;
    Ok(())
}
