//! `p_g² = −Δ_g`, `p_g⁴` and `p_g² p_h²`, products of the momenta `p_g = −i Σ_k g_k ∇_k` of
//! D-vectors `g`, `h`, with `<φ_I| p_g² p_h² |φ_J> = <Δ_g φ_I|Δ_h φ_J>` (docs/properties-derivations.md,
//! eq. 20). In the laboratory frame `g = e_i − μ_i 1` (`μ_i = m_i/m_tot`) gives particle i's
//! momentum in the centre-of-mass frame, the `p_i` of the mass–velocity term (§5). `g` transforms
//! like `∇`, not like `r`: in coordinates `x = U_x r` it is `U_x g`. The generic elements are
//! those of a Gaussian about centres (plain and floating ECGs; `gaussian`, eq. 25'); ECG-GVR has
//! its own (`families/ecg_gvr/operators.rs`: the overlap's generating function, eq. 26b, its
//! `p_g²` the kinetic element with `Λ = g g^T`), given to `p4_of` and `p2p2_of`.
use crate::ecg::Vector;
use crate::families::Family;

pub const P2: &str = "p2";
pub const P4: &str = "p4";
pub const P2P2: &str = "p2p2";

/// `(<φ_I| p_h² |φ_J>, <p_g² φ_I| p_h² φ_J>)` of normalised functions of family `F`, for
/// `p_g = −i Σ_k g_k ∇_k` with D-vectors `g` and `h` (docs/properties-derivations.md §5): at
/// `h = g` the elements of `p_g²` and `p_g⁴`.
pub type Momentum<const D: usize, F> = fn(
    &<F as Family<D>>::Function<f64>,
    &<F as Family<D>>::Function<f64>,
    &<F as Family<D>>::Context,
    &Vector<D>,
    &Vector<D>,
) -> (f64, f64);

/// `<φ_I| p_g² |φ_J>` for normalised functions ((ħ/bohr)²; `gaussian`).
pub fn p2<const D: usize, F: Family<D>>(bra: &F::Function<f64>, ket: &F::Function<f64>, ctx: &F::Context, g: &Vector<D>) -> f64 {
    gaussian::<D, F>(bra, ket, ctx, g, g).0
}

/// `<φ_I| p_g⁴ |φ_J>` for normalised functions ((ħ/bohr)⁴) from the momentum elements `m`.
pub fn p4_of<const D: usize, F: Family<D>>(m: Momentum<D, F>, bra: &F::Function<f64>, ket: &F::Function<f64>, ctx: &F::Context, g: &Vector<D>) -> f64 {
    m(bra, ket, ctx, g, g).1
}

/// `<φ_I| (p_g² p_h² + p_h² p_g²)/2 |φ_J>` for normalised functions, `v = [g, h]` ((ħ/bohr)⁴;
/// symmetric in I ↔ J as in g ↔ h) from the momentum elements `m`: for two particles' momenta, a
/// term of the regularised `<p_i⁴>` (docs/properties-derivations.md §6).
pub fn p2p2_of<const D: usize, F: Family<D>>(m: Momentum<D, F>, bra: &F::Function<f64>, ket: &F::Function<f64>, ctx: &F::Context, v: &[Vector<D>]) -> f64 {
    let (g, h) = (&v[0], &v[1]);
    0.5 * (m(bra, ket, ctx, g, h).1 + m(bra, ket, ctx, h, g).1)
}

/// `p4_of` a Gaussian about centres (`gaussian`).
pub fn p4<const D: usize, F: Family<D>>(bra: &F::Function<f64>, ket: &F::Function<f64>, ctx: &F::Context, g: &Vector<D>) -> f64 {
    p4_of::<D, F>(gaussian::<D, F>, bra, ket, ctx, g)
}

/// `p2p2_of` a Gaussian about centres (`gaussian`).
pub fn p2p2<const D: usize, F: Family<D>>(bra: &F::Function<f64>, ket: &F::Function<f64>, ctx: &F::Context, v: &[Vector<D>]) -> f64 {
    p2p2_of::<D, F>(gaussian::<D, F>, bra, ket, ctx, v)
}

