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
//!   reads them off one factorisation of `A_I + A_J` (`Family::COULOMB`, `gvr::gvr_drachmann`).
//!   `<1/(|r_kl| |r_w|)>` is symmetric in the two vectors, so the operator takes all its instances
//!   at once (`coulomb_all`) and computes each product of two Coulomb pairs once, over the damping
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
//!   ECG is centred at `(A + M)^{-1} A s`, which its kinetic element needs (`Fecg::damped`).
//!   Every family.
use std::f64::consts::PI;
use std::sync::OnceLock;

use nalgebra::{Const, U1};

use super::profile::Profile;
use super::{inverse, inverse_square};
use crate::ecg::{Mat, Vector};
use crate::families::floating::fecg::erf;
use crate::families::gvr::gvr_element::{gauss_legendre, legendre_rule};
use crate::families::{Family, Shape};
use crate::gradient::{seed, Dual};

pub const COULOMB: &str = "coulomb_inv_r";
pub const GRADIENT: &str = "gradient_inv_r";

/// `w ↦ L⁻¹w` with `L Lᵀ = A_I + A_J`, so `|L⁻¹w|² = wᵀ(A_I + A_J)⁻¹w`; None where the sum does not
/// factorise.
fn whitening<const D: usize, F: Family<D>>(bra: &F::Function<f64>, ket: &F::Function<f64>) -> Option<impl Fn(&Vector<D>) -> Vector<D>> {
    let chol = (F::exponent(bra) + F::exponent(ket)).cholesky()?;
    Some(move |w: &Vector<D>| chol.l().solve_lower_triangular(w).unwrap_or_else(|| Vector::<D>::repeat(f64::NAN)))
}

/// `<φ_I| 1/(|r_w| |r_w'_k|) |φ_J>` for each Coulomb pair `(w'_k, q_k)` of the context (bohr⁻²);
/// where `known[k]` is given it is returned instead, not computed (`coulomb_all` passes what it
/// has, or needs not). A family's `Family::COULOMB`.
pub type InverseProducts<const D: usize, F> =
    fn(&<F as Family<D>>::Function<f64>, &<F as Family<D>>::Function<f64>, &<F as Family<D>>::Context, &Vector<D>, &[Option<f64>]) -> Vec<f64>;

/// `<φ_I| V/|r_w| |φ_J> = Σ_k q_k <φ_I| 1/(|r_w| |r_w'_k|) |φ_J>` (hartree/bohr; `v = [w]`) from the
/// family's `Family::COULOMB`.
pub fn coulomb_inv_r<const D: usize, F: Family<D>>(bra: &F::Function<f64>, ket: &F::Function<f64>, ctx: &F::Context, v: &[Vector<D>]) -> f64 {
    let pairs = &F::operators(ctx).pairs;
    potential(pairs, &F::COULOMB(bra, ket, ctx, &v[0], &vec![None; pairs.len()]))
}

/// `Σ_k q_k x_k` over the Coulomb pairs `(w'_k, q_k)`.
fn potential<const D: usize>(pairs: &[(Vector<D>, f64)], x: &[f64]) -> f64 {
    pairs.iter().zip(x).map(|((_, charge), x)| charge * x).sum()
}

/// `coulomb_inv_r` of every instance `[w]` at once (an `operators::Elements::All`).
/// `<1/(|r_w| |r_w'|)>` is symmetric, so an instance that is a Coulomb pair (in the laboratory
/// frame every one: both are `e_i − e_j`) takes each product with another pair from a table, and
/// the table computes it once, integrated over the damping of the lighter pair of the two
/// (`wᵀΛw = 1/(2μ_w)` the larger; of equal ones the first), whose integrand is the smoother
/// (benchmarks/record/relativistic.md, "Drachmann's terms with shared work": damping the protons'
/// pair of H2 costs 2–3 times damping any other). That
/// halves the quadratures of eq. (38) where every pair is asked for (⟨V²⟩ of the regularised
/// ⟨p⁴⟩), and each product is the same bits whichever instances share the call (MPI ranks split
/// them). Any other instance is `coulomb_inv_r`.
pub fn coulomb_all<const D: usize, F: Family<D>>(bra: &F::Function<f64>, ket: &F::Function<f64>, ctx: &F::Context, instances: &[Vec<Vector<D>>]) -> Vec<f64> {
    let ops = F::operators(ctx);
    let (pairs, n) = (&ops.pairs, ops.pairs.len());
    let light: Vec<f64> = pairs.iter().map(|(w, _)| w.dot(&(ops.lambda * w))).collect();
    // whether the product of pairs k and l is integrated over the damping of k
    let damps = |k: usize, l: usize| light[k] > light[l] || (light[k] == light[l] && k <= l);
    // the Coulomb pair each instance is, if any
    let at: Vec<Option<usize>> = instances.iter().map(|v| pairs.iter().position(|(wp, _)| *wp == v[0] || *wp == -v[0])).collect();
    // at k n + l: whether the product of pairs k and l is needed and integrated over k's damping
    let mut need = vec![false; n * n];
    for &c in at.iter().flatten() {
        for l in 0..n {
            let (k, m) = if damps(c, l) { (c, l) } else { (l, c) };
            need[k * n + m] = true;
        }
    }
    // <1/(|r_w'_k| |r_w'_l|)> at k n + l and l n + k: one call of the family per damped pair
    let mut table = vec![f64::NAN; n * n];
    for k in 0..n {
        let skip: Vec<Option<f64>> = (0..n).map(|l| if need[k * n + l] { None } else { Some(0.0) }).collect();
        if skip.iter().all(Option::is_some) {
            continue;
        }
        let x = F::COULOMB(bra, ket, ctx, &pairs[k].0, &skip);
        for l in (0..n).filter(|&l| need[k * n + l]) {
            table[k * n + l] = x[l];
            table[l * n + k] = x[l];
        }
    }
    instances
        .iter()
        .zip(&at)
        .map(|(v, c)| match c {
            None => coulomb_inv_r::<D, F>(bra, ket, ctx, v),
            Some(c) => potential(pairs, &table[c * n..(c + 1) * n]),
        })
        .collect()
}

