//! ECG-GVR matrix elements (paper eqs. globalvector, ecg-gvr; Suzuki & Varga, Lect. Notes
//! Phys. m54, ch. 6–7) in prebo's convention (no 1/2 in the exponent, docs/conventions.md):
//!
//! ```text
//!     phi(r) = |v|^{2K} (v_x + i v_y)^N exp(-r^T A r),   v = u^T r,
//! ```
//!
//! i.e. |v|^{2K+N} Y_NN(v̂) up to a constant of N alone (cancelled by normalisation).
//!
//! # Derivation (docs/gvr.md has the long form)
//! Under the weight `exp(-r^T B r)`, `B = A_I + A_J`, the vectors `a = u_I^T r`, `b = u_J^T r`
//! are jointly Gaussian, each Cartesian component with covariances
//! `x = u_I^T C u_I`, `y = u_J^T C u_J`, `z = u_I^T C u_J`, `C = B^{-1}/2`. Expanding
//! `|b|^{2K}(e·b)^N` in the Laguerre eigenfunctions of the Ornstein–Uhlenbeck semigroup gives
//!
//! ```text
//!     <phi_I|phi_J> = S_0(B) Ω,   Ω = Σ_k ĉ_k x^{K_I-k} y^{K_J-k} z^{N+2k},
//!     ĉ_0 = 1,  ĉ_{k+1} = ĉ_k (K_I-k)(K_J-k) / ((k+1)(k+N+3/2)),   S_0 = (π^D/|B|)^{3/2},
//! ```
//!
//! up to factors f(K_I) f(K_J) that normalisation removes. All terms have one sign, so
//! the sum is stable for large K; it is evaluated as `x^{K_I+N/2} y^{K_J+N/2} ρ^N G(ρ²)`,
//! `ρ = z/√(xy)` ∈ [-1, 1], with the powers in logarithms (no overflow up to K ≈ 170).
//!
//! Kinetic `<∇φ_I|Λ|∇φ_J>`: Stein's lemma and Price's theorem (`∂E/∂z = E[∇_a·∇_b]`,
//! `∂E/∂x = E[Δ_a]/2`) turn every term into Ω or its first derivatives:
//!
//! ```text
//!     T/S_0 = λ Ω_z − 4⟨A_JΛu_I,u_I⟩Ω_x − 2⟨A_JΛu_I,u_J⟩Ω_z − 4⟨A_IΛu_J,u_J⟩Ω_y − 2⟨A_IΛu_J,u_I⟩Ω_z
//!             + 12 Tr(A_IΛA_J C) Ω + 8 ũ_IWũ_I Ω_x + 4 (ũ_IWũ_J + ũ_JWũ_I) Ω_z + 8 ũ_JWũ_J Ω_y,
//! ```
//!
//! `λ = u_I^T Λ u_J`, `⟨p,q⟩ = p^T C q`, `ũ = C u`, `W = A_I Λ A_J`. For K = N = 0 this is the
//! plain-ECG `6 Tr(B^{-1} A_I Λ A_J) S`.
//!
//! CM elimination (paper eq. GENCONSTR:ecggvr, generalised to c_U ≠ 0 and unequal c_A):
//! the same expression with `Λ = 1 1^T/(2 m_tot)`; with `A 1 = c_A m/m_tot`, `1^T u = c_U`,
//! `s = c_I + c_J` it collapses to the closed form of `series::cm_kinetic`.
//!
//! Coulomb `<1/|w^T r|>`: `1/r = (2/√π)∫exp(-t²r²)dt` and `τ² = t²c/(1+t²c)`, `c = w^T B^{-1} w`:
//!
//! ```text
//!     <1/|w^T r|> = (2/√(πc)) S_0 ∫_0^1 Ω(x − τ²γ_I², y − τ²γ_J², z − τ²γ_Iγ_J) dτ,
//!     γ = (B^{-1}u)·w / √(2c),
//! ```
//!
//! an even polynomial of degree 2(K_I+K_J+N) in τ, integrated exactly by the ⌊(K_I+K_J+N)/2⌋+1
//! positive nodes of the Gauss–Legendre rule on [−1, 1] with twice as many nodes (exact to degree
//! 4⌊(K_I+K_J+N)/2⌋+3; for an even integrand ∫_0^1 = ½∫_{−1}^1).
use std::f64::consts::PI;
use std::ops::{Mul, Sub};