/// `(<φ_I| p_h² |φ_J>, <p_g² φ_I| p_h² φ_J>)` of a Gaussian about centres (plain and
/// floating ECGs): with `Δ_gφ_I = (4|a|² − 6α) φ_I`, `a = (A_I g)ᵀ(r − s_I)`, `α = gᵀA_Ig`, and likewise
/// `b`, `β` of `h` and `φ_J`, Gaussian moments under `φ_Iφ_J` (means ā, b̄ at r̄; per-component
/// variances σ_a, σ_b and covariance σ_ab with `C = (A_I + A_J)⁻¹/2`) give
///
/// ```text
///     <Δ_gφ_I|Δ_hφ_J> = S [(4|ā|² + 6(2σ_a − α)) (4|b̄|² + 6(2σ_b − β)) + 96 σ_ab² + 64 σ_ab ā·b̄],   (25')
/// ```
///
/// `<φ_I|Δ_hφ_J> = S (4|b̄|² + 6(2σ_b − β))`; at g = h eqs. (22), (23) and (25).
pub fn gaussian<const D: usize, F: Family<D>>(
    bra: &F::Function<f64>,
    ket: &F::Function<f64>,
    ctx: &F::Context,
    g: &Vector<D>,
    h: &Vector<D>,
) -> (f64, f64) {
    let (ai, aj) = (F::exponent(bra), F::exponent(ket));
    let Some(chol) = (ai + aj).cholesky() else { return (f64::NAN, f64::NAN) };
    let (si, sj) = (F::centres(bra), F::centres(ket));
    let rbar = chol.solve(&(ai * si + aj * sj));
    let (ag, ah) = (ai * g, aj * h);
    let (a_bar, b_bar) = (ag.transpose() * (rbar - si), ah.transpose() * (rbar - sj));
    let (bg, bh) = (chol.solve(&ag), chol.solve(&ah));
    let (s_a, s_b, s_ab) = (0.5 * ag.dot(&bg), 0.5 * ah.dot(&bh), 0.5 * ag.dot(&bh));
    let k_a = 4.0 * a_bar.norm_squared() + 6.0 * (2.0 * s_a - g.dot(&ag));
    let k_b = 4.0 * b_bar.norm_squared() + 6.0 * (2.0 * s_b - h.dot(&ah));
    let s = F::overlap(bra, ket, ctx);
    (-k_b * s, (k_a * k_b + 96.0 * s_ab * s_ab + 64.0 * s_ab * a_bar.dot(&b_bar)) * s)
}

#[cfg(test)]
mod tests {
    //! `p_g²` against each family's own kinetic element with `Λ = g g^T`; `p_g⁴` (and `p_g²`)
    //! against `∫ Δ_gφ_I Δ_gφ_J` by quadrature, with `Δ_g` the second derivatives of the
    //! functions themselves in dual numbers; the Gaussian ratio 5/3; floating ECGs at `s = 0`
    //! equal to plain ECGs; `Σ_i p_{g_i}²/(2 m_i)` with `g_i = e_i − μ_i 1` equal to the family's
    //! `T_TI` (plain, floating and ECG-GVR functions); ECG-GVR's generating-function elements at
    //! K = N = 0 equal to plain ECGs', and for K, N > 0 against the same quadrature (complex
    //! `(v_x + i v_y)^N`) and its `p_g²` against its kinetic element.
    use nalgebra::SMatrix;
    use num_dual::{Dual2_64, DualNum};

    use super::*;
    use crate::ecg::{Mat, Operators};
    use crate::families::fecg::kernel::{Centres, FecgFunction};
    use crate::families::fecg::Fecg;
    use crate::families::ecg_gvr::element::{GvrFunction, GvrOps};
    use crate::families::ecg_gvr::{momentum, EcgGvr};
    use crate::families::pecg::Pecg;
    use crate::operators::fixtures::{centres, close, exponent, gauss_hermite, plain, D};
    use crate::families::ecg_gvr;
    use crate::operators::Specialised;
    use crate::registry::{lookup, names};

