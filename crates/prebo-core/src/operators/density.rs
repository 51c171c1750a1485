//! The spherically averaged density of `r_w` at radius `r`, `ρ̄(r) = (4π)^{-1} ∫ dΩ <δ³(r_w − r n̂)>`
//! (for `w = e_i − e_j` the pair correlation function, whose `4πr² ρ̄` is the distribution of
//! `r_ij`; for `w = e_i − μ`, `μ` the mass fractions, the density of particle i about the centre
//! of mass). `ρ̄` is fixed by its transform `<exp(−α r_w²)> = (1 − u)^{3/2} G(u)` (profile.rs): a
//! polynomial profile `G = Σ_k g_k (1 − u)^k` is the transform of
//! `ρ̄(r) = e^{−x} (2π q^{3/2})^{-1} Σ_k g_k x^k / Γ(k + 3/2)`, `x = r²/q`, term by term
//! (`∫ d³r r^{2k} e^{−(α + 1/q) r²} = 2π Γ(k + 3/2) (q/(1 + αq))^{k + 3/2}`); the exponential
//! profile `S exp(−λu)` of floating ECGs is that of a Gaussian of width `q` about a point at
//! distance `d = (λq)^{1/2}`, `ρ̄(r) = S (πq)^{−3/2} e^{−(r² + d²)/q} sinh(z)/z`, `z = 2rd/q`.
use std::f64::consts::PI;

use super::profile::Profile;
use crate::ecg::Vector;
use crate::families::{Family, Shape};

/// `<φ_I| ρ̄_w(r) |φ_J>` at every radius of `radii` (bohr), for normalised functions (bohr⁻³).
pub fn element<const D: usize, F: Family<D>>(
    bra: &F::Function<f64>,
    ket: &F::Function<f64>,
    ctx: &F::Context,
    w: &Vector<D>,
    radii: &[f64],
) -> Vec<f64> {
    let p = Profile::<D, F>::of(bra, ket, ctx, w);
    let q = p.q;
    match &p.shape {
        Shape::Polynomial(g) => {
            // ln|h_k|, h_k = g_k / Γ(k + 3/2) (from Γ(3/2) = √π/2)
            let mut log_gamma = (PI.sqrt() / 2.0).ln();
            let log_h: Vec<f64> = g.iter().enumerate().map(|(k, gk)| {
                let lh = gk.abs().ln() - log_gamma;
                log_gamma += (k as f64 + 1.5).ln();
                lh
            }).collect();
            let h: Vec<f64> = g.iter().zip(&log_h).map(|(gk, lh)| gk.signum() * lh.exp()).collect();
            let scale = 1.0 / (2.0 * PI * q.powf(1.5));
            radii
                .iter()
                .map(|&r| {
                    let x = r * r / q;
                    let fast = (-x).exp() * h.iter().rev().fold(0.0, |acc, hk| acc * x + hk);
                    // where e^{−x} underflows or Σ h_k x^k overflows, term by term in logarithms
                    let value = if fast.is_finite() && (fast != 0.0 || x < 700.0) {
                        fast
                    } else {
                        g.iter().zip(&log_h).enumerate().map(|(k, (gk, lh))| gk.signum() * (lh + k as f64 * x.ln() - x).exp()).sum()
                    };
                    scale * value
                })
                .collect()
        }
        Shape::Exponential => {
            let d = (p.lambda() * q).sqrt();
            let scale = p.s * (PI * q).powf(-1.5);
            radii
                .iter()
                .map(|&r| {
                    // e^{−(r² + d²)/q} sinh(z)/z = e^{−(r − d)²/q} (1 − e^{−2z})/(2z)
                    let z = 2.0 * r * d / q;
                    let shell = if z > 0.0 { -(-2.0 * z).exp_m1() / (2.0 * z) } else { 1.0 };
                    scale * (-(r - d) * (r - d) / q).exp() * shell
                })
                .collect()
        }
    }
}

