//! `prebo._core`: the thin PyO3 binding of prebo-core. One `Engine` per (basis family,
//! coordinate representation) serves matrices, rows, row gradients, extra operators and <N²>;
//! arrays are converted once (`convert`), the GIL is released around every build, and core
//! errors map to `prebo.errors` through one `From`.
mod convert;

use convert::{blocks, columns, dict, floats, floats_shaped, matrix, Result, Rows, ShapeError};
use numpy::ndarray::Array3;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3};
use prebo_core::engine::{self, Kind, Representation};
use prebo_core::params::Directions;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The representation's arrays: `lam` (n x n), `pair_w` (p x n), `pair_q` (p), `sym_t`
/// (o x n x n), `sym_c` (o), `cm_mass`.
fn representation(
    lam: &Bound<'_, PyAny>,
    pair_w: &Bound<'_, PyAny>,
    pair_q: &Bound<'_, PyAny>,
    sym_t: &Bound<'_, PyAny>,
    sym_c: &Bound<'_, PyAny>,
    cm_mass: Option<f64>,
) -> Result<Representation> {
    let (lambda, shape) = floats_shaped(lam, "lam")?;
    if shape.len() != 2 || shape[0] != shape[1] {
        return Err(ShapeError::new_err(format!("lam: shape {shape:?}, expected (n, n)")).into());
    }
    Ok(Representation {
        n: shape[0],
        lambda,
        pair_w: floats(pair_w, "pair_w")?,
        pair_q: floats(pair_q, "pair_q")?,
        sym_t: floats(sym_t, "sym_t")?,
        sym_c: floats(sym_c, "sym_c")?,
        cm_mass,
    })
}

/// One basis family in one coordinate representation (see `_core.pyi`).
#[pyclass(frozen, module = "prebo._core")]
struct Engine {
    core: engine::Engine,
}

#[pymethods]
impl Engine {
    #[new]
    #[pyo3(signature = (family, lam, pair_w, pair_q, sym_t, sym_c, cm_mass=None, N=0))]
    #[allow(clippy::too_many_arguments, non_snake_case)]
    fn new(
        family: &str,
        lam: &Bound<'_, PyAny>,
        pair_w: &Bound<'_, PyAny>,
        pair_q: &Bound<'_, PyAny>,
        sym_t: &Bound<'_, PyAny>,
        sym_c: &Bound<'_, PyAny>,
        cm_mass: Option<f64>,
        N: u32,
    ) -> Result<Self> {
        let rep = representation(lam, pair_w, pair_q, sym_t, sym_c, cm_mass)?;
        Ok(Self { core: engine::Engine::new(Kind::from_name(family)?, rep, N)? })
    }