    /// The element of operator `name` the registry gives the family `F` (its own, else the
    /// generic one) at the vectors `v`.
    fn registered<const N: usize, F: Specialised<N>>(name: &str, bra: &F::Function<f64>, ket: &F::Function<f64>, ctx: &F::Context, v: &[Vector<N>]) -> f64 {
        lookup::<N, F>(F::NAME, F::NAME, name).unwrap().1.of(bra, ket, ctx, &[v.to_vec()])[0]
    }

    /// Kinetic `Λ = g g^T`, no Coulomb pairs.
    fn squared<const N: usize>(g: &Vector<N>) -> Operators<N> {
        Operators { lambda: g * g.transpose(), pairs: vec![], cm_mass: None }
    }

    /// `g = e_1 − μ_1 1` of the masses (1836.15, 1, 1), and a vector without structure.
    fn vectors() -> [Vector<D>; 2] {
        let mu = Vector::<D>::new(1836.15267343, 1.0, 1.0) / 1838.15267343;
        [Vector::<D>::new(1.0, 0.0, 0.0) - Vector::<D>::repeat(mu[0]), Vector::<D>::new(0.3, -1.1, 0.6)]
    }

    const SEEDS: [(f64, f64); 3] = [(0.1, 0.9), (1.3, 2.2), (0.4, 0.4)];

    #[test]
    fn p2_is_the_kinetic_element_with_lambda_g_g() {
        let mut worst: f64 = 0.0;
        for g in vectors() {
            let go = GvrOps::new(squared(&g), 0, 0).unwrap();
            for (si, sj) in SEEDS {
                let (gi, gj) = (plain(exponent(si), 1.0, &go, 0), plain(exponent(sj), 1.0, &go, 1));
                let got = p2::<D, Pecg>(&gi, &gj, &go, &g);
                let want = <Pecg as Family<D>>::element(&gi, &gj, &go).t;
                assert!(close(got, want, 1e-12), "plain: {got} vs {want}");
                worst = worst.max((got / want - 1.0).abs());
                for spread in [0.3, 1.5] {
                    let fi = FecgFunction::new(exponent(si), centres(0.3, spread), 1.0, 0).unwrap();
                    let fj = FecgFunction::new(exponent(sj), centres(2.1, spread), 1.0, 1).unwrap();
                    let ops = squared(&g);
                    let got = p2::<D, Fecg>(&fi, &fj, &ops, &g);
                    let want = <Fecg as Family<D>>::element(&fi, &fj, &ops).t;
                    assert!(close(got, want, 1e-12), "floating, spread {spread}: {got} vs {want}");
                    worst = worst.max((got / want - 1.0).abs());
                }
            }
        }
        eprintln!("p2 against T(Λ = g gᵀ): largest relative deviation {worst:.1e}");
    }

    /// `φ(r)` and `Δ_gφ(r) = Σ_c ∂²/∂t² φ(r + t g e_c^T)` of `φ = exp(−tr((r − s)^T A (r − s)))`,
    /// the second derivative by dual numbers.
    fn laplacian(a: &Mat<2>, s: &Centres<2>, r: &Centres<2>, g: &Vector<2>) -> (f64, f64) {
        let along = |c: usize| {
            let dt = |k: usize, l: usize| if l == c { g[k] } else { 0.0 };
            let d = SMatrix::<Dual2_64, 2, 3>::from_fn(|k, l| Dual2_64::new(r[(k, l)] - s[(k, l)], dt(k, l), 0.0));
            let mut e = Dual2_64::from_re(0.0);
            for l in 0..3 {
                for k in 0..2 {
                    for m in 0..2 {
                        e += d[(k, l)] * d[(m, l)] * a[(k, m)];
                    }
                }
            }
            (-e).exp()
        };
        (along(0).re, (0..3).map(|c| along(c).v2).sum())
    }

