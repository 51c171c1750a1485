//! Plain ECGs of 2 and 3 particles (laboratory frame, with and without the CM elimination)
//! against what uses neither eq. (19) nor eq. (30): `coulomb_inv_r` against the double
//! integral `(1/π)∫∫(αβ)^{−1/2} <φ_I| e^{−α r_w² − β r_w'²} |φ_J> dα dβ` over the exact damped
//! overlaps (a pair parallel to `w`: the `inv_r2` element); `gradient_inv_r` against
//! `π^{−1/2}∫α^{−1/2} 6 Tr(W (B + α w w^T)^{-1}) <φ_I|e^{−α r_w²}|φ_J> dα`, `W = A_I Λ_TI A_J`, by
//! quadrature, and against eq. (29). ECG-GVR at K = N = 0 and floating ECGs at zero shift
//! equal plain ECGs (floating ECGs with centres: operators/orbit.rs's quadrature); the Boys
//! functions against quadrature.
use std::f64::consts::PI;

use super::coulomb::*;
use super::gradient::*;
use super::*;
use nalgebra::{Const, U1};

use crate::ecg::{Mat, Vector};
use crate::families::Family;
use crate::gradient::{seed, Dual};
use crate::operators::inverse;
use crate::ecg::Operators;
use crate::families::fecg::Fecg;
use crate::families::ecg_gvr::element::GvrOps;
use crate::families::pecg::Pecg;
use crate::registry::lookup;
use crate::families::fecg::kernel::{Centres, FecgFunction};
use crate::families::ecg_gvr::drachmann::{damped_inverse, inverse_products as gvr_products};
use crate::families::ecg_gvr::element::GvrFunction;
use crate::quadrature::gauss_legendre;
use crate::families::ecg_gvr::{self, EcgGvr};
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
/// family's own products (`families/<name>/operators.rs`).
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
fn gradient_by_quadrature<const N: usize>(gi: &GvrFunction<N>, gj: &GvrFunction<N>, go: &GvrOps<N>, w: &Vector<N>) -> f64 {
    let ops = &go.ops;
    let lambda = ops.lambda - ops.cm_mass.map_or(Mat::<N>::zeros(), |m| Mat::<N>::repeat(0.5 / m));
    let wt = gi.a * lambda * gj.a;
    let q = variance(&gi.a, &gj.a, w);
    2.0 / (PI * q).sqrt()
        * quarter(200, |theta: f64| {
            let damping = w * w.transpose() * (theta.tan().powi(2) / q);
            let d = <Pecg as Family<N>>::overlap(gi, &gj.damped(&damping), go);
            let b_alpha = (gi.a + gj.a + damping).try_inverse().unwrap();
            6.0 * (wt * b_alpha).trace() * d / theta.cos().powi(2)
        })
}

