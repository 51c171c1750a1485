//! The damped overlap's profile, shared by the operators of one inter-particle vector `r_w`
//! beyond `r_w²` (docs/properties-derivations.md, §2–4). For every family
//!
//! `<φ_I| exp(−α r_w²) |φ_J> = (1 − u)^{3/2} G(u)`,  `u = αq/(1 + αq)`,  `q = w^T (A_I + A_J)^{-1} w`,
//!
//! (the matrix determinant lemma gives the Gaussian factor), `G(0) = S_IJ`, and `G` is a
//! polynomial of degree `K_I + K_J + N` for ECG-GVR (a constant for plain ECGs), whose
//! coefficients in `1 − u` the family gives, and `S_IJ exp(−λu)` for floating ECGs
//! (`Family::shape`). Between those ends `G` is read off the family's own damped overlap
//! (`Family::damped`), so every element built on it holds for every family, exact up to
//! rounding: a polynomial `G` is integrated exactly by Gauss–Legendre rules, an exponential one in
//! closed form or by a rule panelled in the exponent.
use std::sync::OnceLock;

use crate::ecg::{Mat, Vector};
use crate::quadrature::gauss_legendre;
use crate::families::{Family, Shape};

/// `G(u)` of one pair of functions and one vector `w`.
pub struct Profile<'a, const D: usize, F: Family<D>> {
    bra: &'a F::Function<f64>,
    ket: &'a F::Function<f64>,
    ctx: &'a F::Context,
    ww: Mat<D>,
    /// `S_IJ = G(0)`
    pub s: f64,
    /// `q = w^T (A_I + A_J)^{-1} w`, the variance scale of `r_w` (bohr²)
    pub q: f64,
    pub shape: Shape,
}

impl<'a, const D: usize, F: Family<D>> Profile<'a, D, F> {
    pub fn of(bra: &'a F::Function<f64>, ket: &'a F::Function<f64>, ctx: &'a F::Context, w: &Vector<D>) -> Self {
        let b = F::exponent(bra) + F::exponent(ket);
        let q = b.cholesky().map_or(f64::NAN, |c| w.dot(&c.solve(w)));
        let shape = F::shape(bra, ket, ctx, w);
        // a polynomial profile's G(0) = Σ_k g_k; an exponential one's from the family's overlap
        let s = match &shape {
            Shape::Polynomial(g) => g.iter().sum(),
            Shape::Exponential => F::overlap(bra, ket, ctx),
        };
        Self { bra, ket, ctx, ww: w * w.transpose(), s, q, shape }
    }

    /// The damping `α` of `u`.
    fn alpha(&self, u: f64) -> f64 {
        u / (self.q * (1.0 - u))
    }

    /// `G(u)`, `0 ≤ u < 1`.
    pub fn at(&self, u: f64) -> f64 {
        F::overlap(self.bra, &F::damped(self.ket, &(self.ww * self.alpha(u))), self.ctx) / (1.0 - u).powf(1.5)
    }

    /// `G(1)`, the limit `α → ∞`: `g_0` of a polynomial profile, `G(½)² / S` for `S exp(−λu)`.
    pub fn at_one(&self) -> f64 {
        match &self.shape {
            Shape::Polynomial(g) => g[0],
            Shape::Exponential => {
                let half = self.at(0.5);
                half * half / self.s
            }
        }
    }

    /// `λ ≥ 0` of an exponential profile, `G(u) = S exp(−λu)`: `2 ln(S / G(½))`.
    pub fn lambda(&self) -> f64 {
        (2.0 * (self.s / self.at(0.5)).ln()).max(0.0)
    }