    /// `(∫ φ_I*φ_J, −∫ φ_I* Δ_gφ_J, ∫ (Δ_gφ_I)* Δ_gφ_J)` in two coordinates, over the common factor
    /// `|A_I + A_J|^{−3/2}`, of the functions' `[[Re φ, Im φ], [Re Δ_gφ, Im Δ_gφ]]` at r (`values`):
    /// the M-point Gauss–Hermite product rule in `y = L^T (r − r̄)`, `L L^T = A_I + A_J`,
    /// `r̄ = (A_I + A_J)^{-1}(A_I s_I + A_J s_J)`, exact for the Gaussian `φ_Iφ_J` times polynomials
    /// of degree ≤ 2M − 1 in `r`.
    fn quadrature<const M: usize>(
        ai: &Mat<2>,
        si: &Centres<2>,
        aj: &Mat<2>,
        sj: &Centres<2>,
        values: &dyn Fn(&Centres<2>) -> ([[f64; 2]; 2], [[f64; 2]; 2]),
    ) -> [f64; 3] {
        let b = ai + aj;
        let rbar = b.try_inverse().unwrap() * (ai * si + aj * sj);
        let back = b.cholesky().unwrap().l().transpose().try_inverse().unwrap(); // r = r̄ + L^{-T} y
        let rule = gauss_hermite::<M>();
        let dot = |p: [f64; 2], q: [f64; 2]| p[0] * q[0] + p[1] * q[1]; // Re(p* q)
        let mut sums = [0.0; 3];
        for index in 0..M.pow(6) {
            let (mut y, mut weight) = (Centres::<2>::zeros(), 1.0);
            for e in 0..6 {
                let (node, w) = rule[index / M.pow(e as u32) % M];
                y[(e % 2, e / 2)] = node;
                weight *= w;
            }
            let r = rbar + back * y;
            let weight = weight * y.norm_squared().exp();
            let ([fi, lap_i], [fj, lap_j]) = values(&r);
            for (sum, term) in sums.iter_mut().zip([dot(fi, fj), -dot(fi, lap_j), dot(lap_i, lap_j)]) {
                *sum += weight * term;
            }
        }
        sums
    }

    /// `laplacian` as `quadrature` reads it (real functions).
    fn real(a: &Mat<2>, s: &Centres<2>, r: &Centres<2>, g: &Vector<2>) -> [[f64; 2]; 2] {
        let (f, lap) = laplacian(a, s, r, g);
        [[f, 0.0], [lap, 0.0]]
    }

    #[test]
    fn p2_and_p4_match_quadrature_of_the_laplacians() {
        let g = Vector::<2>::new(0.8, -0.35);
        let sub = |seed: f64| exponent::<2>(seed);
        let go = GvrOps::new(squared(&g), 0, 0).unwrap();
        let mut worst: f64 = 0.0;
        for (si, sj) in SEEDS {
            let (ai, aj) = (sub(si), sub(sj));
            let zero = Centres::<2>::zeros();
            let (gi, gj) = (plain(ai, 1.0, &go, 0), plain(aj, 1.0, &go, 1));
            let s = <Pecg as Family<2>>::overlap(&gi, &gj, &go);
            let got = [p2::<2, Pecg>(&gi, &gj, &go, &g), p4::<2, Pecg>(&gi, &gj, &go, &g)];
            let q = quadrature::<4>(&ai, &zero, &aj, &zero, &|r| (real(&ai, &zero, r, &g), real(&aj, &zero, r, &g)));
            for k in 0..2 {
                let want = q[k + 1] / q[0] * s;
                assert!(close(got[k], want, 1e-12), "plain, p{}: {} vs {want}", 2 * k + 2, got[k]);
                worst = worst.max((got[k] / want - 1.0).abs());
            }
            for spread in [0.3, 1.5] {
                let (ci, cj) = (centres::<2>(0.3, spread), centres::<2>(2.1, spread));
                let ops = squared(&g);
                let (fi, fj) = (FecgFunction::new(ai, ci, 1.0, 0).unwrap(), FecgFunction::new(aj, cj, 1.0, 1).unwrap());
                let s = <Fecg as Family<2>>::overlap(&fi, &fj, &ops);
                let got = [p2::<2, Fecg>(&fi, &fj, &ops, &g), p4::<2, Fecg>(&fi, &fj, &ops, &g)];
                let q = quadrature::<4>(&ai, &ci, &aj, &cj, &|r| (real(&ai, &ci, r, &g), real(&aj, &cj, r, &g)));
                for k in 0..2 {
                    let want = q[k + 1] / q[0] * s;
                    assert!(close(got[k], want, 1e-12), "floating, spread {spread}, p{}: {} vs {want}", 2 * k + 2, got[k]);
                    worst = worst.max((got[k] / want - 1.0).abs());
                }
            }
        }
        eprintln!("p2, p4 against quadrature: largest relative deviation {worst:.1e}");
    }