/// Eq. (29) for plain ECGs: `(2S/√(πq)) (6 Tr(B^{-1}W) − 2 b^T W b/q)`, `b = B^{-1} w`.
fn gradient_closed_form<const N: usize>(gi: &GvrFunction<N>, gj: &GvrFunction<N>, go: &GvrOps<N>, w: &Vector<N>) -> f64 {
    let ops = &go.ops;
    let lambda = ops.lambda - ops.cm_mass.map_or(Mat::<N>::zeros(), |m| Mat::<N>::repeat(0.5 / m));
    let wt = gi.a * lambda * gj.a;
    let binv = (gi.a + gj.a).try_inverse().unwrap();
    let (b, q) = (binv * w, variance(&gi.a, &gj.a, w));
    let s = <Pecg as Family<N>>::overlap(gi, gj, go);
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
                let got = coulomb_inv_r::<N, Pecg>(inverse_products::<N, Pecg>, &gi, &gj, &go, &[w]);
                let want = coulomb_by_quadrature::<N, Pecg>(&gi, &gj, &go, &w, 80);
                assert!(close(got, want, 1e-9), "{label}: coulomb_inv_r {got} vs {want}");
                let got = gradient_inv_r::<N, Pecg>(&gi, &gj, &go, &[w]);
                let (numerical, closed) = (gradient_by_quadrature(&gi, &gj, &go, &w), gradient_closed_form(&gi, &gj, &go, &w));
                assert!(close(got, numerical, 1e-11), "{label}: gradient_inv_r {got} vs quadrature {numerical}");
                assert!(close(got, closed, 1e-12), "{label}: gradient_inv_r {got} vs eq. (29) {closed}");
                // ECG-GVR at K = N = 0: the same functions
                let gvr = gradient_inv_r::<N, EcgGvr>(&gi, &gj, &go, &[w]);
                assert!(close(gvr, got, 1e-13), "{label}: ECG-GVR {gvr} vs {got}");
                // eq. (38) on the same functions against eq. (19), generic and ECG-GVR's own
                let want = coulomb_inv_r::<N, Pecg>(inverse_products::<N, Pecg>, &gi, &gj, &go, &[w]);
                for got in [coulomb_by_damping::<N, EcgGvr>(&gi, &gj, &go, &[w]), coulomb_inv_r::<N, EcgGvr>(gvr_products::<N>, &gi, &gj, &go, &[w])] {
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
            let gi = GvrFunction::new(exponent(0.5, Some((&mu, 0.7))), Vector::<3>::new(0.3, 1.0, -0.4), ki, 0.7, &go, 0).unwrap();
            let gj = GvrFunction::new(exponent(1.1, Some((&mu, 1.3))), Vector::<3>::new(-0.7, 0.2, 0.9), kj, 1.3, &go, 1).unwrap();
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
    let (fi, fj) = (FecgFunction::new(ai, Centres::<3>::zeros(), 1.0, 0).unwrap(), FecgFunction::new(aj, Centres::<3>::zeros(), 1.0, 1).unwrap());
    let w = Vector::<3>::new(1.0, -1.0, 0.0);
    let got = gradient_inv_r::<3, Fecg>(&fi, &fj, &ops, &[w]);
    let want = gradient_inv_r::<3, Pecg>(&plain(ai, 1.0, &go, 0), &plain(aj, 1.0, &go, 1), &go, &[w]);
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
        let (fi, fj) = (FecgFunction::new(ai, Centres::<3>::zeros(), 1.0, 0).unwrap(), FecgFunction::new(aj, Centres::<3>::zeros(), 1.0, 1).unwrap());
        let none = [None; 3];
        let want = inverse_products::<3, Pecg>(&gi, &gj, &go, &w, &none);
        let paths = [
            ("ECG-GVR's own", gvr_products::<3>(&gi, &gj, &go, &w, &none)),
            ("generic, ECG-GVR", products_by_damping::<3, EcgGvr>(&gi, &gj, &go, &w, &none)),
            ("generic, floating", products_by_damping::<3, Fecg>(&fi, &fj, &ops, &w, &none)),
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
        let (fi, fj) = (FecgFunction::new(ai, Centres::<3>::zeros(), 1.0, 0).unwrap(), FecgFunction::new(aj, Centres::<3>::zeros(), 1.0, 1).unwrap());
        for w in [Vector::<3>::new(1.0, 0.0, -1.0), Vector::<3>::new(0.0, 1.0, -1.0), heavy] {
            let want = coulomb_inv_r::<3, Pecg>(inverse_products::<3, Pecg>, &gi, &gj, &go, &[w]);
            let tol = 1e-12 + 1e-15 * tight;
            let got = coulomb_by_damping::<3, EcgGvr>(&gi, &gj, &go, &[w]);
            assert!(close(got, want, tol), "A + {tight} w wᵀ, w = {w:?}: ECG-GVR {got} vs {want}");
            let got = coulomb_inv_r::<3, EcgGvr>(gvr_products::<3>, &gi, &gj, &go, &[w]);
            assert!(close(got, want, tol), "A + {tight} w wᵀ, w = {w:?}: ECG-GVR's own {got} vs {want}");
            let got = coulomb_by_damping::<3, Fecg>(&fi, &fj, &ops, &[w]);
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
            let (fi, fj) = (FecgFunction::new(ai, fixtures::centres(0.3, spread), 0.7, 0).unwrap(), FecgFunction::new(aj, fixtures::centres(2.1, spread), 1.3, 1).unwrap());
            for w in pairs {
                let (got, want) = (coulomb_by_damping::<3, Fecg>(&fi, &fj, &ops, &[w]), coulomb_by_quadrature::<3, Fecg>(&fi, &fj, &ops, &w, 40));
                assert!(close(got, want, 1e-10), "floating, CM {cm}, spread {spread}, w = {w:?}: {got} vs {want}");
            }
        }
        for (ki, kj, n_ang) in [(1, 0, 0), (2, 1, 1), (1, 3, 2)] {
            let go = GvrOps::new(ops.clone(), n_ang, 3).unwrap();
            let gi = GvrFunction::new(ai, Vector::<3>::new(0.3, 1.0, -0.4), ki, 0.7, &go, 0).unwrap();
            let gj = GvrFunction::new(aj, Vector::<3>::new(-0.7, 0.2, 0.9), kj, 1.3, &go, 1).unwrap();
            for w in pairs {
                let want = coulomb_by_quadrature::<3, EcgGvr>(&gi, &gj, &go, &w, 40);
                for got in [coulomb_by_damping::<3, EcgGvr>(&gi, &gj, &go, &[w]), coulomb_inv_r::<3, EcgGvr>(gvr_products::<3>, &gi, &gj, &go, &[w])] {
                    assert!(close(got, want, 1e-10), "K = ({ki}, {kj}), N = {n_ang}, CM {cm}, w = {w:?}: {got} vs {want}");
                }
            }
        }
    }
}

/// ECG-GVR's own eqs. (38) and (30) (`ecg_gvr::drachmann::inverse_products`: rank-one updates of one factorisation;
/// `ecg_gvr::drachmann::gradient_inv_r`: one element per node for both damped functions) against the generic ones
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
                let gi = GvrFunction::new(ai, heavy + Vector::<3>::new(0.0, 0.0, 0.1), ki, 1.0, &go, 0).unwrap();
                let gj = GvrFunction::new(aj, heavy * 0.8, kj, 1.0, &go, 1).unwrap();
                for w in [Vector::<3>::new(1.0, 0.0, -1.0), Vector::<3>::new(0.0, 1.0, -1.0), heavy] {
                    let label = format!("K = ({ki}, {kj}), N = {n_ang}, CM {cm}, A + {tight} w wᵀ, w = {w:?}");
                    let binv = (ai + aj).try_inverse().unwrap();
                    let ww = w * w.transpose();
                    let damped = damped_inverse(&gi, &gj, &go, &w).unwrap();
                    let (got, want) = (gvr_products::<3>(&gi, &gj, &go, &w, &[None; 3]), products_by_damping::<3, EcgGvr>(&gi, &gj, &go, &w, &[None; 3]));
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
                        let mirror = gvr_products::<3>(&gi, &gj, &go, wp, &[None; 3])[c];
                        assert!(close(got[k], mirror, 1e-13 + 2.0 * promised), "<1/(r_w r_w')> damping w or w', {label}, w' = {wp:?}: {} vs {mirror}", got[k]);
                    }
                    let (got, want) = (ecg_gvr::drachmann::gradient_inv_r::<3>(&gi, &gj, &go, &[w]), gradient_inv_r::<3, EcgGvr>(&gi, &gj, &go, &[w]));
                    assert!(close(got, want, 1e-12 + 1e-14 * tight), "gradient: K = ({ki}, {kj}), N = {n_ang}, CM {cm}, A + {tight} w wᵀ, w = {w:?}: {got} vs {want}");
                }
            }
        }
    }
}