/// `<φ_I| 1/(|r_w| |r_w'_k|) |φ_J>` of plain ECGs by eq. (19) (`InverseProducts`).
pub fn inverse_products<const D: usize, F: Family<D>>(bra: &F::Function<f64>, ket: &F::Function<f64>, ctx: &F::Context, w: &Vector<D>, known: &[Option<f64>]) -> Vec<f64> {
    let pairs = &F::operators(ctx).pairs;
    let Some(whiten) = whitening::<D, F>(bra, ket) else { return vec![f64::NAN; pairs.len()] };
    let a = whiten(w);
    let s = F::overlap(bra, ket, ctx);
    pairs.iter().zip(known).map(|((wp, _), x)| x.unwrap_or_else(|| inverse_product(&a, &whiten(wp)) * s)).collect()
}

/// `<φ_I| 1/(|r_w| |r_w'_k|) |φ_J>` of any family by eq. (38) over the family's own `1/|r_w'|`
/// element of its damped functions (`InverseProducts`; module docs; `Family::COULOMB`'s default).
pub fn products_by_damping<const D: usize, F: Family<D>>(bra: &F::Function<f64>, ket: &F::Function<f64>, ctx: &F::Context, w: &Vector<D>, known: &[Option<f64>]) -> Vec<f64> {
    let (ww, pairs) = (w * w.transpose(), &F::operators(ctx).pairs);
    by_damping::<D, F>(bra, ket, ctx, w, known, |alpha, k| inverse::element::<D, F>(bra, &F::damped(ket, &(ww * alpha)), ctx, &pairs[k].0))
}

/// `<φ_I| 1/(|r_w| |r_w'_k|) |φ_J>` for the context's Coulomb pairs `w'_k` by eq. (38) (module
/// docs), given `damped(α, k) = <φ_I| e^{−α r_w²}/|r_w'_k| |φ_J>`; `known[k]` where given.
pub fn by_damping<const D: usize, F: Family<D>>(
    bra: &F::Function<f64>,
    ket: &F::Function<f64>,
    ctx: &F::Context,
    w: &Vector<D>,
    known: &[Option<f64>],
    damped: impl Fn(f64, usize) -> f64,
) -> Vec<f64> {
    let pairs = &F::operators(ctx).pairs;
    let Some(whiten) = whitening::<D, F>(bra, ket) else { return vec![f64::NAN; pairs.len()] };
    let a = whiten(w);
    let q = a.norm_squared();
    let pair = |k: usize, wp: &Vector<D>| {
        let ap = whiten(wp);
        let qp = ap.norm_squared();
        // 1 − ρ² from the wedge: accurate also where the pairs are nearly parallel
        let rest2 = (wedge(&a, &ap).powi(2) / (q * qp)).min(1.0);
        if rest2 <= 1e-28 {
            return (q / qp).sqrt() * inverse_square::element::<D, F>(bra, ket, ctx, w);
        }
        // the integrand of eq. (38) at τ, given 1 − τ² too (accurate where τ → 1)
        let at = |tau: f64, rest: f64| damped(tau * tau / (q * rest), k) / (rest * rest.sqrt());
        let rho2 = 1.0 - rest2;
        // 1e-11, or the rounding of the damped functions near α → ∞, which goes like the condition
        // of B + αwwᵀ there, ~1/(1 − ρ²)
        let tol = 1e-11f64.max(20.0 * f64::EPSILON / rest2);
        let integral = if rho2 < 1e-6 {
            even(&|tau| at(tau, (1.0 - tau) * (1.0 + tau)), 1.0, tol)
        } else {
            // τ = sin φ/ρ, 1 − τ² = (ρ − sin φ)(ρ + sin φ)/ρ²: no cancellation where ρ is small
            // (the difference of cos φ and √(1 − ρ²) cost up to 1e-9 there)
            let rho = rho2.sqrt();
            let f = |phi: f64| {
                let s = phi.sin();
                at(s / rho, (rho - s) * (rho + s) / rho2) * phi.cos() / rho
            };
            even(&f, rho.asin(), tol)
        };
        2.0 / (PI * q).sqrt() * integral
    };
    pairs.iter().zip(known).enumerate().map(|(k, ((wp, _), x))| x.unwrap_or_else(|| pair(k, wp))).collect()
}

/// `|a ∧ b|`.
fn wedge<const D: usize>(a: &Vector<D>, b: &Vector<D>) -> f64 {
    let mut sum = 0.0;
    for i in 0..D {
        for j in i + 1..D {
            sum += (a[i] * b[j] - a[j] * b[i]).powi(2);
        }
    }
    sum.sqrt()
}

/// `∫_0^b g` of an even `g` (eq. 38's integrand is even in φ and in τ): the 2m-point
/// Gauss–Legendre rules on `[−b, b]` (`legendre_rule`, m evaluations) for m = 6, 9, 13, 19, 28,
/// 42, the first that agrees with the one before to `tol` of `∫|g|` (its error is then a small
/// power of `tol`: each rule squares the error of the one before, about), else `adaptive`. The
/// mirror image makes φ = 0 an inner point, where a panel's rule treats it as an end.
fn even(g: &impl Fn(f64) -> f64, b: f64, tol: f64) -> f64 {
    // (∫g, ∫|g|) over [0, b] by the rule of m positive nodes
    let rule = |m: usize| {
        legendre_rule(m).iter().fold((0.0, 0.0), |(sum, size): (f64, f64), &(x, wt)| {
            let y = b * wt * g(b * x);
            (sum + y, size + y.abs())
        })
    };
    let (mut coarse, _) = rule(EVEN[0]);
    for &m in &EVEN[1..] {
        let (fine, size) = rule(m);
        if !fine.is_finite() {
            return fine;
        }
        if (fine - coarse).abs() <= tol * size {
            return fine;
        }
        coarse = fine;
    }
    adaptive(g, 0.0, b, tol)
}

/// The positive nodes of `even`'s rules: each about 1.5 times the one before, so agreeing rules
/// are not near neighbours (`benchmarks/quadrature_rules.py`: on H2's ECG-GVR 8 and 10 accepted a
/// value 5.4e-11 off, 6 and 9 none).
const EVEN: [usize; 6] = [6, 9, 13, 19, 28, 42];