    #[test]
    fn a_gaussian_has_p4_over_p2_squared_five_thirds() {
        let mut worst: f64 = 0.0;
        for g in vectors() {
            let go = GvrOps::new(squared(&g), 0, 0).unwrap();
            for seed in [0.1, 1.3, 2.2] {
                let f = plain(exponent(seed), 1.0, &go, 0);
                let s = <Pecg as Family<D>>::overlap(&f, &f, &go);
                let ratio = p4::<D, Pecg>(&f, &f, &go, &g) * s / p2::<D, Pecg>(&f, &f, &go, &g).powi(2);
                assert!(close(ratio, 5.0 / 3.0, 1e-14), "{ratio}");
                worst = worst.max((ratio * 0.6 - 1.0).abs());
            }
        }
        eprintln!("p4 S/p2² against 5/3: largest relative deviation {worst:.1e}");
    }

    #[test]
    fn floating_ecgs_at_zero_centres_are_plain_ecgs() {
        let mut worst: f64 = 0.0;
        for g in vectors() {
            let (ops, go) = (squared(&g), GvrOps::new(squared(&g), 0, 0).unwrap());
            for (si, sj) in SEEDS {
                let (gi, gj) = (plain(exponent(si), 1.0, &go, 0), plain(exponent(sj), 1.0, &go, 1));
                let fi = FecgFunction::new(exponent(si), Centres::<D>::zeros(), 1.0, 0).unwrap();
                let fj = FecgFunction::new(exponent(sj), Centres::<D>::zeros(), 1.0, 1).unwrap();
                let want = [p2::<D, Pecg>(&gi, &gj, &go, &g), p4::<D, Pecg>(&gi, &gj, &go, &g)];
                let got = [p2::<D, Fecg>(&fi, &fj, &ops, &g), p4::<D, Fecg>(&fi, &fj, &ops, &g)];
                assert!(close(got[0], want[0], 1e-13) && close(got[1], want[1], 1e-13), "{got:?} vs {want:?}");
                worst = worst.max((got[0] / want[0] - 1.0).abs()).max((got[1] / want[1] - 1.0).abs());
            }
        }
        eprintln!("floating ECGs at s = 0 against plain ECGs: largest relative deviation {worst:.1e}");
    }

