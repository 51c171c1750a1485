//! `prebo._core`: the thin PyO3 binding of prebo-core.
//! Converts numpy arrays, maps `CoreError` to `prebo.errors`, releases the GIL.
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArray3};
use prebo_core::ecg::Element;
use prebo_core::api::{self, Directions, FecgFunctions, Functions, GvrFunctions, Setup};
use prebo_core::build::Matrices;
use prebo_core::CoreError;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

pyo3::import_exception!(prebo.errors, NotPositiveDefiniteError);
pyo3::import_exception!(prebo.errors, ShapeError);
pyo3::import_exception!(prebo.errors, UnsupportedError);

fn to_py(e: CoreError) -> PyErr {
    let msg = e.to_string();
    match e {
        CoreError::NotPositiveDefinite { .. } => NotPositiveDefiniteError::new_err(msg),
        CoreError::ShapeMismatch(_) => ShapeError::new_err(msg),
        CoreError::Unsupported(_) => UnsupportedError::new_err(msg),
    }
}

fn slice<'a, T: numpy::Element, D: numpy::ndarray::Dimension>(
    a: &'a numpy::PyReadonlyArray<'_, T, D>,
    what: &str,
) -> PyResult<&'a [T]> {
    a.as_slice().map_err(|_| PyValueError::new_err(format!("{what} must be a C-contiguous array")))
}

type Arr2<'py> = Bound<'py, PyArray2<f64>>;

fn matrix<'py>(py: Python<'py>, rows: usize, cols: usize, v: Vec<f64>) -> Arr2<'py> {
    Array2::from_shape_vec((rows, cols), v).expect("rows x cols values").into_pyarray(py)
}

fn dict<'py>(py: Python<'py>, m: Matrices) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
    let d = pyo3::types::PyDict::new(py);
    d.set_item("S", matrix(py, m.rows, m.cols, m.s))?;
    d.set_item("T", matrix(py, m.rows, m.cols, m.t))?;
    d.set_item("T_ti", matrix(py, m.rows, m.cols, m.t_ti))?;
    d.set_item("V", matrix(py, m.rows, m.cols, m.v))?;
    Ok(d)
}

/// Owned copies of the setup arrays, so that the GIL can be released.
struct SetupData {
    n: usize,
    lambda: Vec<f64>,
    pair_w: Vec<f64>,
    pair_q: Vec<f64>,
    sym_t: Vec<f64>,
    sym_c: Vec<f64>,
    cm_mass: Option<f64>,
}

impl SetupData {
    fn view(&self) -> Setup<'_> {
        Setup {
            n: self.n,
            lambda: &self.lambda,
            pair_w: &self.pair_w,
            pair_q: &self.pair_q,
            sym_t: &self.sym_t,
            sym_c: &self.sym_c,
            cm_mass: self.cm_mass,
        }
    }
}

#[allow(clippy::too_many_arguments)]
fn setup_data(
    lambda: PyReadonlyArray2<f64>,
    pair_w: PyReadonlyArray2<f64>,
    pair_q: PyReadonlyArray1<f64>,
    sym_t: PyReadonlyArray3<f64>,
    sym_c: PyReadonlyArray1<f64>,
    cm_mass: Option<f64>,
) -> PyResult<SetupData> {
    Ok(SetupData {
        n: lambda.as_array().nrows(),
        lambda: slice(&lambda, "lambda")?.to_vec(),
        pair_w: slice(&pair_w, "pair_w")?.to_vec(),
        pair_q: slice(&pair_q, "pair_q")?.to_vec(),
        sym_t: slice(&sym_t, "sym_t")?.to_vec(),
        sym_c: slice(&sym_c, "sym_c")?.to_vec(),
        cm_mass,
    })
}

