//! The orbit–orbit operator of the Breit–Pauli Hamiltonian, `O = p_g · M(r_w) · p_h` with
//! `M_ab = (δ_ab + r̂_a r̂_b)/r`, `r = r_w`, `p_g = −i Σ_k g_k ∇_k` (docs/properties-derivations.md
//! §10). With `v = [w, g_i, g_j]`, `w = e_i − e_j` and `g_k = e_k − μ_k 1` it is the pair term
//! `p_i · M(r_ij) · p_j` in the centre-of-mass frame; `H_OO = −(α²/2) Σ_{i<j} q_i q_j/(m_i m_j) <O_ij>`.
//! Since `M` is divergence-free, `<φ_I|O|φ_J> = ∫ (∇_g φ_I)·M·(∇_h φ_J)` is symmetric in I ↔ J
//! and in g ↔ h.
//!
//! From `M_ab = (2/√π) ∫_0^∞ (δ_ab + 2t² y_a y_b) e^{−t² y²} dt` (eq. 34) the element is a
//! Gaussian expectation under the damped product `φ_I φ_J e^{−αy²}` (mean and covariance as in
//! eq. 28), `(2S/√(πq)) ∫_0^1 e^{−λτ²} P(τ²) dτ` with `P` a quartic in `u` (eq. 35), so a sum
//! of five Boys functions (eq. 36); plain ECGs `16 τ S/√(πq)` (eq. 37).
//!
//! This is the element of the families whose gradients are a Gaussian times a linear polynomial,
//! plain and floating ECGs (one formula; a plain ECG has no centres), and ECG-GVR's own
//! default. ECG-GVR gradients carry the derivatives of `|v|^{2K}(v_x + i v_y)^N`: their element
//! is the overlap's generating function's (`momentum::orbit`, eq. 26c).
use std::f64::consts::PI;

use super::drachmann::gradient::boys;
use crate::ecg::Vector;
use crate::families::Family;

pub const NAME: &str = "orbit_orbit";

/// `<φ_I| p_g · M(r_w) · p_h |φ_J>` for normalised functions, `v = [w, g, h]` (ħ²/bohr³).
pub fn element<const D: usize, F: Family<D>>(bra: &F::Function<f64>, ket: &F::Function<f64>, ctx: &F::Context, v: &[Vector<D>]) -> f64 {
    let (w, g, h) = (&v[0], &v[1], &v[2]);
    let (ai, aj) = (F::exponent(bra), F::exponent(ket));
    let Some(chol) = (ai + aj).cholesky() else { return f64::NAN };
    let (si, sj) = (F::centres(bra), F::centres(ket));
    let rbar = chol.solve(&(ai * si + aj * sj));
    let b = chol.solve(w);
    let q = w.dot(&b);
    // the gradient factors ∇_g φ_I = −2 ξ φ_I, ∇_h φ_J = −2 η φ_J: ξ = (A_I g)^T (r − s_I),
    // η = (A_J h)^T (r − s_J); their means, covariances with y = w^T r, and y's mean m (eq. 35)
    let (ag, ah) = (ai * g, aj * h);
    let tau = ag.dot(&chol.solve(&ah));
    let (beta_i, beta_j) = (ag.dot(&b), ah.dot(&b));
    let xi = ag.transpose() * (rbar - si);
    let eta = ah.transpose() * (rbar - sj);
    let m = w.transpose() * rbar;
    let n = m.norm_squared();
    let (xi_m, eta_m, bb) = (xi.dot(&m), eta.dot(&m), beta_i * beta_j);
    // P(u) = 4(1 + u) H(u) + (8/q) u(1 − u) K(u), H and K quadratics in u (eq. 35)
    let hq = [1.5 * tau + xi.dot(&eta), -(1.5 * bb + beta_j * xi_m + beta_i * eta_m) / q, bb * n / (q * q)];
    let (li, lj) = ([xi_m + 2.0 * beta_i, -beta_i * n / q], [eta_m + 2.0 * beta_j, -beta_j * n / q]);
    let kq = [li[0] * lj[0] - bb + 0.5 * n * tau, li[0] * lj[1] + li[1] * lj[0] - 0.5 * n * bb / q, li[1] * lj[1]];
    let c = 8.0 / q;
    let p = [
        4.0 * hq[0],
        4.0 * (hq[0] + hq[1]) + c * kq[0],
        4.0 * (hq[1] + hq[2]) + c * (kq[1] - kq[0]),
        4.0 * hq[2] + c * (kq[2] - kq[1]),
        -c * kq[2],
    ];
    let lambda = n / q;
    let integral: f64 = p.iter().enumerate().map(|(j, pj)| pj * boys(j, lambda)).sum();
    2.0 * F::overlap(bra, ket, ctx) / (PI * q).sqrt() * integral
}