/// `∫_a^b f` by Gauss–Legendre rules of 8 and 16 nodes per panel, a panel halved (at most 8
/// times) while the two differ by more than `tol` of `∫|f|` (its first estimate) times the
/// panel's share of `[a, b]`; a value that is not finite is returned as it is.
fn adaptive(f: &impl Fn(f64) -> f64, a: f64, b: f64, tol: f64) -> f64 {
    static RULES: OnceLock<[Vec<(f64, f64)>; 2]> = OnceLock::new();
    let [low, high] = RULES.get_or_init(|| [gauss_legendre(8), gauss_legendre(16)]);
    // (∫f, ∫|f|) over [a, b] by the rule r
    let rule = |r: &[(f64, f64)], a: f64, b: f64| {
        let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
        r.iter().fold((0.0, 0.0), |(sum, size), &(x, wt)| {
            let y = half * wt * f(mid + half * x);
            (sum + y, size + y.abs())
        })
    };
    let (whole, size) = rule(high, a, b);
    let tol = tol * size / (b - a);
    // depth first, left to right: (a, b, depth, the 16-node value if known)
    let (mut total, mut stack) = (0.0, vec![(a, b, 8, Some(whole))]);
    while let Some((a, b, depth, known)) = stack.pop() {
        let (fine, coarse) = (known.unwrap_or_else(|| rule(high, a, b).0), rule(low, a, b).0);
        if !fine.is_finite() {
            return fine;
        }
        if depth == 0 || (fine - coarse).abs() <= tol * (b - a) {
            total += fine;
        } else {
            let mid = 0.5 * (a + b);
            stack.extend([(mid, b, depth - 1, None), (a, mid, depth - 1, None)]);
        }
    }
    total
}

/// `<1/(|r_w| |r_w'|)>/S = 4 arcsin(ρ)/(πρ √(q₁₁q₂₂))` (eq. 19) of `a = L^{-1}w`, `b = L^{-1}w'`
/// (`L L^T = A_I + A_J`): `q₁₂ = a·b`, `ρ√(q₁₁q₂₂) = q₁₂` and `arcsin ρ = atan2(q₁₂, |a ∧ b|)`,
/// exact also for parallel vectors (`|a ∧ b| = 0`, eq. 13) and orthogonal ones (`q₁₂ = 0`).
fn inverse_product<const D: usize>(a: &Vector<D>, b: &Vector<D>) -> f64 {
    let (q12, wedge) = (a.dot(b), wedge(a, b));
    if q12 == 0.0 { 4.0 / (PI * wedge) } else { 4.0 * q12.atan2(wedge) / (PI * q12) }
}

/// `<∇φ_I| Λ/|r_w| |∇φ_J>` (hartree/bohr; `v = [w]`; module docs) from the family's kinetic
/// elements of its damped functions (`Family::GRADIENT`'s default).
pub fn gradient_inv_r<const D: usize, F: Family<D>>(bra: &F::Function<f64>, ket: &F::Function<f64>, ctx: &F::Context, v: &[Vector<D>]) -> f64 {
    let w = &v[0];
    let ww = w * w.transpose();
    let kinetic = F::kinetic_only(ctx);
    kinetic_by_damping::<D, F>(bra, ket, ctx, w, |alpha| {
        let damping: Mat<D> = ww * alpha;
        let t = 0.5 * (F::element(&F::damped(bra, &damping), ket, &kinetic).t_ti + F::element(bra, &F::damped(ket, &damping), &kinetic).t_ti);
        let a: Dual<1> = seed(alpha, std::iter::once(1.0));
        let d = F::overlap(&F::cast::<Dual<1>>(bra), &F::damped(ket, &ww.map(|x| a * x)), ctx);
        [t, d.re, -d.eps.unwrap_generic(Const::<1>, U1)[0]]
    })
}

/// `<∇φ_I| Λ/|r_w| |∇φ_J>` by eq. (30) over the profile's rule (module docs), given at the damping
/// `α` the kinetic part `½[T_TI(gφ_I, φ_J) + T_TI(φ_I, gφ_J)]`, `D(α)` and `R = −∂D/∂α` (`node`).
pub fn kinetic_by_damping<const D: usize, F: Family<D>>(
    bra: &F::Function<f64>,
    ket: &F::Function<f64>,
    ctx: &F::Context,
    w: &Vector<D>,
    node: impl Fn(f64) -> [f64; 3],
) -> f64 {
    let p = Profile::<D, F>::of(bra, ket, ctx, w);
    let q = p.q;
    let wlw = w.dot(&(F::operators(ctx).lambda * w));
    // <∇φ_I| g Λ |∇φ_J> / (1 − u)^{3/2} at u (eq. 30)
    let h = |u: f64| {
        let alpha = u / (q * (1.0 - u));
        let [t, d, r] = node(alpha);
        (t + 0.5 * wlw * (4.0 * alpha * alpha * r - 6.0 * alpha * d)) / (1.0 - u).powf(1.5)
    };
    let integral: f64 = match &p.shape {
        // degree M + 1 in u = τ²: exact with ⌊(M + 1)/2⌋ + 1 positive nodes (eq. 18)
        Shape::Polynomial(g) => legendre_rule(g.len() / 2 + 1).iter().map(|&(tau, wt)| wt * h(tau * tau)).sum(),
        // S e^{−λu}(f₀ + f₁u + f₂u²) (eq. 28): the quadratic through u = 0, ¼, ½, then
        // Σ_j f_j F_j(λ) (eq. 29)
        Shape::Exponential => {
            let lambda = p.lambda();
            let [y0, y1, y2] = [0.0, 0.25, 0.5].map(|u| h(u) * (lambda * u).exp());
            let f = [y0, -2.0 * (3.0 * y0 - 4.0 * y1 + y2), 8.0 * (y0 - 2.0 * y1 + y2)];
            (0..3).map(|j| f[j] * boys(j, lambda)).sum()
        }
    };
    2.0 / (PI * q).sqrt() * integral
}

/// The Boys function `F_j(λ) = ∫_0^1 τ^{2j} e^{−λτ²} dτ`: below λ = j + 8 the series of positive
/// terms `e^{−λ} Σ_k (2λ)^k/((2j + 1)(2j + 3)⋯(2j + 2k + 1))` (from integrating by parts), above
/// it `F_0 = √π erf(√λ)/(2√λ)` and the upward recurrence `F_{i+1} = ((2i + 1)F_i − e^{−λ})/(2λ)`,
/// which damps rounding there (`2i + 1 < 2λ`).
pub(super) fn boys(j: usize, lambda: f64) -> f64 {
    if lambda < j as f64 + 8.0 {
        let (mut term, mut sum, mut k) = (1.0 / (2 * j + 1) as f64, 0.0, 0);
        while term > 1e-17 * sum {
            sum += term;
            k += 1;
            term *= 2.0 * lambda / (2 * (j + k) + 1) as f64;
        }
        return (-lambda).exp() * sum;
    }
    let mut f = 0.5 * (PI / lambda).sqrt() * erf(lambda.sqrt());
    for i in 0..j {
        f = ((2 * i + 1) as f64 * f - (-lambda).exp()) / (2.0 * lambda);
    }
    f
}