    /// `<φ_I| |r_w|^n |φ_J>` of a polynomial profile, `n > −3`: the moment of the density (31)
    /// (density.rs), `q^{n/2} Σ_k g_k Γ(k + 3/2 + n/2)/Γ(k + 3/2)` (docs/properties-derivations.md,
    /// eq. 33; `Σ_k g_k = S` at n = 0); `None` for an exponential profile.
    pub fn moment(&self, n: i32) -> Option<f64> {
        let Shape::Polynomial(g) = &self.shape else { return None };
        let shift = 0.5 * n as f64;
        // Γ(k + 3/2 + n/2)/Γ(k + 3/2) from k = 0, times (k + 3/2 + n/2)/(k + 3/2) per step
        let mut ratio = (ln_gamma(1.5 + shift) - ln_gamma(1.5)).exp();
        let mut sum = 0.0;
        for (k, gk) in g.iter().enumerate() {
            sum += gk * ratio;
            ratio *= (k as f64 + 1.5 + shift) / (k as f64 + 1.5);
        }
        Some(self.q.powf(shift) * sum)
    }
}

/// `ln Γ(x)` at the half-integers and integers `x ≥ ½` the moments need (exact recurrences from
/// `Γ(½) = √π` and `Γ(1) = 1`).
fn ln_gamma(x: f64) -> f64 {
    let (mut value, mut y) = (0.0, x);
    while y > 1.0 {
        y -= 1.0;
        value += y.ln();
    }
    value + if y == 0.5 { 0.5 * std::f64::consts::PI.ln() } else { 0.0 }
}

/// `∫_0^1 exp(−λ(1 − σ²)) dσ` (= Dawson's integral `D(√λ)/√λ`): 16-point Gauss–Legendre panels
/// in σ over which the exponent changes by at most 2, down to where it falls below −60.
pub fn rising_gaussian(lambda: f64) -> f64 {
    if !(lambda > 0.0) {
        return 1.0;
    }
    static RULE: OnceLock<Vec<(f64, f64)>> = OnceLock::new();
    let rule = RULE.get_or_init(|| gauss_legendre(16));
    let sigma = |t: f64| (1.0 - t / lambda).max(0.0).sqrt(); // the σ at which the exponent is −t
    let (mut total, mut t) = (0.0, 0.0);
    while t < lambda.min(60.0) {
        let next = (t + 2.0).min(lambda);
        let (hi, lo) = (sigma(t), sigma(next));
        let (mid, half) = (0.5 * (hi + lo), 0.5 * (hi - lo));
        total += half * rule.iter().map(|&(x, wt)| wt * (-lambda * (1.0 - (mid + half * x).powi(2))).exp()).sum::<f64>();
        t = next;
    }
    total
}

#[cfg(test)]
mod tests {
    //! The four operators built on the profile (delta.rs, inverse.rs, inverse_square.rs,
    //! distance.rs), for each family against what does not use the profile: plain ECGs against
    //! the Gaussian moments; ECG-GVR at K = N = 0 equal to plain ECGs; `1/|r_w|` against each
    //! family's own Coulomb element of one unit pair; floating ECGs against the closed forms in
    //! `r̄` (docs/properties-derivations.md, eq. 16) and a 4000-node rule; ECG-GVR with K, N > 0
    //! against 60-node rules on the damped overlap (exact for these polynomial integrands, and kept away from the
    //! α → ∞ ends, where the damped overlap loses digits) and δ against `(α/π)^{3/2}` times the damped
    //! overlap extrapolated to `α → ∞` (Richardson).
    use super::*;
    use std::f64::consts::PI;
    use crate::families::fecg::kernel::{erf, Centres, FecgFunction};
    use crate::families::fecg::Fecg;
    use crate::families::ecg_gvr::element::{GvrFunction, GvrOps};
    use crate::families::ecg_gvr::EcgGvr;
    use crate::families::pecg::Pecg;
    use crate::gradient::{seed, Dual};
    use crate::operators::fixtures::{close, exponent, operators, w, D};
    use crate::operators::{delta, distance, inverse, inverse_square};
    use nalgebra::{Const, U1};

    type El<F> = fn(&<F as Family<D>>::Function<f64>, &<F as Family<D>>::Function<f64>, &<F as Family<D>>::Context, &Vector<D>) -> f64;