#[cfg(test)]
mod tests {
    //! Against an evaluation that uses neither the Gaussian moments nor eq. (35): eq. (34)'s
    //! t-integral by a Gauss–Legendre rule in `τ`, each damped integral
    //! `∫ ∇_gφ_I*·(1 + 2α y yᵀ)·∇_hφ_J e^{−αy²}` by a Gauss–Hermite product rule about the damped
    //! Gaussian (3 nodes, exact for that Gaussian times a quartic; 5 for ECG-GVR's polynomials),
    //! the gradients of the functions themselves in dual numbers; two particles and three
    //! (laboratory frame, CM-separable exponents `A 1 = c_A μ`), plain and floating ECGs, and
    //! ECG-GVR with K, N > 0 for two. Symmetric in I ↔ J and g ↔ h; floating ECGs at zero centres
    //! and ECG-GVR at K = N = 0 equal plain ECGs.
    use nalgebra::{Const, SMatrix, SVector, U1};
    use num_dual::{Derivative, DualNum, DualSVec64};

    use super::*;
    use crate::ecg::{Mat, Operators};
    use crate::families::ecg_gvr::element::{GvrFunction, GvrOps};
    use crate::quadrature::even_rule;
    use crate::families::fecg::kernel::{Centres, FecgFunction};
    use crate::families::fecg::Fecg;
    use crate::families::ecg_gvr::{self, EcgGvr};
    use crate::families::pecg::Pecg;
    use crate::operators::fixtures::{centres, close, exponent, gauss_hermite, plain, separable};

    /// A function's value and `∇_g φ` (a 3-vector) at r, each as (real, imaginary) parts.
    type Value = ([f64; 2], [[f64; 2]; 3]);

    /// `φ(r) = P(uᵀr) exp(−Σ_c (r − s)_c^T A (r − s)_c)` and `∇_g φ`: the derivatives in `t_c` of
    /// `φ` at `r` moved by `t_c g` along the Cartesian axes `c`, in dual numbers; `P = 1` without
    /// `gvr`, else `P(v) = |v|^{2K} (v_x + i v_y)^N` for `gvr = (u, K, N)`.
    fn gradient<const N: usize>(a: &Mat<N>, s: &Centres<N>, gvr: Option<(&Vector<N>, u32, u32)>, r: &Centres<N>, g: &Vector<N>) -> Value {
        type T = DualSVec64<3>;
        let d = SMatrix::<T, N, 3>::from_fn(|k, c| T::new(r[(k, c)] - s[(k, c)], Derivative::some(SVector::<f64, 3>::ith(c, g[k]))));
        let mut e = T::from_re(0.0);
        for c in 0..3 {
            for k in 0..N {
                for l in 0..N {
                    e += d[(k, c)] * d[(l, c)] * a[(k, l)];
                }
            }
        }
        let (mut re, mut im) = ((-e).exp(), T::from_re(0.0));
        if let Some((u, k, n)) = gvr {
            let v: [T; 3] = std::array::from_fn(|c| (0..N).fold(T::from_re(0.0), |acc, l| acc + d[(l, c)] * u[l]));
            re *= (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).powi(k as i32);
            for _ in 0..n {
                (re, im) = (re * v[0] - im * v[1], re * v[1] + im * v[0]);
            }
        }
        let (dre, dim) = (re.eps.unwrap_generic(Const::<3>, U1), im.eps.unwrap_generic(Const::<3>, U1));
        ([re.re, im.re], std::array::from_fn(|c| [dre[c], dim[c]]))
    }

