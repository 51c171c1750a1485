//! The module functions of the binding before `Engine` (`matrices`, `rows`, `gvr_*`, `fecg_*`),
//! kept, with their positional signatures, as thin wrappers of one `Engine` call each until
//! the Python side uses `Engine`.
use numpy::PyArray2;
use prebo_core::engine::{Engine, Kind, Representation};
use prebo_core::family::Directions;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use crate::convert::{self, dict, floats, matrix, OwnedParams, Result, Rows};
use crate::representation;

type Any<'py> = Bound<'py, PyAny>;

/// The setup arrays as the old functions take them.
struct Setup<'a, 'py>([&'a Any<'py>; 5], Option<f64>);

impl Setup<'_, '_> {
    fn engine(&self, kind: Kind, n_ang: u32) -> Result<Engine> {
        let [lam, w, q, t, c] = self.0;
        let rep: Representation = representation(lam, w, q, t, c, self.1)?;
        Ok(Engine::new(kind, rep, n_ang)?)
    }
}

fn params<'py>(kind: Kind, arrays: &[&Any<'py>]) -> Result<OwnedParams> {
    let t = PyTuple::new(arrays[0].py(), arrays)?;
    OwnedParams::new(kind, t.as_any())
}

fn matrices_of<'py>(py: Python<'py>, e: Engine, b: OwnedParams) -> Result<Bound<'py, PyDict>> {
    let m = py.allow_threads(|| e.matrices(&b.view()))?;
    Ok(dict(py, m)?)
}

fn rows_of<'py>(py: Python<'py>, e: Engine, t: OwnedParams, b: OwnedParams, pos: Option<usize>) -> Result<Rows<'py>> {
    let out = py.allow_threads(|| e.rows(&t.view(), &b.view(), pos))?;
    convert::rows(py, out)
}

fn gradient_of<'py>(
    py: Python<'py>,
    e: Engine,
    t: OwnedParams,
    da: &Any,
    dv: &Any,
    b: OwnedParams,
) -> Result<Rows<'py>> {
    let (da, dv) = (floats(da, "d_a")?, floats(dv, "d_v")?);
    let out = py.allow_threads(|| e.row_gradient(&t.view(), &Directions { a: &da, v: &dv }, &b.view()))?;
    convert::rows(py, out)
}

/// Symmetrised matrices `{"S", "T", "T_ti", "V"}` of a plain-ECG basis.
#[pyfunction]
#[pyo3(signature = (a, c_a, lambda_, pair_w, pair_q, sym_t, sym_c, cm_mass=None))]
#[allow(clippy::too_many_arguments)]
fn matrices<'py>(
    py: Python<'py>,
    a: &Any<'py>,
    c_a: &Any<'py>,
    lambda_: &Any<'py>,
    pair_w: &Any<'py>,
    pair_q: &Any<'py>,
    sym_t: &Any<'py>,
    sym_c: &Any<'py>,
    cm_mass: Option<f64>,
) -> Result<Bound<'py, PyDict>> {
    let e = Setup([lambda_, pair_w, pair_q, sym_t, sym_c], cm_mass).engine(Kind::Pecg, 0)?;
    matrices_of(py, e, params(Kind::Pecg, &[a, c_a])?)
}

/// Rows (k x nb) of plain-ECG trials against a basis (trial as bra), and the diagonals (k x 4).
#[pyfunction]
#[pyo3(signature = (trial_a, trial_c_a, a, c_a, lambda_, pair_w, pair_q, sym_t, sym_c, cm_mass=None))]
#[allow(clippy::too_many_arguments)]
fn rows<'py>(
    py: Python<'py>,
    trial_a: &Any<'py>,
    trial_c_a: &Any<'py>,
    a: &Any<'py>,
    c_a: &Any<'py>,
    lambda_: &Any<'py>,
    pair_w: &Any<'py>,
    pair_q: &Any<'py>,
    sym_t: &Any<'py>,
    sym_c: &Any<'py>,
    cm_mass: Option<f64>,
) -> Result<Rows<'py>> {
    let e = Setup([lambda_, pair_w, pair_q, sym_t, sym_c], cm_mass).engine(Kind::Pecg, 0)?;
    rows_of(
        py,
        e,
        params(Kind::Pecg, &[trial_a, trial_c_a])?,
        params(Kind::Pecg, &[a, c_a])?,
        None,
    )
}