    #[getter]
    fn family(&self) -> &'static str {
        self.core.kind.name()
    }

    #[getter]
    fn n(&self) -> usize {
        self.core.rep.n
    }

    #[getter]
    fn oriented(&self) -> bool {
        self.core.kind.oriented()
    }

    fn matrices<'py>(&self, py: Python<'py>, params: &Bound<'py, PyAny>) -> Result<Bound<'py, PyDict>> {
        let basis = columns(self.core.kind, params)?;
        let m = py.allow_threads(|| self.core.matrices(&basis))?;
        Ok(dict(py, m)?)
    }

    #[pyo3(signature = (trials, basis, position=None))]
    fn rows<'py>(
        &self,
        py: Python<'py>,
        trials: &Bound<'py, PyAny>,
        basis: &Bound<'py, PyAny>,
        position: Option<usize>,
    ) -> Result<Rows<'py>> {
        let (t, b) = (columns(self.core.kind, trials)?, columns(self.core.kind, basis)?);
        let out = py.allow_threads(|| self.core.rows(&t, &b, position))?;
        convert::rows(py, out)
    }

    #[pyo3(signature = (f, dA, dv, basis))]
    #[allow(non_snake_case)]
    fn row_gradient<'py>(
        &self,
        py: Python<'py>,
        f: &Bound<'py, PyAny>,
        dA: &Bound<'py, PyAny>,
        dv: Option<&Bound<'py, PyAny>>,
        basis: &Bound<'py, PyAny>,
    ) -> Result<Rows<'py>> {
        let (t, b) = (columns(self.core.kind, f)?, columns(self.core.kind, basis)?);
        let da = floats(dA, "dA")?;
        let dv = match dv {
            Some(dv) => floats(dv, "dv")?,
            None => vec![],
        };
        let out = py.allow_threads(|| self.core.row_gradient(&t, &Directions { a: &da, v: &dv }, &b))?;
        convert::rows(py, out)
    }

    fn operator<'py>(
        &self,
        py: Python<'py>,
        name: &str,
        params: &Bound<'py, PyAny>,
        w: &Bound<'py, PyAny>,
    ) -> Result<Bound<'py, PyArray3<f64>>> {
        let basis = columns(self.core.kind, params)?;
        let w = floats(w, "w")?;
        let nb = self.core.count(&basis)?;
        let m = py.allow_threads(|| self.core.operator(name, &basis, &w))?;
        Ok(blocks(py, nb, m))
    }

    fn between<'py>(
        &self,
        py: Python<'py>,
        name: &str,
        bra: &Bound<'py, PyAny>,
        ket: &Engine,
        ket_params: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
    ) -> Result<Bound<'py, PyArray3<f64>>> {
        let (b, k) = (columns(self.core.kind, bra)?, columns(ket.core.kind, ket_params)?);
        let v = floats(v, "v")?;
        let (nb, nk) = (self.core.count(&b)?, ket.core.count(&k)?);
        let m = py.allow_threads(|| self.core.between(name, &b, &ket.core, &k, &v))?;
        let p = if nb * nk == 0 { 0 } else { m.len() / (nb * nk) };
        Ok(Array3::from_shape_vec((p, nb, nk), m).expect("p x nb x nk values").into_pyarray(py))
    }

    #[pyo3(signature = (name, bra, ket, ket_params, dA, du, v))]
    #[allow(clippy::too_many_arguments, non_snake_case)]
    fn between_gradient<'py>(
        &self,
        py: Python<'py>,
        name: &str,
        bra: &Bound<'py, PyAny>,
        ket: &Engine,
        ket_params: &Bound<'py, PyAny>,
        dA: &Bound<'py, PyAny>,
        du: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
    ) -> Result<Bound<'py, PyArray3<f64>>> {
        let (b, k) = (columns(self.core.kind, bra)?, columns(ket.core.kind, ket_params)?);
        let (da, du, v) = (floats(dA, "dA")?, floats(du, "du")?, floats(v, "v")?);
        let nb = self.core.count(&b)?;
        let rows = 1 + da.len() / (self.core.rep.n * self.core.rep.n);
        let m = py.allow_threads(|| self.core.between_gradient(name, &b, &ket.core, &k, &Directions { a: &da, v: &du }, &v))?;
        let p = m.len().checked_div(rows * nb).unwrap_or(0);
        Ok(Array3::from_shape_vec((p, rows, nb), m).expect("p x (1 + P) x nb values").into_pyarray(py))
    }

    #[allow(non_snake_case)]
    fn density<'py>(
        &self,
        py: Python<'py>,
        params: &Bound<'py, PyAny>,
        w: &Bound<'py, PyAny>,
        C: &Bound<'py, PyAny>,
        r: &Bound<'py, PyAny>,
    ) -> Result<Bound<'py, PyArray3<f64>>> {
        let basis = columns(self.core.kind, params)?;
        let (w, c, r) = (floats(w, "w")?, floats(C, "C")?, floats(r, "r")?);
        let nb = self.core.count(&basis)?;
        let ns = if nb == 0 { 0 } else { c.len() / nb };
        let d = py.allow_threads(|| self.core.density(&basis, &w, &c, &r))?;
        let p = if ns * r.len() == 0 { 0 } else { d.len() / (ns * r.len()) };
        Ok(Array3::from_shape_vec((p, ns, r.len()), d).expect("p x ns x radii values").into_pyarray(py))
    }

    fn __repr__(&self) -> String {
        format!("Engine({:?}, n={}, N={})", self.core.kind.name(), self.core.rep.n, self.core.n_ang)
    }
}

/// Eigenvalues `roots` (0: the lowest) after adding each of k trials (secular equation,
/// prebo_core::secular): `e` (kept), `c` (nb x kept, S-orthonormal columns), rows `h`, `s`
/// (k x nb), diagonals (k); k x len(roots).
#[pyfunction]
#[pyo3(signature = (e, c, h, s, h_nn, s_nn, min_norm, roots))]
#[allow(clippy::too_many_arguments)]
fn roots_with_added<'py>(
    py: Python<'py>,
    e: &Bound<'py, PyAny>,
    c: &Bound<'py, PyAny>,
    h: &Bound<'py, PyAny>,
    s: &Bound<'py, PyAny>,
    h_nn: &Bound<'py, PyAny>,
    s_nn: &Bound<'py, PyAny>,
    min_norm: f64,
    roots: Vec<usize>,
) -> Result<Bound<'py, PyArray2<f64>>> {
    let (e, c) = (floats(e, "e")?, floats(c, "c")?);
    let kept = e.len();
    let (h, s) = (floats(h, "h")?, floats(s, "s")?);
    let (hn, sn) = (floats(h_nn, "h_nn")?, floats(s_nn, "s_nn")?);
    if hn.len() != sn.len() || h.len() != s.len() || (!hn.is_empty() && h.len() % hn.len() != 0) {
        return Err(ShapeError::new_err("rows and diagonals do not fit together").into());
    }
    if kept > 0 && !hn.is_empty() && c.len() != kept * (h.len() / hn.len()) {
        return Err(ShapeError::new_err("eigenvectors do not fit the rows").into());
    }
    let out = py.allow_threads(|| {
        prebo_core::secular::roots_with_added_many(&e, &c, kept, &h, &s, &hn, &sn, min_norm, &roots)
    });
    Ok(numpy::ndarray::Array2::from_shape_vec((hn.len(), roots.len()), out).expect("k x roots").into_pyarray(py))
}

