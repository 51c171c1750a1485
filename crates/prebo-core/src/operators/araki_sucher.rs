//! `P(1/r_w³)`, the Araki–Sucher distribution of the pair vector `r_w` (the α³ QED term of
//! two-electron atoms and molecules; H. Araki, Prog. Theor. Phys. 17, 619 (1957); J. Sucher,
//! Phys. Rev. 109, 1010 (1958)): for the density ρ of `r_w` and Euler's constant γ,
//!
//! `<P(1/r³)> = lim_{a→0} [∫_{r>a} ρ(r)/r³ d³r + 4π(γ + ln a) ρ(0)]`
//! `          = 4π ∫_0^∞ (ρ̄(r) − ρ̄(0) θ(1 − r))/r dr + 4πγ ρ̄(0)`           (ρ̄ the spherical average)
//!
//! (split `4πρ̄(0) ∫_a^1 dr/r = −4πρ̄(0) ln a` off; lengths in bohr). With the damped overlap's
//! profile (profile.rs; docs/properties-derivations.md §11, eqs. 39–42), the density's terms
//! `g_k x^k e^{−x}`, `x = r²/q` (density.rs, eq. 31) give `∫_0^∞ (x^k e^{−x} − δ_k0 θ(1 − x)) dx/x`
//! = `Γ(k)` for k ≥ 1 and `−γ` for k = 0, and the cut at `r = 1` instead of `x = 1` adds
//! `½ g_0 ln q`:
//!
//! `<φ_I| P(1/r_w³) |φ_J> = q^{−3/2} [g_0 (ln q + γ)/Γ(3/2) + Σ_{k≥1} g_k Γ(k)/Γ(k + 3/2)]`
//! `                      = (2/√π) q^{−3/2} [∫_0^1 u^{1/2} (G(u) − G(1))/(1 − u) du + G(1)(ln q + γ)]`,
//!
//! the second by `Γ(k)/Γ(k + 3/2) = ∫_0^1 u^{1/2}(1 − u)^{k−1} du / Γ(3/2)`, which holds for any
//! profile: plain ECGs `2S (ln q + γ)/(√π q^{3/2})`, ECG-GVR the sum over its coefficients, floating
//! ECGs (`G = S e^{−λu} = S e^{−λ} Σ_k λ^k (1 − u)^k / k!`) `(2S/√π) q^{−3/2} [E(λ) + e^{−λ}(ln q + γ)]`
//! with `E` of `floating`.
use std::f64::consts::PI;

use super::profile::Profile;
use crate::ecg::Vector;
use crate::families::{Family, Shape};

pub const NAME: &str = "araki_sucher";

/// Euler's constant γ.
pub const EULER_GAMMA: f64 = 0.577_215_664_901_532_9;

/// `<φ_I| P(1/r_w³) |φ_J>` for normalised functions (bohr⁻³).
pub fn element<const D: usize, F: Family<D>>(bra: &F::Function<f64>, ket: &F::Function<f64>, ctx: &F::Context, w: &Vector<D>) -> f64 {
    let p = Profile::<D, F>::of(bra, ket, ctx, w);
    let (q, root_pi) = (p.q, PI.sqrt());
    let log = q.ln() + EULER_GAMMA;
    let bracket = match &p.shape {
        Shape::Polynomial(g) => {
            // Γ(k)/Γ(k + 3/2) from k = 1 (Γ(5/2) = 3√π/4), times k/(k + 3/2) per step
            let mut ratio = 4.0 / (3.0 * root_pi);
            let mut sum = 2.0 / root_pi * g[0] * log;
            for (k, gk) in g.iter().enumerate().skip(1) {
                sum += gk * ratio;
                ratio *= k as f64 / (k as f64 + 1.5);
            }
            sum
        }
        Shape::Exponential => {
            let lambda = p.lambda();
            2.0 / root_pi * p.s * (floating(lambda) + (-lambda).exp() * log)
        }
    };
    bracket / q.powf(1.5)
}

