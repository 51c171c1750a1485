//! The row gradient of a floating ECG by hand-derived derivatives (issue 15): one reverse pass
//! per element gives the gradients of `S`, `T`, `T_TI` and `V` with respect to the bra's `A_I`
//! and `s_I`, which are then contracted with every direction `(dA_p, ds_p)`. The same row as
//! `path::row_gradient` (the dual-number path, kept as the reference and for the diagonal,
//! `Fecg::row_gradient`).
//!
//! Notation of `fecg` (module docs, docs/gvr.md "Floating ECGs"): `B = A_I + A_J`,
//! `v = A_I s_I + A_J s_J`, `r̄ = B⁻¹v`, `d_I = r̄ - s_I`, `d_J = r̄ - s_J`, `W = A_I Λ A_J`,
//! `⟨X, Y⟩ = Σ X_ab Y_ab`. Along `(dA, ds)`: `dB = dA`, `d(B⁻¹) = -B⁻¹ dA B⁻¹`,
//! `dr̄ = B⁻¹(A_I ds - dA d_I)`. Hence a scalar of `r̄` with adjoint `ȳ` contributes
//! `⟨dA, -(B⁻¹ȳ) d_Iᵀ⟩ + ⟨ds, A_I B⁻¹ȳ⟩`, and the element's scalars give
//! - `ln S = ¾ ln|A_I| + ... - 3/2 ln|B| - (s_IᵀA_Is_I + s_JᵀA_Js_J - vᵀr̄)`:
//!   `d ln S = ¾ Tr(A_I⁻¹dA) + ⟨dA, -3/2 B⁻¹ - d_I d_Iᵀ⟩ + ⟨ds, 2 A_I d_I⟩`;
//! - `τ = 6R + Q` (`T = τS`), `R = Tr(B⁻¹W)`, `Q = 4⟨d_I, W d_J⟩`: `dR = ⟨dA, B⁻¹A_JΛA_JB⁻¹⟩`,
//!   `dQ = 4⟨dA, d_I (ΛA_J d_J)ᵀ - (B⁻¹y) d_Iᵀ⟩ + 4⟨ds, A_I B⁻¹y - W d_J⟩`, `y = W d_J + Wᵀd_I`;
//! - `ν = Σ_w q f(m², c)` (`V = νS`), `c = wᵀB⁻¹w`, `m = wᵀr̄`: with `b = B⁻¹w`,
//!   `dc = -⟨dA, b bᵀ⟩` and `Z = Σ_w 2q ∂f/∂(m²) b m`,
//!   `dν = ⟨dA, -Z d_Iᵀ - Σ_w q ∂f/∂c b bᵀ⟩ + ⟨ds, A_I Z⟩`;
//! - `κ = Q_cm + R_cm` (`T_TI = T - κS`, `c_A` fixed): `Q_cm = q₂ |e|²`, `e = 1ᵀA_Is_I/c_I - ...`,
//!   `dκ = (2q₂/c_I) e·1ᵀ(dA s_I + A_I ds)`.
//! So `dS = S d ln S`, `dT = S(dτ + τ d ln S)`, `dT_TI = dT - κ dS - S dκ`, `dV = S(dν + ν d ln S)`,
//! summed over the images of the ket; the normalisation `¾ Tr(A_I⁻¹dA_p)` multiplies each
//! symmetrised value once per direction.
use std::f64::consts::PI;

use nalgebra::Cholesky;
use rayon::prelude::*;

use super::kernel::{cm_shift, coulomb_factor, coulomb_moments, functions, kinetic, pair, Centres, FecgFunction, FecgParams};
use crate::cache::Cache;
use crate::ecg::{mul, Element, Mat, Operators};
use crate::error::{CoreError, Result};
use crate::params::{check, matrices_of, Directions, Parameters, Symmetry};
use crate::images::Images;
use crate::matrices::Matrices;

/// A gradient with respect to the bra's parameters: `⟨dA, a⟩ + ⟨ds, s⟩` along `(dA, ds)`.
#[derive(Clone, Copy)]
struct Grad<const D: usize> {
    a: Mat<D>,
    s: Centres<D>,
}