use nalgebra::{Cholesky, SMatrix, SVector};

use super::series::{cm_kinetic, horner, omega, series_at_one, Coefficients};
use crate::ecg::{chain, dot_f, inverse_log_det, log_det_cholesky, mul, re, Element, Mat, Operators, Real, Vector};
use crate::error::{CoreError, Result};
use crate::cache::Keyed;
use crate::params::{check, matrices_of, Exponents, Parameters};
use crate::images::Transform;
use crate::quadrature::{legendre_rule, RULES};

/// One ECG-GVR function: exponent `A`, global vector `u`, power `K`, and its CM parameters.
/// `T` is `f64`, or a dual number when derivatives with respect to `A` and `u` are wanted.
#[derive(Clone, Debug)]
pub struct GvrFunction<const D: usize, T: Real = f64> {
    pub a: SMatrix<T, D, D>,
    pub u: SVector<T, D>,
    pub k: u32,
    pub c_a: f64,
    /// `c_U = 1^T u` (the CM component of `u^(x) = U^{-T} u^(r)`)
    pub c_u: T,
    /// `ln <phi|phi>^{1/2}` in the scaling of this module
    pub log_norm: T,
}

/// Angular momentum and Gauss–Legendre nodes shared by all elements.
#[derive(Clone, Debug)]
pub struct GvrOps<const D: usize> {
    pub ops: Operators<D>,
    pub n_ang: u32,
    /// `legendre[d]` = the rule for the Coulomb integrand of K_I + K_J + N = d (`even_rule`)
    legendre: Vec<&'static [(f64, f64)]>,
}

impl<const D: usize> GvrOps<D> {
    pub fn new(ops: Operators<D>, n_ang: u32, k_max: u32) -> Result<Self> {
        let d_max = (2 * k_max + n_ang) as usize;
        if d_max / 2 + 1 >= RULES.len() {
            return Err(CoreError::Unsupported(format!("2 K_max + N = {d_max} (at most {})", 2 * RULES.len() - 3)));
        }
        Ok(Self { ops, n_ang, legendre: (0..=d_max).map(|d| legendre_rule(d / 2 + 1)).collect() })
    }

    /// This context with the kinetic matrix `Λ` replaced, no Coulomb pairs and no CM elimination:
    /// its `T` is `<∇φ_I|Λ|∇φ_J>` alone.
    pub fn with_kinetic(&self, lambda: Mat<D>) -> Self {
        Self { ops: Operators { lambda, pairs: vec![], cm_mass: None }, n_ang: self.n_ang, legendre: self.legendre.clone() }
    }

    /// This context without the Coulomb pairs (`Family::kinetic_only`).
    pub fn without_pairs(&self) -> Self {
        Self { ops: Operators { pairs: vec![], ..self.ops.clone() }, n_ang: self.n_ang, legendre: self.legendre.clone() }
    }

    fn k_max(&self) -> u32 {
        ((self.legendre.len() - 1) as u32 - self.n_ang) / 2
    }

    /// The rule for the Coulomb integrand of K_I + K_J + N = `d`.
    pub(crate) fn rule(&self, d: u32) -> &'static [(f64, f64)] {
        self.legendre[d as usize]
    }
}

