//! `δ³(r_w)`, the contact density of the pair vector `r_w = Σ_k w_k r_k` (for `w = e_i − e_j`,
//! particles i and j at one point): the limit `α → ∞` of `(α/π)^{3/2} exp(−α r_w²)`, so with the
//! damped overlap's profile (profile.rs) `<φ_I| δ³(r_w) |φ_J> = (πq)^{−3/2} G(1)`
//! (docs/properties-derivations.md, eq. 7): plain ECGs `S_IJ (πq)^{−3/2}`, floating ECGs
//! `S_IJ (πq)^{−3/2} exp(−|w^T r̄|²/q)`, ECG-GVR the overlap conditioned on `r_w = 0`.
use std::f64::consts::PI;

use super::profile::Profile;
use crate::ecg::Vector;
use crate::families::Family;

pub const NAME: &str = "delta";

/// `<φ_I| δ³(r_w) |φ_J>` for normalised functions (bohr⁻³).
pub fn element<const D: usize, F: Family<D>>(bra: &F::Function<f64>, ket: &F::Function<f64>, ctx: &F::Context, w: &Vector<D>) -> f64 {
    let p = Profile::<D, F>::of(bra, ket, ctx, w);
    (PI * p.q).powf(-1.5) * p.at_one()
}
