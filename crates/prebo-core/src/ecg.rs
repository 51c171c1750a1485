//! Plain explicitly correlated Gaussians and the operators they are integrated with.
//!
//! Convention (docs/conventions.md): a plain ECG in `D` coordinates is
//! `phi(r) = exp(-r^T (A ⊗ I_3) r)` — no factor 1/2 in the exponent — so that
//! `<phi|phi> = (pi^D / |2A|)^{3/2}`. Every function is used normalised.
use std::ops::{Add, Div, Mul, Sub};

use nalgebra::{Cholesky, RealField, SMatrix, SVector};

use crate::error::{CoreError, Result};

pub type Mat<const D: usize> = SMatrix<f64, D, D>;
pub type Vector<const D: usize> = SVector<f64, D>;

/// A real scalar the generic kernels run on: `f64`, or a forward-mode dual number of
/// num-dual (`DualSVec64<W>`) that carries W directional derivatives through every operation.
pub trait Real:
    RealField + Copy + From<f64> + Add<f64, Output = Self> + Sub<f64, Output = Self> + Mul<f64, Output = Self> + Div<f64, Output = Self>
{
}

impl<T> Real for T where
    T: RealField + Copy + From<f64> + Add<f64, Output = T> + Sub<f64, Output = T> + Mul<f64, Output = T> + Div<f64, Output = T>
{
}

/// `x` as a `T` (a constant: zero derivatives).
#[inline(always)]
pub fn re<T: Real>(x: f64) -> T {
    <T as From<f64>>::from(x)
}

/// One basis function: exponent matrix `A`, `ln|A|`, and its centre-of-mass exponent `c_A`.
#[derive(Clone, Debug)]
pub struct Gaussian<const D: usize> {
    pub a: Mat<D>,
    pub log_det: f64,
    pub c_a: f64,
}

impl<const D: usize> Gaussian<D> {
    /// Checks positive definiteness (Cholesky) and stores `ln|A|`; `index` names the function in errors.
    pub fn new(a: Mat<D>, c_a: f64, index: usize) -> Result<Self> {
        let log_det = log_det_pd(&a).ok_or(CoreError::NotPositiveDefinite { function: index })?;
        Ok(Self { a, log_det, c_a })
    }

    /// The permuted (or otherwise linearly transformed) function `phi(T r)`: `A -> T^T A T`.
    pub fn transformed(&self, t: &Mat<D>, index: usize) -> Result<Self> {
        Self::new(t.transpose() * self.a * t, self.c_a, index)
    }
}

/// `ln|B|` from a Cholesky factor `B = L L^T`: `2 Σ ln L_kk`.
#[inline]
pub fn log_det_cholesky<T: Real, const D: usize>(chol: &Cholesky<T, nalgebra::Const<D>>) -> T {
    chol.l_dirty().diagonal().iter().fold(T::zero(), |acc, d| acc + d.ln()) * 2.0
}

/// `ln|A|` from the Cholesky factor, `None` if `A` is not positive definite.
pub fn log_det_pd<T: Real, const D: usize>(a: &SMatrix<T, D, D>) -> Option<T> {
    let chol = Cholesky::new(*a)?;
    let l = chol.l_dirty();
    let mut ld = T::zero();
    for k in 0..D {
        let d = l[(k, k)];
        if !(d > T::zero()) || !d.is_finite() {
            return None;
        }
        ld += d.ln() * 2.0;
    }
    Some(ld)
}

/// The operators integrated together: kinetic `-∇^T Λ ∇` and Coulomb `Σ q / |w^T r|`.
///
/// In laboratory-frame coordinates `Λ = M = diag(1/(2 m_i))` and `w = e_i - e_j`;
/// in a translationally invariant set `Λ = μ` and `w = U_x^{-T}(e_i - e_j)` (first D rows).
#[derive(Clone, Debug)]
pub struct Operators<const D: usize> {
    pub lambda: Mat<D>,
    pub pairs: Vec<(Vector<D>, f64)>,
    /// Total mass for the c_A elimination of the CM kinetic energy (paper eq. ecg-transl);
    /// `None` when the coordinates carry no CM part.
    pub cm_mass: Option<f64>,
}

/// One (normalised, un-symmetrised) matrix element of every operator.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Element<T = f64> {
    /// overlap `<I|J>`
    pub s: T,
    /// kinetic energy with the full `Λ` (laboratory frame: includes CM motion)
    pub t: T,
    /// kinetic energy with the CM part eliminated (equal to `t` without `cm_mass`)
    pub t_ti: T,
    /// Coulomb potential energy
    pub v: T,
}

impl<T: Real> Element<T> {
    pub fn zero() -> Self {
        Self { s: T::zero(), t: T::zero(), t_ti: T::zero(), v: T::zero() }
    }

    pub fn nan() -> Self {
        let n = re(f64::NAN);
        Self { s: n, t: n, t_ti: n, v: n }
    }
}

impl<T: Real> std::ops::AddAssign<(f64, Element<T>)> for Element<T> {
    fn add_assign(&mut self, (c, e): (f64, Element<T>)) {
        self.s += e.s * c;
        self.t += e.t * c;
        self.t_ti += e.t_ti * c;
        self.v += e.v * c;
    }
}
