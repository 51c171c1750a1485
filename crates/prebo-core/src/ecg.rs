//! Plain explicitly correlated Gaussians and the operators they are integrated with.
//!
//! Convention (docs/conventions.md): a plain ECG in `D` coordinates is
//! `phi(r) = exp(-r^T (A ⊗ I_3) r)` — no factor 1/2 in the exponent — so that
//! `<phi|phi> = (pi^D / |2A|)^{3/2}`. Every function is used normalised.
use std::ops::{Add, Div, Mul, Sub};

use nalgebra::{Cholesky, RealField, SMatrix, SVector};

use crate::error::{CoreError, Result};
use crate::scalar::Scalar;

/// Largest number of coordinates compiled (laboratory frame: particles).
pub const MAX_DIM: usize = 8;

pub type Mat<const D: usize> = SMatrix<f64, D, D>;
pub type Vector<const D: usize> = SVector<f64, D>;

/// A real scalar the generic kernels run on: `f64`, or a forward-mode dual number of
/// num-dual (`DualSVec64<W>`) that carries W directional derivatives through every operation.
pub trait Real:
    RealField
    + Copy
    + From<f64>
    + Add<f64, Output = Self>
    + Sub<f64, Output = Self>
    + Mul<f64, Output = Self>
    + Div<f64, Output = Self>
    + Value
    + Scalar
{
}

impl<T> Real for T where
    T: RealField
        + Copy
        + From<f64>
        + Add<f64, Output = T>
        + Sub<f64, Output = T>
        + Mul<f64, Output = T>
        + Div<f64, Output = T>
        + Value
        + Scalar
{
}

/// The `f64` value of a scalar, and the order of the derivatives it carries: a kernel whose inner
/// loop depends on a few scalars can run that loop in `f64` with hand-derived partial derivatives
/// and chain them onto first-order dual numbers (`chain`); an expansion about the value
/// (`inverse_log_det`) is carried to `ORDER`.
pub trait Value {
    /// 0 for `f64`, 1 for dual numbers, 2 for hyper-dual numbers (whose `ε_1 ε_2` terms survive).
    const ORDER: u32;
    fn value(&self) -> f64;
}

impl Value for f64 {
    const ORDER: u32 = 0;
    #[inline(always)]
    fn value(&self) -> f64 {
        *self
    }
}

impl<const W: usize> Value for num_dual::DualSVec64<W> {
    const ORDER: u32 = 1;
    #[inline(always)]
    fn value(&self) -> f64 {
        self.re
    }
}

impl<const M: usize, const N: usize> Value for num_dual::HyperDualSVec64<M, N> {
    const ORDER: u32 = 2;
    #[inline(always)]
    fn value(&self) -> f64 {
        self.re
    }
}

/// `f` at the inputs `x_k`, given its value `f0` and partial derivatives `∂f/∂x_k` there:
/// `f0 + Σ_k ∂f/∂x_k (x_k − value(x_k))` carries the inputs' derivatives by the chain rule (to
/// first order: exact for `Value::ORDER` ≤ 1).
#[inline]
pub fn chain<T: Real, const K: usize>(f0: f64, inputs: [T; K], partials: [f64; K]) -> T {
    inputs.iter().zip(partials).fold(re(f0), |acc, (x, p)| acc + (*x - x.value()) * p)
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
}

/// `ln|B|` from a Cholesky factor `B = L L^T`: `2 Σ ln L_kk`.
#[inline]
pub fn log_det_cholesky<T: Real, const D: usize>(chol: &Cholesky<T, nalgebra::Const<D>>) -> T {
    chol.l_dirty().diagonal().iter().fold(T::zero(), |acc, d| acc + d.ln()) * 2.0
}

