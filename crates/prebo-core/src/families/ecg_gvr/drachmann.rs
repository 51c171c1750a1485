//! `<φ_I| V/|r_w| |φ_J>` of ECG-GVR functions (its `coulomb_inv_r`, `operators.rs`; docs/properties-derivations.md
//! eq. 38): the quadrature of `drachmann::coulomb::by_damping` over the Coulomb elements of the damped
//! functions `e^{−α r_w²} φ_J`, each read off one factorisation of `B = A_I + A_J` instead of its
//! own. Damping adds `α w wᵀ` to `B`, so (Sherman–Morrison, the matrix determinant lemma)
//!
//! ```text
//!     B_α⁻¹ = B⁻¹ − κ b bᵀ,   |B_α| = (1 + αq) |B|,   b = B⁻¹w,  q = wᵀb,  κ = α/(1 + αq),
//! ```
//!
//! and the inputs of the Coulomb element (`element` module docs) for the pair `w'` move as
//! scalars: `x_α = x − κ(bᵀu_I)²/2`, likewise `y_α`, `z_α = z − κ(bᵀu_I)(bᵀu_J)/2`,
//! `c'_α = c' − κ(bᵀw')²` and `(B_α⁻¹u_I)·w' = (B⁻¹u_I)·w' − κ(bᵀu_I)(bᵀw')`.
//!
//! `<∇φ_I| Λ/|r_w| |∇φ_J>` (its `gradient_inv_r`, `operators.rs`) needs at each node of eq. (30) the kinetic
//! elements of `e^{−α r_w²}φ_I` with `φ_J` and of `φ_I` with `e^{−α r_w²}φ_J`. Both have
//! `B_α = B + αwwᵀ`, so both have its `x, y, z`, `Ω` and its derivatives (`element` module
//! docs), and the kinetic element is linear in `W = A_IΛA_J`, `A_JΛu_I` and `A_IΛu_J`: their mean
//! is one element with `W + (α/2)(w (A_JΛw)ᵀ + (A_IΛw) wᵀ)`, `A_JΛu_I + (α/2)(wᵀΛu_I) w` and
//! `A_IΛu_J + (α/2)(wᵀΛu_J) w`. The damped overlap `D = S_0(B_α) Ω` and `R = −∂D/∂α` follow
//! from `∂ ln|B_α|/∂α = wᵀB_α⁻¹w` and `∂x/∂α = −(u_IᵀB_α⁻¹w)²/2` (likewise y, z). `B_α` is
//! factorised at each node: its Sherman–Morrison update loses digits along `w` where the pair is
//! held close (agreement with the generic path 1.4e-9 against 5.1e-10 at `A + 10⁵ wwᵀ`).
use std::f64::consts::PI;

use super::element::{kinetic, log_s0, quadrature, GvrFunction, GvrOps};
use super::series::{cm_kinetic, omega, Coefficients};
use super::EcgGvr;
use crate::ecg::{log_det_cholesky, Mat, Vector};
use crate::operators::drachmann::{coulomb::by_damping, gradient::kinetic_by_damping};

/// `<φ_I| 1/(|r_w| |r_w'_k|) |φ_J>` for normalised ECG-GVR functions and each Coulomb pair `w'_k`
/// (bohr⁻², `drachmann::InverseProducts`); NaN where `A_I + A_J` does not factorise.
pub fn inverse_products<const D: usize>(bra: &GvrFunction<D>, ket: &GvrFunction<D>, go: &GvrOps<D>, w: &Vector<D>, known: &[Option<f64>]) -> Vec<f64> {
    match damped_inverse(bra, ket, go, w) {
        Some(damped) => by_damping::<D, EcgGvr>(bra, ket, go, w, known, damped),
        None => vec![f64::NAN; go.ops.pairs.len()],
    }
}

