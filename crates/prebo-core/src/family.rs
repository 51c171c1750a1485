//! The basis-family axis: what every kind of basis function provides to the one build path
//! (`path`). A family names its function type, generic over the scalar (`f64`, or a num-dual
//! number that carries derivatives), reads its parameters from flat row-major arrays, transforms
//! a function under a symmetry operation (`images::Transform`) and evaluates the normalised
//! element `<phi_I| 1, T, T_TI, V |phi_J>`. The builds, rows and row gradients of `path` then
//! work for it unchanged; a family with a faster kernel overrides `matrices` and `rows`
//! (plain ECGs: `plain`, the SIMD kernel of `build`).
//!
//! Families: plain ECG (`plain::PlainEcg`), ECG-GVR (`gvr::EcgGvr`), floating ECG
//! (`fecg::FloatingEcg`).
use nalgebra::SMatrix;

use crate::cache::Cache;
use crate::ecg::{Element, Mat, Operators, Real};
use crate::error::{CoreError, Result};
use crate::gradient::Dual;
use crate::images::Transform;
use crate::matrices::Matrices;
use crate::path;

/// The parameters of `k` functions as flat row-major arrays: `a` (`k x n x n`) and `c_a` (`k`)
/// for every family; `v` the global vectors `u` (`k x n`, ECG-GVR) or the centres `s`
/// (`k x n x 3`, floating ECGs), empty for plain ECGs; `k_pow` the powers K (ECG-GVR).
#[derive(Clone, Copy, Debug, Default)]
pub struct Params<'a> {
    pub a: &'a [f64],
    pub c_a: &'a [f64],
    pub v: &'a [f64],
    pub k_pow: &'a [u32],
}

impl Params<'_> {
    pub fn len(&self) -> usize {
        self.c_a.len()
    }

    pub fn is_empty(&self) -> bool {
        self.c_a.is_empty()
    }

    /// The exponent matrices, checked against `c_a`.
    pub fn exponents<const D: usize>(&self) -> Result<Vec<Mat<D>>> {
        check(self.a.len(), self.len() * D * D, "exponent matrices")?;
        Ok(self.a.chunks_exact(D * D).map(Mat::<D>::from_row_slice).collect())
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

/// A kind of basis function in `D` coordinates.
pub trait Family<const D: usize>: Sized + 'static {
    /// The name the binding uses (`"pecg"`, `"ecg-gvr"`, `"fecg"`).
    const NAME: &'static str;
    /// Whether `rows(.., position)` evaluates every element in the orientation of a full build
    /// (lower index as bra), so that rows patched into the matrices give the bits of `matrices`.
    const ORIENTED: bool = true;
    /// One function over the scalar `T`.
    type Function<T: Real>: Clone + Send + Sync + Transform<D, Self::Context>;
    /// What the elements need beside the functions (operators, quadrature rules, N).
    type Context: Sync;

    /// The context for the operators `ops`, total angular momentum `n_ang`, and the function
    /// sets that will meet in one call.
    fn context(ops: Operators<D>, n_ang: u32, sets: &[&Params]) -> Result<Self::Context>;

    /// The functions of `p` (checked: positive-definite `A`, the family's own conditions).
    fn functions(p: &Params, ctx: &Self::Context) -> Result<Vec<Self::Function<f64>>>;

    /// `<phi_I| 1, T, T_TI, V |phi_J>` for normalised functions.
    fn element<T: Real>(bra: &Self::Function<T>, ket: &Self::Function<T>, ctx: &Self::Context) -> Element<T>;

    /// `<phi_I|phi_J>` alone (default: from `element`).
    fn overlap<T: Real>(bra: &Self::Function<T>, ket: &Self::Function<T>, ctx: &Self::Context) -> T {
        Self::element(bra, ket, ctx).s
    }

    /// `f` over another scalar, with zero derivatives.
    fn cast<T: Real>(f: &Self::Function<f64>) -> Self::Function<T>;

    /// `f` with its parameters seeded along the directions `da[p]` and `dv` (the vector part,
    /// `da.len()` of them, flat): the derivatives of every element then come out of `element`.
    fn seeded<const W: usize>(
        f: &Self::Function<f64>,
        da: &[Mat<D>],
        dv: &[f64],
        ctx: &Self::Context,
    ) -> Result<Self::Function<Dual<W>>>;

    /// `phi(r) exp(-r^T (M ⊗ I_3) r)` with the normalisation constants of `phi` kept: the ket
    /// of an overlap that generates Gaussian-weighted operators (e.g. `r_w²` as `-∂/∂α` of the
    /// overlap at `M = α w w^T`). Only its overlaps (`overlap`) are meaningful.
    fn damped<T: Real>(f: &Self::Function<f64>, m: &SMatrix<T, D, D>) -> Self::Function<T>;

    /// The symmetrised matrices of a basis (default: the generic path).
    fn matrices(ctx: &Self::Context, sym: &Symmetry<D>, basis: &Params) -> Result<Matrices> {
        path::matrices::<D, Self>(ctx, sym, basis)
    }

    /// Rows of trials against a basis and the trials' diagonals (default: the generic path,
    /// oriented for a trial that will sit at `position`, `None`: appended). The basis side's
    /// preparations are kept in `cache` for the next call against the same basis.
    fn rows(
        ctx: &Self::Context,
        sym: &Symmetry<D>,
        trials: &Params,
        basis: &Params,
        position: Option<usize>,
        cache: &Cache,
    ) -> Result<(Matrices, Vec<Element>)> {
        path::rows::<D, Self>(ctx, sym, trials, basis, position, cache)
    }

    /// The row of one function against a basis and its diagonal, with their derivatives along
    /// the directions `dir` (default: dual numbers through `element`, `path::row_gradient`);
    /// `cache` as for `rows`.
    fn row_gradient(
        ctx: &Self::Context,
        sym: &Symmetry<D>,
        trial: &Params,
        dir: &Directions,
        basis: &Params,
        cache: &Cache,
    ) -> Result<(Matrices, Vec<Element>)> {
        path::row_gradient::<D, Self>(ctx, sym, trial, dir, basis, cache)
    }
}