#[cfg(test)]
mod tests {
    //! Plain ECGs of 2 and 3 particles (laboratory frame, with and without the CM elimination)
    //! against what uses neither eq. (19) nor eq. (30): `coulomb_inv_r` against the double
    //! integral `(1/π)∫∫(αβ)^{−1/2} <φ_I| e^{−α r_w² − β r_w'²} |φ_J> dα dβ` over the exact damped
    //! overlaps (a pair parallel to `w`: the `inv_r2` element); `gradient_inv_r` against
    //! `π^{−1/2}∫α^{−1/2} 6 Tr(W (B + α w w^T)^{-1}) <φ_I|e^{−α r_w²}|φ_J> dα`, `W = A_I Λ_TI A_J`, by
    //! quadrature, and against eq. (29). ECG-GVR at K = N = 0 and floating ECGs at zero shift
    //! equal plain ECGs (floating ECGs with centres: operators/orbit.rs's quadrature); the Boys
    //! functions against quadrature.
    use super::*;
    use crate::ecg::Operators;
    use crate::families::floating::FloatingEcg;
    use crate::families::gvr::gvr_element::GvrOps;
    use crate::families::plain::PlainEcg;
    use crate::operators::lookup;
    use crate::families::floating::fecg::{Centres, Fecg};
    use crate::families::gvr::gvr_drachmann::damped_inverse;
    use crate::families::gvr::gvr_element::{gauss_legendre, Gvr};
    use crate::families::gvr::EcgGvr;
    use crate::operators::fixtures::{self, close, plain, separable};
    use crate::operators::inverse_square;

    /// A positive-definite exponent varied by `seed`; with `mu`, CM-separable (`A 1 = c_A μ`).
    fn exponent<const N: usize>(seed: f64, cm: Option<(&Vector<N>, f64)>) -> Mat<N> {
        let a0 = fixtures::exponent(seed);
        cm.map_or(a0, |(mu, c_a)| separable(&a0, mu, c_a))
    }

    /// The laboratory frame of particles of `masses` and `charges`: `Λ = diag(1/2m)`, the Coulomb
    /// pairs `e_k − e_l`, with or without the CM elimination.
    fn laboratory<const N: usize>(masses: [f64; N], charges: [f64; N], cm: bool) -> Operators<N> {
        let mut pairs = vec![];
        for k in 0..N {
            for l in k + 1..N {
                pairs.push((Vector::<N>::from_fn(|i, _| (i == k) as i32 as f64 - (i == l) as i32 as f64), charges[k] * charges[l]));
            }
        }
        let lambda = Mat::<N>::from_diagonal(&Vector::<N>::from_fn(|i, _| 0.5 / masses[i]));
        Operators { lambda, pairs, cm_mass: cm.then(|| masses.iter().sum()) }
    }

    /// `<φ_I| V/|r_w| |φ_J>` by the generic eq. (38) (`products_by_damping`), whatever the
    /// family's own `Family::COULOMB`.
    fn coulomb_by_damping<const N: usize, F: Family<N>>(fi: &F::Function<f64>, fj: &F::Function<f64>, ctx: &F::Context, v: &[Vector<N>]) -> f64 {
        let pairs = &F::operators(ctx).pairs;
        potential(pairs, &products_by_damping::<N, F>(fi, fj, ctx, &v[0], &vec![None; pairs.len()]))
    }

    /// `∫_0^{π/2} f` by an n-point Gauss–Legendre rule.
    fn quarter(n: usize, f: impl Fn(f64) -> f64) -> f64 {
        gauss_legendre(n).iter().map(|&(x, wt)| 0.25 * PI * wt * f(0.25 * PI * (x + 1.0))).sum()
    }

    /// `q = w^T (A_I + A_J)^{-1} w`.
    fn variance<const N: usize>(ai: &Mat<N>, aj: &Mat<N>, w: &Vector<N>) -> f64 {
        w.dot(&((ai + aj).try_inverse().unwrap() * w))
    }

    /// `Σ_kl q_kl <1/(r_kl r_w)>` by the double integral (module docs) with α = tan²θ/q₁₁,
    /// β = tan²ϑ/q₂₂, and the `inv_r2` element for a pair parallel to `w`; any family.
    fn coulomb_by_quadrature<const N: usize, F: Family<N>>(fi: &F::Function<f64>, fj: &F::Function<f64>, ctx: &F::Context, w: &Vector<N>, n: usize) -> f64 {
        let (ai, aj) = (F::exponent(fi), F::exponent(fj));
        let q11 = variance(ai, aj, w);
        let mut total = 0.0;
        for (wp, charge) in &F::operators(ctx).pairs {
            if wp == w || *wp == -w {
                total += charge * inverse_square::element::<N, F>(fi, fj, ctx, w);
                continue;
            }
            let q22 = variance(ai, aj, wp);
            let (ww, wpwp) = (w * w.transpose(), wp * wp.transpose());
            let inner = |theta: f64| {
                quarter(n, |vartheta: f64| {
                    let damping = ww * (theta.tan().powi(2) / q11) + wpwp * (vartheta.tan().powi(2) / q22);
                    F::overlap(fi, &F::damped(fj, &damping), ctx) / (theta.cos() * vartheta.cos()).powi(2)
                })
            };
            total += charge * 4.0 / (PI * (q11 * q22).sqrt()) * quarter(n, inner);
        }
        total
    }

    /// `π^{−1/2}∫α^{−1/2} X(α) dα`, `X = 6 Tr(W B_α^{-1}) D(α)` (module docs), α = tan²θ/q.
    fn gradient_by_quadrature<const N: usize>(gi: &Gvr<N>, gj: &Gvr<N>, go: &GvrOps<N>, w: &Vector<N>) -> f64 {
        let ops = &go.ops;
        let lambda = ops.lambda - ops.cm_mass.map_or(Mat::<N>::zeros(), |m| Mat::<N>::repeat(0.5 / m));
        let wt = gi.a * lambda * gj.a;
        let q = variance(&gi.a, &gj.a, w);
        2.0 / (PI * q).sqrt()
            * quarter(200, |theta: f64| {
                let damping = w * w.transpose() * (theta.tan().powi(2) / q);
                let d = <PlainEcg as Family<N>>::overlap(gi, &gj.damped(&damping), go);
                let b_alpha = (gi.a + gj.a + damping).try_inverse().unwrap();
                6.0 * (wt * b_alpha).trace() * d / theta.cos().powi(2)
            })
    }

