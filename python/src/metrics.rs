//! Multi-object metrics for Python: OSPA and GOSPA between two point sets (arrays `M × d`),
//! OSPA(2) between two sets of tracks over a window (each track an array `T × d` whose rows of
//! NaN mark the steps where it is absent).
//!
//! Not for: the metrics' definitions (`smc_lmb::metrics`).

use crate::convert::{lib, table, vec_array, Table};
use numpy::PyArray1;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use smc_lmb::metrics::{self, TrackHistory};

fn points(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<Vec<f64>>> {
    let t = table(obj, what, 0)?;
    Ok((0..t.rows).map(|i| t.row(i).to_vec()).collect())
}

/// OSPA distance of cut-off `c` and order `p` between point sets `x` and `y` (`M × d`
/// arrays). Returns `{"distance", "localisation", "cardinality"}`.
#[pyfunction]
#[pyo3(signature = (x, y, c, p=1.0))]
fn ospa<'py>(
    py: Python<'py>,
    x: &Bound<'py, PyAny>,
    y: &Bound<'py, PyAny>,
    c: f64,
    p: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let (x, y) = (points(x, "x")?, points(y, "y")?);
    let o = lib(py.detach(|| metrics::ospa(&x, &y, c, p)))?;
    let d = PyDict::new(py);
    d.set_item("distance", o.distance)?;
    d.set_item("localisation", o.localisation)?;
    d.set_item("cardinality", o.cardinality)?;
    Ok(d)
}

/// GOSPA (α = 2) of cut-off `c` and order `p` between `truth` and `estimates` (`M × d`
/// arrays). Returns `{"distance", "localisation", "missed", "false_alarms", "n_missed",
/// "n_false"}`.
#[pyfunction]
#[pyo3(signature = (truth, estimates, c, p=1.0))]
fn gospa<'py>(
    py: Python<'py>,
    truth: &Bound<'py, PyAny>,
    estimates: &Bound<'py, PyAny>,
    c: f64,
    p: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let (x, y) = (points(truth, "truth")?, points(estimates, "estimates")?);
    let g = lib(py.detach(|| metrics::gospa(&x, &y, c, p)))?;
    let d = PyDict::new(py);
    d.set_item("distance", g.distance)?;
    d.set_item("localisation", g.localisation)?;
    d.set_item("missed", g.missed)?;
    d.set_item("false_alarms", g.false_alarms)?;
    d.set_item("n_missed", g.n_missed)?;
    d.set_item("n_false", g.n_false)?;
    Ok(d)
}

/// Tracks as histories: track `i` is a `T_i × d` array, rows holding a NaN are absences.
fn histories(tracks: &[Bound<'_, PyAny>], what: &str) -> PyResult<Vec<TrackHistory>> {
    tracks
        .iter()
        .enumerate()
        .map(|(i, t)| {
            let t: Table = table(t, &format!("{what}[{i}]"), 0)?;
            let states = (0..t.rows)
                .map(|k| {
                    let r = t.row(k);
                    if r.iter().any(|v| v.is_nan()) {
                        None
                    } else {
                        Some(r.to_vec())
                    }
                })
                .collect();
            Ok(TrackHistory::new(i as u64, states))
        })
        .collect()
}

/// OSPA(2) between track sets `truth` and `estimated` (lists of `T × d` arrays, NaN rows where
/// a track is absent) over the steps `window = (start, end)` (default: all steps), with
/// cut-off `c`, order `p` and time-averaging order `q`. Returns `{"distance",
/// "localisation", "cardinality"}`.
#[pyfunction]
#[pyo3(signature = (truth, estimated, c, p=1.0, q=1.0, window=None))]
fn ospa2<'py>(
    py: Python<'py>,
    truth: Vec<Bound<'py, PyAny>>,
    estimated: Vec<Bound<'py, PyAny>>,
    c: f64,
    p: f64,
    q: f64,
    window: Option<(usize, usize)>,
) -> PyResult<Bound<'py, PyDict>> {
    let (a, b) = (
        histories(&truth, "truth")?,
        histories(&estimated, "estimated")?,
    );
    let steps = a
        .iter()
        .chain(&b)
        .map(|t| t.states.len())
        .max()
        .unwrap_or(0);
    let (start, end) = window.unwrap_or((0, steps));
    if start > end {
        return Err(PyValueError::new_err(format!(
            "window: start {start} after end {end}"
        )));
    }
    let o = lib(py.detach(|| metrics::ospa2_parts(&a, &b, start..end, c, p, q)))?;
    let d = PyDict::new(py);
    d.set_item("distance", o.distance)?;
    d.set_item("localisation", o.localisation)?;
    d.set_item("cardinality", o.cardinality)?;
    Ok(d)
}

/// OSPA(2) over a sliding window of `window_len` steps ending at every step (see `ospa2`).
#[pyfunction]
#[pyo3(signature = (truth, estimated, window_len, c, p=1.0, q=1.0))]
fn ospa2_series<'py>(
    py: Python<'py>,
    truth: Vec<Bound<'py, PyAny>>,
    estimated: Vec<Bound<'py, PyAny>>,
    window_len: usize,
    c: f64,
    p: f64,
    q: f64,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let (a, b) = (
        histories(&truth, "truth")?,
        histories(&estimated, "estimated")?,
    );
    let s = lib(py.detach(|| metrics::ospa2_series(&a, &b, window_len, c, p, q)))?;
    Ok(vec_array(py, s))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(ospa, m)?)?;
    m.add_function(wrap_pyfunction!(gospa, m)?)?;
    m.add_function(wrap_pyfunction!(ospa2, m)?)?;
    m.add_function(wrap_pyfunction!(ospa2_series, m)?)?;
    Ok(())
}
