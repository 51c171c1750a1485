//! The hand-derived floating-ECG row gradient against the dual-number path
//! (`path::row_gradient`) and central differences: D = 2, 3, 4, symmetry images, `cm_mass`
//! `Some`/`None`, centres with different CM positions, Coulomb arguments from the series
//! branch (`|m|` tiny) to `erf = 1`.
use super::*;
use crate::ecg::Vector;
use crate::families::fecg::{kernel, Fecg};
use crate::families::Family;
use crate::params::Exponents;
use crate::path;
use crate::test_support::Rng;

/// Flat parameters of `k` floating ECGs: `A = L Lᵀ + 0.2 I`, centres `base + jitter · random`
/// (`base`: particle `i` at `(i - (D-1)/2) spread` along a random axis, the same for every function, so
/// that `|m| = |wᵀr̄|` is about `spread`, or `jitter` when `spread = 0`), `c_A`.
struct Set {
    a: Vec<f64>,
    c_a: Vec<f64>,
    s: Vec<f64>,
}

impl Set {
    fn new<const D: usize>(rng: &mut Rng, k: usize, spread: f64, jitter: f64) -> Self {
        let axis = [rng.signed(), rng.signed(), 0.5 + rng.next()];
        let (mut a, mut c_a, mut s) = (Vec::new(), Vec::new(), Vec::new());
        for _ in 0..k {
            let l = Mat::<D>::from_fn(|i, j| if j <= i { rng.signed() } else { 0.0 });
            a.extend((l * l.transpose() + Mat::<D>::identity() * 0.2).transpose().iter());
            c_a.push(0.3 + 2.0 * rng.next());
            for i in 0..D {
                s.extend((0..3).map(|x| (i as f64 - (D - 1) as f64 / 2.0) * spread * axis[x] + jitter * rng.signed()));
            }
        }
        Self { a, c_a, s }
    }

    fn params(&self) -> FecgParams<'_> {
        FecgParams { e: Exponents { a: &self.a, c_a: &self.c_a }, s: &self.s }
    }

    fn function<const D: usize>(&self, i: usize) -> FecgFunction<D> {
        <Fecg as Family<D>>::functions(&self.params(), &ops_none::<D>()).unwrap().remove(i)
    }
}

fn ops_none<const D: usize>() -> Operators<D> {
    Operators { lambda: Mat::identity(), pairs: vec![], cm_mass: None }
}

/// Laboratory frame: `Λ = diag(1/(2m))`, pairs `e_i - e_j`, the CM eliminated; otherwise a
/// dense `Λ`, random `w` and no CM part.
fn operators<const D: usize>(rng: &mut Rng, lab: bool) -> Operators<D> {
    if lab {
        let masses: Vec<f64> = (0..D).map(|_| 1.0 + 3000.0 * rng.next()).collect();
        let mut pairs = Vec::new();
        for i in 0..D {
            for j in i + 1..D {
                let w = Vector::<D>::from_fn(|k, _| (k == i) as u8 as f64 - (k == j) as u8 as f64);
                pairs.push((w, if rng.next() < 0.5 { -1.0 } else { 2.0 }));
            }
        }
        let lambda = Mat::from_fn(|i, j| if i == j { 0.5 / masses[i] } else { 0.0 });
        Operators { lambda, pairs, cm_mass: Some(masses.iter().sum()) }
    } else {
        let b = Mat::<D>::from_fn(|_, _| rng.signed());
        let pairs = (0..3).map(|_| (Vector::<D>::from_fn(|_, _| rng.signed()), rng.signed())).collect();
        Operators { lambda: b * b.transpose() * 0.1 + Mat::identity() * 0.01, pairs, cm_mass: None }
    }
}

/// The identity and the exchange of coordinates 0 and 1, `(1 ± P_01)/2`.
fn symmetry<const D: usize>(sign: f64) -> Vec<(Mat<D>, f64)> {
    let mut p = Mat::<D>::identity();
    p.swap_rows(0, 1);
    vec![(Mat::identity(), 0.5), (p, 0.5 * sign)]
}

/// `count` directions of unit norm: `dA` symmetric (`D x D`), `ds` (`D x 3`), flat.
fn directions<const D: usize>(rng: &mut Rng, count: usize) -> (Vec<f64>, Vec<f64>) {
    let (mut da, mut ds) = (Vec::new(), Vec::new());
    for _ in 0..count {
        let x = Mat::<D>::from_fn(|_, _| rng.signed());
        let a = x + x.transpose();
        let s = Centres::<D>::from_fn(|_, _| rng.signed());
        let norm = (a.norm_squared() + s.norm_squared()).sqrt();
        da.extend((a / norm).transpose().iter());
        ds.extend((s / norm).transpose().iter());
    }
    (da, ds)
}

fn column(m: &Matrices, k: usize, j: usize) -> [f64; 4] {
    let i = k * m.cols + j;
    [m.s[i], m.t[i], m.t_ti[i], m.v[i]]
}