impl<const D: usize, T: Real> GvrFunction<D, T> {
    /// Checks `A` (positive definite), `u` (non-zero) and `K` (within the prepared range).
    pub fn new(a: SMatrix<T, D, D>, u: SVector<T, D>, k: u32, c_a: f64, go: &GvrOps<D>, index: usize) -> Result<Self> {
        if k > go.k_max() {
            return Err(CoreError::Unsupported(format!("function {index}: K = {k} above K_max = {}", go.k_max())));
        }
        let chol = Cholesky::new(a).ok_or(CoreError::NotPositiveDefinite { function: index })?;
        // <phi|phi>: B = 2A, x = y = z = u^T (2A)^{-1} u / 2 = u^T A^{-1} u / 4
        let x = u.dot(&chol.solve(&u)) * 0.25;
        if !(x > T::zero()) || !x.is_finite() {
            return Err(CoreError::Unsupported(format!("function {index}: global vector u is zero")));
        }
        let log_det_2a = log_det_cholesky(&chol) + (D as f64) * 2f64.ln();
        let n = go.n_ang as f64;
        let g = series_at_one(k, go.n_ang);
        let log_s0 = log_s0::<T, D>(log_det_2a);
        let log_norm = (log_s0 + x.ln() * (2.0 * k as f64 + n) + g.ln()) * 0.5;
        Ok(Self { a, u, k, c_a, c_u: u.sum(), log_norm })
    }

    /// This function with dual-number entries of zero derivative.
    pub fn cast<S: Real>(&self) -> GvrFunction<D, S>
    where
        T: Into<S>,
    {
        GvrFunction {
            a: self.a.map(Into::into),
            u: self.u.map(Into::into),
            k: self.k,
            c_a: self.c_a,
            c_u: self.c_u.into(),
            log_norm: self.log_norm.into(),
        }
    }
}

impl<const D: usize> GvrFunction<D> {
    /// `phi(r) exp(-r^T (M ⊗ I_3) r)` with the normalisation constants of `phi` kept
    /// (`Family::damped`): `A → A + M`.
    pub fn damped<T: Real>(&self, m: &SMatrix<T, D, D>) -> GvrFunction<D, T> {
        let mut g: GvrFunction<D, T> = self.cast();
        g.a += m;
        g
    }
}

/// The parameters of `k` ECG-GVR functions: `A` and `c_A` (`e`), the global vectors `u`
/// (`k x n`) and the powers `K` (`k`).
#[derive(Clone, Copy, Debug, Default)]
pub struct GvrParams<'a> {
    pub e: Exponents<'a>,
    pub u: &'a [f64],
    pub k: &'a [u32],
}

impl Parameters for GvrParams<'_> {
    fn len(&self) -> usize {
        self.e.len()
    }
}

impl Keyed for GvrParams<'_> {
    fn key(&self) -> Vec<u64> {
        let lengths = [self.u.len(), self.k.len()].map(|n| n as u64);
        let values = self.u.iter().map(|x| x.to_bits()).chain(self.k.iter().map(|&k| k as u64));
        self.e.bits().chain(lengths).chain(values).collect()
    }
}

/// The functions of `p`, checked by `GvrFunction::new`.
pub fn functions<const D: usize>(p: &GvrParams, go: &GvrOps<D>) -> Result<Vec<GvrFunction<D>>> {
    let a = p.e.exponents::<D>()?;
    let u = matrices_of::<D, 1>(p.u, p.len(), "global vectors")?;
    check(p.k.len(), p.len(), "powers K")?;
    (0..p.len()).map(|i| GvrFunction::new(a[i], u[i], p.k[i], p.e.c_a[i], go, i)).collect()
}