#[cfg(test)]
mod tests {
    //! Each family's density against what defines it: its transform `∫ 4πr² ρ̄(r) e^{−αr²} dr`
    //! (a 400-node rule on [0, d + 14 q^{1/2}]) equals the damped overlap for α from 0 (the
    //! overlap) to 5/q — for ECG-GVR up to K = 20, where the profile's coefficients could not be
    //! recovered from its values — and `ρ̄(0)` is the contact density (delta.rs).
    use super::*;
    use crate::families::fecg::kernel::{Centres, FecgFunction};
    use crate::families::fecg::Fecg;
    use crate::families::ecg_gvr::element::{GvrFunction, GvrOps};
    use crate::quadrature::gauss_legendre;
    use crate::families::ecg_gvr::EcgGvr;
    use crate::families::pecg::Pecg;
    use crate::operators::delta;
    use crate::operators::fixtures::{close, exponent, operators, w, D};

    fn check<F: Family<D>>(bra: &F::Function<f64>, ket: &F::Function<f64>, ctx: &F::Context, label: &str) {
        let p = Profile::<D, F>::of(bra, ket, ctx, &w());
        let d = if p.shape == Shape::Exponential { (p.lambda() * p.q).sqrt() } else { 0.0 };
        let top = d + 14.0 * p.q.sqrt();
        let rule: Vec<(f64, f64)> = gauss_legendre(400).into_iter().map(|(x, wt)| (0.5 * top * (x + 1.0), 0.5 * top * wt)).collect();
        let radii: Vec<f64> = rule.iter().map(|&(r, _)| r).collect();
        let rho = element::<D, F>(bra, ket, ctx, &w(), &radii);
        for alpha in [0.0, 0.1, 1.0, 5.0].map(|a| a / p.q) {
            let got: f64 = rule.iter().zip(&rho).map(|(&(r, wt), x)| wt * 4.0 * PI * r * r * x * (-alpha * r * r).exp()).sum();
            let want = F::overlap(bra, &F::damped(ket, &(w() * w().transpose() * alpha)), ctx);
            assert!(close(got, want, 1e-11), "{label}, α q = {}: {got} vs {want}", alpha * p.q);
        }
        let (at_zero, contact) = (element::<D, F>(bra, ket, ctx, &w(), &[0.0])[0], delta::element::<D, F>(bra, ket, ctx, &w()));
        assert!(close(at_zero, contact, 1e-13), "{label}: ρ̄(0) {at_zero} vs δ {contact}");
    }

    #[test]
    fn plain_and_global_vector_densities_transform_to_the_damped_overlap() {
        for (ki, kj, n_ang) in [(0, 0, 0), (1, 0, 0), (2, 1, 1), (1, 3, 2), (12, 15, 1), (20, 7, 2)] {
            let go = GvrOps::new(operators(vec![(w(), 1.0)]), n_ang, 20).unwrap();
            let gi = GvrFunction::new(exponent(0.5), Vector::<D>::new(0.3, 1.0, -0.4), ki, 1.0, &go, 0).unwrap();
            let gj = GvrFunction::new(exponent(1.1), Vector::<D>::new(-0.7, 0.2, 0.9), kj, 1.0, &go, 1).unwrap();
            check::<EcgGvr>(&gi, &gj, &go, &format!("ECG-GVR K = ({ki}, {kj}), N = {n_ang}"));
            // global vectors nearly along w: the variance left at r_w = 0 a small difference
            let along = |x: f64| w() + Vector::<D>::new(0.0, 0.0, x);
            let gi = GvrFunction::new(exponent(0.5), along(1e-4), ki, 1.0, &go, 0).unwrap();
            let gj = GvrFunction::new(exponent(1.1), along(-2e-4), kj, 1.0, &go, 1).unwrap();
            check::<EcgGvr>(&gi, &gj, &go, &format!("ECG-GVR along w, K = ({ki}, {kj}), N = {n_ang}"));
            if ki + kj + n_ang == 0 {
                check::<Pecg>(&gi, &gj, &go, "plain");
            }
        }
    }

    #[test]
    fn floating_densities_transform_to_the_damped_overlap() {
        let ops = operators(vec![(w(), 1.0)]);
        let centres = |x: f64, spread: f64| Centres::<D>::from_fn(|i, c| spread * (x + i as f64 * 1.1 + c as f64 * 0.37).cos());
        for spread in [0.0, 0.05, 1.0, 4.0] {
            let fi = FecgFunction::new(exponent(0.2), centres(0.3, spread), 1.0, 0).unwrap();
            let fj = FecgFunction::new(exponent(1.7), centres(2.1, spread), 1.0, 1).unwrap();
            check::<Fecg>(&fi, &fj, &ops, &format!("floating, spread {spread}"));
        }
    }
}
