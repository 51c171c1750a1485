//! `coulomb_inv_r`, `<φ_I| V/|r_w| |φ_J>` (module `drachmann`'s docs, eqs. 13, 19, 38).

use std::f64::consts::PI;
use std::sync::OnceLock;

use crate::ecg::Vector;
use crate::quadrature::{gauss_legendre, legendre_rule};
use crate::families::Family;
use crate::operators::{inverse, inverse_square};

/// `w ↦ L⁻¹w` with `L Lᵀ = A_I + A_J`, so `|L⁻¹w|² = wᵀ(A_I + A_J)⁻¹w`; None where the sum does not
/// factorise.
fn whitening<const D: usize, F: Family<D>>(bra: &F::Function<f64>, ket: &F::Function<f64>) -> Option<impl Fn(&Vector<D>) -> Vector<D>> {
    let chol = (F::exponent(bra) + F::exponent(ket)).cholesky()?;
    Some(move |w: &Vector<D>| chol.l().solve_lower_triangular(w).unwrap_or_else(|| Vector::<D>::repeat(f64::NAN)))
}

/// `<φ_I| 1/(|r_w| |r_w'_k|) |φ_J>` for each Coulomb pair `(w'_k, q_k)` of the context (bohr⁻²);
/// where `known[k]` is given it is returned instead, not computed (`all_of` passes what it
/// has, or needs not). Any family's `products_by_damping`; a family's own in its folder
/// (`families/<name>/operators.rs`).
pub type InverseProducts<const D: usize, F> =
    fn(&<F as Family<D>>::Function<f64>, &<F as Family<D>>::Function<f64>, &<F as Family<D>>::Context, &Vector<D>, &[Option<f64>]) -> Vec<f64>;

/// `<φ_I| V/|r_w| |φ_J> = Σ_k q_k <φ_I| 1/(|r_w| |r_w'_k|) |φ_J>` (hartree/bohr; `v = [w]`) from the
/// products `products`.
pub fn coulomb_inv_r<const D: usize, F: Family<D>>(
    products: InverseProducts<D, F>,
    bra: &F::Function<f64>,
    ket: &F::Function<f64>,
    ctx: &F::Context,
    v: &[Vector<D>],
) -> f64 {
    let pairs = &F::operators(ctx).pairs;
    potential(pairs, &products(bra, ket, ctx, &v[0], &vec![None; pairs.len()]))
}

/// `Σ_k q_k x_k` over the Coulomb pairs `(w'_k, q_k)`.
pub(super) fn potential<const D: usize>(pairs: &[(Vector<D>, f64)], x: &[f64]) -> f64 {
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
/// them). Any other instance is `coulomb_inv_r`. From the products `products`.
pub fn all_of<const D: usize, F: Family<D>>(
    products: InverseProducts<D, F>,
    bra: &F::Function<f64>,
    ket: &F::Function<f64>,
    ctx: &F::Context,
    instances: &[Vec<Vector<D>>],
) -> Vec<f64> {
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
        let x = products(bra, ket, ctx, &pairs[k].0, &skip);
        for l in (0..n).filter(|&l| need[k * n + l]) {
            table[k * n + l] = x[l];
            table[l * n + k] = x[l];
        }
    }
    instances
        .iter()
        .zip(&at)
        .map(|(v, c)| match c {
            None => coulomb_inv_r::<D, F>(products, bra, ket, ctx, v),
            Some(c) => potential(pairs, &table[c * n..(c + 1) * n]),
        })
        .collect()
}

/// `all_of` any family's products by damping (`products_by_damping`): the generic element.
pub fn all<const D: usize, F: Family<D>>(bra: &F::Function<f64>, ket: &F::Function<f64>, ctx: &F::Context, instances: &[Vec<Vector<D>>]) -> Vec<f64> {
    all_of::<D, F>(products_by_damping::<D, F>, bra, ket, ctx, instances)
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
/// element of its damped functions (`InverseProducts`; module docs).
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