/// Symmetrised matrices `{"S", "T", "T_ti", "V"}` of a plain-ECG basis.
#[pyfunction]
#[pyo3(signature = (a, c_a, lambda_, pair_w, pair_q, sym_t, sym_c, cm_mass=None))]
#[allow(clippy::too_many_arguments)]
fn matrices<'py>(
    py: Python<'py>,
    a: PyReadonlyArray3<f64>,
    c_a: PyReadonlyArray1<f64>,
    lambda_: PyReadonlyArray2<f64>,
    pair_w: PyReadonlyArray2<f64>,
    pair_q: PyReadonlyArray1<f64>,
    sym_t: PyReadonlyArray3<f64>,
    sym_c: PyReadonlyArray1<f64>,
    cm_mass: Option<f64>,
) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
    let setup = setup_data(lambda_, pair_w, pair_q, sym_t, sym_c, cm_mass)?;
    let (a, c_a) = (slice(&a, "a")?.to_vec(), slice(&c_a, "c_a")?.to_vec());
    let m = py
        .allow_threads(|| api::matrices(&setup.view(), &Functions { a: &a, c_a: &c_a }))
        .map_err(to_py)?;
    dict(py, m)
}

/// Rows `{"S", "T", "T_ti", "V"}` (k x nb) of trial functions against a basis,
/// and the trials' diagonal elements as a k x 4 array (S, T, T_ti, V).
#[pyfunction]
#[pyo3(signature = (trial_a, trial_c_a, a, c_a, lambda_, pair_w, pair_q, sym_t, sym_c, cm_mass=None))]
#[allow(clippy::too_many_arguments)]
fn rows<'py>(
    py: Python<'py>,
    trial_a: PyReadonlyArray3<f64>,
    trial_c_a: PyReadonlyArray1<f64>,
    a: PyReadonlyArray3<f64>,
    c_a: PyReadonlyArray1<f64>,
    lambda_: PyReadonlyArray2<f64>,
    pair_w: PyReadonlyArray2<f64>,
    pair_q: PyReadonlyArray1<f64>,
    sym_t: PyReadonlyArray3<f64>,
    sym_c: PyReadonlyArray1<f64>,
    cm_mass: Option<f64>,
) -> PyResult<(Bound<'py, pyo3::types::PyDict>, Arr2<'py>)> {
    let setup = setup_data(lambda_, pair_w, pair_q, sym_t, sym_c, cm_mass)?;
    let (ta, tc) = (slice(&trial_a, "trial_a")?.to_vec(), slice(&trial_c_a, "trial_c_a")?.to_vec());
    let (a, c_a) = (slice(&a, "a")?.to_vec(), slice(&c_a, "c_a")?.to_vec());
    let (m, diag) = py
        .allow_threads(|| {
            api::rows(&setup.view(), &Functions { a: &ta, c_a: &tc }, &Functions { a: &a, c_a: &c_a })
        })
        .map_err(to_py)?;
    Ok((dict(py, m)?, diag_array(py, &diag)))
}


/// Owned ECG-GVR function arrays.
struct GvrData {
    a: Vec<f64>,
    u: Vec<f64>,
    k: Vec<u32>,
    c_a: Vec<f64>,
}

impl GvrData {
    fn new(
        a: PyReadonlyArray3<f64>,
        u: PyReadonlyArray2<f64>,
        k: PyReadonlyArray1<u32>,
        c_a: PyReadonlyArray1<f64>,
    ) -> PyResult<Self> {
        Ok(Self {
            a: slice(&a, "a")?.to_vec(),
            u: slice(&u, "u")?.to_vec(),
            k: slice(&k, "K")?.to_vec(),
            c_a: slice(&c_a, "c_a")?.to_vec(),
        })
    }

    fn view(&self) -> GvrFunctions<'_> {
        GvrFunctions { a: &self.a, u: &self.u, k: &self.k, c_a: &self.c_a }
    }
}

fn diag_array<'py>(py: Python<'py>, diag: &[Element]) -> Arr2<'py> {
    let d: Vec<f64> = diag.iter().flat_map(|e| [e.s, e.t, e.t_ti, e.v]).collect();
    matrix(py, diag.len(), 4, d)
}