/// `B^{-1}` and `ln|B|` of a positive-definite `B`; `None` when `B` has no Cholesky factor in
/// floating point. Numbers with derivatives are expanded around the value `B_0` to their order
/// (`Value::ORDER`, where the expansion is exact: a product of more derivative parts vanishes),
/// with `X = B_0^{-1}(B − B_0)`: `B^{-1} = Σ_k (−X)^k B_0^{-1}` (Neumann series, by Horner:
/// `B^{-1} ← B_0^{-1} − X B^{-1}`), `ln|B| = ln|B_0| + Σ_k (−1)^{k+1} Tr(X^k)/k`; so the
/// factorisation and the inverse run in `f64`.
#[inline]
pub fn inverse_log_det<T: Real, const D: usize>(b: &SMatrix<T, D, D>) -> Option<(SMatrix<T, D, D>, T)> {
    let b0: Mat<D> = b.map(|x| x.value());
    let chol = Cholesky::new(b0)?;
    let (binv0, log_det0) = (chol.inverse(), log_det_cholesky(&chol));
    if T::ORDER == 0 {
        return Some((binv0.map(re), re(log_det0)));
    }
    let db = SMatrix::<T, D, D>::from_fn(|i, j| b[(i, j)] - b0[(i, j)]);
    let x = mul(&binv0, &db); // B_0^{-1}(B − B_0)
    let mut binv = SMatrix::from_fn(|i, j| (0..D).fold(re(binv0[(i, j)]), |acc, k| acc - x[(i, k)] * binv0[(k, j)]));
    let mut log_det = (0..D).fold(re(log_det0), |acc, k| acc + x[(k, k)]);
    let mut power = x; // X^k
    for k in 2..=T::ORDER {
        binv = SMatrix::from_fn(|i, j| (0..D).fold(re(binv0[(i, j)]), |acc, l| acc - x[(i, l)] * binv[(l, j)]));
        power = mul(&x, &power);
        let sign = if k % 2 == 0 { -1.0 } else { 1.0 };
        log_det += (0..D).fold(T::zero(), |acc, l| acc + power[(l, l)]) * (sign / k as f64);
    }
    Some((binv, log_det))
}

/// `a b` by plain sums, for `a` of `T` or of constants (`f64`); nalgebra's generic product also
/// multiplies every term by α = 1, which costs a dual-number product per term.
#[inline]
pub fn mul<S: nalgebra::Scalar + Copy, T: Real + Mul<S, Output = T>, const R: usize, const K: usize, const C: usize>(
    a: &SMatrix<S, R, K>,
    b: &SMatrix<T, K, C>,
) -> SMatrix<T, R, C> {
    SMatrix::from_fn(|i, j| (0..K).fold(T::zero(), |acc, k| acc + b[(k, j)] * a[(i, k)]))
}

