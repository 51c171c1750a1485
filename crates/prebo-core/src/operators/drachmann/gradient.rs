//! `gradient_inv_r`, `<∇φ_I| Λ/|r_w| |∇φ_J>` (module `drachmann`'s docs, eqs. 28–30).

use std::f64::consts::PI;

use nalgebra::{Const, U1};

use crate::ecg::{Mat, Vector};
use crate::quadrature::legendre_rule;
use crate::families::fecg::kernel::erf;
use crate::families::{Family, Shape};
use crate::gradient::{seed, Dual};
use crate::operators::profile::Profile;

/// `<∇φ_I| Λ/|r_w| |∇φ_J>` (hartree/bohr; `v = [w]`; module docs) from the family's kinetic
/// elements of its damped functions (the generic element; ECG-GVR has its own, `ecg_gvr::drachmann`).
pub fn gradient_inv_r<const D: usize, F: Family<D>>(bra: &F::Function<f64>, ket: &F::Function<f64>, ctx: &F::Context, v: &[Vector<D>]) -> f64 {
    let w = &v[0];
    let ww = w * w.transpose();
    let kinetic = F::kinetic_only(ctx);
    kinetic_by_damping::<D, F>(bra, ket, ctx, w, |alpha| {
        let damping: Mat<D> = ww * alpha;
        let t = 0.5 * (F::element(&F::damped(bra, &damping), ket, &kinetic).t_ti + F::element(bra, &F::damped(ket, &damping), &kinetic).t_ti);
        let a: Dual<1> = seed(alpha, std::iter::once(1.0));
        let d = F::overlap(&F::cast::<Dual<1>>(bra), &F::damped(ket, &ww.map(|x| a * x)), ctx);
        [t, d.re, -d.eps.unwrap_generic(Const::<1>, U1)[0]]
    })
}

/// `<∇φ_I| Λ/|r_w| |∇φ_J>` by eq. (30) over the profile's rule (module docs), given at the damping
/// `α` the kinetic part `½[T_TI(gφ_I, φ_J) + T_TI(φ_I, gφ_J)]`, `D(α)` and `R = −∂D/∂α` (`node`).
pub fn kinetic_by_damping<const D: usize, F: Family<D>>(
    bra: &F::Function<f64>,
    ket: &F::Function<f64>,
    ctx: &F::Context,
    w: &Vector<D>,
    node: impl Fn(f64) -> [f64; 3],
) -> f64 {
    let p = Profile::<D, F>::of(bra, ket, ctx, w);
    let q = p.q;
    let wlw = w.dot(&(F::operators(ctx).lambda * w));
    // <∇φ_I| g Λ |∇φ_J> / (1 − u)^{3/2} at u (eq. 30)
    let h = |u: f64| {
        let alpha = u / (q * (1.0 - u));
        let [t, d, r] = node(alpha);
        (t + 0.5 * wlw * (4.0 * alpha * alpha * r - 6.0 * alpha * d)) / (1.0 - u).powf(1.5)
    };
    let integral: f64 = match &p.shape {
        // degree M + 1 in u = τ²: exact with ⌊(M + 1)/2⌋ + 1 positive nodes (eq. 18)
        Shape::Polynomial(g) => legendre_rule(g.len() / 2 + 1).iter().map(|&(tau, wt)| wt * h(tau * tau)).sum(),
        // S e^{−λu}(f₀ + f₁u + f₂u²) (eq. 28): the quadratic through u = 0, ¼, ½, then
        // Σ_j f_j F_j(λ) (eq. 29)
        Shape::Exponential => {
            let lambda = p.lambda();
            let [y0, y1, y2] = [0.0, 0.25, 0.5].map(|u| h(u) * (lambda * u).exp());
            let f = [y0, -2.0 * (3.0 * y0 - 4.0 * y1 + y2), 8.0 * (y0 - 2.0 * y1 + y2)];
            (0..3).map(|j| f[j] * boys(j, lambda)).sum()
        }
    };
    2.0 / (PI * q).sqrt() * integral
}

/// The Boys function `F_j(λ) = ∫_0^1 τ^{2j} e^{−λτ²} dτ`: below λ = j + 8 the series of positive
/// terms `e^{−λ} Σ_k (2λ)^k/((2j + 1)(2j + 3)⋯(2j + 2k + 1))` (from integrating by parts), above
/// it `F_0 = √π erf(√λ)/(2√λ)` and the upward recurrence `F_{i+1} = ((2i + 1)F_i − e^{−λ})/(2λ)`,
/// which damps rounding there (`2i + 1 < 2λ`).
pub(crate) fn boys(j: usize, lambda: f64) -> f64 {
    if lambda < j as f64 + 8.0 {
        let (mut term, mut sum, mut k) = (1.0 / (2 * j + 1) as f64, 0.0, 0);
        while term > 1e-17 * sum {
            sum += term;
            k += 1;
            term *= 2.0 * lambda / (2 * (j + k) + 1) as f64;
        }
        return (-lambda).exp() * sum;
    }
    let mut f = 0.5 * (PI / lambda).sqrt() * erf(lambda.sqrt());
    for i in 0..j {
        f = ((2 * i + 1) as f64 * f - (-lambda).exp()) / (2.0 * lambda);
    }
    f
}