    /// (δ, 1/r, r, 1/r²) of one pair of functions of family F.
    fn four<F: Family<D>>(bra: &F::Function<f64>, ket: &F::Function<f64>, ctx: &F::Context) -> [f64; 4] {
        let els: [El<F>; 4] = [delta::element::<D, F>, inverse::element::<D, F>, distance::element::<D, F>, inverse_square::element::<D, F>];
        els.map(|el| el(bra, ket, ctx, &w()))
    }

    /// `−∂/∂α <φ_I| exp(−α r_w²) |φ_J>` at the `α` of `u`, over `(1 − u)^{3/2}` (`<r_w² exp(−α r_w²)>`),
    /// in dual numbers: the integrand of `<|r_w|>` (eq. 18) without the profile's coefficients.
    fn slope<F: Family<D>>(p: &Profile<D, F>, u: f64) -> f64 {
        let alpha: Dual<1> = seed(p.alpha(u), std::iter::once(1.0));
        let damping = p.ww.map(|x| alpha * x);
        let d = F::overlap(&F::cast::<Dual<1>>(p.bra), &F::damped(p.ket, &damping), p.ctx);
        -d.eps.unwrap_generic(Const::<1>, U1)[0] / (1.0 - u).powf(1.5)
    }

    /// `∫_0^1 f` by an n-point Gauss–Legendre rule.
    fn integral(n: usize, f: impl Fn(f64) -> f64) -> f64 {
        gauss_legendre(n).iter().map(|&(x, wt)| 0.5 * wt * f(0.5 * (x + 1.0))).sum()
    }

    #[test]
    fn plain_ecgs_match_the_gaussian_moments_and_ecg_gvr_at_k_n_zero() {
        let ops = operators(vec![(w(), 1.0)]);
        let go = GvrOps::new(ops.clone(), 0, 0).unwrap();
        let u = Vector::<D>::new(1.0, 0.0, 0.0);
        for (si, sj) in [(0.1, 0.9), (1.3, 2.2), (0.4, 0.4)] {
            let (ai, aj) = (exponent(si), exponent(sj));
            let (gi, gj) = (GvrFunction::new(ai, u, 0, 1.0, &go, 0).unwrap(), GvrFunction::new(aj, u, 0, 1.0, &go, 1).unwrap());
            let s = <Pecg as Family<D>>::overlap(&gi, &gj, &go);
            let q = (w().transpose() * (ai + aj).try_inverse().unwrap() * w())[(0, 0)];
            let want = [s * (PI * q).powf(-1.5), 2.0 * s / (PI * q).sqrt(), 2.0 * s * (q / PI).sqrt(), 2.0 * s / q];
            let (plain, gvr) = (four::<Pecg>(&gi, &gj, &go), four::<EcgGvr>(&gi, &gj, &go));
            for k in 0..4 {
                assert!(close(plain[k], want[k], 1e-13), "operator {k}: {} vs {}", plain[k], want[k]);
                assert!(close(gvr[k], want[k], 1e-13), "operator {k}, ECG-GVR: {} vs {}", gvr[k], want[k]);
            }
            let coulomb = <Pecg as Family<D>>::element(&gi, &gj, &go).v;
            assert!(close(plain[1], coulomb, 1e-13), "1/r {} vs the Coulomb element {coulomb}", plain[1]);
        }
    }

