//! A basis's parameters as the binding passes them: the arrays of a family's tuple (`Column`,
//! `Field`), views of `k` functions' parameters (`Parameters`; every family's `Exponents`), P
//! directions in one function's parameter space (`Directions`), the symmetry operations
//! (`Symmetry`), and the shape checks of flat arrays.
use nalgebra::SMatrix;

use crate::cache::Keyed;
use crate::ecg::Mat;
use crate::error::{CoreError, Result};

/// One array of a family's parameter tuple as the binding passes it (`Family::FIELDS`, in order).
#[derive(Clone, Debug, PartialEq)]
pub enum Column {
    Floats(Vec<f64>),
    /// non-negative integers (the powers K)
    Naturals(Vec<u32>),
}

impl Column {
    /// The values of a `Floats` column.
    pub fn floats(&self) -> Result<&[f64]> {
        match self {
            Column::Floats(v) => Ok(v),
            Column::Naturals(_) => Err(CoreError::ShapeMismatch("integers where floats are expected".into())),
        }
    }

    /// The values of a `Naturals` column.
    pub fn naturals(&self) -> Result<&[u32]> {
        match self {
            Column::Naturals(v) => Ok(v),
            Column::Floats(_) => Err(CoreError::ShapeMismatch("floats where integers are expected".into())),
        }
    }
}

/// One array of a family's parameter tuple: its name (in errors) and whether it holds integers.
#[derive(Clone, Copy, Debug)]
pub struct Field {
    pub name: &'static str,
    pub naturals: bool,
}

impl Field {
    pub const fn floats(name: &'static str) -> Self {
        Self { name, naturals: false }
    }

    pub const fn naturals(name: &'static str) -> Self {
        Self { name, naturals: true }
    }
}

/// The columns of a tuple, checked against the family's fields in number (each column's kind is
/// checked where it is read: `Column::floats`, `Column::naturals`).
pub fn columns<'a>(family: &str, fields: &[Field], columns: &'a [Column]) -> Result<&'a [Column]> {
    check(columns.len(), fields.len(), &format!("{family} parameter arrays"))?;
    Ok(columns)
}

/// A family's parameters of `k` functions (`Family::Params`): views of flat row-major arrays, with
/// their exact bits as the key of the basis side kept between calls (`cache`).
pub trait Parameters: Keyed + Default + Copy + Send + Sync {
    /// `k`, the number of functions.
    fn len(&self) -> usize;

    fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The part every family's parameters have: the exponent matrices `a` (`k x n x n`) and the CM
/// exponents `c_a` (`k`); the plain-ECG parameters.
#[derive(Clone, Copy, Debug, Default)]
pub struct Exponents<'a> {
    pub a: &'a [f64],
    pub c_a: &'a [f64],
}

impl Exponents<'_> {
    /// The exponent matrices, checked against `c_a`.
    pub fn exponents<const D: usize>(&self) -> Result<Vec<Mat<D>>> {
        check(self.a.len(), self.len() * D * D, "exponent matrices")?;
        Ok(self.a.chunks_exact(D * D).map(Mat::<D>::from_row_slice).collect())
    }

    /// The key's part of these arrays: their lengths, then every value's bits.
    pub fn bits(&self) -> impl Iterator<Item = u64> + '_ {
        let lengths = [self.a.len(), self.c_a.len()].map(|n| n as u64);
        lengths.into_iter().chain(self.a.iter().chain(self.c_a).map(|x| x.to_bits()))
    }
}

impl Parameters for Exponents<'_> {
    fn len(&self) -> usize {
        self.c_a.len()
    }
}

impl Keyed for Exponents<'_> {
    fn key(&self) -> Vec<u64> {
        self.bits().collect()
    }
}

/// P directions in one function's parameter space: `P x n x n` derivatives of `A` and the
/// derivatives of the family's vector part (`P x n` of `u`, `P x n x 3` of `s`; plain ECGs: none).
#[derive(Clone, Copy, Debug)]
pub struct Directions<'a> {
    pub a: &'a [f64],
    pub v: &'a [f64],
}

impl Directions<'_> {
    /// The `A` directions as matrices, and the number of vector values per direction.
    pub fn exponents<const D: usize>(&self) -> Result<(Vec<Mat<D>>, usize)> {
        let p = self.a.len() / (D * D).max(1);
        check(self.a.len(), p * D * D, "exponent directions")?;
        let per = self.v.len().checked_div(p).unwrap_or(0);
        check(self.v.len(), p * per, "vector directions")?;
        Ok((self.a.chunks_exact(D * D).map(Mat::<D>::from_row_slice).collect(), per))
    }
}

/// `count` matrices of `R x C` values each from a flat slice (the vector part of directions).
pub fn matrices_of<const R: usize, const C: usize>(
    v: &[f64],
    count: usize,
    what: &str,
) -> Result<Vec<SMatrix<f64, R, C>>> {
    check(v.len(), count * R * C, what)?;
    Ok(v.chunks_exact(R * C)
        .map(SMatrix::<f64, R, C>::from_row_slice)
        .collect())
}

pub fn check(len: usize, want: usize, what: &str) -> Result<()> {
    if len == want {
        Ok(())
    } else {
        Err(CoreError::ShapeMismatch(format!(
            "{what}: {len} values, expected {want}"
        )))
    }
}

/// Symmetry operations `(T, c_P)`: `phi -> phi(T r)` with Young-operator coefficient `c_P`.
pub type Symmetry<const D: usize> = [(Mat<D>, f64)];