/// `∫_0^1 Ω(x − τ²γ_I², y − τ²γ_J², z − τ²γ_Iγ_J) dτ / e^L` (module docs) for the inputs
/// `[x, y, z, γ_I, γ_J]`. At a node the integrand is, with `a = x_τ/x`, `b = y_τ/y`,
/// `ζ = z_τ/√(xy)`, `P(a, b, ζ) = Σ ĉ_k a^{K_I−k} b^{K_J−k} ζ^{N+2k} = a^{K_I} b^{K_J} ζ^N G(ζ²/(ab))`:
/// integer powers of ratios ≤ 1 and a polynomial in `ζ²/(ab)` ≤ 1.
pub(crate) fn quadrature<T: Real>(inputs: [T; 5], rule: &[(f64, f64)], series: &Coefficients) -> T {
    let [x, y, z, gam_i, gam_j] = inputs;
    let rt = (x * y).sqrt();
    let mut integral = T::zero();
    for &(tau, weight) in rule {
        let t2 = tau * tau;
        // x_τ, y_τ >= 0 analytically (covariances of B + t² w w^T); clamp rounding
        let xt = (x - gam_i * t2 * gam_i).max(T::zero());
        let yt = (y - gam_j * t2 * gam_j).max(T::zero());
        let zt = z - gam_i * t2 * gam_j;
        let r2 = if xt * yt > T::zero() { (zt * zt / (xt * yt)).min(T::one()) } else { T::one() };
        let g = horner(&series.c, r2);
        integral += (xt / x).powi(series.ki as i32)
            * weight
            * (yt / y).powi(series.kj as i32)
            * (zt / rt).powi(series.n as i32)
            * g;
    }
    integral
}

/// `quadrature` in `f64` with its partial derivatives with respect to `[x, y, z, γ_I, γ_J]`,
/// for dual numbers (`chain`): `P_a = a^{K_I−1} b^{K_J} ζ^N Σ ĉ_k(K_I−k) r^k`, likewise `P_b`,
/// `P_ζ = a^{K_I} b^{K_J} ζ^{N−1} Σ ĉ_k(N+2k) r^k` (`r = ζ²/(ab)`; for N = 0
/// `a^{K_I−1} b^{K_J−1} ζ Σ ĉ_{k+1} 2(k+1) r^k`), through `a = 1 − γ_I²τ²/x`, `b = 1 − γ_J²τ²/y`,
/// `ζ = (z − γ_Iγ_Jτ²)/√(xy)`. Every node has τ < 1, so `a, b ≥ 1 − τ² > 0`.
fn quadrature_partials(inputs: [f64; 5], rule: &[(f64, f64)], series: &Coefficients) -> (f64, [f64; 5]) {
    let [x, y, z, gam_i, gam_j] = inputs;
    let (ki, kj, n) = (series.ki as i32, series.kj as i32, series.n as i32);
    let rt = (x * y).sqrt();
    let (mut f, mut d) = (0.0, [0.0; 5]);
    for &(tau, weight) in rule {
        let t2 = tau * tau;
        let a = (1.0 - gam_i * gam_i * t2 / x).max(0.0);
        let b = (1.0 - gam_j * gam_j * t2 / y).max(0.0);
        let zeta = (z - gam_i * gam_j * t2) / rt;
        let r = if a * b > 0.0 { (zeta * zeta / (a * b)).min(1.0) } else { 1.0 };
        let (pa, pb, pz) = (a.powi(ki), b.powi(kj), zeta.powi(n));
        f += weight * pa * pb * pz * horner(&series.c, r);
        let p_a = if ki > 0 { weight * a.powi(ki - 1) * pb * pz * horner(&series.cx, r) } else { 0.0 };
        let p_b = if kj > 0 { weight * pa * b.powi(kj - 1) * pz * horner(&series.cy, r) } else { 0.0 };
        let p_z = match n {
            0 if ki > 0 && kj > 0 => weight * a.powi(ki - 1) * b.powi(kj - 1) * zeta * horner(&series.cz, r),
            0 => 0.0,
            _ => weight * pa * pb * zeta.powi(n - 1) * horner(&series.cz, r),
        };
        // a(x, γ_I), b(y, γ_J), ζ(x, y, z, γ_I, γ_J)
        d[0] += p_a * gam_i * gam_i * t2 / (x * x) - p_z * zeta / (2.0 * x);
        d[1] += p_b * gam_j * gam_j * t2 / (y * y) - p_z * zeta / (2.0 * y);
        d[2] += p_z / rt;
        d[3] += -p_a * 2.0 * gam_i * t2 / x - p_z * gam_j * t2 / rt;
        d[4] += -p_b * 2.0 * gam_j * t2 / y - p_z * gam_i * t2 / rt;
    }
    (f, d)
}
/// The ĉ_k of the pair (K_I, K_J) and the context's N (module docs), k = 0..=min(K_I, K_J).
pub(crate) fn series_coefficients<const D: usize>(go: &GvrOps<D>, ki: u32, kj: u32) -> Vec<f64> {
    Coefficients::new(ki, kj, go.n_ang).c
}