    #[test]
    fn the_momenta_in_the_centre_of_mass_frame_sum_to_the_translation_free_kinetic_energy() {
        // Σ_i (p_i − μ_i P)²/(2 m_i) = T − P²/(2 m_tot) (§5) for CM-separable functions, A 1 = c_A μ:
        // A = Π A_0 Π^T + c_A μ μ^T with Π = 1 − μ 1^T (Π^T 1 = 0)
        let m = Vector::<D>::new(1836.15267343, 1.0, 1.0);
        let (m_tot, mu) = (m.sum(), m / m.sum());
        let pi = Mat::<D>::identity() - mu * Vector::<D>::repeat(1.0).transpose();
        let separable = |seed: f64, c_a: f64| pi * exponent(seed) * pi.transpose() + mu * mu.transpose() * c_a;
        let lambda = Mat::<D>::from_diagonal(&m.map(|x| 0.5 / x));
        let ops = Operators { lambda, pairs: vec![], cm_mass: Some(m_tot) };
        let go = GvrOps::new(ops.clone(), 0, 0).unwrap();
        let g = |i: usize| Vector::<D>::ith(i, 1.0) - Vector::<D>::repeat(mu[i]);
        let mut worst: f64 = 0.0;
        for ((si, sj), (ci, cj)) in SEEDS.into_iter().zip([(0.7, 1.3), (0.7, 0.7), (2.0, 0.4)]) {
            let (ai, aj) = (separable(si, ci), separable(sj, cj));
            let (gi, gj) = (plain(ai, ci, &go, 0), plain(aj, cj, &go, 1));
            let got = (0..D).map(|i| p2::<D, Pecg>(&gi, &gj, &go, &g(i)) / (2.0 * m[i])).sum::<f64>();
            let want = <Pecg as Family<D>>::element(&gi, &gj, &go).t_ti;
            assert!(close(got, want, 1e-12), "plain: {got} vs {want}");
            worst = worst.max((got / want - 1.0).abs());
            let fi = FecgFunction::new(ai, centres(0.3, 1.0), ci, 0).unwrap();
            let fj = FecgFunction::new(aj, centres(2.1, 1.0), cj, 1).unwrap();
            let got = (0..D).map(|i| p2::<D, Fecg>(&fi, &fj, &ops, &g(i)) / (2.0 * m[i])).sum::<f64>();
            let want = <Fecg as Family<D>>::element(&fi, &fj, &ops).t_ti;
            assert!(close(got, want, 1e-12), "floating: {got} vs {want}");
            worst = worst.max((got / want - 1.0).abs());
            // ECG-GVR (its kinetic element with Λ = g gᵀ), K = 2 and 3, N = 1, 1ᵀu = 0
            let gvr_ops = GvrOps::new(ops.clone(), 1, 3).unwrap();
            let (ui, uj) = (Vector::<D>::new(0.4, -1.0, 0.6), Vector::<D>::new(-0.9, 0.2, 0.7));
            let (gi, gj) = (GvrFunction::new(ai, ui, 2, ci, &gvr_ops, 0).unwrap(), GvrFunction::new(aj, uj, 3, cj, &gvr_ops, 1).unwrap());
            let got = (0..D).map(|i| registered::<D, EcgGvr>(P2, &gi, &gj, &gvr_ops, &[g(i)]) / (2.0 * m[i])).sum::<f64>();
            let want = <EcgGvr as Family<D>>::element(&gi, &gj, &gvr_ops).t_ti;
            assert!(close(got, want, 1e-12), "ECG-GVR: {got} vs {want}");
            worst = worst.max((got / want - 1.0).abs());
        }
        eprintln!("Σ_i p2(e_i − μ_i 1)/(2 m_i) against T_TI: largest relative deviation {worst:.1e}");
    }

    #[test]
    fn ecg_gvr_functions_at_k_and_n_zero_are_plain_ecgs() {
        let mut worst: f64 = 0.0;
        for g in vectors() {
            let go = GvrOps::new(squared(&g), 0, 0).unwrap();
            for (si, sj) in SEEDS {
                let (gi, gj) = (plain(exponent(si), 1.0, &go, 0), plain(exponent(sj), 1.0, &go, 1));
                let want = [p2::<D, Pecg>(&gi, &gj, &go, &g), p4::<D, Pecg>(&gi, &gj, &go, &g)];
                let (p2_h, p4_h) = momentum::momentum(&gi, &gj, &go, &g, &g);
                assert!(close(p2_h, want[0], 1e-13) && close(p4_h, want[1], 1e-13), "{:?} vs {want:?}", (p2_h, p4_h));
                worst = worst.max((p2_h / want[0] - 1.0).abs()).max((p4_h / want[1] - 1.0).abs());
            }
        }
        eprintln!("ECG-GVR at K = N = 0 against plain ECGs: largest relative deviation {worst:.1e}");
    }

    #[test]
    fn ecg_gvr_p2_by_the_generating_function_is_its_kinetic_element() {
        let mut worst: f64 = 0.0;
        for g in vectors() {
            for n in [0, 1, 2] {
                let go = GvrOps::new(squared(&g), n, 3).unwrap();
                for ((si, sj), (ki, kj)) in SEEDS.into_iter().zip([(0, 3), (2, 1), (3, 3)]) {
                    let (ui, uj) = (Vector::<D>::new(0.4, -1.0, 0.6), Vector::<D>::new(-0.9, 0.2, 0.7 + si));
                    let fi = GvrFunction::new(exponent(si), ui, ki, 1.0, &go, 0).unwrap();
                    let fj = GvrFunction::new(exponent(sj), uj, kj, 1.0, &go, 1).unwrap();
                    let want = registered::<D, EcgGvr>(P2, &fi, &fj, &go, &[g]);
                    let got = momentum::momentum(&fi, &fj, &go, &g, &g).0;
                    assert!(close(got, want, 1e-12), "N = {n}, K = ({ki}, {kj}): {got} vs {want}");
                    worst = worst.max((got / want - 1.0).abs());
                }
            }
        }
        eprintln!("ECG-GVR p2 (eq. 26b) against its kinetic element: largest relative deviation {worst:.1e}");
    }