/// The scale of symmetrised element `(I, J)` and, for unit directions, of its derivatives:
/// `Σ_P |c_P| √(X_II X_JJ)` with the un-symmetrised diagonals (`V` with charges `|q|`, `T_TI`
/// with the scale of `T`).
fn scale<const D: usize>(fi: &FecgFunction<D>, fj: &FecgFunction<D>, ops: &Operators<D>, sym: &[(Mat<D>, f64)]) -> [f64; 4] {
    let abs = Operators { pairs: ops.pairs.iter().map(|(w, q)| (*w, q.abs())).collect(), ..ops.clone() };
    let (ei, ej) = (kernel::element(fi, fi, &abs), kernel::element(fj, fj, &abs));
    let c: f64 = sym.iter().map(|(_, c)| c.abs()).sum();
    let g = |x: f64, y: f64| c * (x * y).abs().sqrt();
    [g(ei.s, ej.s), g(ei.t, ej.t), g(ei.t, ej.t), g(ei.v, ej.v)]
}

/// The largest `|hand - reference| / scale` over values (row 0) and derivatives (rows 1..).
fn deviation<const D: usize>(
    set: &Set,
    ops: &Operators<D>,
    sym: &[(Mat<D>, f64)],
    hand: &Matrices,
    reference: &Matrices,
) -> (f64, f64) {
    let (mut values, mut derivatives) = (0.0f64, 0.0f64);
    let fi = set.function::<D>(0);
    for j in 0..hand.cols {
        let sc = scale(&fi, &set.function::<D>(j + 1), ops, sym);
        for k in 0..hand.rows {
            let (h, r) = (column(hand, k, j), column(reference, k, j));
            for x in 0..4 {
                let d = (h[x] - r[x]).abs() / sc[x];
                assert!(d.is_finite(), "element {j}, row {k}, output {x}: {} vs {}", h[x], r[x]);
                if k == 0 { values = values.max(d) } else { derivatives = derivatives.max(d) }
            }
        }
    }
    (values, derivatives)
}

/// `(min, max)` of `t = m²/c` over the Coulomb pairs of the trial against every image of the basis.
fn coulomb_range<const D: usize>(set: &Set, ops: &Operators<D>, sym: &[(Mat<D>, f64)]) -> (f64, f64) {
    let b = path::images::<D, Fecg>(ops, sym, &set.params()).unwrap();
    let fi = set.function::<D>(0);
    let mut range = (f64::INFINITY, 0.0f64);
    for ket in b.images.iter().skip(1).flatten() {
        let (_, binv, rbar) = kernel::pair(&fi, ket).unwrap();
        for (w, _) in &ops.pairs {
            let (_, c, m) = coulomb_moments(w, &binv, &rbar);
            range = (range.0.min(m.norm_squared() / c), range.1.max(m.norm_squared() / c));
        }
    }
    range
}

/// Hand against dual numbers over lab/internal operators, both symmetries and four centre
/// configurations; returns the Coulomb `t` range covered.
fn against_dual<const D: usize>(n_dir: usize) -> (f64, f64) {
    let mut rng = Rng(0x5851_f42d_4c95_7f2d ^ D as u64);
    let mut covered = (f64::INFINITY, 0.0f64);
    for lab in [true, false] {
        let ops = operators::<D>(&mut rng, lab);
        for (spread, jitter) in [(0.0, 1e-5), (0.0, 0.05), (1.0, 0.4), (9.0, 0.3)] {
            for sign in [1.0, -1.0] {
                let sym = symmetry::<D>(sign);
                let set = Set::new::<D>(&mut rng, 7, spread, jitter);
                let (da, ds) = directions::<D>(&mut rng, n_dir);
                let p = set.params();
                let trial = FecgParams { e: Exponents { a: &p.e.a[..D * D], c_a: &p.e.c_a[..1] }, s: &p.s[..3 * D] };
                let basis = FecgParams { e: Exponents { a: &p.e.a[D * D..], c_a: &p.e.c_a[1..] }, s: &p.s[3 * D..] };
                let dir = Directions { a: &da, v: &ds };
                let (hand, hand_diag) = <Fecg as Family<D>>::row_gradient(&ops, &sym, &trial, &dir, &basis, &Cache::default()).unwrap();
                let (dual, dual_diag) = path::row_gradient::<D, Fecg>(&ops, &sym, &trial, &dir, &basis, &Cache::default()).unwrap();
                assert_eq!((hand.rows, hand.cols), (1 + n_dir, 6));
                assert_eq!(hand_diag, dual_diag);
                let (values, derivatives) = deviation(&set, &ops, &sym, &hand, &dual);
                let case = format!("D = {D}, lab {lab}, spread {spread}, jitter {jitter}, sign {sign}");
                assert!(values <= 1e-13, "{case}: values {values:e}");
                assert!(derivatives <= 1e-12, "{case}: derivatives {derivatives:e}");
                // the values are those of `rows` with the trial as bra (at position 0), bit for bit
                let (rows, _) = <Fecg as Family<D>>::rows(&ops, &sym, &trial, &basis, Some(0), &Cache::default()).unwrap();
                assert_eq!(rows.s.iter().chain(&rows.v).chain(&rows.t_ti).map(|x| x.to_bits()).collect::<Vec<_>>(),
                    hand.s[..6].iter().chain(&hand.v[..6]).chain(&hand.t_ti[..6]).map(|x| x.to_bits()).collect::<Vec<_>>());
                let r = coulomb_range(&set, &ops, &sym);
                covered = (covered.0.min(r.0), covered.1.max(r.1));
            }
        }
    }
    covered
}

