//! `p_g²`, `p_g⁴` and the orbit–orbit operator of ECG-GVR functions (docs/properties-derivations.md
//! eqs. 26–26c):
//! `<φ_I| p_g⁴ |φ_J> = <Δ_gφ_I|Δ_gφ_J>` with, for `φ = P(v) exp(−rᵀAr)`, `v = uᵀr`, `y = (Ag)ᵀr`,
//!
//! ```text
//!     Δ_g φ = [(uᵀg)² Δ_v P − 4 (uᵀg) y·∇_v P + (4|y|² − 6 gᵀAg) P] exp(−rᵀAr).        (26)
//! ```
//!
//! Each bracketed term is a first derivative of the overlap's generating function
//!
//! ```text
//!     G(ξ, s, t) = S_0(B') Ω(x' + ξ_I, y' + ξ_J, z'),   B' = B + t_I h_I h_Iᵀ + t_J h_J h_Jᵀ,
//!     u_I' = u_I + s_I h_I,  u_J' = u_J + s_J h_J,  h = A g,                                (26a)
//! ```
//!
//! x', y', z' the covariances of u_I', u_J' under B': `−∂_t` weights by |y|², `∂_s` is `y·∇_v`
//! (it moves v to v + s y), and `2∂_ξ` is `Δ_v` by Price's theorem (`∂Ω/∂x = E[Δ_a …]/2`). So
//! with `D_I = 2(u_Iᵀg)² ∂_{ξ_I} − 4(u_Iᵀg) ∂_{s_I} − 4 ∂_{t_I}` and `c_I = −6 gᵀA_Ig`,
//!
//! ```text
//!     <Δ_gφ_I|Δ_gφ_J> = (D_I + c_I)(D_J + c_J) G,   <φ_I|Δ_gφ_J> = (D_J + c_J) G,           (26b)
//! ```
//!
//! both read off one evaluation of G in hyper-dual numbers (ε₁ along D_I, ε₂ along D_J). The
//! orbit–orbit element (`orbit`) is read off the same generating function of damped functions.
use std::f64::consts::PI;
use std::ops::{Mul, Sub};

use nalgebra::{Cholesky, Const, RealField, SMatrix, SVector};
use num_dual::{Dual64, HyperDual64};

use super::element::{log_s0, GvrFunction, GvrOps};
use crate::quadrature::legendre_rule;
use super::series::{omega, Coefficients};
use crate::ecg::{log_det_cholesky, Vector};
use crate::scalar::Scalar;

type H = HyperDual64;

/// The generating function's moves (eq. 26a; `Generating::at`): `B' = B + b`, `u_I' = u_I + u_i`, `u_J' = u_J + u_j`,
/// and Ω's arguments moved by `omega` beyond the covariances under B'; in dual numbers where one
/// derivative is read (`Dual64`), hyper-dual ones where a mixed second one is (`H`).
struct Moves<T, const D: usize> {
    b: SMatrix<T, D, D>,
    u_i: SVector<T, D>,
    u_j: SVector<T, D>,
    omega: [T; 3],
}

/// The numbers the moves are made in: `Dual64` and `H`.
trait Moving: RealField + Copy + From<f64> + Mul<f64, Output = Self> + Sub<f64, Output = Self> + Scalar {}
impl<T: RealField + Copy + From<f64> + Mul<f64, Output = T> + Sub<f64, Output = T> + Scalar> Moving for T {}

/// `c (v wᵀ + w vᵀ)/2`: the matrix of the quadratic form `c (vᵀr)·(wᵀr)` (3-vectors dotted).
fn dyad<T: Moving, const D: usize>(v: &Vector<D>, w: &Vector<D>, c: T) -> SMatrix<T, D, D> {
    ((v * w.transpose() + w * v.transpose()) * 0.5).map(T::from) * c
}

