//! Floating ECG matrix elements (paper section FECG and eq. GENCONSTR:fecg) in prebo's
//! convention `phi(r) = exp(-(r - s)^T (A ⊗ I_3) (r - s))`, `s` an `D x 3` matrix of centres.
//!
//! With `B = A_I + A_J`, `v = A_I s_I + A_J s_J`, `r̄ = B^{-1} v`, `C = B^{-1}/2`:
//! - overlap  `S = (2^D |A_I|^{1/2}|A_J|^{1/2}/|B|)^{3/2} exp(-(s_I^T A_I s_I + s_J^T A_J s_J - v^T B^{-1} v))`
//!   (normalised; traces over the Cartesian index implied);
//! - kinetic  `T = [6 Tr(B^{-1} A_I Λ A_J) + 4 (r̄ - s_I)^T A_I Λ A_J (r̄ - s_J)] S` (paper: 6R + Q);
//! - Coulomb  `<1/|w^T r|> = erf(|m|/√c)/|m| S`, `m = w^T r̄` (a 3-vector), `c = w^T B^{-1} w`,
//!   with the series `2/√(πc) (1 - z²/3 + z⁴/10 - z⁶/42 + z⁸/216)`, `z = |m|/√c`, below z = 1e-3
//!   (erf(z)/z loses digits to cancellation there; the series' next term is below 1e-25);
//! - CM elimination: the kinetic element with `Λ = 1 1^T/(2 m_tot)`. With `A 1 = c_A μ`
//!   (`μ = m/m_tot`), `μ^T B^{-1} = 1^T/(c_I + c_J)`, it is
//!   `[3 c_I c_J/(m_tot s) - (2/m_tot)(c_I c_J/s)² |μ^T (s_I - s_J)|²] S`, `s = c_I + c_J`
//!   (the R and Q corrections of the paper: the Q correction needs centres whose CM
//!   positions `μ^T s` differ);
//! - translation-free angular momentum `N_TI = Σ r_i × p_i - R × P`: `N_TI phi = -2i Σ_i r_i × t_i phi`
//!   with `t = (A - c_A μ μ^T) s`, so
//!   `<N_TI²> = 4 [(Σ_i r̄_i × t_{I,i})·(Σ_k r̄_k × t_{J,k}) + 2 Σ_ik C_ik t_{I,i}·t_{J,k}] S`;
use std::f64::consts::PI;

use nalgebra::SMatrix;

use crate::ecg::{dot_f, inverse_log_det, log_det_pd, mul, re, Element, Mat, Operators, Real, Vector};
use crate::error::{CoreError, Result};
use crate::cache::Keyed;
use crate::params::{matrices_of, Exponents, Parameters};
use crate::images::Transform;

pub type Centres<const D: usize, T = f64> = SMatrix<T, D, 3>;

/// One floating ECG: exponent `A`, centres `s` (one 3-vector per coordinate), `c_A`.
/// `T` is `f64`, or a dual number when derivatives with respect to `A` and `s` are wanted.
#[derive(Clone, Debug)]
pub struct FecgFunction<const D: usize, T: Real = f64> {
    pub a: SMatrix<T, D, D>,
    pub s: Centres<D, T>,
    pub c_a: f64,
    pub log_det: T,
    /// `A s`
    pub a_s: Centres<D, T>,
    /// `s^T A s` (trace over Cartesian components)
    pub s_a_s: T,
}

impl<const D: usize, T: Real> FecgFunction<D, T> {
    pub fn new(a: SMatrix<T, D, D>, s: Centres<D, T>, c_a: f64, index: usize) -> Result<Self> {
        let log_det = log_det_pd(&a).ok_or(CoreError::NotPositiveDefinite { function: index })?;
        let a_s = a * s;
        let s_a_s = s.component_mul(&a_s).sum();
        Ok(Self { a, s, c_a, log_det, a_s, s_a_s })
    }

    /// This function with dual-number entries of zero derivative.
    pub fn cast<S: Real>(&self) -> FecgFunction<D, S>
    where
        T: Into<S>,
    {
        FecgFunction {
            a: self.a.map(Into::into),
            s: self.s.map(Into::into),
            c_a: self.c_a,
            log_det: self.log_det.into(),
            a_s: self.a_s.map(Into::into),
            s_a_s: self.s_a_s.into(),
        }
    }
}