/// `E(λ) = ∫_0^1 u^{1/2} (e^{−λu} − e^{−λ})/(1 − u) du ≥ 0`, the floating ECG's term beyond the
/// contact density. Below λ = 50 its series `Γ(3/2) Σ_{k≥1} e^{−λ} λ^k/(k Γ(k + 3/2))` (the
/// polynomial profile's sum over the coefficients of `e^{−λu}` in `1 − u`; positive terms, peaked
/// at k ≈ λ), summed until past the peak a term adds less than 1e-17; from λ = 50 Watson's
/// asymptotic series `Σ_{m≥0} Γ(m + 3/2)/λ^{m + 3/2}` (`1/(1 − u) = Σ u^m` under `u^{1/2} e^{−λu}`),
/// summed until a term adds less than 1e-17 (m ≈ 26 at λ = 50, far before its smallest term near
/// m ≈ λ): what it leaves out is O(e^{−λ} ln λ), below 1e-18 of `E ≈ Γ(3/2) λ^{−3/2}` there.
pub fn floating(lambda: f64) -> f64 {
    if lambda < 50.0 {
        // e^{−λ} λ^k Γ(3/2)/(k Γ(k + 3/2)) at k = 1 is (2/3) λ e^{−λ}; the ratio of terms k + 1 to k
        // is λ k/((k + 1)(k + 3/2))
        let (mut term, mut sum, mut k) = (2.0 / 3.0 * lambda * (-lambda).exp(), 0.0, 1.0);
        loop {
            sum += term;
            if k > lambda && term <= 1e-17 * sum {
                return sum;
            }
            term *= lambda * k / ((k + 1.0) * (k + 1.5));
            k += 1.0;
        }
    }
    let (mut term, mut sum, mut m) = (0.5 * PI.sqrt() * lambda.powf(-1.5), 0.0, 0.0);
    while term > 1e-17 * sum || sum == 0.0 {
        sum += term;
        term *= (m + 1.5) / lambda;
        m += 1.0;
    }
    sum
}

#[cfg(test)]
mod tests {
    //! The element against what defines it, for each family's profile: the regularised radial
    //! integral (eq. 39) of each family's density (density.rs, itself checked against the damped
    //! overlap there) by Gauss–Legendre panels; the u-form (eq. 40) by a rule on the family's damped
    //! overlap (ECG-GVR, exact for its polynomial profile); the a → 0 limit of the definition on one
    //! floating pair; plain ECGs equal to ECG-GVR at K = N = 0; `E(λ)` against a panelled rule.
    use super::*;
    use crate::families::ecg_gvr::element::{GvrFunction, GvrOps};
    use crate::families::ecg_gvr::EcgGvr;
    use crate::families::fecg::kernel::{Centres, FecgFunction};
    use crate::families::fecg::Fecg;
    use crate::families::pecg::Pecg;
    use crate::operators::density;
    use crate::operators::fixtures::{exponent, operators, w, D};
    use crate::quadrature::gauss_legendre;

    /// `Σ f` over 20-point Gauss–Legendre panels of width ≤ `width` between consecutive `cuts`.
    fn panels(cuts: &[f64], width: f64, f: impl Fn(&[f64]) -> Vec<f64>) -> f64 {
        let rule = gauss_legendre(20);
        let (mut nodes, mut weights) = (vec![], vec![]);
        for pair in cuts.windows(2) {
            let n = ((pair[1] - pair[0]) / width).ceil().max(1.0) as usize;
            let h = (pair[1] - pair[0]) / n as f64;
            for i in 0..n {
                let mid = pair[0] + (i as f64 + 0.5) * h;
                for &(x, wt) in &rule {
                    nodes.push(mid + 0.5 * h * x);
                    weights.push(0.5 * h * wt);
                }
            }
        }
        f(&nodes).iter().zip(&weights).map(|(v, wt)| v * wt).sum()
    }