/// What every move of one pair's generating function shares: the factor of `B = A_I + A_J`, Ω's
/// series and its scale L at B, and `S_0(B) e^L / (𝒩_I 𝒩_J)`, by which `at`'s ratios become
/// normalised elements.
struct Generating<'a, const D: usize> {
    bra: &'a GvrFunction<D>,
    ket: &'a GvrFunction<D>,
    chol: Cholesky<f64, Const<D>>,
    series: Coefficients,
    log_det: f64,
    l: f64,
    scale: f64,
}

impl<'a, const D: usize> Generating<'a, D> {
    /// None where `A_I + A_J` does not factorise.
    fn new(bra: &'a GvrFunction<D>, ket: &'a GvrFunction<D>, go: &GvrOps<D>) -> Option<Self> {
        let chol = (bra.a + ket.a).cholesky()?;
        let (ci, cj) = (chol.solve(&bra.u), chol.solve(&ket.u));
        let series = Coefficients::new(bra.k, ket.k, go.n_ang);
        let (l, ..) = omega(&series.terms(), bra.u.dot(&ci) * 0.5, ket.u.dot(&cj) * 0.5, bra.u.dot(&cj) * 0.5);
        let log_det = log_det_cholesky(&chol);
        let log_s0 = log_s0::<_, D>(log_det);
        let scale = (log_s0 + l - bra.log_norm - ket.log_norm).exp();
        Some(Self { bra, ket, chol, series, log_det, l, scale })
    }

    /// `G(moves) / (S_0(B) e^L)`; None where B' does not factorise.
    fn at<T: Moving>(&self, moves: Moves<T, D>) -> Option<T> {
        let (bra, ket) = (self.bra, self.ket);
        let moved = Cholesky::new((bra.a + ket.a).map(T::from) + moves.b)?;
        let (ui, uj) = (bra.u.map(T::from) + moves.u_i, ket.u.map(T::from) + moves.u_j);
        let (bi, bj) = (moved.solve(&ui), moved.solve(&uj));
        let [dx, dy, dz] = moves.omega;
        let (x, y, z) = (ui.dot(&bi) * 0.5 + dx, uj.dot(&bj) * 0.5 + dy, ui.dot(&bj) * 0.5 + dz);
        let (l, om, ..) = omega(&self.series.terms(), x, y, z);
        let l_moved = moved.l();
        let log_det = (0..D).fold(T::from(0.0), |acc, k| acc + l_moved[(k, k)].ln() * 2.0);
        // S_0(B')/S_0(B) = (|B|/|B'|)^{3/2}
        Some(((log_det - self.log_det) * -1.5 + (l - self.l)).exp() * om)
    }
}

/// `(<φ_I| p_h² |φ_J>, <p_g² φ_I| p_h² φ_J>)` for normalised ECG-GVR functions (eq. 26b, with
/// `h` in D_J and c_J; `operators::momentum::Momentum`); NaN where `A_I + A_J` does not factorise.
pub fn momentum<const D: usize>(bra: &GvrFunction<D>, ket: &GvrFunction<D>, go: &GvrOps<D>, g: &Vector<D>, h: &Vector<D>) -> (f64, f64) {
    let (hi, hj) = (bra.a * g, ket.a * h);
    let (ugi, ugj) = (bra.u.dot(g), ket.u.dot(h));
    let (ci, cj) = (-6.0 * g.dot(&hi), -6.0 * h.dot(&hj));
    // D_I along ε₁, D_J along ε₂
    let (e1, e2) = (H::new(0.0, 1.0, 0.0, 0.0), H::new(0.0, 0.0, 1.0, 0.0));
    let moves = Moves {
        b: dyad(&hi, &hi, e1 * -4.0) + dyad(&hj, &hj, e2 * -4.0),
        u_i: hi.map(H::from) * (e1 * (-4.0 * ugi)),
        u_j: hj.map(H::from) * (e2 * (-4.0 * ugj)),
        omega: [e1 * (2.0 * ugi * ugi), e2 * (2.0 * ugj * ugj), H::from(0.0)],
    };
    let Some((g_h, scale)) = Generating::new(bra, ket, go).and_then(|gen| Some((gen.at(moves)?, gen.scale))) else {
        return (f64::NAN, f64::NAN);
    };
    let laplacian = g_h.eps2 + cj * g_h.re;
    let quartic = g_h.eps1eps2 + cj * g_h.eps1 + ci * g_h.eps2 + ci * cj * g_h.re;
    (-scale * laplacian, scale * quartic)
}

