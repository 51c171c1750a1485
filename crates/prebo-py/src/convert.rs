//! Conversions between Python and the core: array-likes to owned flat arrays (any dtype numpy
//! can cast safely, any memory layout), core results to numpy arrays, and `CoreError` (and the
//! eigenpair refinement's `Indefinite`) to the exceptions of `prebo.errors`.
use numpy::ndarray::{Array2, Array3};
use numpy::{AllowTypeChange, IntoPyArray, PyArray2, PyArray3, PyArrayLikeDyn, PyUntypedArrayMethods};
use prebo_core::ecg::Element;
use prebo_core::eigenpair::Indefinite;
use prebo_core::engine::Kind;
use prebo_core::params::Column;
use prebo_core::matrices::Matrices;
use prebo_core::CoreError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

pyo3::import_exception!(prebo.errors, NotPositiveDefiniteError);
pyo3::import_exception!(prebo.errors, ShapeError);
pyo3::import_exception!(prebo.errors, UnsupportedError);

/// An error of a binding call: from the core, or from Python (conversion).
pub enum Error {
    Core(CoreError),
    Py(PyErr),
}

impl From<CoreError> for Error {
    fn from(e: CoreError) -> Self {
        Error::Core(e)
    }
}

impl From<Indefinite> for Error {
    fn from(e: Indefinite) -> Self {
        Error::Py(NotPositiveDefiniteError::new_err(e.to_string()))
    }
}

impl From<PyErr> for Error {
    fn from(e: PyErr) -> Self {
        Error::Py(e)
    }
}

impl From<Error> for PyErr {
    fn from(e: Error) -> Self {
        match e {
            Error::Py(e) => e,
            Error::Core(e) => {
                let msg = e.to_string();
                match e {
                    CoreError::NotPositiveDefinite { .. } => NotPositiveDefiniteError::new_err(msg),
                    CoreError::ShapeMismatch(_) => ShapeError::new_err(msg),
                    CoreError::Unsupported(_) => UnsupportedError::new_err(msg),
                }
            }
        }
    }
}

pub type Result<T> = std::result::Result<T, Error>;

fn shape_error(msg: String) -> Error {
    Error::Core(CoreError::ShapeMismatch(msg))
}

/// An array-like as float64 values in row-major order, and its shape.
pub fn floats_shaped(x: &Bound<'_, PyAny>, what: &str) -> Result<(Vec<f64>, Vec<usize>)> {
    let a = x
        .extract::<PyArrayLikeDyn<'_, f64, AllowTypeChange>>()
        .map_err(|e| shape_error(format!("{what}: not convertible to a float64 array ({e})")))?;
    // `as_slice` also accepts Fortran order (memory order): only C order is copied as is
    let v = match a.as_slice() {
        Ok(s) if a.is_c_contiguous() => s.to_vec(),
        _ => a.as_array().iter().copied().collect(),
    };
    Ok((v, a.as_array().shape().to_vec()))
}

/// An array-like as float64 values in row-major order.
pub fn floats(x: &Bound<'_, PyAny>, what: &str) -> Result<Vec<f64>> {
    Ok(floats_shaped(x, what)?.0)
}

/// Non-negative integers below 2^32 (the powers K), from any numeric array-like.
pub fn naturals(x: &Bound<'_, PyAny>, what: &str) -> Result<Vec<u32>> {
    floats(x, what)?
        .into_iter()
        .map(|k| {
            if k >= 0.0 && k <= u32::MAX as f64 && k.fract() == 0.0 {
                Ok(k as u32)
            } else {
                Err(shape_error(format!("{what}: {k} is not a non-negative integer")))
            }
        })
        .collect()
}

/// A family's parameter tuple, owned: its arrays in the order and of the kinds the family
/// declares (`Family::FIELDS`: pecg `(A, c_A)`, ecg-gvr `(A, u, K, c_A)`, fecg `(A, s, c_A)`).
pub fn columns(kind: Kind, params: &Bound<'_, PyAny>) -> Result<Vec<Column>> {
    let t = params.downcast::<PyTuple>().map_err(PyErr::from)?;
    let fields = kind.fields();
    if t.len() != fields.len() {
        return Err(shape_error(format!(
            "{} parameters: {} arrays, expected {}",
            kind.name(),
            t.len(),
            fields.len()
        )));
    }
    fields
        .iter()
        .enumerate()
        .map(|(i, f)| {
            let x = t.get_item(i)?;
            Ok(match f.naturals {
                true => Column::Naturals(naturals(&x, f.name)?),
                false => Column::Floats(floats(&x, f.name)?),
            })
        })
        .collect()
}

pub fn matrix<'py>(py: Python<'py>, rows: usize, cols: usize, v: Vec<f64>) -> Bound<'py, PyArray2<f64>> {
    Array2::from_shape_vec((rows, cols), v)
        .expect("rows x cols values")
        .into_pyarray(py)
}

/// `p` row-major `nb x nb` blocks as a `(p, nb, nb)` array.
pub fn blocks(py: Python<'_>, nb: usize, v: Vec<f64>) -> Bound<'_, PyArray3<f64>> {
    let p = if nb == 0 { 0 } else { v.len() / (nb * nb) };
    Array3::from_shape_vec((p, nb, nb), v)
        .expect("p x nb x nb values")
        .into_pyarray(py)
}

/// `{"S", "T", "T_ti", "V"}`.
pub fn dict(py: Python<'_>, m: Matrices) -> PyResult<Bound<'_, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("S", matrix(py, m.rows, m.cols, m.s))?;
    d.set_item("T", matrix(py, m.rows, m.cols, m.t))?;
    d.set_item("T_ti", matrix(py, m.rows, m.cols, m.t_ti))?;
    d.set_item("V", matrix(py, m.rows, m.cols, m.v))?;
    Ok(d)
}

/// Diagonal elements as a `k x 4` array (S, T, T_ti, V).
pub fn diag_array<'py>(py: Python<'py>, diag: &[Element]) -> Bound<'py, PyArray2<f64>> {
    let d: Vec<f64> = diag.iter().flat_map(|e| [e.s, e.t, e.t_ti, e.v]).collect();
    matrix(py, diag.len(), 4, d)
}

pub type Rows<'py> = (Bound<'py, PyDict>, Bound<'py, PyArray2<f64>>);

/// Rows (or row gradients) and diagonals as Python objects.
pub fn rows(py: Python<'_>, (m, diag): (Matrices, Vec<Element>)) -> Result<Rows<'_>> {
    Ok((dict(py, m)?, diag_array(py, &diag)))
}
