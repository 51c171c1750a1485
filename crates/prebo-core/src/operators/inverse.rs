//! `1/|r_w|`: from `1/|y| = π^{−1/2} ∫_0^∞ t^{−1/2} exp(−t y²) dt` and the damped overlap's
//! profile (profile.rs), `<φ_I| 1/|r_w| |φ_J> = (2/√(πq)) ∫_0^1 G(τ²) dτ`
//! (docs/properties-derivations.md, eq. 12): for a polynomial `G` the moment n = −1 of its
//! coefficients (`Profile::moment`, eq. 33); `S erf(√λ)/√(λq)` for `G = S exp(−λu)` (the
//! floating-ECG Coulomb element).
use super::profile::Profile;
use crate::ecg::Vector;
use crate::families::fecg::kernel::coulomb_factor;
use crate::families::Family;

pub const NAME: &str = "inv_r";

/// `<φ_I| 1/|r_w| |φ_J>` for normalised functions (bohr⁻¹).
pub fn element<const D: usize, F: Family<D>>(bra: &F::Function<f64>, ket: &F::Function<f64>, ctx: &F::Context, w: &Vector<D>) -> f64 {
    let p = Profile::<D, F>::of(bra, ket, ctx, w);
    p.moment(-1).unwrap_or_else(|| p.s * coulomb_factor(p.lambda() * p.q, p.q))
}