    /// (the integral, the integral of its absolute value): the radial distance of the density's
    /// support, `d` (a floating pair's centre distance, else 0) plus `(q (M + 10√M + 70))^{1/2}`,
    /// beyond which `x^M e^{−x}` of the density's top term is below e^{−70} of its peak.
    fn reach<F: Family<D>>(p: &Profile<D, F>) -> (f64, f64) {
        match &p.shape {
            Shape::Polynomial(g) => {
                let m = (g.len() - 1) as f64;
                (0.0, (p.q * (m + 10.0 * m.sqrt() + 70.0)).sqrt())
            }
            Shape::Exponential => ((p.lambda() * p.q).sqrt(), (70.0 * p.q).sqrt()),
        }
    }

    /// Eq. (39) by panels of width ≤ √q/4 in r on the density of `density.rs`, cut at r = 1 and
    /// at the edges of the density's support: (value, scale), the scale the same integral of
    /// absolute values (the size of the rounding).
    fn radial<F: Family<D>>(bra: &F::Function<f64>, ket: &F::Function<f64>, ctx: &F::Context) -> (f64, f64) {
        let p = Profile::<D, F>::of(bra, ket, ctx, &w());
        let (d, spread) = reach(&p);
        let rho0 = density::element::<D, F>(bra, ket, ctx, &w(), &[0.0])[0];
        let mut cuts = vec![0.0, 1.0, (d - spread).max(0.0), d + spread];
        cuts.sort_by(f64::total_cmp);
        cuts.dedup();
        let integrand = |r: &[f64], abs: bool| -> Vec<f64> {
            let rho = density::element::<D, F>(bra, ket, ctx, &w(), r);
            r.iter().zip(rho).map(|(&r, x)| {
                let v = (x - if r < 1.0 { rho0 } else { 0.0 }) / r;
                4.0 * PI * if abs { v.abs() } else { v }
            }).collect()
        };
        let width = 0.25 * p.q.sqrt();
        let value = panels(&cuts, width, |r| integrand(r, false)) + 4.0 * PI * EULER_GAMMA * rho0;
        let scale = panels(&cuts, width, |r| integrand(r, true)) + 4.0 * PI * EULER_GAMMA * rho0.abs();
        (value, scale)
    }

    /// The element within 5e-14 of the radial integral's scale (measured: ≤ 1.2e-15 but for
    /// ECG-GVR of K = (12, 15) and (20, 7) with the global vectors nearly along w, 2.0e-14 and
    /// 2.2e-14, where the profile's coefficients are largest against their sum); the deviation.
    fn check<F: Family<D>>(bra: &F::Function<f64>, ket: &F::Function<f64>, ctx: &F::Context, label: &str) -> f64 {
        let got = element::<D, F>(bra, ket, ctx, &w());
        let (want, scale) = radial::<F>(bra, ket, ctx);
        let off = (got - want).abs() / scale;
        assert!(off < 5e-14, "{label}: {got} vs the radial integral {want} ({off:.1e} of {scale})");
        off
    }

    fn gvr(ki: u32, kj: u32, n_ang: u32, along: f64) -> (GvrFunction<D>, GvrFunction<D>, GvrOps<D>) {
        let go = GvrOps::new(operators(vec![(w(), 1.0)]), n_ang, 20).unwrap();
        let (ui, uj) = if along > 0.0 {
            (w() + Vector::<D>::new(0.0, 0.0, along), w() - Vector::<D>::new(0.0, 0.0, 2.0 * along))
        } else {
            (Vector::<D>::new(0.3, 1.0, -0.4), Vector::<D>::new(-0.7, 0.2, 0.9))
        };
        let gi = GvrFunction::new(exponent(0.5), ui, ki, 1.0, &go, 0).unwrap();
        let gj = GvrFunction::new(exponent(1.1), uj, kj, 1.0, &go, 1).unwrap();
        (gi, gj, go)
    }