/// Symmetrised matrices of an ECG-GVR basis (angular momentum `n_ang`, M = N).
#[pyfunction]
#[pyo3(signature = (a, u, k, c_a, n_ang, lambda_, pair_w, pair_q, sym_t, sym_c, cm_mass=None))]
#[allow(clippy::too_many_arguments)]
fn gvr_matrices<'py>(
    py: Python<'py>,
    a: &Any<'py>,
    u: &Any<'py>,
    k: &Any<'py>,
    c_a: &Any<'py>,
    n_ang: u32,
    lambda_: &Any<'py>,
    pair_w: &Any<'py>,
    pair_q: &Any<'py>,
    sym_t: &Any<'py>,
    sym_c: &Any<'py>,
    cm_mass: Option<f64>,
) -> Result<Bound<'py, PyDict>> {
    let e = Setup([lambda_, pair_w, pair_q, sym_t, sym_c], cm_mass).engine(Kind::EcgGvr, n_ang)?;
    matrices_of(py, e, params(Kind::EcgGvr, &[a, u, k, c_a])?)
}

/// Rows (k x nb) of ECG-GVR trials against a basis (oriented for `position`), diagonals (k x 4).
#[pyfunction]
#[pyo3(signature = (trial_a, trial_u, trial_k, trial_c_a, a, u, k, c_a, n_ang, lambda_, pair_w, pair_q, sym_t, sym_c, cm_mass=None, position=None))]
#[allow(clippy::too_many_arguments)]
fn gvr_rows<'py>(
    py: Python<'py>,
    trial_a: &Any<'py>,
    trial_u: &Any<'py>,
    trial_k: &Any<'py>,
    trial_c_a: &Any<'py>,
    a: &Any<'py>,
    u: &Any<'py>,
    k: &Any<'py>,
    c_a: &Any<'py>,
    n_ang: u32,
    lambda_: &Any<'py>,
    pair_w: &Any<'py>,
    pair_q: &Any<'py>,
    sym_t: &Any<'py>,
    sym_c: &Any<'py>,
    cm_mass: Option<f64>,
    position: Option<usize>,
) -> Result<Rows<'py>> {
    let e = Setup([lambda_, pair_w, pair_q, sym_t, sym_c], cm_mass).engine(Kind::EcgGvr, n_ang)?;
    let t = params(Kind::EcgGvr, &[trial_a, trial_u, trial_k, trial_c_a])?;
    rows_of(py, e, t, params(Kind::EcgGvr, &[a, u, k, c_a])?, position)
}

/// The row of one ECG-GVR function against a basis and its diagonal, with derivatives along
/// `(d_a[p], d_u[p])`: dict of `(1 + P) x nb` arrays (row 0 the values), `(1 + P) x 4` diagonal.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn gvr_row_gradient<'py>(
    py: Python<'py>,
    trial_a: &Any<'py>,
    trial_u: &Any<'py>,
    trial_k: &Any<'py>,
    trial_c_a: &Any<'py>,
    d_a: &Any<'py>,
    d_u: &Any<'py>,
    a: &Any<'py>,
    u: &Any<'py>,
    k: &Any<'py>,
    c_a: &Any<'py>,
    n_ang: u32,
    lambda_: &Any<'py>,
    pair_w: &Any<'py>,
    pair_q: &Any<'py>,
    sym_t: &Any<'py>,
    sym_c: &Any<'py>,
    cm_mass: Option<f64>,
) -> Result<Rows<'py>> {
    let e = Setup([lambda_, pair_w, pair_q, sym_t, sym_c], cm_mass).engine(Kind::EcgGvr, n_ang)?;
    let t = params(Kind::EcgGvr, &[trial_a, trial_u, trial_k, trial_c_a])?;
    gradient_of(py, e, t, d_a, d_u, params(Kind::EcgGvr, &[a, u, k, c_a])?)
}

/// Symmetrised matrices of a floating-ECG basis.
#[pyfunction]
#[pyo3(signature = (a, s, c_a, lambda_, pair_w, pair_q, sym_t, sym_c, cm_mass=None))]
#[allow(clippy::too_many_arguments)]
fn fecg_matrices<'py>(
    py: Python<'py>,
    a: &Any<'py>,
    s: &Any<'py>,
    c_a: &Any<'py>,
    lambda_: &Any<'py>,
    pair_w: &Any<'py>,
    pair_q: &Any<'py>,
    sym_t: &Any<'py>,
    sym_c: &Any<'py>,
    cm_mass: Option<f64>,
) -> Result<Bound<'py, PyDict>> {
    let e = Setup([lambda_, pair_w, pair_q, sym_t, sym_c], cm_mass).engine(Kind::Fecg, 0)?;
    matrices_of(py, e, params(Kind::Fecg, &[a, s, c_a])?)
}