    /// `Re(p* q)` of complex numbers as (real, imaginary) parts.
    fn dot(p: [f64; 2], q: [f64; 2]) -> f64 {
        p[0] * q[0] + p[1] * q[1]
    }

    /// `∫ f(r) φ_I* φ_J e^{−α r_w²} dr` (unnormalised functions) by the M-point Gauss–Hermite product
    /// rule in `y = L^T (r − r̄_α)`, `L L^T = B + α w w^T`, `f` given `r`, `φ_I* φ_J e^{−αy²}` and `y`.
    fn damped<const N: usize, const M: usize>(
        (ai, si, aj, sj): (&Mat<N>, &Centres<N>, &Mat<N>, &Centres<N>),
        w: &Vector<N>,
        alpha: f64,
        f: impl Fn(&Centres<N>, [f64; 3]) -> f64,
    ) -> f64 {
        let b = ai + aj + w * w.transpose() * alpha;
        let rbar = b.try_inverse().unwrap() * (ai * si + aj * sj);
        let chol = b.cholesky().unwrap();
        let back = chol.l().transpose().try_inverse().unwrap();
        let rule = gauss_hermite::<M>().map(|(node, weight)| (node, weight / std::f64::consts::PI.sqrt()));
        let mut sum = 0.0;
        for index in 0..M.pow(3 * N as u32) {
            let (mut y, mut weight) = (Centres::<N>::zeros(), 1.0);
            for e in 0..3 * N {
                let (node, wt) = rule[index / M.pow(e as u32) % M];
                y[(e % N, e / N)] = node;
                weight *= wt;
            }
            let r = rbar + back * y;
            let yw = w.transpose() * r;
            sum += weight * y.norm_squared().exp() * f(&r, [yw[0], yw[1], yw[2]]);
        }
        sum * std::f64::consts::PI.powf(1.5 * N as f64) / chol.l().diagonal().product().powi(3)
    }

