//! The two elements Drachmann's regularised contact density needs beside `1/|r_w|`
//! (docs/properties-derivations.md §6, eq. 27):
//!
//! `<δ³(r_ij)> = (μ_ij/π) [ <(E − V)/r_ij> − <∇Ψ| Λ/r_ij |∇Ψ> ]`,
//!
//! an identity for eigenstates of `T_TI + V` whose right side converges faster in Gaussians,
//! which lack the cusp (`prebo.drachmann` assembles it per state).
//!
//! - `coulomb_inv_r`: `<φ_I| V/|r_w| |φ_J> = Σ_{k<l} q_k q_l <1/(|r_kl| |r_w|)>` over the Coulomb
//!   pairs `w'` of the context. Plain ECGs: each by eq. (19), `S 4 arcsin(ρ)/(πρ √(q₁₁q₂₂))`.
//!   Every other family: a pair parallel to `w` is `<1/r_w²>` scaled (eq. 13); any other pair is
//!   `1/|r_w| = π^{−1/2}∫α^{−1/2}e^{−α r_w²}dα` over the family's `1/|r_w'|` element of its
//!   damped functions (eq. 38), `(2/√(πq)) ∫_0^1 (1 − τ²)^{−3/2} <φ_I| e^{−α r_w²}/|r_w'| |φ_J> dτ`,
//!   `α = τ²/(q(1 − τ²))`. For plain ECGs the integrand is `S (2/√π)/√(q₂₂(1 − ρ²τ²))`, `ρ` the
//!   correlation of `r_w` and `r_w'` in the Gaussian: `τ = sin φ/ρ` makes it constant, and makes
//!   every family's integrand smooth where pairs are nearly parallel (a light particle's distances
//!   to two heavy ones). The integrand is even in φ: Gauss–Legendre rules on `[−φ_max, φ_max]` of
//!   growing size until two agree to 1e-11 (`even`), else panels halved until two rules agree
//!   (`adaptive`); `by_damping`. It costs tens of the family's `1/|r_w'|` elements per pair, up to
//!   hundreds where a floating ECG's centres or nearly parallel pairs shape the integrand; ECG-GVR
//!   reads them off one factorisation of `A_I + A_J` (`ecg_gvr::drachmann`).
//!   `<1/(|r_kl| |r_w|)>` is symmetric in the two vectors, so the operator takes all its instances
//!   at once (`coulomb::all`) and computes each product of two Coulomb pairs once, over the damping
//!   of the lighter pair: every pair asked for costs half the quadratures.
//! - `gradient_inv_r`: `<∇φ_I| Λ/|r_w| |∇φ_J>` with the `Λ` of the context's `T_TI` (the CM part
//!   removed: `1^T w = 0`, so `w^T Λ w = 1/(2μ_ij)` either way), from `1/|y| = π^{−1/2}∫t^{−1/2}e^{−ty²}dt`
//!   and eq. (30): with `g = exp(−α r_w²)`, `D(α) = <φ_I|g|φ_J>` and `R = −∂D/∂α`,
//!   `<∇φ_I| g Λ |∇φ_J> = ½[T_TI(gφ_I, φ_J) + T_TI(φ_I, gφ_J)] + ½ w^TΛw (4α²R − 6αD)`,
//!   the kinetic elements of the family's damped functions (`Family::damped`, in its context
//!   without Coulomb pairs, `Family::kinetic_only`). Divided by
//!   `(1 − u)^{3/2}` it is a polynomial of degree `M + 1` in `u = αq/(1 + αq)` for a profile of
//!   degree M (eq. 28; plain ECGs M = 0), integrated exactly by the rule of eq. (18); for an
//!   exponential profile (floating ECGs) `S e^{−λu}` times a quadratic (eq. 28), whose
//!   coefficients three values fix, integrated with Boys functions (eq. 29); the damped floating
//!   ECG is centred at `(A + M)^{-1} A s`, which its kinetic element needs (`FecgFunction::damped`).
//!   Every family.
pub mod coulomb;
pub mod gradient;

pub const COULOMB: &str = "coulomb_inv_r";
pub const GRADIENT: &str = "gradient_inv_r";

#[cfg(test)]
mod tests;