/// Rows (k x nb) of floating-ECG trials against a basis (oriented for `position`), diagonals (k x 4).
#[pyfunction]
#[pyo3(signature = (trial_a, trial_s, trial_c_a, a, s, c_a, lambda_, pair_w, pair_q, sym_t, sym_c, cm_mass=None, position=None))]
#[allow(clippy::too_many_arguments)]
fn fecg_rows<'py>(
    py: Python<'py>,
    trial_a: &Any<'py>,
    trial_s: &Any<'py>,
    trial_c_a: &Any<'py>,
    a: &Any<'py>,
    s: &Any<'py>,
    c_a: &Any<'py>,
    lambda_: &Any<'py>,
    pair_w: &Any<'py>,
    pair_q: &Any<'py>,
    sym_t: &Any<'py>,
    sym_c: &Any<'py>,
    cm_mass: Option<f64>,
    position: Option<usize>,
) -> Result<Rows<'py>> {
    let e = Setup([lambda_, pair_w, pair_q, sym_t, sym_c], cm_mass).engine(Kind::Fecg, 0)?;
    let t = params(Kind::Fecg, &[trial_a, trial_s, trial_c_a])?;
    rows_of(py, e, t, params(Kind::Fecg, &[a, s, c_a])?, position)
}

/// `gvr_row_gradient` for floating ECGs: directions `(d_a[p], d_s[p])`.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn fecg_row_gradient<'py>(
    py: Python<'py>,
    trial_a: &Any<'py>,
    trial_s: &Any<'py>,
    trial_c_a: &Any<'py>,
    d_a: &Any<'py>,
    d_s: &Any<'py>,
    a: &Any<'py>,
    s: &Any<'py>,
    c_a: &Any<'py>,
    lambda_: &Any<'py>,
    pair_w: &Any<'py>,
    pair_q: &Any<'py>,
    sym_t: &Any<'py>,
    sym_c: &Any<'py>,
    cm_mass: Option<f64>,
) -> Result<Rows<'py>> {
    let e = Setup([lambda_, pair_w, pair_q, sym_t, sym_c], cm_mass).engine(Kind::Fecg, 0)?;
    let t = params(Kind::Fecg, &[trial_a, trial_s, trial_c_a])?;
    gradient_of(py, e, t, d_a, d_s, params(Kind::Fecg, &[a, s, c_a])?)
}

/// The symmetrised translation-free `<N²>` matrix of a floating-ECG basis; `mu` = m/m_tot.
#[pyfunction]
#[pyo3(signature = (a, s, c_a, mu, lambda_, pair_w, pair_q, sym_t, sym_c))]
#[allow(clippy::too_many_arguments)]
fn fecg_angular<'py>(
    py: Python<'py>,
    a: &Any<'py>,
    s: &Any<'py>,
    c_a: &Any<'py>,
    mu: &Any<'py>,
    lambda_: &Any<'py>,
    pair_w: &Any<'py>,
    pair_q: &Any<'py>,
    sym_t: &Any<'py>,
    sym_c: &Any<'py>,
) -> Result<Bound<'py, PyArray2<f64>>> {
    let e = Setup([lambda_, pair_w, pair_q, sym_t, sym_c], None).engine(Kind::Fecg, 0)?;
    let (b, mu) = (params(Kind::Fecg, &[a, s, c_a])?, floats(mu, "mu")?);
    let nb = b.view().len();
    let m = py.allow_threads(|| e.angular(&b.view(), &mu))?;
    Ok(matrix(py, nb, nb, m))
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(matrices, m)?)?;
    m.add_function(wrap_pyfunction!(rows, m)?)?;
    m.add_function(wrap_pyfunction!(gvr_matrices, m)?)?;
    m.add_function(wrap_pyfunction!(gvr_rows, m)?)?;
    m.add_function(wrap_pyfunction!(gvr_row_gradient, m)?)?;
    m.add_function(wrap_pyfunction!(fecg_matrices, m)?)?;
    m.add_function(wrap_pyfunction!(fecg_rows, m)?)?;
    m.add_function(wrap_pyfunction!(fecg_row_gradient, m)?)?;
    m.add_function(wrap_pyfunction!(fecg_angular, m)?)?;
    Ok(())
}
