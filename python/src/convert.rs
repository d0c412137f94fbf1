//! Conversions at the border: NumPy arrays (or anything `numpy.asarray` accepts) to the
//! library's row tables and poses, its results back to arrays, and its errors to Python
//! exceptions.
//!
//! Not for: checking what the values mean; the library does that and its errors come back
//! through [`to_py_err`].

use nalgebra::{Isometry3, Matrix3, Matrix4, Rotation3, Translation3, UnitQuaternion};
use numpy::ndarray::{Array2, ShapeBuilder};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3, PyArrayMethods};
use pyo3::exceptions::{PyFileNotFoundError, PyOSError, PyPermissionError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

/// A library error as a Python exception: I/O problems as `OSError` (`FileNotFoundError`,
/// `PermissionError` where they apply), everything else (bad
/// values, parse errors) as `ValueError`, with the library's message (file, line, field).
pub fn to_py_err(e: smc_lmb::Error) -> PyErr {
    match e {
        smc_lmb::Error::Io { ref source, .. } => match source.kind() {
            std::io::ErrorKind::NotFound => PyFileNotFoundError::new_err(e.to_string()),
            std::io::ErrorKind::PermissionDenied => PyPermissionError::new_err(e.to_string()),
            _ => PyOSError::new_err(e.to_string()),
        },
        _ => PyValueError::new_err(e.to_string()),
    }
}

/// Shorthand for converting a library result.
pub fn lib<T>(r: smc_lmb::Result<T>) -> PyResult<T> {
    r.map_err(to_py_err)
}

/// A row-major table of `rows × cols` values.
#[derive(Clone, Debug, Default)]
pub struct Table {
    pub rows: usize,
    pub cols: usize,
    pub data: Vec<f64>,
}

impl Table {
    /// Row `i`.
    pub fn row(&self, i: usize) -> &[f64] {
        &self.data[i * self.cols..(i + 1) * self.cols]
    }

    /// The rows as slices.
    pub fn row_slices(&self) -> Vec<&[f64]> {
        (0..self.rows).map(|i| self.row(i)).collect()
    }
}

/// `obj` as a float64 array (of any number of dimensions) through `numpy.asarray`.
fn as_f64_array<'py>(
    obj: &Bound<'py, PyAny>,
    what: &str,
) -> PyResult<Bound<'py, numpy::PyArrayDyn<f64>>> {
    let py = obj.py();
    let np = py.import("numpy")?;
    np.getattr("asarray")?
        .call((obj, "float64"), None)
        .map_err(|e| PyValueError::new_err(format!("{what}: not a numeric array ({e})")))?
        .cast_into::<numpy::PyArrayDyn<f64>>()
        .map_err(|_| {
            PyValueError::new_err(format!(
                "{what}: numpy.asarray did not give a float64 array"
            ))
        })
}

/// A 2-D table (`M × d`) from any array-like; an empty 1-D array or list is 0 rows of
/// `empty_cols` columns.
pub fn table(obj: &Bound<'_, PyAny>, what: &str, empty_cols: usize) -> PyResult<Table> {
    let arr = as_f64_array(obj, what)?;
    let ro = arr.readonly();
    let view = ro.as_array();
    match view.ndim() {
        1 if view.is_empty() => Ok(Table {
            rows: 0,
            cols: empty_cols,
            data: Vec::new(),
        }),
        2 => {
            let (rows, cols) = (view.shape()[0], view.shape()[1]);
            Ok(Table {
                rows,
                cols,
                data: view.iter().copied().collect(),
            })
        }
        n => Err(PyValueError::new_err(format!(
            "{what}: expected a 2-D array (rows × components), got {n} dimension(s) of shape {:?}",
            view.shape()
        ))),
    }
}