/// Symmetrised matrices `{"S", "T", "T_ti", "V"}` of an ECG-GVR basis (angular momentum `n_ang`, M = N).
#[pyfunction]
#[pyo3(signature = (a, u, k, c_a, n_ang, lambda_, pair_w, pair_q, sym_t, sym_c, cm_mass=None))]
#[allow(clippy::too_many_arguments)]
fn gvr_matrices<'py>(
    py: Python<'py>,
    a: PyReadonlyArray3<f64>,
    u: PyReadonlyArray2<f64>,
    k: PyReadonlyArray1<u32>,
    c_a: PyReadonlyArray1<f64>,
    n_ang: u32,
    lambda_: PyReadonlyArray2<f64>,
    pair_w: PyReadonlyArray2<f64>,
    pair_q: PyReadonlyArray1<f64>,
    sym_t: PyReadonlyArray3<f64>,
    sym_c: PyReadonlyArray1<f64>,
    cm_mass: Option<f64>,
) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
    let setup = setup_data(lambda_, pair_w, pair_q, sym_t, sym_c, cm_mass)?;
    let basis = GvrData::new(a, u, k, c_a)?;
    let m = py.allow_threads(|| api::gvr_matrices(&setup.view(), n_ang, &basis.view())).map_err(to_py)?;
    dict(py, m)
}

/// Rows (k x nb) of ECG-GVR trial functions against a basis, and the trials' diagonals (k x 4).
#[pyfunction]
#[pyo3(signature = (trial_a, trial_u, trial_k, trial_c_a, a, u, k, c_a, n_ang, lambda_, pair_w, pair_q, sym_t, sym_c, cm_mass=None, position=None))]
#[allow(clippy::too_many_arguments)]
fn gvr_rows<'py>(
    py: Python<'py>,
    trial_a: PyReadonlyArray3<f64>,
    trial_u: PyReadonlyArray2<f64>,
    trial_k: PyReadonlyArray1<u32>,
    trial_c_a: PyReadonlyArray1<f64>,
    a: PyReadonlyArray3<f64>,
    u: PyReadonlyArray2<f64>,
    k: PyReadonlyArray1<u32>,
    c_a: PyReadonlyArray1<f64>,
    n_ang: u32,
    lambda_: PyReadonlyArray2<f64>,
    pair_w: PyReadonlyArray2<f64>,
    pair_q: PyReadonlyArray1<f64>,
    sym_t: PyReadonlyArray3<f64>,
    sym_c: PyReadonlyArray1<f64>,
    cm_mass: Option<f64>,
    position: Option<usize>,
) -> PyResult<(Bound<'py, pyo3::types::PyDict>, Arr2<'py>)> {
    let setup = setup_data(lambda_, pair_w, pair_q, sym_t, sym_c, cm_mass)?;
    let trials = GvrData::new(trial_a, trial_u, trial_k, trial_c_a)?;
    let basis = GvrData::new(a, u, k, c_a)?;
    let (m, diag) = py
        .allow_threads(|| api::gvr_rows(&setup.view(), n_ang, &trials.view(), &basis.view(), position))
        .map_err(to_py)?;
    Ok((dict(py, m)?, diag_array(py, &diag)))
}

/// The row of one ECG-GVR function against a basis, and its diagonal, with derivatives along
/// `P` directions `(d_a[p], d_u[p])`: dict of `(1 + P) x nb` arrays (row 0 the values), `(1 + P) x 4` diagonal.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn gvr_row_gradient<'py>(
    py: Python<'py>,
    trial_a: PyReadonlyArray3<f64>,
    trial_u: PyReadonlyArray2<f64>,
    trial_k: PyReadonlyArray1<u32>,
    trial_c_a: PyReadonlyArray1<f64>,
    d_a: PyReadonlyArray3<f64>,
    d_u: PyReadonlyArray2<f64>,
    a: PyReadonlyArray3<f64>,
    u: PyReadonlyArray2<f64>,
    k: PyReadonlyArray1<u32>,
    c_a: PyReadonlyArray1<f64>,
    n_ang: u32,
    lambda_: PyReadonlyArray2<f64>,
    pair_w: PyReadonlyArray2<f64>,
    pair_q: PyReadonlyArray1<f64>,
    sym_t: PyReadonlyArray3<f64>,
    sym_c: PyReadonlyArray1<f64>,
    cm_mass: Option<f64>,
) -> PyResult<(Bound<'py, pyo3::types::PyDict>, Arr2<'py>)> {
    let setup = setup_data(lambda_, pair_w, pair_q, sym_t, sym_c, cm_mass)?;
    let trial = GvrData::new(trial_a, trial_u, trial_k, trial_c_a)?;
    let basis = GvrData::new(a, u, k, c_a)?;
    let (d_a, d_u) = (slice(&d_a, "d_a")?.to_vec(), slice(&d_u, "d_u")?.to_vec());
    let (m, diag) = py
        .allow_threads(|| {
            let dir = Directions { a: &d_a, v: &d_u };
            api::gvr_row_gradient(&setup.view(), n_ang, &trial.view(), &dir, &basis.view())
        })
        .map_err(to_py)?;
    Ok((dict(py, m)?, diag_array(py, &diag)))
}