impl<const D: usize> FecgFunction<D> {
    /// `(r-s)^T A (r-s) + r^T M r = r^T (A+M) r - 2 r^T A s + s^T A s`: `A` grows, `A s`, `s^T A s`
    /// and `ln|A|` (the normalisation) stay (`Family::damped`); the centre moves to `(A+M)⁻¹ A s`,
    /// which the kinetic element reads (docs/properties-derivations.md, eq. 30).
    pub fn damped<T: Real>(&self, m: &SMatrix<T, D, D>) -> FecgFunction<D, T> {
        let mut g: FecgFunction<D, T> = self.cast();
        g.a += m;
        if let Some(chol) = g.a.cholesky() {
            g.s = chol.solve(&g.a_s);
        }
        g
    }
}

/// The parameters of `k` floating ECGs: `A` and `c_A` (`e`) and the centres `s` (`k x n x 3`).
#[derive(Clone, Copy, Debug, Default)]
pub struct FecgParams<'a> {
    pub e: Exponents<'a>,
    pub s: &'a [f64],
}

impl Parameters for FecgParams<'_> {
    fn len(&self) -> usize {
        self.e.len()
    }
}

impl Keyed for FecgParams<'_> {
    fn key(&self) -> Vec<u64> {
        self.e.bits().chain([self.s.len() as u64]).chain(self.s.iter().map(|x| x.to_bits())).collect()
    }
}

/// The functions of `p`, checked by `FecgFunction::new`.
pub fn functions<const D: usize>(p: &FecgParams) -> Result<Vec<FecgFunction<D>>> {
    let a = p.e.exponents::<D>()?;
    let s = matrices_of::<D, 3>(p.s, p.len(), "centres")?;
    (0..p.len()).map(|i| FecgFunction::new(a[i], s[i], p.e.c_a[i], i)).collect()
}

impl<const D: usize, T: Real, Ctx> Transform<D, Ctx> for FecgFunction<D, T> {
    /// `phi(T r)`: `A -> T^T A T`, `s -> T^{-1} s`.
    fn transformed(&self, t: &Mat<D>, _: &Ctx, index: usize) -> Result<Self> {
        let t_inv = t.try_inverse().ok_or_else(|| CoreError::Unsupported("singular symmetry operation".into()))?;
        let (t, t_inv): (SMatrix<T, D, D>, SMatrix<T, D, D>) = (t.map(re), t_inv.map(re));
        Self::new(t.transpose() * self.a * t, t_inv * self.s, self.c_a, index)
    }
}

/// `erf(|m|/√c)/|m|` with the small-argument series (module docs).
#[inline]
pub(crate) fn coulomb_factor<T: Real>(m2: T, c: T) -> T {
    let z2 = m2 / c;
    if z2 < re(1e-6) {
        let series = T::one() - z2 / 3.0 + z2 * z2 / 10.0 - z2 * z2 * z2 / 42.0 + z2.powi(4) / 216.0;
        (c * PI).sqrt().recip() * 2.0 * series
    } else {
        let m = m2.sqrt();
        erf(m / c.sqrt()) / m
    }
}

/// Error function: Maclaurin series below |x| = 2 (terms up to ~10, so ~1 digit of
/// cancellation at worst), Lentz's continued fraction for erfc up to 6, 1 beyond
/// (erfc(6) < 3e-17). Checked against tabulated values to 2e-16. Generic, so that dual
/// numbers carry erf' = 2/√π exp(-x²) through the same arithmetic.
pub fn erf<T: Real>(x: T) -> T {
    let ax = x.abs();
    let r = if ax < re(2.0) {
        // erf(x) = 2/√π Σ (-1)^n x^{2n+1}/(n!(2n+1))
        let x2 = ax * ax;
        let (mut term, mut sum, mut n) = (ax, ax, 0.0);
        loop {
            n += 1.0;
            term *= -x2 / n;
            let add = term / (2.0 * n + 1.0);
            sum += add;
            if add.abs() < sum.abs() * 1e-17 {
                break;
            }
        }
        sum * (2.0 / PI.sqrt())
    } else if ax < re(6.0) {
        T::one() - erfc_cf(ax)
    } else {
        T::one()
    };
    if x < T::zero() {
        -r
    } else {
        r
    }
}