impl<const D: usize> Grad<D> {
    fn zero() -> Self {
        Self { a: Mat::zeros(), s: Centres::zeros() }
    }

    /// `self += x g`
    fn add(&mut self, x: f64, g: &Self) {
        self.a += g.a * x;
        self.s += g.s * x;
    }

    fn along(&self, da: &Mat<D>, ds: &Centres<D>) -> f64 {
        self.a.dot(da) + self.s.dot(ds)
    }
}

/// The gradients of `[S, T, T_TI, V]`.
type Gradients<const D: usize> = [Grad<D>; 4];

/// `F_1(t) = Σ_n (-t)^n/(n!(2n+3))` for `t < 0.1`: eleven terms, the next below 2e-18.
const F1_SERIES: [f64; 11] = {
    let mut a = [0.0; 11];
    let (mut term, mut n) = (1.0, 0); // (-1)^n/n!
    while n < 11 {
        a[n] = term / (2 * n + 3) as f64;
        n += 1;
        term = -term / n as f64;
    }
    a
};

/// `f = erf(|m|/√c)/|m|` (`kernel::coulomb_factor`) with `∂f/∂(m²)` and `∂f/∂c`. With
/// `f = 2/√(πc) F_0(t)`, `t = m²/c` and the Boys functions `F_0' = -F_1`,
/// `F_1 = (F_0 - e^{-t})/(2t)`: `∂f/∂(m²) = -2/√(πc) F_1(t)/c`, `∂f/∂c = -e^{-t}/(√π c^{3/2})`.
/// `F_1` by its series below `t = 0.1`, where the recursion would lose digits to cancellation.
fn coulomb_partials(m2: f64, c: f64) -> (f64, f64, f64) {
    let f = coulomb_factor(m2, c);
    let t = m2 / c;
    let exp_t = (-t).exp();
    let k = 2.0 / (PI * c).sqrt();
    let f1 = if t < 0.1 {
        F1_SERIES.iter().rev().fold(0.0, |acc, a| acc * t + a)
    } else {
        (f / k - exp_t) / (2.0 * t)
    };
    (f, -k * f1 / c, -k * exp_t / (2.0 * c))
}

/// Adds `coef <bra|O|ket>` to `e` and `coef` times its gradients (module docs, without the
/// normalisation's `¾ Tr(A_I⁻¹dA)`) to `g`; the values are those of `kernel::element`, bit for bit.
fn add_element<const D: usize>(
    bra: &FecgFunction<D>,
    ket: &FecgFunction<D>,
    ops: &Operators<D>,
    coef: f64,
    e: &mut Element,
    g: &mut Gradients<D>,
) {
    let Some((s, binv, rbar)) = pair(bra, ket) else {
        *e += (coef, Element::nan());
        for x in g.iter_mut() {
            x.a.fill(f64::NAN);
            x.s.fill(f64::NAN);
        }
        return;
    };
    let k = kinetic(bra, ket, &ops.lambda, &binv, &rbar);
    let t = k.tau * s;
    let cm = ops.cm_mass.map(|m| cm_shift(bra, ket, m));
    let kappa = cm.as_ref().map_or(0.0, |cm| cm.kappa);
    let t_ti = if cm.is_some() { t - kappa * s } else { t };
    let (mut nu, mut z, mut x) = (0.0, Centres::<D>::zeros(), Mat::<D>::zeros());
    for (w, q) in &ops.pairs {
        let (b, c, m) = coulomb_moments(w, &binv, &rbar);
        let (f, f_m2, f_c) = coulomb_partials(m.norm_squared(), c);
        nu += f * *q;
        z += mul(&b, &m) * (2.0 * q * f_m2);
        x += mul(&b, &b.transpose()) * (q * f_c);
    }
    *e += (coef, Element { s, t, t_ti, v: nu * s });

    let (ai, di) = (&bra.a, &k.di);
    let di_t = di.transpose();
    let ln_s = Grad { a: binv * -1.5 - mul(di, &di_t), s: mul(ai, di) * 2.0 };
    let p = mul(&binv, &ket.a); // B⁻¹A_J
    let h = mul(&ops.lambda, &mul(&ket.a, &k.dj)); // ΛA_J d_J
    let by = mul(&binv, &(k.w_dj + mul(&k.w.transpose(), di))); // B⁻¹y
    let tau = Grad {
        a: mul(&mul(&p, &ops.lambda), &p.transpose()) * 6.0 + (mul(di, &h.transpose()) - mul(&by, &di_t)) * 4.0,
        s: (mul(ai, &by) - k.w_dj) * 4.0,
    };
    let nu_g = Grad { a: -mul(&z, &di_t) - x, s: mul(ai, &z) };

    let sc = coef * s;
    g[0].add(sc, &ln_s);
    g[1].add(sc * k.tau, &ln_s);
    g[1].add(sc, &tau);
    g[2].add(sc * (k.tau - kappa), &ln_s);
    g[2].add(sc, &tau);
    g[3].add(sc * nu, &ln_s);
    g[3].add(sc, &nu_g);
    if let Some(cm) = cm {
        // -S dκ: dκ = (2 q₂/c_I) Σ_k e_k (1ᵀ dA s_I + 1ᵀ A_I ds)_k
        let scale = -sc * 2.0 * cm.q_per_d2 / bra.c_a;
        for b in 0..D {
            let (mut se, mut col) = (0.0, 0.0); // (s_I e)_b, (1ᵀA_I)_b
            for i in 0..D {
                col += ai[(i, b)];
            }
            for (xyz, ek) in cm.e.iter().enumerate() {
                se += bra.s[(b, xyz)] * ek;
                g[2].s[(b, xyz)] += scale * col * ek;
            }
            for a in 0..D {
                g[2].a[(a, b)] += scale * se;
            }
        }
    }
}