    /// Eq. (29) for plain ECGs: `(2S/√(πq)) (6 Tr(B^{-1}W) − 2 b^T W b/q)`, `b = B^{-1} w`.
    fn gradient_closed_form<const N: usize>(gi: &Gvr<N>, gj: &Gvr<N>, go: &GvrOps<N>, w: &Vector<N>) -> f64 {
        let ops = &go.ops;
        let lambda = ops.lambda - ops.cm_mass.map_or(Mat::<N>::zeros(), |m| Mat::<N>::repeat(0.5 / m));
        let wt = gi.a * lambda * gj.a;
        let binv = (gi.a + gj.a).try_inverse().unwrap();
        let (b, q) = (binv * w, variance(&gi.a, &gj.a, w));
        let s = <PlainEcg as Family<N>>::overlap(gi, gj, go);
        2.0 * s / (PI * q).sqrt() * (6.0 * (binv * wt).trace() - 2.0 * b.dot(&(wt * b)) / q)
    }

    /// Both elements of plain ECGs against the references for the pairs `(i, j)` of `N` particles.
    fn check_plain<const N: usize>(masses: [f64; N], charges: [f64; N], pairs: &[(usize, usize)]) {
        let mu = Vector::<N>::from_row_slice(&masses) / masses.iter().sum::<f64>();
        for cm in [false, true] {
            let go = GvrOps::new(laboratory(masses, charges, cm), 0, 0).unwrap();
            for (si, sj) in [(0.1, 0.9), (1.3, 2.2), (0.4, 0.4)] {
                let (ai, aj) = if cm {
                    (exponent(si, Some((&mu, 0.7))), exponent(sj, Some((&mu, 1.3))))
                } else {
                    (exponent(si, None), exponent(sj, None))
                };
                let (gi, gj) = (plain(ai, 0.7, &go, 0), plain(aj, 1.3, &go, 1));
                for &(i, j) in pairs {
                    let w = Vector::<N>::from_fn(|k, _| (k == i) as i32 as f64 - (k == j) as i32 as f64);
                    let label = format!("N = {N}, CM {cm}, seeds ({si}, {sj}), pair ({i}, {j})");
                    let got = coulomb_inv_r::<N, PlainEcg>(&gi, &gj, &go, &[w]);
                    let want = coulomb_by_quadrature::<N, PlainEcg>(&gi, &gj, &go, &w, 80);
                    assert!(close(got, want, 1e-9), "{label}: coulomb_inv_r {got} vs {want}");
                    let got = gradient_inv_r::<N, PlainEcg>(&gi, &gj, &go, &[w]);
                    let (numerical, closed) = (gradient_by_quadrature(&gi, &gj, &go, &w), gradient_closed_form(&gi, &gj, &go, &w));
                    assert!(close(got, numerical, 1e-11), "{label}: gradient_inv_r {got} vs quadrature {numerical}");
                    assert!(close(got, closed, 1e-12), "{label}: gradient_inv_r {got} vs eq. (29) {closed}");
                    // ECG-GVR at K = N = 0: the same functions
                    let gvr = gradient_inv_r::<N, EcgGvr>(&gi, &gj, &go, &[w]);
                    assert!(close(gvr, got, 1e-13), "{label}: ECG-GVR {gvr} vs {got}");
                    // eq. (38) on the same functions against eq. (19), generic and ECG-GVR's own
                    let want = coulomb_inv_r::<N, PlainEcg>(&gi, &gj, &go, &[w]);
                    for got in [coulomb_by_damping::<N, EcgGvr>(&gi, &gj, &go, &[w]), coulomb_inv_r::<N, EcgGvr>(&gi, &gj, &go, &[w])] {
                        assert!(close(got, want, 1e-12), "{label}: eq. (38) {got} vs eq. (19) {want}");
                    }
                }
            }
        }
    }

    #[test]
    fn two_particles_match_the_quadratures() {
        check_plain([1836.15267343, 1.0], [1.0, -1.0], &[(0, 1), (1, 0)]);
    }

    #[test]
    fn three_particles_match_the_quadratures() {
        check_plain([7294.29954142, 1.0, 1.0], [2.0, -1.0, -1.0], &[(0, 1), (0, 2), (1, 2)]);
    }

    /// ECG-GVR with K, N > 0: the rule of `gradient_inv_r` against
    /// `(2/√(πq))∫_0^1 (1 − τ²)^{−3/2} X(α(τ²)) dτ` by a 24-point Gauss–Legendre rule on [0, 1] (a
    /// polynomial of degree 2M + 2 in τ: exact too), with `X` split symmetrically,
    /// `h = exp(−α r_w²/2)`: `X = T_TI(hφ_I, hφ_J) + w^TΛw (α²R − 3αD)` (another combination than
    /// eq. 30).
    #[test]
    fn global_vector_functions_match_a_rule_on_the_symmetric_split() {
        let masses = [7294.29954142, 1.0, 1.0];
        let mu = Vector::<3>::from_row_slice(&masses) / masses.iter().sum::<f64>();
        for (ki, kj, n_ang) in [(1, 0, 0), (2, 1, 1), (1, 3, 2)] {
            for cm in [false, true] {
                let go = GvrOps::new(laboratory(masses, [2.0, -1.0, -1.0], cm), n_ang, 3).unwrap();
                let gi = Gvr::new(exponent(0.5, Some((&mu, 0.7))), Vector::<3>::new(0.3, 1.0, -0.4), ki, 0.7, &go, 0).unwrap();
                let gj = Gvr::new(exponent(1.1, Some((&mu, 1.3))), Vector::<3>::new(-0.7, 0.2, 0.9), kj, 1.3, &go, 1).unwrap();
                for w in [Vector::<3>::new(1.0, -1.0, 0.0), Vector::<3>::new(0.0, 1.0, -1.0)] {
                    let (q, ww, wlw) = (variance(&gi.a, &gj.a, &w), w * w.transpose(), w.dot(&(go.ops.lambda * w)));
                    let x = |tau: f64| {
                        let alpha = tau * tau / (q * (1.0 - tau * tau));
                        let half = ww * (0.5 * alpha);
                        let t = <EcgGvr as Family<3>>::element(&gi.damped(&half), &gj.damped(&half), &go).t_ti;
                        let a: Dual<1> = seed(alpha, std::iter::once(1.0));
                        let d = <EcgGvr as Family<3>>::overlap(&gi.cast::<Dual<1>>(), &gj.damped(&ww.map(|x| a * x)), &go);
                        let r = -d.eps.unwrap_generic(Const::<1>, U1)[0];
                        (t + wlw * (alpha * alpha * r - 3.0 * alpha * d.re)) / (1.0 - tau * tau).powf(1.5)
                    };
                    let rule: f64 = gauss_legendre(24).iter().map(|&(y, wt)| 0.5 * wt * x(0.5 * (y + 1.0))).sum();
                    let want = 2.0 / (PI * q).sqrt() * rule;
                    let got = gradient_inv_r::<3, EcgGvr>(&gi, &gj, &go, &[w]);
                    assert!(close(got, want, 1e-11), "K = ({ki}, {kj}), N = {n_ang}, CM {cm}: {got} vs {want}");
                }
            }
        }
    }

