//! Plain ECG matrix elements (paper section "pECG"; Suzuki & Varga, Lect. Notes Phys. m54, ch. 6).
//!
//! With `phi = exp(-r^T A r)` (no 1/2, see `ecg.rs`), `A_IJ = A_I + A_J`, `B = A_IJ^{-1}`:
//! - overlap      `S = (2^D |A_I|^{1/2} |A_J|^{1/2} / |A_IJ|)^{3/2}`           (normalised functions)
//! - kinetic      `T = 6 Tr(B A_I Λ A_J) S`                                      (paper: `6 R`)
//! - Coulomb      `<1/|w^T r|> = 2 / sqrt(pi w^T B w) S`
//! - CM removal   `T_TI = T - 3 c_I c_J / ((c_I + c_J) m_tot) S`
//!
//! The last line is paper eq. ecg-transl in this convention: the CM block of
//! `U_x B U_y^T` is `1/(c_I + c_J)`, of `U_y Λ U_x^T` is `1/(2 m_tot)`, so the CM
//! part of `6 Tr(B A_I Λ A_J)` is `6 c_I c_J / (2 m_tot (c_I + c_J))`
//! (= `3 c_A / (2 m_tot)` for a shared `c_A`, the kinetic energy of `exp(-c_A X^2)`).
//! It equals the kinetic element with `Λ = M - 1 1^T / (2 m_tot)` for every basis
//! whose functions are CM-separable, whatever their `c_A` (tests/test_elimination.py).
use std::f64::consts::{LN_2, PI};

use nalgebra::Cholesky;

use crate::ecg::{Element, Gaussian, Operators};

/// `<phi_I| 1, T, V |phi_J>` for one pair of normalised plain ECGs.
#[inline]
pub fn element<const D: usize>(bra: &Gaussian<D>, ket: &Gaussian<D>, ops: &Operators<D>) -> Element {
    let a_ij = bra.a + ket.a;
    // A_I + A_J is a sum of positive-definite matrices, hence positive definite:
    // the factorisation cannot fail for inputs that passed `Gaussian::new`.
    let chol = Cholesky::new(a_ij).expect("A_I + A_J of positive-definite A_I, A_J");
    let l = chol.l_dirty();
    let mut log_det_ij = 0.0;
    for k in 0..D {
        log_det_ij += 2.0 * l[(k, k)].ln();
    }
    // D coordinates, each 3-dimensional: the 3/2 power.
    let s = (1.5 * (D as f64 * LN_2 + 0.5 * (bra.log_det + ket.log_det) - log_det_ij)).exp();
    let b = chol.inverse();

    let x = bra.a * ops.lambda * ket.a;
    let r = b.component_mul(&x.transpose()).sum(); // Tr(B X)
    let t = 6.0 * r * s;
    let t_ti = match ops.cm_mass {
        Some(m_tot) => t - 3.0 * bra.c_a * ket.c_a / ((bra.c_a + ket.c_a) * m_tot) * s,
        None => t,
    };

    let mut v = 0.0;
    for (w, q) in &ops.pairs {
        let c = (w.transpose() * b * w)[(0, 0)];
        v += q * 2.0 / (PI * c).sqrt();
    }
    Element { s, t, t_ti, v: v * s }
}