/// `v^T w` for a constant `w`.
#[inline]
pub fn dot_f<T: Real, const D: usize>(v: &SVector<T, D>, w: &Vector<D>) -> T {
    (0..D).fold(T::zero(), |acc, k| acc + v[k] * w[k])
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

/// The Coulomb pairs in the kernels' form: per pair `2 q` and the non-zero terms `(a, b, f)`,
/// `a <= b`, `f = w_a w_b` (doubled off the diagonal), so that `wᵀBw = Σ f B_ab`.
pub type CoulombTerms = Vec<(f64, Vec<(usize, usize, f64)>)>;

impl<const D: usize> Operators<D> {
    /// The Coulomb pairs as `CoulombTerms`.
    pub fn coulomb_terms(&self) -> CoulombTerms {
        self.pairs
            .iter()
            .map(|(w, q)| {
                let mut terms = Vec::new();
                for a in 0..D {
                    for b in a..D {
                        let f = if a == b { w[a] * w[a] } else { 2.0 * w[a] * w[b] };
                        if f != 0.0 {
                            terms.push((a, b, f));
                        }
                    }
                }
                (2.0 * q, terms)
            })
            .collect()
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gradient::{seed_matrix, Dual};

    #[test]
    fn inverse_log_det_matches_dual_cholesky() {
        let b = Mat::<3>::new(2.0, 0.3, -0.4, 0.3, 1.5, 0.2, -0.4, 0.2, 0.9);
        let dirs = [
            Mat::<3>::new(1.0, 0.5, 0.0, 0.5, 0.0, -0.2, 0.0, -0.2, 0.3),
            Mat::<3>::new(0.0, 0.0, 1.0, 0.0, 2.0, 0.0, 1.0, 0.0, -1.0),
        ];
        let bd: SMatrix<Dual<2>, 3, 3> = seed_matrix(&b, &dirs);
        let (binv, log_det) = inverse_log_det(&bd).unwrap();
        let chol = Cholesky::new(bd).unwrap();
        let (binv_ref, log_det_ref) = (chol.inverse(), log_det_cholesky(&chol));
        let close = |a: &Dual<2>, r: &Dual<2>| {
            let (da, dr) = (
                a.eps.unwrap_generic(nalgebra::Const::<2>, nalgebra::U1),
                r.eps.unwrap_generic(nalgebra::Const::<2>, nalgebra::U1),
            );
            (a.re - r.re).abs() < 1e-14 && (da - dr).norm() < 1e-13
        };
        assert!(close(&log_det, &log_det_ref));
        assert!(binv.iter().zip(binv_ref.iter()).all(|(a, r)| close(a, r)));
        assert!(inverse_log_det(&Mat::<2>::new(1.0, 2.0, 2.0, 1.0)).is_none(), "indefinite B has no factor");
    }

    #[test]
    fn inverse_log_det_matches_a_hyper_dual_cholesky_to_second_order() {
        use nalgebra::{Const, U1};
        use num_dual::{Derivative, HyperDualSVec64};
        type H = HyperDualSVec64<2, 1>;
        // B(θ_1, θ_2, α) with every part non-zero, the ε_1 ε_2 one included
        let sym = |m: Mat<3>| m + m.transpose();
        let b0 = Mat::<3>::new(2.0, 0.3, -0.4, 0.3, 1.5, 0.2, -0.4, 0.2, 0.9);
        let d1 = [sym(Mat::<3>::new(0.5, 0.5, 0.0, 0.0, 0.0, -0.2, 0.0, 0.0, 0.3)), sym(Mat::<3>::new(0.0, 0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, -0.5))];
        let d2 = sym(Mat::<3>::new(0.3, -0.1, 0.2, 0.0, 0.4, 0.1, 0.0, 0.0, 0.2));
        let d12 = [sym(Mat::<3>::new(0.1, 0.2, 0.0, 0.0, -0.3, 0.0, 0.1, 0.0, 0.05)), sym(Mat::<3>::new(0.0, 0.1, 0.1, 0.0, 0.0, 0.2, 0.0, 0.0, 0.1))];
        let b = SMatrix::<H, 3, 3>::from_fn(|i, j| {
            let (e1, e12) = (SMatrix::<f64, 2, 1>::new(d1[0][(i, j)], d1[1][(i, j)]), SMatrix::<f64, 2, 1>::new(d12[0][(i, j)], d12[1][(i, j)]));
            H::new(b0[(i, j)], Derivative::some(e1), Derivative::some(SMatrix::<f64, 1, 1>::new(d2[(i, j)])), Derivative::some(e12))
        });
        let (binv, log_det) = inverse_log_det(&b).unwrap();
        let chol = Cholesky::new(b).unwrap();
        let (binv_ref, log_det_ref) = (chol.inverse(), log_det_cholesky(&chol));
        let parts = |x: &H| {
            let (e1, e2) = (x.eps1.unwrap_generic(Const::<2>, U1), x.eps2.unwrap_generic(U1, Const::<1>));
            [x.re, e1[0], e1[1], e2[0], x.eps1eps2.unwrap_generic(Const::<2>, Const::<1>)[0], x.eps1eps2.unwrap_generic(Const::<2>, Const::<1>)[1]]
        };
        let close = |a: &H, r: &H| parts(a).iter().zip(parts(r)).all(|(x, y)| (x - y).abs() < 1e-13);
        assert!(close(&log_det, &log_det_ref), "{log_det} vs {log_det_ref}");
        assert!(binv.iter().zip(binv_ref.iter()).all(|(a, r)| close(a, r)));
        // the second-order term −Tr(X_1 X_2) that a first-order expansion misses is there
        let first = (b0.try_inverse().unwrap() * d12[0]).trace();
        assert!((parts(&log_det_ref)[4] - first).abs() > 0.1);
    }
}
