//! `N_TI²`, the square of the total orbital angular momentum in the centre-of-mass frame
//! (`N_TI = Σ_i r_i × p_i − R × P`, ħ = 1); one vector, the mass fractions `μ = m/m_tot` that
//! define R and P. Only families whose functions are not its eigenfunctions have an element, in
//! their folder (floating ECGs: families/fecg/operators.rs, `fecg::kernel::angular`); plain ECGs
//! and ECG-GVR are eigenfunctions, `N_TI² φ = N(N + 1) φ`, and there is no generic element.
pub const NAME: &str = "n2";