/// A 1-D float vector from any array-like.
pub fn vector(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<f64>> {
    let arr = as_f64_array(obj, what)?;
    let ro = arr.readonly();
    let view = ro.as_array();
    if view.ndim() != 1 {
        return Err(PyValueError::new_err(format!(
            "{what}: expected a 1-D array, got shape {:?}",
            view.shape()
        )));
    }
    Ok(view.iter().copied().collect())
}

/// A rigid pose from a 4 × 4 homogeneous matrix (rotation part re-orthonormalised only if it
/// is a rotation to 1e-6).
pub fn pose(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Isometry3<f64>> {
    let t = table(obj, what, 4)?;
    if t.rows != 4 || t.cols != 4 {
        return Err(PyValueError::new_err(format!(
            "{what}: expected a 4 × 4 matrix, got {} × {}",
            t.rows, t.cols
        )));
    }
    let m = Matrix4::from_row_slice(&t.data);
    if m.iter().any(|v| !v.is_finite()) {
        return Err(PyValueError::new_err(format!("{what}: not finite")));
    }
    let r: Matrix3<f64> = m.fixed_view::<3, 3>(0, 0).into_owned();
    let orthogonal = (r.transpose() * r - Matrix3::identity()).amax() < 1e-6;
    if !orthogonal || r.determinant() < 0.0 || (m.row(3) - Matrix4::identity().row(3)).amax() > 1e-9
    {
        return Err(PyValueError::new_err(format!(
            "{what}: not a rigid motion (rotation part not orthonormal with determinant 1, or last row not [0, 0, 0, 1])"
        )));
    }
    let rot = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r));
    Ok(Isometry3::from_parts(
        Translation3::new(m[(0, 3)], m[(1, 3)], m[(2, 3)]),
        rot,
    ))
}

/// Poses as a `K × 4 × 4` array of homogeneous matrices.
pub fn poses_array<'py>(py: Python<'py>, poses: &[Isometry3<f64>]) -> Bound<'py, PyArray3<f64>> {
    let mut data = Vec::with_capacity(poses.len() * 16);
    for p in poses {
        let m = p.to_homogeneous();
        for r in 0..4 {
            for c in 0..4 {
                data.push(m[(r, c)]);
            }
        }
    }
    numpy::ndarray::Array3::from_shape_vec((poses.len(), 4, 4), data)
        .expect("16 values per pose")
        .into_pyarray(py)
}

/// Row-major values as an `rows × cols` array.
pub fn rows_array<'py>(
    py: Python<'py>,
    rows: usize,
    cols: usize,
    data: Vec<f64>,
) -> Bound<'py, PyArray2<f64>> {
    Array2::from_shape_vec((rows, cols), data)
        .expect("rows × cols values")
        .into_pyarray(py)
}

/// Column-major values (`cols` columns of `rows` each, one after the other) as an
/// `rows × cols` array in Fortran order, without reordering them.
pub fn columns_array<'py>(
    py: Python<'py>,
    rows: usize,
    cols: usize,
    data: Vec<f64>,
) -> Bound<'py, PyArray2<f64>> {
    Array2::from_shape_vec((rows, cols).f(), data)
        .expect("rows × cols values")
        .into_pyarray(py)
}

/// A vector as a 1-D array.
pub fn vec_array<'py, T: numpy::Element>(py: Python<'py>, v: Vec<T>) -> Bound<'py, PyArray1<T>> {
    v.into_pyarray(py)
}

/// Fixed-size rows as an `n × N` array.
pub fn fixed_rows<'py, const N: usize>(
    py: Python<'py>,
    rows: impl IntoIterator<Item = [f64; N]>,
) -> Bound<'py, PyArray2<f64>> {
    let data: Vec<f64> = rows.into_iter().flatten().collect();
    let n = data.len() / N;
    rows_array(py, n, N, data)
}

/// Reads a configuration of type `T` (any serde type of the library) from a dict (through
/// JSON) or TOML text; errors name `what` and, for TOML, the line.
pub fn read_config_as<T: serde::de::DeserializeOwned>(
    config: &Bound<'_, PyAny>,
    what: &str,
) -> PyResult<T> {
    if let Ok(s) = config.cast::<PyString>() {
        let text = s.to_str()?;
        return toml::from_str(text).map_err(|e| {
            let line = e.span().map_or(0, |sp| {
                1 + text.as_bytes()[..sp.start.min(text.len())]
                    .iter()
                    .filter(|&&b| b == b'\n')
                    .count()
            });
            PyValueError::new_err(format!("{what} (TOML) line {line}: {}", e.message()))
        });
    }
    if config.cast::<PyDict>().is_ok() {
        let json = config
            .py()
            .import("json")?
            .getattr("dumps")?
            .call1((config,))?;
        let text: String = json.extract()?;
        return serde_json::from_str(&text)
            .map_err(|e| PyValueError::new_err(format!("{what}: {e}")));
    }
    Err(PyValueError::new_err(format!(
        "{what}: expected a dict or TOML text"
    )))
}