/// Owned floating-ECG arrays.
struct FecgData {
    a: Vec<f64>,
    s: Vec<f64>,
    c_a: Vec<f64>,
}

impl FecgData {
    fn new(a: PyReadonlyArray3<f64>, s: PyReadonlyArray3<f64>, c_a: PyReadonlyArray1<f64>) -> PyResult<Self> {
        Ok(Self { a: slice(&a, "a")?.to_vec(), s: slice(&s, "s")?.to_vec(), c_a: slice(&c_a, "c_a")?.to_vec() })
    }

    fn view(&self) -> FecgFunctions<'_> {
        FecgFunctions { a: &self.a, s: &self.s, c_a: &self.c_a }
    }
}

/// Symmetrised matrices `{"S", "T", "T_ti", "V"}` of a floating-ECG basis.
#[pyfunction]
#[pyo3(signature = (a, s, c_a, lambda_, pair_w, pair_q, sym_t, sym_c, cm_mass=None))]
#[allow(clippy::too_many_arguments)]
fn fecg_matrices<'py>(
    py: Python<'py>,
    a: PyReadonlyArray3<f64>,
    s: PyReadonlyArray3<f64>,
    c_a: PyReadonlyArray1<f64>,
    lambda_: PyReadonlyArray2<f64>,
    pair_w: PyReadonlyArray2<f64>,
    pair_q: PyReadonlyArray1<f64>,
    sym_t: PyReadonlyArray3<f64>,
    sym_c: PyReadonlyArray1<f64>,
    cm_mass: Option<f64>,
) -> PyResult<Bound<'py, pyo3::types::PyDict>> {
    let setup = setup_data(lambda_, pair_w, pair_q, sym_t, sym_c, cm_mass)?;
    let basis = FecgData::new(a, s, c_a)?;
    let m = py.allow_threads(|| api::fecg_matrices(&setup.view(), &basis.view())).map_err(to_py)?;
    dict(py, m)
}

/// Rows (k x nb) of floating-ECG trial functions against a basis, and the trials' diagonals (k x 4).
#[pyfunction]
#[pyo3(signature = (trial_a, trial_s, trial_c_a, a, s, c_a, lambda_, pair_w, pair_q, sym_t, sym_c, cm_mass=None, position=None))]
#[allow(clippy::too_many_arguments)]
fn fecg_rows<'py>(
    py: Python<'py>,
    trial_a: PyReadonlyArray3<f64>,
    trial_s: PyReadonlyArray3<f64>,
    trial_c_a: PyReadonlyArray1<f64>,
    a: PyReadonlyArray3<f64>,
    s: PyReadonlyArray3<f64>,
    c_a: PyReadonlyArray1<f64>,
    lambda_: PyReadonlyArray2<f64>,
    pair_w: PyReadonlyArray2<f64>,
    pair_q: PyReadonlyArray1<f64>,
    sym_t: PyReadonlyArray3<f64>,
    sym_c: PyReadonlyArray1<f64>,
    cm_mass: Option<f64>,
    position: Option<usize>,
) -> PyResult<(Bound<'py, pyo3::types::PyDict>, Arr2<'py>)> {
    let setup = setup_data(lambda_, pair_w, pair_q, sym_t, sym_c, cm_mass)?;
    let trials = FecgData::new(trial_a, trial_s, trial_c_a)?;
    let basis = FecgData::new(a, s, c_a)?;
    let (m, diag) = py
        .allow_threads(|| api::fecg_rows(&setup.view(), &trials.view(), &basis.view(), position))
        .map_err(to_py)?;
    Ok((dict(py, m)?, diag_array(py, &diag)))
}

