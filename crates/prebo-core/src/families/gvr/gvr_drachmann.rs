//! `<φ_I| V/|r_w| |φ_J>` of ECG-GVR functions (`Family::COULOMB`; docs/properties-derivations.md
//! eq. 38): the quadrature of `drachmann::by_damping` over the Coulomb elements of the damped
//! functions `e^{−α r_w²} φ_J`, each read off one factorisation of `B = A_I + A_J` instead of its
//! own. Damping adds `α w wᵀ` to `B`, so (Sherman–Morrison, the matrix determinant lemma)
//!
//! ```text
//!     B_α⁻¹ = B⁻¹ − κ b bᵀ,   |B_α| = (1 + αq) |B|,   b = B⁻¹w,  q = wᵀb,  κ = α/(1 + αq),
//! ```
//!
//! and the inputs of the Coulomb element (`gvr_element` module docs) for the pair `w'` move as
//! scalars: `x_α = x − κ(bᵀu_I)²/2`, likewise `y_α`, `z_α = z − κ(bᵀu_I)(bᵀu_J)/2`,
//! `c'_α = c' − κ(bᵀw')²` and `(B_α⁻¹u_I)·w' = (B⁻¹u_I)·w' − κ(bᵀu_I)(bᵀw')`.
use std::f64::consts::PI;

use super::gvr_element::{quadrature, Gvr, GvrOps};
use super::gvr_series::Coefficients;
use super::EcgGvr;
use crate::ecg::{log_det_cholesky, Vector};
use crate::operators::drachmann::by_damping;

/// `Σ_k q_k <φ_I| 1/(|r_w| |r_w'_k|) |φ_J>` for normalised ECG-GVR functions (hartree/bohr;
/// `v = [w]`); NaN where `A_I + A_J` does not factorise.
pub fn coulomb_inv_r<const D: usize>(bra: &Gvr<D>, ket: &Gvr<D>, go: &GvrOps<D>, v: &[Vector<D>]) -> f64 {
    let w = &v[0];
    let Some(chol) = (bra.a + ket.a).cholesky() else { return f64::NAN };
    let (gi, gj, b) = (chol.solve(&bra.u), chol.solve(&ket.u), chol.solve(w));
    let (x, y, z) = (bra.u.dot(&gi) * 0.5, ket.u.dot(&gj) * 0.5, bra.u.dot(&gj) * 0.5);
    let (q, bi, bj) = (w.dot(&b), bra.u.dot(&b), ket.u.dot(&b));
    let log_s0 = (log_det_cholesky(&chol) - D as f64 * PI.ln()) * -1.5 - bra.log_norm - ket.log_norm;
    let n = go.n_ang;
    let (pi, pj) = (bra.k as f64 + 0.5 * n as f64, ket.k as f64 + 0.5 * n as f64);
    let (series, rule) = (Coefficients::new(bra.k, ket.k, n), go.rule(bra.k + ket.k + n));
    // per Coulomb pair w': c' = w'ᵀB⁻¹w', (B⁻¹u_I)·w', (B⁻¹u_J)·w', bᵀw'
    let pairs: Vec<[f64; 4]> = go.ops.pairs.iter().map(|(wp, _)| [wp.dot(&chol.solve(wp)), gi.dot(wp), gj.dot(wp), b.dot(wp)]).collect();
    by_damping::<D, EcgGvr>(bra, ket, go, w, |alpha, k| {
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
