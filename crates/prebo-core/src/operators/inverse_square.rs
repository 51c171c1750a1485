//! `1/r_w²`: from `1/y² = ∫_0^∞ exp(−t y²) dt` and the damped overlap's profile (profile.rs),
//! `<φ_I| 1/r_w² |φ_J> = (2/q) ∫_0^1 G(1 − σ²) dσ` (docs/properties-derivations.md, eq. 13):
//! for a polynomial `G` the moment n = −2 of its coefficients (`Profile::moment`, eq. 33);
//! `(2S/q) ∫_0^1 exp(−λ(1 − σ²)) dσ` (Dawson's integral) for `G = S exp(−λu)`.
use super::profile::{rising_gaussian, Profile};
use crate::ecg::Vector;
use crate::families::Family;

pub const NAME: &str = "inv_r2";

/// `<φ_I| 1/r_w² |φ_J>` for normalised functions (bohr⁻²).
pub fn element<const D: usize, F: Family<D>>(bra: &F::Function<f64>, ket: &F::Function<f64>, ctx: &F::Context, w: &Vector<D>) -> f64 {
    let p = Profile::<D, F>::of(bra, ket, ctx, w);
    p.moment(-2).unwrap_or_else(|| 2.0 * p.s / p.q * rising_gaussian(p.lambda()))
}