    #[test]
    fn floating_ecgs_at_zero_shift_are_plain_ecgs() {
        let ops = laboratory([7294.29954142, 1.0, 1.0], [2.0, -1.0, -1.0], false);
        let go = GvrOps::new(ops.clone(), 0, 0).unwrap();
        let (ai, aj) = (exponent::<3>(0.2, None), exponent::<3>(1.7, None));
        let (fi, fj) = (Fecg::new(ai, Centres::<3>::zeros(), 1.0, 0).unwrap(), Fecg::new(aj, Centres::<3>::zeros(), 1.0, 1).unwrap());
        let w = Vector::<3>::new(1.0, -1.0, 0.0);
        let got = gradient_inv_r::<3, FloatingEcg>(&fi, &fj, &ops, &[w]);
        let want = gradient_inv_r::<3, PlainEcg>(&plain(ai, 1.0, &go, 0), &plain(aj, 1.0, &go, 1), &go, &[w]);
        assert!(close(got, want, 1e-12), "{got} vs {want}");
    }

    /// Eq. (38) where the pairs are nearly uncorrelated in the Gaussian (ρ² from 6e-4 down to
    /// 7e-7, and 0), each product against eq. (19) to 1e-13: ECG-GVR at K = N = 0 by its own path
    /// and the generic one, floating ECGs at zero centres (measured: 9.1e-16 at most). Where
    /// 1 − τ² was the difference cos φ − √(1 − ρ²) it lost about ε/ρ² (b25cc10's code: 2.7e-11
    /// at ρ² = 6e-6, 6.9e-13 at 7e-5).
    #[test]
    fn nearly_uncorrelated_pairs_match_eq_19() {
        let ops = laboratory([1836.15267343, 1.0, 1.0], [1.0, -1.0, -1.0], false);
        let go = GvrOps::new(ops.clone(), 0, 0).unwrap();
        let (w, wp) = (Vector::<3>::new(1.0, 0.0, -1.0), Vector::<3>::new(0.0, 1.0, -1.0));
        for delta in [3e-2, 1e-2, 3e-3, 1e-3, 0.0] {
            // (A_I + A_J)⁻¹ = 1 + s (w w'ᵀ + w' wᵀ), so that wᵀ(A_I + A_J)⁻¹w' = 1 + 5s = δ
            let s = (delta - 1.0) / 5.0;
            let b = (Mat::<3>::identity() + (w * wp.transpose() + wp * w.transpose()) * s).try_inverse().unwrap();
            let (ai, aj) = (b * 0.4 + Mat::<3>::identity() * 0.01, b * 0.6 - Mat::<3>::identity() * 0.01);
            let (gi, gj) = (plain(ai, 1.0, &go, 0), plain(aj, 1.0, &go, 1));
            let (fi, fj) = (Fecg::new(ai, Centres::<3>::zeros(), 1.0, 0).unwrap(), Fecg::new(aj, Centres::<3>::zeros(), 1.0, 1).unwrap());
            let none = [None; 3];
            let want = inverse_products::<3, PlainEcg>(&gi, &gj, &go, &w, &none);
            let paths = [
                ("ECG-GVR's own", <EcgGvr as Family<3>>::COULOMB(&gi, &gj, &go, &w, &none)),
                ("generic, ECG-GVR", products_by_damping::<3, EcgGvr>(&gi, &gj, &go, &w, &none)),
                ("generic, floating", products_by_damping::<3, FloatingEcg>(&fi, &fj, &ops, &w, &none)),
            ];
            for (path, got) in paths {
                for k in 0..3 {
                    assert!(close(got[k], want[k], 1e-13), "δ = {delta}, pair {k}, {path}: {} vs {}", got[k], want[k]);
                }
            }
        }
    }

    /// Eq. (38) where the pairs are nearly parallel: a light particle between two heavy ones held
    /// close (`A` grows by `tight` along their pair vector), so that its distances to them
    /// correlate up to ρ² = 1 − 1.2·10⁻⁵; against eq. (19) on plain ECGs and for floating ECGs at
    /// zero centres. The damped functions near α → ∞ round like the condition of `B + αwwᵀ` there,
    /// which grows with `tight`: 1e-12 + 1e-15·tight relative (measured 2.1e-14, 2.2e-13 and
    /// 4.0e-11 at tight = 10, 10³, 10⁵, the charges' sum cancelling about tenfold).
    #[test]
    fn nearly_parallel_pairs_match_eq_19() {
        let ops = laboratory([1836.15267343, 1836.15267343, 1.0], [1.0, 1.0, -1.0], false);
        let go = GvrOps::new(ops.clone(), 0, 0).unwrap();
        let heavy = Vector::<3>::new(1.0, -1.0, 0.0);
        for tight in [10.0, 1e3, 1e5] {
            let (ai, aj) = [0.3, 1.9].map(|seed| exponent::<3>(seed, None) + heavy * heavy.transpose() * tight).into();
            let (gi, gj) = (plain(ai, 1.0, &go, 0), plain(aj, 1.0, &go, 1));
            let (fi, fj) = (Fecg::new(ai, Centres::<3>::zeros(), 1.0, 0).unwrap(), Fecg::new(aj, Centres::<3>::zeros(), 1.0, 1).unwrap());
            for w in [Vector::<3>::new(1.0, 0.0, -1.0), Vector::<3>::new(0.0, 1.0, -1.0), heavy] {
                let want = coulomb_inv_r::<3, PlainEcg>(&gi, &gj, &go, &[w]);
                let tol = 1e-12 + 1e-15 * tight;
                let got = coulomb_by_damping::<3, EcgGvr>(&gi, &gj, &go, &[w]);
                assert!(close(got, want, tol), "A + {tight} w wᵀ, w = {w:?}: ECG-GVR {got} vs {want}");
                let got = coulomb_inv_r::<3, EcgGvr>(&gi, &gj, &go, &[w]);
                assert!(close(got, want, tol), "A + {tight} w wᵀ, w = {w:?}: ECG-GVR's own {got} vs {want}");
                let got = coulomb_by_damping::<3, FloatingEcg>(&fi, &fj, &ops, &[w]);
                assert!(close(got, want, tol), "A + {tight} w wᵀ, w = {w:?}: floating {got} vs {want}");
            }
        }
    }