/// `gvr_row_gradient` for floating ECGs: directions `(d_a[p], d_s[p])` of the exponent and the centres.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn fecg_row_gradient<'py>(
    py: Python<'py>,
    trial_a: PyReadonlyArray3<f64>,
    trial_s: PyReadonlyArray3<f64>,
    trial_c_a: PyReadonlyArray1<f64>,
    d_a: PyReadonlyArray3<f64>,
    d_s: PyReadonlyArray3<f64>,
    a: PyReadonlyArray3<f64>,
    s: PyReadonlyArray3<f64>,
    c_a: PyReadonlyArray1<f64>,
    lambda_: PyReadonlyArray2<f64>,
    pair_w: PyReadonlyArray2<f64>,
    pair_q: PyReadonlyArray1<f64>,
    sym_t: PyReadonlyArray3<f64>,
    sym_c: PyReadonlyArray1<f64>,
    cm_mass: Option<f64>,
) -> PyResult<(Bound<'py, pyo3::types::PyDict>, Arr2<'py>)> {
    let setup = setup_data(lambda_, pair_w, pair_q, sym_t, sym_c, cm_mass)?;
    let trial = FecgData::new(trial_a, trial_s, trial_c_a)?;
    let basis = FecgData::new(a, s, c_a)?;
    let (d_a, d_s) = (slice(&d_a, "d_a")?.to_vec(), slice(&d_s, "d_s")?.to_vec());
    let (m, diag) = py
        .allow_threads(|| {
            let dir = Directions { a: &d_a, v: &d_s };
            api::fecg_row_gradient(&setup.view(), &trial.view(), &dir, &basis.view())
        })
        .map_err(to_py)?;
    Ok((dict(py, m)?, diag_array(py, &diag)))
}

/// The symmetrised translation-free `<N²>` matrix of a floating-ECG basis; `mu` = m/m_tot.
#[pyfunction]
#[pyo3(signature = (a, s, c_a, mu, lambda_, pair_w, pair_q, sym_t, sym_c))]
#[allow(clippy::too_many_arguments)]
fn fecg_angular<'py>(
    py: Python<'py>,
    a: PyReadonlyArray3<f64>,
    s: PyReadonlyArray3<f64>,
    c_a: PyReadonlyArray1<f64>,
    mu: PyReadonlyArray1<f64>,
    lambda_: PyReadonlyArray2<f64>,
    pair_w: PyReadonlyArray2<f64>,
    pair_q: PyReadonlyArray1<f64>,
    sym_t: PyReadonlyArray3<f64>,
    sym_c: PyReadonlyArray1<f64>,
) -> PyResult<Arr2<'py>> {
    let setup = setup_data(lambda_, pair_w, pair_q, sym_t, sym_c, None)?;
    let basis = FecgData::new(a, s, c_a)?;
    let mu = slice(&mu, "mu")?.to_vec();
    let nb = basis.c_a.len();
    let m = py.allow_threads(|| api::fecg_angular(&setup.view(), &mu, &basis.view())).map_err(to_py)?;
    Ok(matrix(py, nb, nb, m))
}