/// erfc(x) for x >= 2 by Lentz's continued fraction.
fn erfc_cf<T: Real>(x: T) -> T {
    // erfc(x) = exp(-x²)/√π · 1/(x + 1/2/(x + 1/(x + 3/2/(x + 2/(x + ...)))))
    let tiny = 1e-300;
    let mut f = x;
    let mut c = x;
    let mut d = T::zero();
    for k in 1..300 {
        let a = k as f64 / 2.0;
        d = x + d * a;
        d = if d.abs() < re(tiny) { re(tiny) } else { d };
        c = x + re::<T>(a) / c;
        c = if c.abs() < re(tiny) { re(tiny) } else { c };
        d = d.recip();
        let delta = c * d;
        f *= delta;
        if (delta - 1.0).abs() < re(1e-17) {
            break;
        }
    }
    (-x * x).exp() / PI.sqrt() / f
}

/// Cross product of two 3-vectors given as row slices.
#[inline]
fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn row<const D: usize>(m: &Centres<D>, i: usize) -> [f64; 3] {
    [m[(i, 0)], m[(i, 1)], m[(i, 2)]]
}

/// The shared pieces of one pair: `(S, B^{-1}, r̄)`, or `None` when `A_I + A_J` has no
/// Cholesky factor in floating point (possible only for near-singular functions, whose
/// elements are then NaN and the caller rejects them).
#[inline]
pub(crate) fn pair<const D: usize, T: Real>(bra: &FecgFunction<D, T>, ket: &FecgFunction<D, T>) -> Option<(T, SMatrix<T, D, D>, Centres<D, T>)> {
    let (binv, log_det) = inverse_log_det(&(bra.a + ket.a))?;
    let v = bra.a_s + ket.a_s;
    let rbar = mul(&binv, &v);
    let delta = bra.s_a_s + ket.s_a_s - v.component_mul(&rbar).sum();
    let s = (((bra.log_det + ket.log_det) * 0.5 + D as f64 * 2f64.ln() - log_det) * 1.5 - delta).exp();
    Some((s, binv, rbar))
}

/// The kinetic pieces of one pair (module docs): `W = A_I Λ A_J`, `d_I = r̄ - s_I`,
/// `d_J = r̄ - s_J`, `W d_J`, and `τ = 6R + Q` (`T = τ S`).
pub(crate) struct Kinetic<const D: usize, T: Real> {
    pub w: SMatrix<T, D, D>,
    pub di: Centres<D, T>,
    pub dj: Centres<D, T>,
    pub w_dj: Centres<D, T>,
    pub tau: T,
}

#[inline]
pub(crate) fn kinetic<const D: usize, T: Real>(
    bra: &FecgFunction<D, T>,
    ket: &FecgFunction<D, T>,
    lambda: &Mat<D>,
    binv: &SMatrix<T, D, D>,
    rbar: &Centres<D, T>,
) -> Kinetic<D, T> {
    let w = mul(&bra.a, &mul(lambda, &ket.a)); // A_I Λ A_J
    let r = binv.component_mul(&w.transpose()).sum();
    let di = rbar - bra.s;
    let dj = rbar - ket.s;
    let w_dj = mul(&w, &dj);
    let q = di.component_mul(&w_dj).sum() * 4.0;
    Kinetic { w, di, dj, w_dj, tau: r * 6.0 + q }
}

/// The CM elimination of one pair (module docs), `T_TI = T - κ S` with `κ = Q_cm + R_cm`,
/// `Q_cm = q_per_d2 |e|²`, `e = μ^T s_I - μ^T s_J` (`μ^T s = 1^T A s / c_A`).
pub(crate) struct CmShift<T> {
    pub kappa: T,
    pub e: [T; 3],
    pub q_per_d2: f64,
}

#[inline]
pub(crate) fn cm_shift<const D: usize, T: Real>(bra: &FecgFunction<D, T>, ket: &FecgFunction<D, T>, m: f64) -> CmShift<T> {
    let (ci, cj) = (bra.c_a, ket.c_a);
    let sum = ci + cj;
    let mut e = [T::zero(); 3];
    let mut d2 = T::zero();
    for k in 0..3 {
        let (mut xi, mut xj) = (T::zero(), T::zero());
        for i in 0..D {
            xi += bra.a_s[(i, k)];
            xj += ket.a_s[(i, k)];
        }
        e[k] = xi / ci - xj / cj;
        d2 += e[k].powi(2);
    }
    let r_cm = 3.0 * ci * cj / (m * sum);
    let q_per_d2 = -2.0 / m * (ci * cj / sum).powi(2);
    CmShift { kappa: d2 * q_per_d2 + r_cm, e, q_per_d2 }
}