    /// Eq. (38) for floating ECGs with centres and ECG-GVR with K, N > 0 (three particles, with
    /// and without CM-separable exponents) against the double integral over their own damped
    /// overlaps (`coulomb_by_quadrature`).
    #[test]
    fn floating_and_global_vector_functions_match_the_double_integral() {
        let masses = [7294.29954142, 1.0, 1.0];
        let mu = Vector::<3>::from_row_slice(&masses) / masses.iter().sum::<f64>();
        let pairs = [Vector::<3>::new(1.0, -1.0, 0.0), Vector::<3>::new(0.0, 1.0, -1.0)];
        for cm in [false, true] {
            let ops = laboratory(masses, [2.0, -1.0, -1.0], cm);
            let cm_of = |c_a: f64| cm.then_some((&mu, c_a));
            let (ai, aj) = (exponent(0.5, cm_of(0.7)), exponent(1.1, cm_of(1.3)));
            for spread in [0.3, 1.5] {
                // centres with a common shift along the CM direction only where A is CM-separable
                let (fi, fj) = (Fecg::new(ai, fixtures::centres(0.3, spread), 0.7, 0).unwrap(), Fecg::new(aj, fixtures::centres(2.1, spread), 1.3, 1).unwrap());
                for w in pairs {
                    let (got, want) = (coulomb_by_damping::<3, FloatingEcg>(&fi, &fj, &ops, &[w]), coulomb_by_quadrature::<3, FloatingEcg>(&fi, &fj, &ops, &w, 40));
                    assert!(close(got, want, 1e-10), "floating, CM {cm}, spread {spread}, w = {w:?}: {got} vs {want}");
                }
            }
            for (ki, kj, n_ang) in [(1, 0, 0), (2, 1, 1), (1, 3, 2)] {
                let go = GvrOps::new(ops.clone(), n_ang, 3).unwrap();
                let gi = Gvr::new(ai, Vector::<3>::new(0.3, 1.0, -0.4), ki, 0.7, &go, 0).unwrap();
                let gj = Gvr::new(aj, Vector::<3>::new(-0.7, 0.2, 0.9), kj, 1.3, &go, 1).unwrap();
                for w in pairs {
                    let want = coulomb_by_quadrature::<3, EcgGvr>(&gi, &gj, &go, &w, 40);
                    for got in [coulomb_by_damping::<3, EcgGvr>(&gi, &gj, &go, &[w]), coulomb_inv_r::<3, EcgGvr>(&gi, &gj, &go, &[w])] {
                        assert!(close(got, want, 1e-10), "K = ({ki}, {kj}), N = {n_ang}, CM {cm}, w = {w:?}: {got} vs {want}");
                    }
                }
            }
        }
    }

