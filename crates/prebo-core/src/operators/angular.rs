//! `N_TI²`, the square of the total orbital angular momentum in the centre-of-mass frame
//! (`N_TI = Σ_i r_i × p_i − R × P`, ħ = 1), for the families whose functions are not its
//! eigenfunctions (`Family::ANGULAR`: floating ECGs, crates/prebo-core/src/families/floating/fecg.rs);
//! one vector, the mass fractions `μ = m/m_tot` that define R and P. Plain ECGs and ECG-GVR are
//! eigenfunctions, `N_TI² φ = N(N + 1) φ`, and the registry has no element for them.
use crate::ecg::Vector;
use crate::families::Family;

pub const NAME: &str = "n2";

/// `<φ_I| N_TI² |φ_J>` for normalised functions of a family that has it (ħ²; `operators::lookup` checks).
pub fn element<const D: usize, F: Family<D>>(bra: &F::Function<f64>, ket: &F::Function<f64>, _: &F::Context, mu: &Vector<D>) -> f64 {
    let element = F::ANGULAR.unwrap_or_else(|| panic!("N_TI²: no element for {} functions", F::NAME));
    element(bra, ket, mu)
}