#[test]
fn agrees_with_dual_numbers_in_every_branch() {
    let ranges = [against_dual::<2>(5), against_dual::<3>(9), against_dual::<4>(15)];
    for (lo, hi) in ranges {
        // the small-argument series (t < 1e-6) and erf = 1 (z = √t > 6) are both exercised
        assert!(lo < 1e-6 && hi > 36.0, "t in [{lo:e}, {hi:e}]");
    }
}

#[test]
fn agrees_with_central_differences() {
    const D: usize = 3;
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    let ops = operators::<D>(&mut rng, true);
    let sym = symmetry::<D>(1.0);
    let set = Set::new::<D>(&mut rng, 5, 1.0, 0.4);
    let (da, ds) = directions::<D>(&mut rng, 4);
    let p = set.params();
    let basis = FecgParams { e: Exponents { a: &p.e.a[D * D..], c_a: &p.e.c_a[1..] }, s: &p.s[3 * D..] };
    let trial = |h: f64, k: usize| -> Matrices {
        let a: Vec<f64> = (0..D * D).map(|i| p.e.a[i] + h * da[k * D * D + i]).collect();
        let s: Vec<f64> = (0..3 * D).map(|i| p.s[i] + h * ds[k * 3 * D + i]).collect();
        let t = FecgParams { e: Exponents { a: &a, c_a: &p.e.c_a[..1] }, s: &s };
        <Fecg as Family<D>>::rows(&ops, &sym, &t, &basis, Some(0), &Cache::default()).unwrap().0
    };
    let t0 = FecgParams { e: Exponents { a: &p.e.a[..D * D], c_a: &p.e.c_a[..1] }, s: &p.s[..3 * D] };
    let (hand, _) = <Fecg as Family<D>>::row_gradient(&ops, &sym, &t0, &Directions { a: &da, v: &ds }, &basis, &Cache::default()).unwrap();
    let h = 1e-5;
    let fi = set.function::<D>(0);
    for k in 0..4 {
        let (plus, minus) = (trial(h, k), trial(-h, k));
        for j in 0..4 {
            let sc = scale(&fi, &set.function::<D>(j + 1), &ops, &sym);
            let (x, y, d) = (column(&plus, 0, j), column(&minus, 0, j), column(&hand, 1 + k, j));
            for o in 0..4 {
                let fd = (x[o] - y[o]) / (2.0 * h);
                assert!((fd - d[o]).abs() < 1e-8 * sc[o], "direction {k}, element {j}, output {o}: {fd} vs {}", d[o]);
            }
        }
    }
}

#[test]
fn coulomb_partials_match_40_digit_references() {
    // (t, f, ∂f/∂(m²), ∂f/∂c) at c = 0.7, m² = t c: mpmath (40 digits) of erf(√(m²/c))/√m²,
    // its derivative by mp.diff, and -exp(-t)/(√π c^{3/2}); one t per branch of `erf` and `F_1`
    let c = 0.7;
    let references = [
        (1e-7, 1.348_671_017_733_770_1, -0.642_224_277_032_957_15, -0.963_336_377_015_979_54),
        (0.05, 1.326_526_404_215_343_3, -0.623_297_220_178_164_21, -0.916_353_999_144_908_41),
        (0.3, 1.225_123_186_807_305_5, -0.538_102_594_906_595_53, -0.713_657_212_104_668_14),
        (3.9, 0.602_065_446_715_050_5, -0.105_268_455_401_936_14, -0.019_499_771_586_056_549),
        (10.0, 0.377_961_545_970_545, -0.026_992_879_742_787_586, -4.373_540_822_771_270_1e-5),
        (36.1, 0.198_928_670_004_856_43, -0.003_936_063_909_870_521_3, -2.021_841_967_242_053_9e-16),
    ];
    for (t, f, f_m2, f_c) in references {
        let got = coulomb_partials(t * c, c);
        for (x, want) in [(got.0, f), (got.1, f_m2), (got.2, f_c)] {
            // a few roundings, and e^{-t} of a rounded t (condition number t)
            assert!((x - want).abs() < 2e-16 * (4.0 + t) * want.abs(), "t = {t}: {x:e} vs {want:e}");
        }
    }
    // the series of F_1 joins the recursion (which is good to ~1e-14 at t = 0.01..0.1)
    for t in [0.01, 0.05, 0.0999] {
        let series = F1_SERIES.iter().rev().fold(0.0, |acc, a| acc * t + a);
        let f0 = kernel::coulomb_factor(t, 1.0) * PI.sqrt() / 2.0;
        let recursion = (f0 - (-t as f64).exp()) / (2.0 * t);
        assert!((series - recursion).abs() < 1e-13 * series, "t = {t}: {series} vs {recursion}");
    }
}