    /// ECG-GVR's own eqs. (38) and (30) (`Family::COULOMB`: rank-one updates of one factorisation;
    /// `Family::GRADIENT`: one element per node for both damped functions) against the generic ones
    /// (`coulomb_by_damping`, `gradient_inv_r`: each damped function its own element) where a
    /// molecule's would differ if either rounded badly:
    /// K up to 15 along the heavy pair, held close (1 − ρ² down to ~1e-5), N = 0 and 1, with and
    /// without the CM elimination, every pair vector; to the generic path's own rounding there
    /// (`nearly_parallel_pairs_match_eq_19`) and what the quadrature promises: measured per product
    /// up to 1.4e-14, 2.6e-12 and 3.8e-10 at tight = 10, 10³, 10⁵ (Coulomb, 30b3384), 7e-14,
    /// 2.2e-12 and 5.1e-10 (gradient).
    #[test]
    fn global_vector_functions_match_the_generic_path() {
        let masses = [1836.15267343, 1836.15267343, 1.0];
        let heavy = Vector::<3>::new(1.0, -1.0, 0.0);
        let mu = Vector::<3>::from_row_slice(&masses) / masses.iter().sum::<f64>();
        for cm in [true, false] {
            let ops = laboratory(masses, [1.0, 1.0, -1.0], cm);
            for n_ang in [0, 1] {
                let go = GvrOps::new(ops.clone(), n_ang, 15).unwrap();
                for (ki, kj, tight) in [(3, 5, 10.0), (15, 12, 1e3), (9, 0, 1e5)] {
                    let [ai, aj] = [0.3, 1.9].map(|seed| exponent::<3>(seed, cm.then_some((&mu, 1.0))) + heavy * heavy.transpose() * tight);
                    let gi = Gvr::new(ai, heavy + Vector::<3>::new(0.0, 0.0, 0.1), ki, 1.0, &go, 0).unwrap();
                    let gj = Gvr::new(aj, heavy * 0.8, kj, 1.0, &go, 1).unwrap();
                    for w in [Vector::<3>::new(1.0, 0.0, -1.0), Vector::<3>::new(0.0, 1.0, -1.0), heavy] {
                        let label = format!("K = ({ki}, {kj}), N = {n_ang}, CM {cm}, A + {tight} w wᵀ, w = {w:?}");
                        let binv = (ai + aj).try_inverse().unwrap();
                        let ww = w * w.transpose();
                        let damped = damped_inverse(&gi, &gj, &go, &w).unwrap();
                        let (got, want) = (<EcgGvr as Family<3>>::COULOMB(&gi, &gj, &go, &w, &[None; 3]), products_by_damping::<3, EcgGvr>(&gi, &gj, &go, &w, &[None; 3]));
                        for (k, (wp, _)) in ops.pairs.iter().enumerate() {
                            // the integrands (α = τ²/(q(1 − τ²))): the two paths round apart as the
                            // condition of A_I + A_J (~ `tight`) and of the damping grow (at τ = 0.99
                            // 1.1e-12, 4.6e-11, 1.4e-10 for the three `tight`)
                            for tau in [0.1, 0.5, 0.9] {
                                let alpha = tau * tau / (w.dot(&(binv * w)) * (1.0 - tau * tau));
                                let (got, want) = (damped(alpha, k), inverse::element::<3, EcgGvr>(&gi, &EcgGvr::damped(&gj, &(ww * alpha)), &go, wp));
                                assert!(close(got, want, 1e-13 + 2e-14 * tight), "damped, {label}, w' = {wp:?}, τ = {tau}: {got} vs {want}");
                            }
                            // the integrals: that rounding (at `tight` = 10⁵ 1.1e-10 for τ ≤ 0.9, up to
                            // 8.6e-10 towards τ = 1), and twice what each quadrature promises
                            // (`by_damping`: 1e-11, or 20ε/(1 − ρ²))
                            let rho2 = w.dot(&(binv * wp)).powi(2) / (w.dot(&(binv * w)) * wp.dot(&(binv * wp)));
                            let promised = if *wp == w || *wp == -w { 0.0 } else { 1e-11f64.max(20.0 * f64::EPSILON / (1.0 - rho2)) };
                            assert!(close(got[k], want[k], 1e-12 + 1e-14 * tight + 2.0 * promised), "<1/(r_w r_w')>, {label}, w' = {wp:?}: {} vs {}", got[k], want[k]);
                            // ECG-GVR's own two orientations, which round little (damping the heavy
                            // pair or the other agree to 7.5e-13 at 10⁵, the generic path's to 1.7e-10)
                            let c = ops.pairs.iter().position(|(v, _)| *v == w).unwrap();
                            let mirror = <EcgGvr as Family<3>>::COULOMB(&gi, &gj, &go, wp, &[None; 3])[c];
                            assert!(close(got[k], mirror, 1e-13 + 2.0 * promised), "<1/(r_w r_w')> damping w or w', {label}, w' = {wp:?}: {} vs {mirror}", got[k]);
                        }
                        let (got, want) = (<EcgGvr as Family<3>>::GRADIENT(&gi, &gj, &go, &[w]), gradient_inv_r::<3, EcgGvr>(&gi, &gj, &go, &[w]));
                        assert!(close(got, want, 1e-12 + 1e-14 * tight), "gradient: K = ({ki}, {kj}), N = {n_ang}, CM {cm}, A + {tight} w wᵀ, w = {w:?}: {got} vs {want}");
                    }
                }
            }
        }
    }

    /// Every instance at once (`coulomb_all`, each product of two pairs computed once) against each
    /// alone (`coulomb_inv_r`), for floating ECGs with centres and ECG-GVR, three particles in the
    /// laboratory frame: the instances every Coulomb pair, one of them twice and reversed, and a
    /// vector that is none; and the same bits for an instance in any company (MPI ranks split the
    /// instances).
    #[test]
    fn all_instances_at_once_match_each_alone() {
        let masses = [1836.15267343, 1.0, 1.0];
        let ops = laboratory(masses, [1.0, -1.0, -1.0], true);
        let mu = Vector::<3>::from_row_slice(&masses) / masses.iter().sum::<f64>();
        let (ai, aj) = (exponent(0.5, Some((&mu, 0.7))), exponent(1.1, Some((&mu, 1.3))));
        let mut instances: Vec<Vec<Vector<3>>> = ops.pairs.iter().map(|(w, _)| vec![*w]).collect();
        instances.extend([vec![-ops.pairs[1].0], vec![Vector::<3>::new(0.5, 0.5, -1.0)]]);
        let check = |all: &dyn Fn(&[Vec<Vector<3>>]) -> Vec<f64>, each: &dyn Fn(&[Vector<3>]) -> f64, label: &str| {
            let together = all(&instances);
            for (k, (got, v)) in together.iter().zip(&instances).enumerate() {
                let want = each(v);
                assert!(close(*got, want, 1e-10), "{label}, w = {:?}: {got} vs {want}", v[0]);
                assert_eq!(all(&instances[k..k + 1])[0].to_bits(), got.to_bits(), "{label}, w = {:?} alone", v[0]);
            }
        };
        let (fi, fj) = (Fecg::new(ai, fixtures::centres(0.3, 1.5), 0.7, 0).unwrap(), Fecg::new(aj, fixtures::centres(2.1, 1.5), 1.3, 1).unwrap());
        check(&|v| coulomb_all::<3, FloatingEcg>(&fi, &fj, &ops, v), &|v| coulomb_inv_r::<3, FloatingEcg>(&fi, &fj, &ops, v), "floating");
        let go = GvrOps::new(ops.clone(), 1, 3).unwrap();
        let gi = Gvr::new(ai, Vector::<3>::new(0.3, 1.0, -0.4), 2, 0.7, &go, 0).unwrap();
        let gj = Gvr::new(aj, Vector::<3>::new(-0.7, 0.2, 0.9), 3, 1.3, &go, 1).unwrap();
        check(&|v| coulomb_all::<3, EcgGvr>(&gi, &gj, &go, v), &|v| coulomb_inv_r::<3, EcgGvr>(&gi, &gj, &go, v), "global vector");
    }

    #[test]
    fn boys_functions_match_quadrature() {
        for lambda in [0.0, 1e-3, 0.7, 1.0, 3.5, 7.99, 8.0, 12.9, 13.1, 40.0] {
            for j in 0..6 {
                let want: f64 = gauss_legendre(60).iter().map(|&(x, wt)| {
                    let t = 0.5 * (x + 1.0);
                    0.5 * wt * t.powi(2 * j as i32) * (-lambda * t * t).exp()
                }).sum();
                assert!(close(boys(j, lambda), want, 1e-13), "F_{j}({lambda}) = {} vs {want}", boys(j, lambda));
            }
        }
    }

    #[test]
    fn every_family_has_them() {
        for name in [COULOMB, GRADIENT] {
            assert!(lookup::<3, PlainEcg>(name).is_ok() && lookup::<3, EcgGvr>(name).is_ok() && lookup::<3, FloatingEcg>(name).is_ok());
        }
    }
}