/// `(α, k) ↦ <φ_I| e^{−α r_w²}/|r_w'_k| |φ_J>` for normalised ECG-GVR functions and the Coulomb
/// pairs `w'_k`, each read off the factorisation of `A_I + A_J` (module docs); None where it does
/// not factorise.
pub(crate) fn damped_inverse<'a, const D: usize>(bra: &'a GvrFunction<D>, ket: &'a GvrFunction<D>, go: &'a GvrOps<D>, w: &Vector<D>) -> Option<impl Fn(f64, usize) -> f64 + 'a> {
    let chol = (bra.a + ket.a).cholesky()?;
    let (gi, gj, b) = (chol.solve(&bra.u), chol.solve(&ket.u), chol.solve(w));
    let (x, y, z) = (bra.u.dot(&gi) * 0.5, ket.u.dot(&gj) * 0.5, bra.u.dot(&gj) * 0.5);
    let (q, bi, bj) = (w.dot(&b), bra.u.dot(&b), ket.u.dot(&b));
    let log_s0 = log_s0::<_, D>(log_det_cholesky(&chol)) - bra.log_norm - ket.log_norm;
    let n = go.n_ang;
    let (pi, pj) = (bra.k as f64 + 0.5 * n as f64, ket.k as f64 + 0.5 * n as f64);
    let (series, rule) = (Coefficients::new(bra.k, ket.k, n), go.rule(bra.k + ket.k + n));
    // per Coulomb pair w': c' = w'ᵀB⁻¹w', (B⁻¹u_I)·w', (B⁻¹u_J)·w', bᵀw'
    let pairs: Vec<[f64; 4]> = go.ops.pairs.iter().map(|(wp, _)| [wp.dot(&chol.solve(wp)), gi.dot(wp), gj.dot(wp), b.dot(wp)]).collect();
    Some(move |alpha: f64, k: usize| {
        let [c, gwi, gwj, bw] = pairs[k];
        let kappa = alpha / (1.0 + alpha * q);
        let (xa, ya, za) = (x - 0.5 * kappa * bi * bi, y - 0.5 * kappa * bj * bj, z - 0.5 * kappa * bi * bj);
        let ca = c - kappa * bw * bw;
        let sq = (2.0 * ca).sqrt();
        let inputs = [xa, ya, za, (gwi - kappa * bi * bw) / sq, (gwj - kappa * bj * bw) / sq];
        // S_0(B_α) e^{L_α} / (𝒩_I 𝒩_J), L_α = (K_I + N/2) ln x_α + (K_J + N/2) ln y_α
        let scale = (log_s0 - 1.5 * (alpha * q).ln_1p() + pi * xa.ln() + pj * ya.ln()).exp();
        scale * 2.0 / (PI * ca).sqrt() * quadrature(inputs, rule, &series)
    })
}

/// `<∇φ_I| Λ/|r_w| |∇φ_J>` for normalised ECG-GVR functions (hartree/bohr; `v = [w]`; module
/// docs); NaN where `A_I + A_J` or a damped `B_α` does not factorise.
pub fn gradient_inv_r<const D: usize>(bra: &GvrFunction<D>, ket: &GvrFunction<D>, go: &GvrOps<D>, v: &[Vector<D>]) -> f64 {
    let (w, lambda) = (&v[0], &go.ops.lambda);
    let series = Coefficients::new(bra.k, ket.k, go.n_ang);
    let terms = series.terms();
    let (lw, lui, luj) = (lambda * w, lambda * bra.u, lambda * ket.u);
    let (lam, wlui, wluj) = (bra.u.dot(&luj), w.dot(&lui), w.dot(&luj));
    // W, A_JΛu_I, A_IΛu_J and the rank-one parts damping adds to their mean (module docs)
    let (w0, zl0, zr0) = (bra.a * lambda * ket.a, ket.a * lui, bra.a * luj);
    let dw: Mat<D> = w * (ket.a * lw).transpose() + (bra.a * lw) * w.transpose();
    let (b_sum, ww) = (bra.a + ket.a, w * w.transpose());
    kinetic_by_damping::<D, EcgGvr>(bra, ket, go, w, |alpha| {
        let Some(chol) = (b_sum + ww * alpha).cholesky() else { return [f64::NAN; 3] };
        let binv_a = chol.inverse();
        // C u = B_α⁻¹u/2
        let (hi, hj) = (binv_a * bra.u * 0.5, binv_a * ket.u * 0.5);
        let (x, y, z) = (bra.u.dot(&hi), ket.u.dot(&hj), bra.u.dot(&hj));
        let (l, om, ox, oy, oz) = omega(&terms, x, y, z);
        let scale = (log_s0::<_, D>(log_det_cholesky(&chol)) - bra.log_norm - ket.log_norm + l).exp();
        let wm = w0 + dw * (0.5 * alpha);
        let (zl, zr) = (zl0 + w * (0.5 * alpha * wlui), zr0 + w * (0.5 * alpha * wluj));
        let t = kinetic(lam, [&zl, &zr, &hi, &hj], &wm, &binv_a, (om, ox, oy, oz));
        let cm = go.ops.cm_mass.map_or(0.0, |m| cm_kinetic(bra.c_a, ket.c_a, bra.c_u, ket.c_u, m, (om, ox, oy, oz)));
        // B_α⁻¹w: its products with u_I, u_J, w
        let ba = binv_a * w;
        let (bia, bja, qa) = (bra.u.dot(&ba), ket.u.dot(&ba), w.dot(&ba));
        let d = scale * om;
        let r = 1.5 * qa * d + 0.5 * scale * (ox * bia * bia + oy * bja * bja + oz * bia * bja);
        [scale * (t - cm), d, r]
    })
}