/// The row of one floating ECG against a basis with its derivatives along the directions `dir`:
/// the row of `path::row_gradient` (`(1 + P) x nb` matrices, row 0 the values with the function
/// as bra, the function un-transformed) by `add_element`; the basis images kept in `cache` (as
/// `path::basis_images`).
pub fn row_gradient<const D: usize>(
    ops: &Operators<D>,
    sym: &Symmetry<D>,
    trial: &FecgParams,
    dir: &Directions,
    basis: &FecgParams,
    cache: &Cache,
) -> Result<Matrices> {
    check(trial.len(), 1, "trial functions")?;
    let f = functions::<D>(trial)?.remove(0);
    let b = cache.get(basis, || Images::new(functions::<D>(basis)?, sym, ops))?;
    let (da, _) = dir.exponents::<D>()?;
    let ds = matrices_of::<D, 3>(dir.v, da.len(), "centre directions")?;
    let a_inv = Cholesky::new(f.a).ok_or(CoreError::NotPositiveDefinite { function: 0 })?.inverse();
    let norm: Vec<f64> = da.iter().map(|d| 0.75 * a_inv.dot(d)).collect(); // ¾ Tr(A_I⁻¹dA_p)
    let columns: Vec<Vec<Element>> = (0..b.len())
        .into_par_iter()
        .map(|j| {
            let (mut e, mut g) = (Element::zero(), [Grad::zero(); 4]);
            for (ket, c) in b.images[j].iter().zip(&b.coef) {
                add_element(&f, ket, ops, *c, &mut e, &mut g);
            }
            let mut out = Vec::with_capacity(1 + da.len());
            out.push(e);
            out.extend(da.iter().zip(&ds).zip(&norm).map(|((da, ds), n)| {
                let d = |x: &Grad<D>, value: f64| x.along(da, ds) + value * n;
                Element { s: d(&g[0], e.s), t: d(&g[1], e.t), t_ti: d(&g[2], e.t_ti), v: d(&g[3], e.v) }
            }));
            out
        })
        .collect();
    let mut m = Matrices::zeros(1 + da.len(), b.len());
    for (j, column) in columns.iter().enumerate() {
        for (k, x) in column.iter().enumerate() {
            m.set(k, j, x);
        }
    }
    Ok(m)
}

#[cfg(test)]
#[path = "gradient_tests.rs"]
mod tests;