    /// Two floating ECGs with centres of spread `spread`, different or (`shared`) the same: then
    /// the overlap keeps its size however far the pair's centres are apart, and λ grows as their
    /// distance squared.
    fn floating_pair(spread: f64, shared: bool) -> (FecgFunction<D>, FecgFunction<D>) {
        let centres = |x: f64| Centres::<D>::from_fn(|i, c| spread * (x + i as f64 * 1.1 + c as f64 * 0.37).cos());
        let other = centres(if shared { 0.3 } else { 2.1 });
        (FecgFunction::new(exponent(0.2), centres(0.3), 1.0, 0).unwrap(), FecgFunction::new(exponent(1.7), other, 1.0, 1).unwrap())
    }

    #[test]
    fn plain_and_global_vector_elements_are_the_radial_integral_of_their_density() {
        let mut worst: f64 = 0.0;
        for (ki, kj, n_ang) in [(0, 0, 0), (1, 0, 0), (2, 1, 1), (1, 3, 2), (12, 15, 1), (20, 7, 2)] {
            for along in [0.0, 1e-4] {
                let (gi, gj, go) = gvr(ki, kj, n_ang, along);
                worst = worst.max(check::<EcgGvr>(&gi, &gj, &go, &format!("ECG-GVR K = ({ki}, {kj}), N = {n_ang}, along {along}")));
                if ki + kj + n_ang == 0 {
                    let (plain, gvr) = (element::<D, Pecg>(&gi, &gj, &go, &w()), element::<D, EcgGvr>(&gi, &gj, &go, &w()));
                    assert_eq!(plain, gvr, "plain vs ECG-GVR at K = N = 0");
                    worst = worst.max(check::<Pecg>(&gi, &gj, &go, "plain"));
                }
            }
        }
        println!("plain and ECG-GVR: largest deviation from the radial integral {worst:.1e} of its scale");
    }

    #[test]
    fn global_vector_elements_are_the_u_form_on_the_damped_overlap() {
        // eq. (40) with u = τ²: ∫_0^1 2τ² (G(τ²) − G(1))/(1 − τ²) dτ, a polynomial in τ of degree
        // 2(K_I + K_J + N) ≤ 56, exact by 32 Gauss–Legendre nodes on [0, 1] (more put nodes nearer
        // τ = 1, where the damped overlap loses digits and 1/(1 − τ²) amplifies them: 60 nodes
        // gave 1.1e-12, these 7e-14 to 4.6e-13); G(1) = g_0, as δ (delta.rs)
        for (ki, kj, n_ang) in [(1, 0, 0), (2, 1, 1), (1, 3, 2), (12, 15, 1)] {
            let (gi, gj, go) = gvr(ki, kj, n_ang, 0.0);
            let p = Profile::<D, EcgGvr>::of(&gi, &gj, &go, &w());
            let g1 = p.at_one();
            let integral: f64 = gauss_legendre(32).iter().map(|&(x, wt)| {
                let t = 0.5 * (x + 1.0);
                0.5 * wt * 2.0 * t * t * (p.at(t * t) - g1) / (1.0 - t * t)
            }).sum();
            let want = 2.0 / PI.sqrt() * (integral + g1 * (p.q.ln() + EULER_GAMMA)) / p.q.powf(1.5);
            let got = element::<D, EcgGvr>(&gi, &gj, &go, &w());
            assert!((got - want).abs() < 1e-12 * want.abs(), "K = ({ki}, {kj}), N = {n_ang}: {got} vs {want}");
        }
    }