/// `ln S_0 = −(3/2) ln(|B|/π^D)` (module docs) from `ln|B|`.
#[inline]
pub(crate) fn log_s0<T: Sub<f64, Output = T> + Mul<f64, Output = T>, const D: usize>(log_det: T) -> T {
    (log_det - D as f64 * PI.ln()) * -1.5
}

/// `<phi_I| 1, T, V |phi_J>` for one pair of normalised ECG-GVR functions.
pub fn element<const D: usize, T: Real>(bra: &GvrFunction<D, T>, ket: &GvrFunction<D, T>, go: &GvrOps<D>) -> Element<T> {
    let ops = &go.ops;
    let n = go.n_ang;
    // A_I + A_J is positive definite, but for near-singular functions its factorisation can
    // fail in floating point: the element is then NaN and the caller rejects the function
    let Some((binv, log_det)) = inverse_log_det(&(bra.a + ket.a)) else {
        return Element::nan();
    };
    let gi = mul(&binv, &bra.u);
    let gj = mul(&binv, &ket.u);
    let x = bra.u.dot(&gi) * 0.5;
    let y = ket.u.dot(&gj) * 0.5;
    let z = bra.u.dot(&gj) * 0.5;
    let log_s0 = log_s0::<_, D>(log_det);
    let series = Coefficients::new(bra.k, ket.k, n);
    let (l, om, ox, oy, oz) = omega(&series.terms(), x, y, z);
    let scale = (log_s0 + l - bra.log_norm - ket.log_norm).exp();
    let s = scale * om;

    // kinetic with Λ
    let lam_ui = mul(&ops.lambda, &bra.u);
    let lam_uj = mul(&ops.lambda, &ket.u);
    let zl = mul(&ket.a, &lam_ui); // A_J Λ u_I
    let zr = mul(&bra.a, &lam_uj); // A_I Λ u_J
    let w = mul(&bra.a, &mul(&ops.lambda, &ket.a)); // A_I Λ A_J
    let (hi, hj) = (gi * re::<T>(0.5), gj * re::<T>(0.5)); // C u
    let t = scale * kinetic(bra.u.dot(&lam_uj), [&zl, &zr, &hi, &hj], &w, &binv, (om, ox, oy, oz));
    let t_ti = match ops.cm_mass {
        Some(m) => t - scale * cm_kinetic(bra.c_a, ket.c_a, bra.c_u, ket.c_u, m, (om, ox, oy, oz)),
        None => t,
    };

    // Coulomb by exact Gauss–Legendre quadrature in τ (`quadrature`)
    let rule = go.legendre[(bra.k + ket.k + n) as usize];
    let mut v = T::zero();
    for (wv, q) in &ops.pairs {
        let c = dot_f(&mul(&wv.transpose(), &binv).transpose(), wv); // w^T B^{-1} w
        let sq = (c * 2.0).sqrt();
        let inputs = [x, y, z, dot_f(&gi, wv) / sq, dot_f(&gj, wv) / sq];
        // the f64 node loop with its partials chained on (first order); hyper-duals run it in `T`
        let integral = if T::ORDER == 1 {
            let (f0, partials) = quadrature_partials(inputs.map(|s| s.value()), rule, &series);
            chain(f0, inputs, partials)
        } else {
            quadrature(inputs, rule, &series)
        };
        v += re::<T>(*q * 2.0) / (c * PI).sqrt() * integral;
    }
    Element { s, t, t_ti, v: scale * v }
}