/// `<φ_I| p_g·M(r_w)·p_h |φ_J>`, `M_ab = (δ_ab + r̂_a r̂_b)/r`, for normalised ECG-GVR functions,
/// `v = [w, g, h]` (eq. 26c; `operators::orbit`). With `∇_gφ = [(uᵀg) ∇_v P − 2 y P] e^{−rᵀAr}`,
/// `y = (Ag)ᵀr`, and eq. (34)'s `M = (2/√π) ∫ (δ + 2t² r_w r_wᵀ) e^{−t² r_w²} dt`, at each t
/// (τ² = t²q/(1 + t²q), q = wᵀB⁻¹w, as the Coulomb element) the `δ_ab` part is one derivative
/// of G of the damped functions — `∇_vP_I·∇_vP_J` is `∂_z` by Price's theorem, the cross terms move
/// u_I along A_J h and u_J along A_I g, `y_I·y_J` weights by `−∂_t` along `sym(A_I g, A_J h)` —
/// and the `r̂r̂` part is the mixed derivative of `r_w·∇_gφ_I` (u_I along w, and `sym(w, A_I g)`)
/// and `r_w·∇_hφ_J`. The τ-integrand is a polynomial of degree ≤ K_I + K_J + N + 2 in τ².
pub fn orbit<const D: usize>(bra: &GvrFunction<D>, ket: &GvrFunction<D>, go: &GvrOps<D>, v: &[Vector<D>]) -> f64 {
    let (w, g, h) = (&v[0], &v[1], &v[2]);
    let Some(gen) = Generating::new(bra, ket, go) else { return f64::NAN };
    let q = w.dot(&gen.chol.solve(w));
    let (hi, hj) = (bra.a * g, ket.a * h);
    let (ugi, uhj) = (bra.u.dot(g), ket.u.dot(h));
    // the isotropic part needs one derivative (dual numbers), the radial one a mixed second
    let (d, zero) = (Dual64::new(0.0, 1.0), Dual64::from(0.0));
    let (e1, e2) = (H::new(0.0, 1.0, 0.0, 0.0), H::new(0.0, 0.0, 1.0, 0.0));
    let lift = |v: &Vector<D>, c: H| v.map(H::from) * c;
    let mut sum = 0.0;
    for &(tau, weight) in legendre_rule(((bra.k + ket.k + go.n_ang) / 2 + 2) as usize) {
        let (t2, shrink) = (tau * tau / (q * (1.0 - tau * tau)), 1.0 - tau * tau);
        let isotropic = Moves {
            b: dyad(w, w, Dual64::from(t2)) + dyad(&hi, &hj, d * -4.0),
            u_i: hj.map(Dual64::from) * (d * (-2.0 * ugi)),
            u_j: hi.map(Dual64::from) * (d * (-2.0 * uhj)),
            omega: [zero, zero, d * (ugi * uhj)],
        };
        let radial = Moves {
            b: dyad(w, w, H::from(t2)) + dyad(w, &hi, e1 * 2.0) + dyad(w, &hj, e2 * 2.0),
            u_i: lift(w, e1 * ugi),
            u_j: lift(w, e2 * uhj),
            omega: [H::from(0.0); 3],
        };
        let (Some(one), Some(two)) = (gen.at(isotropic), gen.at(radial)) else { return f64::NAN };
        sum += weight * (one.eps + 2.0 * t2 * two.eps1eps2) / shrink.powf(1.5);
    }
    gen.scale * 2.0 / (PI * q).sqrt() * sum
}