    #[test]
    fn floating_elements_are_the_radial_integral_of_their_density() {
        let ops = operators(vec![(w(), 1.0)]);
        let (mut lambdas, mut worst) = (vec![], 0.0_f64);
        for (spread, shared) in [(0.0, false), (0.05, false), (1.0, false), (4.0, false), (8.0, false), (4.0, true), (8.0, true)] {
            let (fi, fj) = floating_pair(spread, shared);
            lambdas.push(Profile::<D, Fecg>::of(&fi, &fj, &ops, &w()).lambda());
            worst = worst.max(check::<Fecg>(&fi, &fj, &ops, &format!("floating, spread {spread}, shared centres {shared}")));
        }
        println!("floating: λ = {lambdas:?}, largest deviation from the radial integral {worst:.1e} of its scale");
        // both branches of E: the series below λ = 50 and the asymptotic series above
        assert!(lambdas.iter().any(|&l| l > 0.0 && l < 50.0) && lambdas.iter().any(|&l| l > 50.0), "{lambdas:?}");
    }

    #[test]
    fn the_definition_tends_to_the_element_as_a_squared() {
        // ∫_{r>a} ρ̄/r³ d³r + 4π(γ + ln a) ρ̄(0) differs from the limit by −4π∫_0^a (ρ̄ − ρ̄(0))/r dr
        // = −π ρ̄''(0) a² + O(a⁴): panels in ln r from ln a to the density's edge
        let ops = operators(vec![(w(), 1.0)]);
        let (fi, fj) = floating_pair(1.0, false);
        let p = Profile::<D, Fecg>::of(&fi, &fj, &ops, &w());
        let (d, spread) = reach(&p);
        let rho0 = density::element::<D, Fecg>(&fi, &fj, &ops, &w(), &[0.0])[0];
        let limit = element::<D, Fecg>(&fi, &fj, &ops, &w());
        let off = [1e-2, 1e-3, 1e-4].map(|a: f64| {
            let outer = panels(&[a.ln(), (d + spread).ln()], 0.02, |s| {
                let r: Vec<f64> = s.iter().map(|x| x.exp()).collect();
                density::element::<D, Fecg>(&fi, &fj, &ops, &w(), &r).into_iter().map(|x| 4.0 * PI * x).collect()
            });
            outer + 4.0 * PI * (EULER_GAMMA + a.ln()) * rho0 - limit
        });
        println!("a = 1e-2, 1e-3, 1e-4: definition − element = {off:?} (element {limit})");
        assert!(off[2].abs() < 1e-7 * limit.abs(), "{off:?} against {limit}");
        for k in 0..2 {
            let ratio = off[k] / off[k + 1];
            assert!((ratio - 100.0).abs() < 0.1, "a² convergence: {off:?}");
        }
    }

    #[test]
    fn the_floating_term_matches_a_panelled_rule() {
        // E(λ) = ∫_0^1 2τ² e^{−λτ²} (1 − e^{−λ(1 − τ²)})/(1 − τ²) dτ, 400 panels of 20 nodes, whose
        // rounding is the deviation measured here (up to 7.9e-15, at λ = 30): the series themselves
        // were within 2.4e-16 of a 40-digit quadrature (mpmath) at λ = 5, 30, 49.9, 50.1, 120
        let mut worst: f64 = 0.0;
        for lambda in [1e-6, 0.3, 5.0, 30.0, 49.9, 50.1, 120.0, 1e4] {
            let want = panels(&[0.0, 1.0], 1.0 / 400.0, |t| t.iter().map(|&t| {
                let v = 1.0 - t * t;
                2.0 * t * t * (-lambda * t * t).exp() * if v > 0.0 { -(-lambda * v).exp_m1() / v } else { lambda }
            }).collect());
            let got = floating(lambda);
            worst = worst.max((got / want - 1.0).abs());
            assert!((got - want).abs() < 1e-14 * want, "λ = {lambda}: {got} vs {want} ({:.1e})", (got / want - 1.0).abs());
        }
        println!("E(λ): largest relative deviation from the rule {worst:.1e}");
    }
}