/// `T/(S_0 e^L)` of the module docs from `λ = u_IᵀΛu_J`, `[A_JΛu_I, A_IΛu_J, ũ_I, ũ_J]`, `W`, `B⁻¹`
/// and `(Ω, Ω_x, Ω_y, Ω_z)/e^L` (`omega`).
#[inline]
pub(crate) fn kinetic<T: Real, const D: usize>(lam: T, v: [&SVector<T, D>; 4], w: &SMatrix<T, D, D>, binv: &SMatrix<T, D, D>, omegas: (T, T, T, T)) -> T {
    let ([zl, zr, hi, hj], (om, ox, oy, oz)) = (v, omegas);
    let tr_wc = binv.component_mul(&w.transpose()).sum() * 0.5;
    let (w_hi, w_hj) = (mul(w, hi), mul(w, hj));
    // (written as `a * 4.0 * b` to keep the rounding of the f64 kernel's `4.0 * a * b`)
    lam * oz - zl.dot(hi) * 4.0 * ox - zl.dot(hj) * 2.0 * oz - zr.dot(hj) * 4.0 * oy - zr.dot(hi) * 2.0 * oz
        + tr_wc * 12.0 * om
        + hi.dot(&w_hi) * 8.0 * ox
        + (hi.dot(&w_hj) + hj.dot(&w_hi)) * 4.0 * oz
        + hj.dot(&w_hj) * 8.0 * oy
}

/// The profile of the damped overlap `<φ_I| exp(−α r_w²) |φ_J> = (1 − u)^{3/2} G(u)`,
/// `u = αq/(1 + αq)` (`operators::profile`), as the coefficients `g_k` of `G = Σ_k g_k v^k`,
/// `v = 1 − u`. Damping by `α w wᵀ` turns `B^{-1}` into `B^{-1} − (u/q) b bᵀ`, `b = B^{-1} w`
/// (Sherman–Morrison), and `S_0` into `(1 − u)^{3/2} S_0`, so x, y, z fall linearly in u as in the
/// Coulomb element: `G = S_0 Ω(x' + vγ_I², y' + vγ_J², z' + vγ_Iγ_J)`, `x' = x − γ_I²`,
/// `y' = y − γ_J²`, `z' = z − γ_Iγ_J` (the covariances conditioned on `r_w = 0`), expanded in v
/// term by term of Ω scaled by `x`, `y`, `√(xy)` as `omega` scales it.
pub fn profile<const D: usize>(bra: &GvrFunction<D>, ket: &GvrFunction<D>, go: &GvrOps<D>, w: &Vector<D>) -> Vec<f64> {
    let n = go.n_ang;
    let Some((binv, log_det)) = inverse_log_det(&(bra.a + ket.a)) else {
        return vec![f64::NAN; (bra.k + ket.k + n) as usize + 1];
    };
    let (gi, gj) = (binv * bra.u, binv * ket.u);
    let (x, y, z) = (bra.u.dot(&gi) * 0.5, ket.u.dot(&gj) * 0.5, bra.u.dot(&gj) * 0.5);
    let sq = (w.dot(&(binv * w)) * 2.0).sqrt();
    let (gam_i, gam_j) = (gi.dot(w) / sq, gj.dot(w) / sq);
    let rt = (x * y).sqrt();
    // X/x, Y/y, Z/√(xy) as polynomials a_0 + a_1 v
    let xs = [(x - gam_i * gam_i) / x, gam_i * gam_i / x];
    let ys = [(y - gam_j * gam_j) / y, gam_j * gam_j / y];
    let zs = [(z - gam_i * gam_j) / rt, gam_i * gam_j / rt];
    // Σ_k ĉ_k (XY)^{m−k} (Z²)^k, m = min(K_I, K_J), by Horner in XY: acc ← acc XY + ĉ_k Z^{2k}
    let c = Coefficients::new(bra.k, ket.k, n).c;
    let xy = [xs[0] * ys[0], xs[0] * ys[1] + xs[1] * ys[0], xs[1] * ys[1]];
    let zz = [zs[0] * zs[0], 2.0 * zs[0] * zs[1], zs[1] * zs[1]];
    let degree = (bra.k + ket.k + n) as usize;
    let (mut acc, mut zz_k) = (Vec::with_capacity(degree + 1), Vec::with_capacity(degree + 1));
    acc.push(c[0]);
    zz_k.push(1.0);
    for ck in &c[1..] {
        times(&mut zz_k, &zz);
        times(&mut acc, &xy);
        for (a, b) in acc.iter_mut().zip(&zz_k) {
            *a += ck * b;
        }
    }
    let m = c.len() as u32 - 1;
    for (factor, power) in [(&xs, bra.k - m), (&ys, ket.k - m), (&zs, n)] {
        for _ in 0..power {
            times(&mut acc, factor);
        }
    }
    let nf = n as f64;
    let l = x.ln() * (bra.k as f64 + 0.5 * nf) + y.ln() * (ket.k as f64 + 0.5 * nf);
    let log_s0 = log_s0::<_, D>(log_det);
    let scale = (log_s0 + l - bra.log_norm - ket.log_norm).exp();
    acc.iter().map(|g| scale * g).collect()
}