/// `(b, c, m)` of one Coulomb pair `w`: `b = B^{-1} w`, `c = w^T B^{-1} w`, `m = w^T r̄`.
#[inline]
pub(crate) fn coulomb_moments<const D: usize, T: Real>(
    w: &Vector<D>,
    binv: &SMatrix<T, D, D>,
    rbar: &Centres<D, T>,
) -> (SMatrix<T, D, 1>, T, SMatrix<T, 1, 3>) {
    let b = mul(&w.transpose(), binv).transpose();
    (b, dot_f(&b, w), mul(&w.transpose(), rbar))
}

/// `<phi_I| 1, T, V |phi_J>` for one pair of normalised floating ECGs.
pub fn element<const D: usize, T: Real>(bra: &FecgFunction<D, T>, ket: &FecgFunction<D, T>, ops: &Operators<D>) -> Element<T> {
    let Some((s, binv, rbar)) = pair(bra, ket) else { return Element::nan() };
    let t = kinetic(bra, ket, &ops.lambda, &binv, &rbar).tau * s;
    let t_ti = match ops.cm_mass {
        Some(m) => t - cm_shift(bra, ket, m).kappa * s,
        None => t,
    };
    let mut v = T::zero();
    for (w, q) in &ops.pairs {
        let (_, c, m) = coulomb_moments(w, &binv, &rbar);
        v += coulomb_factor(m.norm_squared(), c) * *q;
    }
    Element { s, t, t_ti, v: v * s }
}

/// `<phi_I| N_TI² |phi_J>` (module docs); `mu` = m/m_tot.
pub fn angular<const D: usize>(bra: &FecgFunction<D>, ket: &FecgFunction<D>, mu: &Vector<D>) -> f64 {
    let Some((s, binv, rbar)) = pair(bra, ket) else { return f64::NAN };
    let ti = bra.a_s - bra.c_a * mu * (mu.transpose() * bra.s);
    let tj = ket.a_s - ket.c_a * mu * (mu.transpose() * ket.s);
    let (mut li, mut lj) = ([0.0; 3], [0.0; 3]);
    for i in 0..D {
        let ci = cross(row(&rbar, i), row(&ti, i));
        let cj = cross(row(&rbar, i), row(&tj, i));
        for k in 0..3 {
            li[k] += ci[k];
            lj[k] += cj[k];
        }
    }
    let mean = li[0] * lj[0] + li[1] * lj[1] + li[2] * lj[2];
    let fluct = (ti * tj.transpose()).component_mul(&binv).sum(); // Σ_ik B^{-1}_ik t_I,i·t_J,k = 2 Σ C_ik ...
    4.0 * (mean + fluct) * s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn erf_matches_known_values() {
        // reference values: Abramowitz & Stegun table 7.1 / high-precision evaluation
        let cases = [
            (0.1, 0.112_462_916_018_284_9),
            (0.5, 0.520_499_877_813_046_5),
            (1.0, 0.842_700_792_949_714_9),
            (1.9, 0.992_790_429_235_257_5),
            (2.0, 0.995_322_265_018_952_7),
            (3.0, 0.999_977_909_503_001_4),
            (4.5, 0.999_999_999_803_383_9),
        ];
        for (x, want) in cases {
            assert!((erf(x) - want).abs() < 2e-16, "erf({x}) = {} vs {want}", erf(x));
            assert!((erf(-x) + want).abs() < 2e-16);
        }
    }

    #[test]
    fn coulomb_series_joins_the_closed_form() {
        let c: f64 = 0.7;
        for z2 in [1e-7, 9.9e-7, 1.01e-6, 1e-5] {
            let m = (z2 * c).sqrt();
            let closed = erf(m / c.sqrt()) / m;
            assert!((coulomb_factor(z2 * c, c) - closed).abs() < 1e-12 * closed);
        }
    }
}