    /// One side of `quadrature`: a function's exponent, centres and polynomial (`gradient`).
    type Side<'a, const N: usize> = (&'a Mat<N>, &'a Centres<N>, Option<(&'a Vector<N>, u32, u32)>);

    /// `<φ_I| p_g·M(r_w)·p_h |φ_J> / S_IJ` by eq. (34) with `t² = α = τ²/(q(1 − τ²))`:
    /// `(2/√(πq)) ∫_0^1 (1 − τ²)^{−3/2} E(α) dτ` on `m` positive Gauss–Legendre nodes, each damped
    /// integral by the M-point product rule; with `dyad = 0` its `δ_ab/r` part alone,
    /// `<∇_gφ_I| 1/r_w |∇_hφ_J> / S_IJ`.
    fn quadrature<const N: usize, const M: usize>(fi: Side<N>, fj: Side<N>, v: &[Vector<N>; 3], m: usize, dyad: f64) -> f64 {
        let [w, g, h] = v;
        let pair = (fi.0, fi.1, fj.0, fj.1);
        let q = w.dot(&((fi.0 + fj.0).try_inverse().unwrap() * w));
        let integrand = |alpha: f64| {
            move |r: &Centres<N>, y: [f64; 3]| {
                let (di, dj) = (gradient(fi.0, fi.1, fi.2, r, g).1, gradient(fj.0, fj.1, fj.2, r, h).1);
                let along = |d: [[f64; 2]; 3]| std::array::from_fn::<f64, 2, _>(|p| (0..3).map(|c| d[c][p] * y[c]).sum());
                let dd = (0..3).map(|c| dot(di[c], dj[c])).sum::<f64>();
                let y2 = y.iter().map(|x| x * x).sum::<f64>();
                (dd + dyad * 2.0 * alpha * dot(along(di), along(dj))) * (-alpha * y2).exp()
            }
        };
        let overlap = damped::<N, M>(pair, w, 0.0, |r, _| dot(gradient(fi.0, fi.1, fi.2, r, g).0, gradient(fj.0, fj.1, fj.2, r, h).0));
        let t_integral: f64 = even_rule(m)
            .iter()
            .map(|&(tau, wt)| {
                let alpha = tau * tau / (q * (1.0 - tau * tau));
                wt * damped::<N, M>(pair, w, alpha, integrand(alpha)) / (1.0 - tau * tau).powf(1.5)
            })
            .sum();
        2.0 / (std::f64::consts::PI * q).sqrt() * t_integral / overlap
    }

    /// `[w, g_i, g_j]` of the pair (i, j): `w = e_i − e_j`, `g_k = e_k − μ_k 1`.
    fn vectors<const N: usize>(mu: &Vector<N>, i: usize, j: usize) -> [Vector<N>; 3] {
        let e = |k: usize| Vector::<N>::from_fn(|l, _| (l == k) as i32 as f64);
        [e(i) - e(j), e(i) - Vector::<N>::repeat(mu[i]), e(j) - Vector::<N>::repeat(mu[j])]
    }

    /// The element of plain and floating ECGs against `quadrature` for the pairs of N particles of
    /// `masses`; CM-separable exponents (`A 1 = c_A μ`) when `cm`. The largest relative deviation.
    fn check<const N: usize>(masses: [f64; N], pairs: &[(usize, usize)], cm: bool, seeds: &[(f64, f64)], spreads: &[f64]) -> f64 {
        let mu = Vector::<N>::from_row_slice(&masses) / masses.iter().sum::<f64>();
        let a = |seed: f64, c_a: f64| {
            let a0 = exponent::<N>(seed);
            if cm { separable(&a0, &mu, c_a) } else { a0 }
        };
        let ops = Operators { lambda: Mat::<N>::identity() * 0.5, pairs: vec![], cm_mass: None };
        let go = GvrOps::new(ops.clone(), 0, 0).unwrap();
        let mut worst: f64 = 0.0;
        for &(si, sj) in seeds {
            let (ai, aj) = (a(si, 0.7), a(sj, 1.3));
            // the pairs' vectors, and momentum vectors without structure (for two particles
            // h = −g, where ξ̄ = η̄ hides terms of eq. 35)
            let free = |x: f64| Vector::<N>::from_fn(|k, _| (0.7 * k as f64 + x).cos());
            let sets = pairs.iter().map(|&(i, j)| vectors(&mu, i, j)).chain([[vectors(&mu, 0, 1)[0], free(0.3), free(2.0)]]);
            for (set, v) in sets.enumerate() {
                let zero = Centres::<N>::zeros();
                let got = element::<N, Pecg>(&plain(ai, 0.7, &go, 0), &plain(aj, 1.3, &go, 1), &go, &v);
                let s = <Pecg as Family<N>>::overlap(&plain(ai, 0.7, &go, 0), &plain(aj, 1.3, &go, 1), &go);
                let want = quadrature::<N, 3>((&ai, &zero, None), (&aj, &zero, None), &v, 5, 1.0) * s;
                assert!(close(got, want, 1e-12), "N = {N}, plain, vectors {set}: {got} vs {want}");
                worst = worst.max((got / want - 1.0).abs());
                for &spread in spreads {
                    let (ci, cj) = (centres::<N>(0.3, spread), centres::<N>(2.1, spread));
                    let (fi, fj) = (FecgFunction::new(ai, ci, 0.7, 0).unwrap(), FecgFunction::new(aj, cj, 1.3, 1).unwrap());
                    let got = element::<N, Fecg>(&fi, &fj, &ops, &v);
                    let want = quadrature::<N, 3>((&ai, &ci, None), (&aj, &cj, None), &v, 12, 1.0) * <Fecg as Family<N>>::overlap(&fi, &fj, &ops);
                    assert!(close(got, want, 1e-11), "N = {N}, floating, spread {spread}, vectors {set}: {got} vs {want}");
                    worst = worst.max((got / want - 1.0).abs());
                }
            }
        }
        worst
    }

    const SEEDS: [(f64, f64); 2] = [(0.1, 0.9), (1.3, 2.2)];

    #[test]
    fn two_particles_match_quadrature() {
        let worst = check([1836.15267343, 1.0], &[(0, 1)], false, &SEEDS, &[0.3, 1.5]);
        eprintln!("orbit-orbit, 2 particles, against quadrature: largest relative deviation {worst:.1e}");
    }

    #[test]
    fn three_particles_match_quadrature() {
        let worst = check([7294.29954142, 1.0, 1.0], &[(0, 1)], true, &SEEDS[1..], &[1.5]);
        eprintln!("orbit-orbit, 3 particles (A 1 = c_A μ), against quadrature: largest relative deviation {worst:.1e}");
    }

    /// Three particles' functions of both families (exponents without structure, centres spread 1)
    /// and the vectors of the pair (0, 2).
    fn three() -> (GvrOps<3>, [GvrFunction<3>; 2], Operators<3>, [FecgFunction<3>; 2], [Vector<3>; 3]) {
        let ops = Operators { lambda: Mat::<3>::identity() * 0.5, pairs: vec![], cm_mass: None };
        let go = GvrOps::new(ops.clone(), 0, 0).unwrap();
        let (ai, aj) = (exponent(0.4), exponent(1.9));
        let g = [plain(ai, 1.0, &go, 0), plain(aj, 1.0, &go, 1)];
        let f = [FecgFunction::new(ai, centres(0.3, 1.0), 1.0, 0).unwrap(), FecgFunction::new(aj, centres(2.1, 1.0), 1.0, 1).unwrap()];
        let mu = Vector::<3>::new(1836.15267343, 1.0, 1.0) / 1838.15267343;
        (go, g, ops, f, vectors(&mu, 0, 2))
    }

    #[test]
    fn symmetric_in_bra_and_ket_and_in_the_momenta() {
        let (go, [gi, gj], ops, [fi, fj], [w, g, h]) = three();
        let mut worst: f64 = 0.0;
        for v in [[w, g, h], [w, g * 0.3 - h, h * 1.7 + g]] {
            let swapped = [v[0], v[2], v[1]];
            let plain = [element::<3, Pecg>(&gi, &gj, &go, &v), element::<3, Pecg>(&gj, &gi, &go, &v), element::<3, Pecg>(&gi, &gj, &go, &swapped)];
            let floating = [element::<3, Fecg>(&fi, &fj, &ops, &v), element::<3, Fecg>(&fj, &fi, &ops, &v), element::<3, Fecg>(&fi, &fj, &ops, &swapped)];
            for x in [plain, floating] {
                assert!(close(x[1], x[0], 1e-13) && close(x[2], x[0], 1e-13), "{x:?}");
                worst = worst.max((x[1] / x[0] - 1.0).abs()).max((x[2] / x[0] - 1.0).abs());
            }
        }
        eprintln!("orbit-orbit, I <-> J and g <-> h: largest relative deviation {worst:.1e}");
    }

    #[test]
    fn floating_ecgs_at_zero_centres_are_plain_ecgs_and_those_the_closed_form() {
        let (go, [gi, gj], ops, _, v) = three();
        let [w, g, h] = v;
        let zero = |f: &GvrFunction<3>| FecgFunction::new(f.a, Centres::<3>::zeros(), 1.0, 0).unwrap();
        let got = element::<3, Fecg>(&zero(&gi), &zero(&gj), &ops, &v);
        let want = element::<3, Pecg>(&gi, &gj, &go, &v);
        assert!(close(got, want, 1e-14), "{got} vs {want}");
        // eq. (37): 16 τ S/√(πq)
        let binv = (gi.a + gj.a).try_inverse().unwrap();
        let (tau, q) = ((gi.a * g).dot(&(binv * gj.a * h)), w.dot(&(binv * w)));
        let closed = 16.0 * tau * <Pecg as Family<3>>::overlap(&gi, &gj, &go) / (std::f64::consts::PI * q).sqrt();
        assert!(close(want, closed, 1e-14), "{want} vs eq. (37) {closed}");
        eprintln!("orbit-orbit, floating at s = 0 against plain: {:.1e}; plain against eq. (37): {:.1e}", (got / want - 1.0).abs(), (want / closed - 1.0).abs());
    }

    /// ECG-GVR functions (`momentum::orbit`, eq. 26c) of (K_I, K_J, N) and global vectors
    /// varied by `x`, in N_C coordinates.
    fn gvr_pair<const NC: usize>(a: [Mat<NC>; 2], (ki, kj, n): (u32, u32, u32), x: f64) -> (GvrOps<NC>, [GvrFunction<NC>; 2]) {
        let go = GvrOps::new(Operators { lambda: Mat::<NC>::identity() * 0.5, pairs: vec![], cm_mass: None }, n, 3).unwrap();
        let u = |y: f64| Vector::<NC>::from_fn(|k, _| (1.3 * k as f64 + y).sin());
        (go.clone(), [GvrFunction::new(a[0], u(x), ki, 1.0, &go, 0).unwrap(), GvrFunction::new(a[1], u(x + 2.0), kj, 1.0, &go, 1).unwrap()])
    }

    #[test]
    fn ecg_gvr_functions_match_quadrature() {
        // two coordinates, exponents and vectors without structure; 5 Gauss–Hermite nodes a side are
        // exact for the Gaussian times (2K_I + N + 1) + (2K_J + N + 1) + 2 ≤ 9 powers of r, and 4
        // τ-nodes for the τ-integrand of degree ≤ 2(K_I + K_J + N + 2) in τ
        let v = [Vector::<2>::new(1.0, -1.0), Vector::<2>::new(0.8, -0.35), Vector::<2>::new(-0.2, 0.9)];
        let mut worst: f64 = 0.0;
        for (case, powers) in [(1, 0, 1), (1, 1, 0), (0, 0, 2), (0, 0, 0)].into_iter().enumerate() {
            let a = [exponent::<2>(0.3 + case as f64), exponent::<2>(1.7 + case as f64)];
            let (go, [fi, fj]) = gvr_pair(a, powers, 0.4 * case as f64);
            let got = ecg_gvr::momentum::orbit::<2>(&fi, &fj, &go, &v);
            let zero = Centres::<2>::zeros();
            let (si, sj) = ((&fi.u, fi.k, go.n_ang), (&fj.u, fj.k, go.n_ang));
            let want = quadrature::<2, 5>((&fi.a, &zero, Some(si)), (&fj.a, &zero, Some(sj)), &v, 4, 1.0)
                * <EcgGvr as Family<2>>::overlap(&fi, &fj, &go);
            assert!(close(got, want, 1e-11), "(K_I, K_J, N) = {powers:?}: {got} vs {want}");
            worst = worst.max((got / want - 1.0).abs());
        }
        eprintln!("orbit-orbit, ECG-GVR against quadrature: largest relative deviation {worst:.1e}");
    }

    #[test]
    fn ecg_gvr_functions_are_symmetric_and_at_k_n_zero_plain_ecgs() {
        let (go, [gi, gj], _, _, v) = three();
        let [w, g, h] = v;
        let (gvr_go, [fi, fj]) = gvr_pair([gi.a, gj.a], (0, 0, 0), 0.0);
        let (got, want) = (ecg_gvr::momentum::orbit::<3>(&fi, &fj, &gvr_go, &v), element::<3, Pecg>(&gi, &gj, &go, &v));
        assert!(close(got, want, 1e-13), "K = N = 0: {got} vs {want}");
        let mut worst = (got / want - 1.0).abs();
        let (gvr_go, [fi, fj]) = gvr_pair([gi.a, gj.a], (2, 1, 1), 0.7);
        for v in [[w, g, h], [w, g * 0.3 - h, h * 1.7 + g]] {
            let x = [(&fi, &fj, v), (&fj, &fi, v), (&fi, &fj, [v[0], v[2], v[1]])]
                .map(|(bra, ket, v)| ecg_gvr::momentum::orbit::<3>(bra, ket, &gvr_go, &v));
            assert!(close(x[1], x[0], 1e-12) && close(x[2], x[0], 1e-12), "{x:?}");
            worst = worst.max((x[1] / x[0] - 1.0).abs()).max((x[2] / x[0] - 1.0).abs());
        }
        eprintln!("orbit-orbit, ECG-GVR at K = N = 0 against plain, and I <-> J, g <-> h: largest relative deviation {worst:.1e}");
    }

    #[test]
    fn a_gaussian_in_the_relative_coordinate_has_the_textbook_value() {
        // φ = exp(−a r_12² − c_A R²) of an electron and a proton: ∇_{g_1} = −∇_{g_2} = ∇_r on it
        // and r̂·M·r̂ = 2/r, so <p_1·M·p_2> = −4a² <r·M·r> = −8a² <r> = −8a √(2a/π)
        let mu = Vector::<2>::new(1836.15267343, 1.0) / 1837.15267343;
        let (a, c_a) = (0.37, 1.1);
        let w = Vector::<2>::new(1.0, -1.0);
        let go = GvrOps::new(Operators { lambda: Mat::<2>::identity() * 0.5, pairs: vec![], cm_mass: None }, 0, 0).unwrap();
        let f = plain(w * w.transpose() * a + mu * mu.transpose() * c_a, c_a, &go, 0);
        let got = element::<2, Pecg>(&f, &f, &go, &vectors(&mu, 0, 1));
        let want = -8.0 * a * (2.0 * a / std::f64::consts::PI).sqrt();
        assert!(close(got, want, 1e-14), "{got} vs {want}");
        eprintln!("orbit-orbit of exp(−a r² − c_A R²) against −8a√(2a/π): {:.1e}", (got / want - 1.0).abs());
    }

    /// Drachmann's `<∇φ_I| Λ/r_w |∇φ_J>` (`drachmann::gradient::gradient_inv_r`) of floating ECGs, whose
    /// damped functions move their centres (`FecgFunction::damped`), against the `δ_ab/r` part of this
    /// quadrature with `Λ = g gᵀ`: centres 0.3 to 2.5 apart, three particles, CM-separable exponents.
    #[test]
    fn floating_gradient_inv_r_matches_quadrature() {
        const N: usize = 3;
        let mu = Vector::<N>::new(7294.29954142, 1.0, 1.0) / 7296.29954142;
        let mut worst: f64 = 0.0;
        for (seed, spread) in [(0.1, 0.3), (1.3, 1.5), (0.4, 2.5)] {
            let ai = separable(&exponent(seed), &mu, 0.7);
            let aj = separable(&exponent(seed + 0.8), &mu, 1.3);
            let (ci, cj) = (centres::<N>(0.3, spread), centres::<N>(2.1, spread));
            let (fi, fj) = (FecgFunction::new(ai, ci, 0.7, 0).unwrap(), FecgFunction::new(aj, cj, 1.3, 1).unwrap());
            let [w, g, _] = vectors(&mu, 0, 1);
            let ops = Operators { lambda: g * g.transpose(), pairs: vec![], cm_mass: None };
            let got = super::super::drachmann::gradient::gradient_inv_r::<N, Fecg>(&fi, &fj, &ops, &[w]);
            let want = quadrature::<N, 3>((&ai, &ci, None), (&aj, &cj, None), &[w, g, g], 12, 0.0) * <Fecg as Family<N>>::overlap(&fi, &fj, &ops);
            assert!(close(got, want, 1e-11), "spread {spread}: {got} vs {want}");
            worst = worst.max((got / want - 1.0).abs());
        }
        eprintln!("floating ECGs' <∇φ|Λ/r|∇φ> against quadrature: largest relative deviation {worst:.1e}");
    }
}
