//! `|r_w|`: from `|y| = π^{−1/2} ∫_0^∞ t^{−1/2} y² exp(−t y²) dt` and the damped overlap
//! (profile.rs), `<φ_I| |r_w| |φ_J> = (2/√(πq)) ∫_0^1 (1 − τ²)^{−3/2} R(α(τ²)) dτ` with
//! `R = −∂_α <φ_I| exp(−α r_w²) |φ_J>` (docs/properties-derivations.md, eq. 18): for a
//! polynomial profile the moment n = 1 of its coefficients (`Profile::moment`, eq. 33);
//! `S [√(q/π) e^{−λ} + (λq + q/2) erf(√λ)/√(λq)]` for `G = S exp(−λu)` (eq. 16).
use std::f64::consts::PI;

use super::profile::Profile;
use crate::ecg::Vector;
use crate::families::fecg::kernel::coulomb_factor;
use crate::families::Family;

pub const NAME: &str = "r";

/// `<φ_I| |r_w| |φ_J>` for normalised functions (bohr).
pub fn element<const D: usize, F: Family<D>>(bra: &F::Function<f64>, ket: &F::Function<f64>, ctx: &F::Context, w: &Vector<D>) -> f64 {
    let p = Profile::<D, F>::of(bra, ket, ctx, w);
    p.moment(1).unwrap_or_else(|| {
        let (lambda, q) = (p.lambda(), p.q);
        p.s * ((q / PI).sqrt() * (-lambda).exp() + (lambda * q + 0.5 * q) * coulomb_factor(lambda * q, q))
    })
}