/// Every instance at once (`all`, each product of two pairs computed once) against each
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
    let (fi, fj) = (FecgFunction::new(ai, fixtures::centres(0.3, 1.5), 0.7, 0).unwrap(), FecgFunction::new(aj, fixtures::centres(2.1, 1.5), 1.3, 1).unwrap());
    check(&|v| all::<3, Fecg>(&fi, &fj, &ops, v), &|v| coulomb_inv_r::<3, Fecg>(products_by_damping::<3, Fecg>, &fi, &fj, &ops, v), "floating");
    let go = GvrOps::new(ops.clone(), 1, 3).unwrap();
    let gi = GvrFunction::new(ai, Vector::<3>::new(0.3, 1.0, -0.4), 2, 0.7, &go, 0).unwrap();
    let gj = GvrFunction::new(aj, Vector::<3>::new(-0.7, 0.2, 0.9), 3, 1.3, &go, 1).unwrap();
    check(&|v| all_of::<3, EcgGvr>(gvr_products::<3>, &gi, &gj, &go, v), &|v| coulomb_inv_r::<3, EcgGvr>(gvr_products::<3>, &gi, &gj, &go, v), "global vector");
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
        assert!(lookup::<3, Pecg>("pecg", "pecg", name).is_ok() && lookup::<3, EcgGvr>("ecg-gvr", "ecg-gvr", name).is_ok() && lookup::<3, Fecg>("fecg", "fecg", name).is_ok());
    }
}