/// Lowest eigenvalue after adding each of k trials (secular equation, prebo_core::secular):
/// `e` (kept), `c` (nb x kept, S-orthonormal columns), rows `h`, `s` (k x nb), diagonals (k).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
fn lowest_with_added<'py>(
    py: Python<'py>,
    e: PyReadonlyArray1<f64>,
    c: PyReadonlyArray2<f64>,
    h: PyReadonlyArray2<f64>,
    s: PyReadonlyArray2<f64>,
    h_nn: PyReadonlyArray1<f64>,
    s_nn: PyReadonlyArray1<f64>,
    min_norm: f64,
) -> PyResult<Bound<'py, numpy::PyArray1<f64>>> {
    let kept = e.len()?;
    let (e, c) = (slice(&e, "e")?.to_vec(), slice(&c, "c")?.to_vec());
    let (h, s) = (slice(&h, "h")?.to_vec(), slice(&s, "s")?.to_vec());
    let (hn, sn) = (slice(&h_nn, "h_nn")?.to_vec(), slice(&s_nn, "s_nn")?.to_vec());
    if hn.len() != sn.len() || h.len() != s.len() || (!hn.is_empty() && h.len() % hn.len() != 0) {
        return Err(ShapeError::new_err("rows and diagonals do not fit together"));
    }
    if kept > 0 && !hn.is_empty() && c.len() != kept * (h.len() / hn.len()) {
        return Err(ShapeError::new_err("eigenvectors do not fit the rows"));
    }
    let out = py.allow_threads(|| {
        prebo_core::secular::lowest_with_added_many(&e, &c, kept, &h, &s, &hn, &sn, min_norm)
    });
    Ok(numpy::ndarray::Array1::from_vec(out).into_pyarray(py))
}

/// Refined lowest `roots` eigenpairs of H c = E S c (prebo_core::eigenpair): from `e` (kept,
/// ascending) and `c` (nb x kept, S-orthonormal columns) of a double-precision solver. Returns
/// the energies (roots), the S-normalised vectors (nb x roots), the iterations and whether
/// each root converged.
#[pyfunction]
#[allow(clippy::type_complexity)]
fn refine_eigenpairs<'py>(
    py: Python<'py>,
    h: PyReadonlyArray2<f64>,
    s: PyReadonlyArray2<f64>,
    e: PyReadonlyArray1<f64>,
    c: PyReadonlyArray2<f64>,
    roots: usize,
) -> PyResult<(Bound<'py, numpy::PyArray1<f64>>, Arr2<'py>, Vec<usize>, Vec<bool>)> {
    let nb = h.as_array().nrows();
    let kept = e.len()?;
    if h.as_array().ncols() != nb || s.as_array().dim() != (nb, nb) || c.as_array().dim() != (nb, kept) {
        return Err(ShapeError::new_err("H, S (nb x nb) and the eigenvectors (nb x kept) do not fit together"));
    }
    let (h, s) = (slice(&h, "h")?.to_vec(), slice(&s, "s")?.to_vec());
    let (e, c) = (slice(&e, "e")?.to_vec(), slice(&c, "c")?.to_vec());
    let out = py.allow_threads(|| prebo_core::eigenpair::refine_lowest(&h, &s, &e, &c, roots));
    let energies = numpy::ndarray::Array1::from_iter(out.iter().map(|r| r.energy)).into_pyarray(py);
    let mut vectors = vec![0.0; nb * out.len()];
    for (m, r) in out.iter().enumerate() {
        for (i, v) in r.vector.iter().enumerate() {
            vectors[i * out.len() + m] = *v;
        }
    }
    let iterations = out.iter().map(|r| r.iterations).collect();
    let converged = out.iter().map(|r| r.converged).collect();
    Ok((energies, matrix(py, nb, out.len(), vectors), iterations, converged))
}

/// Number of rayon worker threads in use.
#[pyfunction]
fn num_threads() -> usize {
    rayon::current_num_threads()
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(matrices, m)?)?;
    m.add_function(wrap_pyfunction!(rows, m)?)?;
    m.add_function(wrap_pyfunction!(gvr_matrices, m)?)?;
    m.add_function(wrap_pyfunction!(gvr_rows, m)?)?;
    m.add_function(wrap_pyfunction!(gvr_row_gradient, m)?)?;
    m.add_function(wrap_pyfunction!(fecg_matrices, m)?)?;
    m.add_function(wrap_pyfunction!(fecg_rows, m)?)?;
    m.add_function(wrap_pyfunction!(fecg_row_gradient, m)?)?;
    m.add_function(wrap_pyfunction!(fecg_angular, m)?)?;
    m.add_function(wrap_pyfunction!(lowest_with_added, m)?)?;
    m.add_function(wrap_pyfunction!(refine_eigenpairs, m)?)?;
    m.add_function(wrap_pyfunction!(num_threads, m)?)?;
    m.add("MAX_DIM", api::MAX_DIM)?;
    Ok(())
}