/// H, S (nb x nb) and the eigenvalues e (kept) and eigenvectors c (nb x kept) of a
/// double-precision solution, as flat arrays, and nb.
#[allow(clippy::type_complexity)]
fn pencil(
    h: &Bound<'_, PyAny>,
    s: &Bound<'_, PyAny>,
    e: &Bound<'_, PyAny>,
    c: &Bound<'_, PyAny>,
) -> Result<(Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>, usize)> {
    let ((h, hs), (s, ss)) = (floats_shaped(h, "h")?, floats_shaped(s, "s")?);
    let ((e, _), (c, cs)) = (floats_shaped(e, "e")?, floats_shaped(c, "c")?);
    let (nb, kept) = (hs.first().copied().unwrap_or(0), e.len());
    if hs != [nb, nb] || ss != [nb, nb] || cs != [nb, kept] {
        return Err(
            ShapeError::new_err("H, S (nb x nb) and the eigenvectors (nb x kept) do not fit together").into()
        );
    }
    Ok((h, s, e, c, nb))
}

/// Refined lowest `roots` eigenpairs of H c = E S c (prebo_core::eigenpair): from `e` (kept,
/// ascending) and `c` (nb x kept, S-orthonormal columns) of a double-precision solver. Returns
/// the energies (roots), the S-normalised vectors (nb x roots), the iterations and whether
/// each root converged.
#[pyfunction]
#[allow(clippy::type_complexity)]
fn refine_eigenpairs<'py>(
    py: Python<'py>,
    h: &Bound<'py, PyAny>,
    s: &Bound<'py, PyAny>,
    e: &Bound<'py, PyAny>,
    c: &Bound<'py, PyAny>,
    roots: usize,
) -> Result<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray2<f64>>, Vec<usize>, Vec<bool>)> {
    let (h, s, e, c, nb) = pencil(h, s, e, c)?;
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

/// The lowest eigenpair of H c = E S c by inverse iteration in double-double
/// (prebo_core::eigenpair::inverse_iteration), where `refine_eigenpairs` does not converge:
/// from `e` (kept ≥ 1, ascending) and `c` (nb x kept, S-orthonormal columns). Returns the
/// energy, the S-normalised vector (nb), the iterations and whether it converged;
/// NotPositiveDefiniteError for an overlap without a double-double LDLᵀ factorisation.
#[pyfunction]
fn inverse_iteration<'py>(
    py: Python<'py>,
    h: &Bound<'py, PyAny>,
    s: &Bound<'py, PyAny>,
    e: &Bound<'py, PyAny>,
    c: &Bound<'py, PyAny>,
) -> Result<(f64, Bound<'py, PyArray1<f64>>, usize, bool)> {
    let (h, s, e, c, _) = pencil(h, s, e, c)?;
    if e.is_empty() {
        return Err(ShapeError::new_err("no eigenpair to start the inverse iteration from (kept = 0)").into());
    }
    let r = py.allow_threads(|| prebo_core::eigenpair::inverse_iteration(&h, &s, &e, &c))?;
    let vector = numpy::ndarray::Array1::from_vec(r.vector).into_pyarray(py);
    Ok((r.energy, vector, r.iterations, r.converged))
}

/// Number of rayon worker threads in use.
#[pyfunction]
fn num_threads() -> usize {
    rayon::current_num_threads()
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Engine>()?;
    m.add_function(wrap_pyfunction!(roots_with_added, m)?)?;
    m.add_function(wrap_pyfunction!(refine_eigenpairs, m)?)?;
    m.add_function(wrap_pyfunction!(inverse_iteration, m)?)?;
    m.add_function(wrap_pyfunction!(num_threads, m)?)?;
    m.add("MAX_DIM", prebo_core::ecg::MAX_DIM)?;
    m.add("GIT_COMMIT", env!("PREBO_GIT_COMMIT"))?;
    let operators = PyDict::new(m.py());
    for kind in [Kind::Pecg, Kind::EcgGvr, Kind::Fecg] {
        operators.set_item(kind.name(), kind.operators())?;
    }
    m.add("OPERATORS", operators)?;
    Ok(())
}