    #[test]
    fn floating_ecgs_match_the_closed_forms_in_the_centre() {
        let ops = operators(vec![(w(), 1.0)]);
        let centres = |x: f64, spread: f64| Centres::<D>::from_fn(|i, c| spread * (x + i as f64 * 1.1 + c as f64 * 0.37).cos());
        for spread in [0.0, 0.05, 1.0, 4.0] {
            let (fi, fj) = (FecgFunction::new(exponent(0.2), centres(0.3, spread), 1.0, 0).unwrap(), FecgFunction::new(exponent(1.7), centres(2.1, spread), 1.0, 1).unwrap());
            let b = fi.a + fj.a;
            let binv = b.try_inverse().unwrap();
            let m = w().transpose() * binv * (fi.a * fi.s + fj.a * fj.s);
            let (q, m2) = ((w().transpose() * binv * w())[(0, 0)], m.norm_squared());
            let (s, lambda) = (<Fecg as Family<D>>::overlap(&fi, &fj, &ops), m2 / q);
            let got = four::<Fecg>(&fi, &fj, &ops);
            let delta = s * (PI * q).powf(-1.5) * (-lambda).exp();
            let inv_r = if m2 > 0.0 { s * erf(m2.sqrt() / q.sqrt()) / m2.sqrt() } else { 2.0 * s / (PI * q).sqrt() };
            let r = s * ((q / PI).sqrt() * (-lambda).exp() + (m2 + 0.5 * q) * inv_r / s);
            let inv_r2 = 2.0 * s / q * integral(4000, |x| (-lambda * (1.0 - x * x)).exp());
            let coulomb = <Fecg as Family<D>>::element(&fi, &fj, &ops).v;
            for (k, want) in [delta, inv_r, r, inv_r2].into_iter().enumerate() {
                assert!(close(got[k], want, 2e-13), "spread {spread}, operator {k}: {} vs {want}", got[k]);
            }
            assert!(close(got[1], coulomb, 1e-13), "1/r {} vs the Coulomb element {coulomb}", got[1]);
        }
    }

    #[test]
    fn global_vector_functions_match_rules_on_the_damped_overlap() {
        for (ki, kj, n_ang) in [(1, 0, 0), (2, 1, 1), (1, 3, 2), (12, 15, 1)] {
            let go = GvrOps::new(operators(vec![(w(), 1.0)]), n_ang, 15).unwrap();
            let gi = GvrFunction::new(exponent(0.5), Vector::<D>::new(0.3, 1.0, -0.4), ki, 1.0, &go, 0).unwrap();
            let gj = GvrFunction::new(exponent(1.1), Vector::<D>::new(-0.7, 0.2, 0.9), kj, 1.0, &go, 1).unwrap();
            let p = Profile::<D, EcgGvr>::of(&gi, &gj, &go, &w());
            let q = p.q;
            let damped = |alpha: f64| {
                <EcgGvr as Family<D>>::overlap(&gi, &<EcgGvr as Family<D>>::damped(&gj, &(w() * w().transpose() * alpha)), &go)
            };
            let alpha = |u: f64| u / (q * (1.0 - u));
            let inv_r = 2.0 / (PI * q).sqrt() * integral(60, |t| damped(alpha(t * t)) / (1.0 - t * t).powf(1.5));
            let inv_r2 = 2.0 / q * integral(60, |s| damped(alpha(1.0 - s * s)) / (s * s * s));
            let r = 2.0 / (PI * q).sqrt() * integral(60, |t| slope(&p, t * t));
            // (α/π)^{3/2} D(α) = δ (1 − 3/(2αq) + …), analytic in 1/α: Richardson over α = 2^j·64/q
            let mut table: Vec<f64> = (0..9).map(|j| {
                let a = 64.0 * 2f64.powi(j) / q;
                (a / PI).powf(1.5) * damped(a)
            }).collect();
            for level in 1..table.len() {
                for j in (level..table.len()).rev() {
                    let f = 2f64.powi(level as i32);
                    table[j] = (f * table[j] - table[j - 1]) / (f - 1.0);
                }
            }
            let got = four::<EcgGvr>(&gi, &gj, &go);
            let coulomb = <EcgGvr as Family<D>>::element(&gi, &gj, &go).v;
            let label = format!("K = ({ki}, {kj}), N = {n_ang}");
            assert!(close(got[0], table[8], 1e-9), "{label}: δ {} vs {}", got[0], table[8]);
            for (k, want) in [(1, inv_r), (1, coulomb), (2, r), (3, inv_r2)] {
                assert!(close(got[k], want, 1e-12), "{label}, operator {k}: {} vs {want}", got[k]);
            }
        }
    }
}