/// `a ← a b` for polynomials (coefficients from the constant term up), in place: from the top
/// term down, each new coefficient reads only old ones below it (summed from a's lowest term up).
fn times(a: &mut Vec<f64>, b: &[f64]) {
    let n = a.len();
    a.resize(n + b.len() - 1, 0.0);
    for i in (0..a.len()).rev() {
        a[i] = (i.saturating_sub(n - 1)..b.len().min(i + 1)).rev().fold(0.0, |sum, j| sum + a[i - j] * b[j]);
    }
}

impl<const D: usize, T: Real> Transform<D, GvrOps<D>> for GvrFunction<D, T> {
    /// `phi(T r)`: `A -> T^T A T`, `u -> T^T u`.
    fn transformed(&self, t: &Mat<D>, go: &GvrOps<D>, index: usize) -> Result<Self> {
        let t: SMatrix<T, D, D> = t.map(re);
        Self::new(t.transpose() * self.a * t, t.transpose() * self.u, self.k, self.c_a, go, index)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::families::ecg_gvr::build::{self, coulomb_partials};
    use crate::families::ecg_gvr::tau::{derivative_series, padded_rule};
    use crate::isa::Isa;

    #[test]
    fn quadrature_partials_match_dual_numbers() {
        use crate::gradient::{seed, Dual};
        // inputs of a valid covariance structure: x = |p|², y = |q|², z = p·q, γ_I = p·e,
        // γ_J = q·e for a unit vector e (then x_τ, y_τ, x_τ y_τ − z_τ² >= 0 for τ <= 1)
        let (p, q, e) = ([0.9, -0.3, 0.4], [0.2, 0.7, -0.5], [0.6, 0.0, 0.8]);
        let dot = |a: &[f64; 3], b: &[f64; 3]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
        let inputs = [dot(&p, &p), dot(&q, &q), dot(&p, &q), dot(&p, &e), dot(&q, &e)];
        let duals: [Dual<5>; 5] = std::array::from_fn(|k| seed(inputs[k], (0..5).map(|l| f64::from(k == l))));
        for (ki, kj, n) in
            [(0, 0, 0), (1, 0, 0), (0, 3, 0), (2, 2, 0), (7, 4, 0), (0, 0, 1), (3, 0, 2), (5, 9, 1), (30, 24, 0)]
        {
            let series = Coefficients::new(ki, kj, n);
            let rule = legendre_rule(((ki + kj + n) / 2 + 1) as usize);
            let (f, d) = quadrature_partials(inputs, rule, &series);
            let reference = quadrature(duals, rule, &series);
            let scale = reference.re.abs().max(1e-300);
            assert!((f - reference.re).abs() < 1e-13 * scale, "K=({ki},{kj}) N={n}: value");
            let eps = reference.eps.unwrap_generic(nalgebra::Const::<5>, nalgebra::U1);
            for k in 0..5 {
                let tol = 1e-12 * (eps[k].abs() + scale);
                assert!((d[k] - eps[k]).abs() < tol, "K=({ki},{kj}) N={n}: ∂/∂input {k}: {} vs {}", d[k], eps[k]);
            }
        }
    }

    #[test]
    fn coulomb_partials_match_the_node_loop() {
        // valid covariance inputs as in `quadrature_partials_match_dual_numbers`, several per call
        let dot = |a: &[f64; 3], b: &[f64; 3]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
        let e = [0.6, 0.0, 0.8];
        let inputs: Vec<[f64; 5]> = [([0.9, -0.3, 0.4], [0.2, 0.7, -0.5]), ([0.1, 0.5, 0.3], [0.6, 0.2, 0.1]), ([0.6, 0.0, 0.8], [0.5, 0.1, 0.7])]
            .iter()
            .map(|(p, q)| [dot(p, p), dot(q, q), dot(p, q), dot(p, &e), dot(q, &e)])
            .collect();
        let ops = Operators { lambda: Mat::<2>::identity(), pairs: vec![], cm_mass: None };
        for n in 0..3 {
            let go = GvrOps::new(ops.clone(), n, 40).unwrap();
            for (ki, kj) in [(0, 0), (1, 0), (0, 3), (2, 2), (7, 4), (19, 12), (30, 24), (40, 40)] {
                let mut out = vec![(0.0, [0.0; 5]); inputs.len()];
                coulomb_partials(&go, ki, kj, &inputs, &mut out);
                let series = Coefficients::new(ki, kj, n);
                let rule = go.legendre[(ki + kj + n) as usize];
                for (x, (f, d)) in inputs.iter().zip(&out) {
                    let (f0, d0) = quadrature_partials(*x, rule, &series);
                    assert!((f - f0).abs() <= 1e-13 * f0.abs(), "K=({ki},{kj}) N={n}: {f} vs {f0}");
                    for k in 0..5 {
                        assert!((d[k] - d0[k]).abs() <= 1e-13 * d0[k].abs().max(f0.abs()), "K=({ki},{kj}) N={n} ∂{k}: {} vs {}", d[k], d0[k]);
                    }
                }
                // the same bits on every instruction set
                let (tau2, weight) = padded_rule(rule);
                for isa in [Isa::Plain, Isa::Avx2, Isa::Avx512] {
                    let mut o = vec![(0.0, [0.0; 5]); inputs.len()];
                    build::partials_with(isa, (&series.c, &derivative_series(&series.c)), (ki, kj, n), &tau2, &weight, &inputs, &mut o);
                    assert_eq!(o, out, "{isa:?}");
                }
            }
        }
    }

    #[test]
    fn series_matches_hand_values() {
        // K_I = K_J = 1, N = 0: G = ĉ_0 + ĉ_1 ρ² with ĉ_1 = 1/(1·3/2) = 2/3
        let series = Coefficients::new(1, 1, 0);
        let (g, gx, gy) = (horner(&series.c, 0.25f64), horner(&series.cx, 0.25f64), horner(&series.cy, 0.25f64));
        let gz = 0.25 * horner(&series.cz, 0.25f64); // stored divided by r for N = 0
        assert!((g - (1.0 + 0.25 * 2.0 / 3.0)).abs() < 1e-15);
        assert!((gx - 1.0).abs() < 1e-15 && (gy - 1.0).abs() < 1e-15);
        assert!((gz - 2.0 * 0.25 * 2.0 / 3.0).abs() < 1e-15);
    }
}