    /// `(φ, Δ_gφ)` of `φ = |v|^{2K} (v_x + i v_y)^N exp(−tr(rᵀAr))`, `v = uᵀr`, each as (real,
    /// imaginary) parts, the second derivatives along `g e_c^T` by dual numbers.
    fn gvr_laplacian(a: &Mat<2>, u: &Vector<2>, k: u32, n: u32, r: &Centres<2>, g: &Vector<2>) -> [[f64; 2]; 2] {
        let along = |c: usize| {
            let at = |kk: usize, l: usize| Dual2_64::new(r[(kk, l)], if l == c { g[kk] } else { 0.0 }, 0.0);
            let (mut q, mut v) = (Dual2_64::from_re(0.0), [Dual2_64::from_re(0.0); 3]);
            for l in 0..3 {
                for kk in 0..2 {
                    v[l] += at(kk, l) * u[kk];
                    for m in 0..2 {
                        q += at(kk, l) * at(m, l) * a[(kk, m)];
                    }
                }
            }
            let radial = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).powi(k as i32) * (-q).exp();
            let (mut re, mut im) = (radial, Dual2_64::from_re(0.0));
            for _ in 0..n {
                (re, im) = (re * v[0] - im * v[1], re * v[1] + im * v[0]);
            }
            [re, im]
        };
        let sides = [0, 1, 2].map(along);
        [[sides[0][0].re, sides[0][1].re], [0, 1].map(|p| sides.iter().map(|side| side[p].v2).sum())]
    }

    #[test]
    fn ecg_gvr_p2_and_p4_match_quadrature_of_the_laplacians() {
        let g = Vector::<2>::new(0.8, -0.35);
        let go = |n: u32| GvrOps::new(squared(&g), n, 2).unwrap();
        let (ui, uj) = (Vector::<2>::new(0.7, -0.4), Vector::<2>::new(0.3, 0.9));
        let mut worst: f64 = 0.0;
        // 6 Gauss–Hermite nodes a side are exact to degree 11 ≥ (2K_I + N + 2) + (2K_J + N + 2)
        for ((si, sj), (ki, kj, n)) in SEEDS.into_iter().zip([(1, 0, 1), (2, 1, 0), (0, 1, 2)]) {
            let (ai, aj) = (exponent::<2>(si), exponent::<2>(sj));
            let ctx = go(n);
            let (fi, fj) = (GvrFunction::new(ai, ui, ki, 1.0, &ctx, 0).unwrap(), GvrFunction::new(aj, uj, kj, 1.0, &ctx, 1).unwrap());
            let s = <EcgGvr as Family<2>>::overlap(&fi, &fj, &ctx);
            let got = momentum::momentum(&fi, &fj, &ctx, &g, &g);
            let zero = Centres::<2>::zeros();
            let q = quadrature::<6>(&ai, &zero, &aj, &zero, &|r| (gvr_laplacian(&ai, &ui, ki, n, r, &g), gvr_laplacian(&aj, &uj, kj, n, r, &g)));
            for (k, got) in [got.0, got.1].into_iter().enumerate() {
                let want = q[k + 1] / q[0] * s;
                assert!(close(got, want, 1e-11), "K = ({ki}, {kj}), N = {n}, p{}: {got} vs {want}", 2 * k + 2);
                worst = worst.max((got / want - 1.0).abs());
            }
        }
        eprintln!("ECG-GVR p2, p4 against quadrature: largest relative deviation {worst:.1e}");
    }

    #[test]
    fn products_of_two_momenta_match_quadrature() {
        // (<φ_I|p_h²|φ_J>, <p_g²φ_I|p_h²φ_J>) with g ≠ h, every family, against the quadrature of
        // Δ_gφ_I and Δ_hφ_J (6 nodes a side for ECG-GVR: degree 5 + 5); and p2p2, their symmetrised
        // mean, symmetric in I ↔ J and g ↔ h
        let (g, h) = (Vector::<2>::new(0.8, -0.35), Vector::<2>::new(-0.3, 0.6));
        let (ops, go) = (squared(&g), GvrOps::new(squared(&g), 1, 2).unwrap());
        let zero = Centres::<2>::zeros();
        let mut worst: f64 = 0.0;
        let mut check = |family: &str, got: (f64, f64), s: f64, q: [f64; 3]| {
            for (got, want) in [(got.0, q[1] / q[0] * s), (got.1, q[2] / q[0] * s)] {
                assert!(close(got, want, 1e-11), "{family}: {got} vs {want}");
                worst = worst.max((got / want - 1.0).abs());
            }
        };
        for (si, sj) in SEEDS {
            let (ai, aj) = (exponent::<2>(si), exponent::<2>(sj));
            let (gi, gj) = (plain(ai, 1.0, &go, 0), plain(aj, 1.0, &go, 1));
            let q = quadrature::<4>(&ai, &zero, &aj, &zero, &|r| (real(&ai, &zero, r, &g), real(&aj, &zero, r, &h)));
            let s = <Pecg as Family<2>>::overlap(&gi, &gj, &go);
            check("plain", gaussian::<2, Pecg>(&gi, &gj, &go, &g, &h), s, q);
            let (ci, cj) = (centres::<2>(0.3, 1.5), centres::<2>(2.1, 1.5));
            let (fi, fj) = (FecgFunction::new(ai, ci, 1.0, 0).unwrap(), FecgFunction::new(aj, cj, 1.0, 1).unwrap());
            let q = quadrature::<4>(&ai, &ci, &aj, &cj, &|r| (real(&ai, &ci, r, &g), real(&aj, &cj, r, &h)));
            let s = <Fecg as Family<2>>::overlap(&fi, &fj, &ops);
            check("floating", gaussian::<2, Fecg>(&fi, &fj, &ops, &g, &h), s, q);
            let (ui, uj) = (Vector::<2>::new(0.7, -0.4), Vector::<2>::new(0.3, 0.9));
            let (vi, vj) = (GvrFunction::new(ai, ui, 1, 1.0, &go, 0).unwrap(), GvrFunction::new(aj, uj, 1, 1.0, &go, 1).unwrap());
            let q = quadrature::<6>(&ai, &zero, &aj, &zero, &|r| (gvr_laplacian(&ai, &ui, 1, 1, r, &g), gvr_laplacian(&aj, &uj, 1, 1, r, &h)));
            let s = <EcgGvr as Family<2>>::overlap(&vi, &vj, &go);
            check("ECG-GVR", ecg_gvr::momentum::momentum::<2>(&vi, &vj, &go, &g, &h), s, q);
            for (bra, ket) in [(&gi, &gj), (&vi, &vj)] {
                let x = [(bra, ket, [g, h]), (ket, bra, [g, h]), (bra, ket, [h, g])].map(|(b, k, v)| registered::<2, EcgGvr>(P2P2, b, k, &go, &v));
                assert!(close(x[1], x[0], 1e-13) && close(x[2], x[0], 1e-13), "{x:?}");
            }
        }
        eprintln!("<p_h²>, <p_g² p_h²> (g ≠ h) against quadrature: largest relative deviation {worst:.1e}");
    }

    #[test]
    fn every_family_evaluates_p2_p4_and_p2p2() {
        assert!(names().contains(&P2) && names().contains(&P4) && names().contains(&P2P2));
        for name in [P2, P4, P2P2] {
            assert!(lookup::<D, Pecg>("pecg", "pecg", name).is_ok() && lookup::<D, Fecg>("fecg", "fecg", name).is_ok());
            assert!(lookup::<D, EcgGvr>("ecg-gvr", "ecg-gvr", name).is_ok());
        }
        assert!(lookup::<D, Pecg>("pecg", "pecg", P2P2).is_ok_and(|(arity, _)| arity == 2));
    }
}
