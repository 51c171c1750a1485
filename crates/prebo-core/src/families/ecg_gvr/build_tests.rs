//! The f64 kernel against `element::element` (the generic path), the same bits on every instruction
//! set, and rows patched into matrices with the bits of a full build.
use super::*;
use crate::ecg::{Mat, Operators, Vector};
use crate::families::ecg_gvr::kernel;
use crate::families::ecg_gvr::EcgGvr;
use crate::families::Family;
use crate::params::Exponents;
use crate::isa::best_isa;
use crate::path;
use crate::test_support::Rng;

/// Flat parameters of `nb` random functions: `A = L Lᵀ + 0.05`, `u`, K in `0..=k_max`, `c_A`.
struct Basis {
    a: Vec<f64>,
    c_a: Vec<f64>,
    u: Vec<f64>,
    k: Vec<u32>,
}

impl Basis {
    fn random<const D: usize>(rng: &mut Rng, nb: usize, k_max: u32) -> Self {
        let mut b = Basis { a: vec![], c_a: vec![], u: vec![], k: vec![] };
        for _ in 0..nb {
            let l = Mat::<D>::from_fn(|r, c| if c <= r { rng.signed() } else { 0.0 });
            let a = l * l.transpose() + Mat::<D>::identity() * 0.05;
            b.a.extend(a.transpose().iter());
            b.u.extend((0..D).map(|_| rng.signed()));
            b.c_a.push(0.5 + rng.signed().abs());
            b.k.push(((rng.signed().abs() * (k_max + 1) as f64) as u32).min(k_max));
        }
        b
    }

    fn params(&self) -> GvrParams<'_> {
        GvrParams { e: Exponents { a: &self.a, c_a: &self.c_a }, u: &self.u, k: &self.k }
    }

    /// Function `i` alone, and the others.
    fn split<const D: usize>(&self, i: usize) -> (Basis, Basis) {
        let pick = |keep: &dyn Fn(usize) -> bool| Basis {
            a: (0..self.k.len()).filter(|&j| keep(j)).flat_map(|j| self.a[j * D * D..(j + 1) * D * D].to_vec()).collect(),
            c_a: (0..self.k.len()).filter(|&j| keep(j)).map(|j| self.c_a[j]).collect(),
            u: (0..self.k.len()).filter(|&j| keep(j)).flat_map(|j| self.u[j * D..(j + 1) * D].to_vec()).collect(),
            k: (0..self.k.len()).filter(|&j| keep(j)).map(|j| self.k[j]).collect(),
        };
        (pick(&|j| j == i), pick(&|j| j != i))
    }
}

/// Particle permutations of D particles with coefficients (all of them for D <= 3, the four of
/// (1 − P12)(1 + P34)-type for D = 4 with unequal weights), laboratory-frame operators.
fn system<const D: usize>(rng: &mut Rng, cm: bool) -> (Vec<(Mat<D>, f64)>, Operators<D>) {
    let perm = |p: &[usize]| Mat::<D>::from_fn(|i, j| if p[i] == j { 1.0 } else { 0.0 });
    let ident: Vec<usize> = (0..D).collect();
    let mut swap01 = ident.clone();
    swap01.swap(0, 1);
    let mut sym = vec![(perm(&ident), 1.0), (perm(&swap01), -0.7)];
    if D >= 4 {
        let mut swap23 = ident.clone();
        swap23.swap(2, 3);
        let mut both = swap01.clone();
        both.swap(2, 3);
        sym.push((perm(&swap23), 0.6));
        sym.push((perm(&both), -0.4));
    }
    let masses: Vec<f64> = (0..D).map(|i| if i < D / 2 { 1836.15 } else { 1.0 + 0.3 * rng.signed().abs() }).collect();
    let q: Vec<f64> = (0..D).map(|i| if i < D / 2 { 1.0 } else { -1.0 }).collect();
    let mut pairs = Vec::new();
    for i in 0..D {
        for j in (i + 1)..D {
            let mut w = Vector::<D>::zeros();
            w[i] = 1.0;
            w[j] = -1.0;
            pairs.push((w, q[i] * q[j]));
        }
    }
    let lambda = Mat::<D>::from_fn(|i, j| if i == j { 0.5 / masses[i] } else { 0.0 });
    (sym, Operators { lambda, pairs, cm_mass: cm.then(|| masses.iter().sum()) })
}

fn bits(m: &Matrices) -> Vec<u64> {
    [&m.s, &m.t, &m.t_ti, &m.v].iter().flat_map(|v| v.iter().map(|x| x.to_bits())).collect()
}

const ISAS: [Isa; 3] = [Isa::Plain, Isa::Avx2, Isa::Avx512];

/// Kernel matrices against the generic path's, element (i, j) to 1e-13 of the bound of its
/// terms: by Cauchy–Schwarz `|c_P <i|X|P j>| <= |c_P| sqrt(U_ii U_jj)` for the positive operators
/// S, T, T_ti with their unsymmetrised diagonals `U`, and for V (indefinite: attraction and
/// repulsion cancel in its diagonal) `Σ_pairs |q| <i|1/r|P j>` bounds it, the V of charges `|q|`.
fn against_generic<const D: usize>(seed: u64, nb: usize, k_max: u32, n: u32, cm: bool) {
    let mut rng = Rng(seed);
    let (sym, ops) = system::<D>(&mut rng, cm);
    let basis = Basis::random::<D>(&mut rng, nb, k_max);
    let go = <EcgGvr as Family<D>>::context(ops, n, &[&basis.params()]).unwrap();
    let reference = path::matrices::<D, EcgGvr>(&go, &sym, &basis.params()).unwrap();
    let ident = [(Mat::<D>::identity(), 1.0)];
    let u = path::matrices::<D, EcgGvr>(&go, &ident, &basis.params()).unwrap();
    let mut ops_abs = go.ops.clone();
    ops_abs.pairs.iter_mut().for_each(|(_, q)| *q = q.abs());
    let go_abs = <EcgGvr as Family<D>>::context(ops_abs, n, &[&basis.params()]).unwrap();
    let v_abs = path::matrices::<D, EcgGvr>(&go_abs, &ident, &basis.params()).unwrap();
    let c_sum: f64 = sym.iter().map(|(_, c)| c.abs()).sum();
    let fast = matrices(&go, &sym, &basis.params(), Isa::Plain).unwrap();
    let cases = [
        ("S", &fast.s, &reference.s, &u.s),
        ("T", &fast.t, &reference.t, &u.t),
        ("T_ti", &fast.t_ti, &reference.t_ti, &u.t_ti),
        ("V", &fast.v, &reference.v, &v_abs.v),
    ];
    for (name, x, r, u) in cases {
        for i in 0..nb {
            for j in 0..nb {
                let scale = c_sum * (u[i * nb + i] * u[j * nb + j]).abs().sqrt();
                let (a, b) = (x[i * nb + j], r[i * nb + j]);
                assert!(
                    (a - b).abs() <= 1e-13 * scale,
                    "D={D} N={n} cm={cm} {name}[{i},{j}] (K {}, {}): {a} vs {b} (scale {scale})",
                    basis.k[i],
                    basis.k[j]
                );
            }
        }
    }
}

#[test]
fn kernel_matches_the_generic_element() {
    for (seed, n, cm) in [(1, 0, true), (2, 1, false), (3, 2, true), (4, 0, false)] {
        against_generic::<2>(seed, 12, 40, n, cm);
        against_generic::<3>(seed + 10, 12, 40, n, cm);
        against_generic::<4>(seed + 20, 12, 40, n, cm);
        against_generic::<4>(seed + 30, 10, 3, n, cm);
    }
}

#[test]
fn instruction_sets_agree_bit_for_bit() {
    let mut rng = Rng(7);
    let (sym, ops) = system::<4>(&mut rng, true);
    let basis = Basis::random::<4>(&mut rng, 9, 25);
    let trials = Basis::random::<4>(&mut rng, 2, 25);
    let go = <EcgGvr as Family<4>>::context(ops, 1, &[&basis.params(), &trials.params()]).unwrap();
    let m0 = matrices(&go, &sym, &basis.params(), Isa::Plain).unwrap();
    let kept = Cache::default(); // the basis prepared once, then reused: the same bits
    for pos in [None, Some(0), Some(4)] {
        let (r0, d0) = rows(&go, &sym, &trials.params(), &basis.params(), pos, Isa::Plain, &Cache::default()).unwrap();
        for isa in ISAS {
            assert_eq!(bits(&matrices(&go, &sym, &basis.params(), isa).unwrap()), bits(&m0), "{isa:?}");
            let (r, d) = rows(&go, &sym, &trials.params(), &basis.params(), pos, isa, &kept).unwrap();
            assert_eq!(bits(&r), bits(&r0), "{isa:?} {pos:?}");
            assert_eq!(d, d0, "{isa:?}");
        }
    }
}

#[test]
fn rows_patched_into_matrices_give_the_full_build() {
    let mut rng = Rng(5);
    let (sym, ops) = system::<4>(&mut rng, true);
    let nb = 11;
    let basis = Basis::random::<4>(&mut rng, nb, 30);
    let go = <EcgGvr as Family<4>>::context(ops, 0, &[&basis.params()]).unwrap();
    let full = matrices(&go, &sym, &basis.params(), best_isa()).unwrap();
    for p in [0, 5, nb - 1] {
        let (trial, rest) = basis.split::<4>(p);
        let (r, d) = rows(&go, &sym, &trial.params(), &rest.params(), Some(p), best_isa(), &Cache::default()).unwrap();
        for (x, row) in [(&full.s, &r.s), (&full.t, &r.t), (&full.t_ti, &r.t_ti), (&full.v, &r.v)] {
            for j in 0..nb - 1 {
                let col = if j < p { j } else { j + 1 };
                assert_eq!(row[j].to_bits(), x[p * nb + col].to_bits(), "function {p}, column {col}");
            }
        }
        let diag = [full.s[p * nb + p], full.t[p * nb + p], full.t_ti[p * nb + p], full.v[p * nb + p]];
        assert_eq!([d[0].s, d[0].t, d[0].t_ti, d[0].v].map(f64::to_bits), diag.map(f64::to_bits));
    }
}

/// Symmetry images in lanes (`kernel::symmetrised`, four at a time, the rest one by one)
/// against the images one by one (`kernel::element`), bit for bit: one, four and six
/// images, and four where one image's `A_I + A_J` is not positive definite (every lane again
/// one by one, that image's element NaN).
#[test]
fn images_in_lanes_have_the_bits_of_one_by_one() {
    let mut rng = Rng(11);
    let (mut sym, ops) = system::<4>(&mut rng, true);
    let perm = |p: [usize; 4]| Mat::<4>::from_fn(|i, j| if p[i] == j { 1.0 } else { 0.0 });
    sym.extend([(perm([1, 2, 0, 3]), 0.3), (perm([0, 3, 2, 1]), -0.9)]);
    let basis = Basis::random::<4>(&mut rng, 6, 30);
    let go = <EcgGvr as Family<4>>::context(ops, 1, &[&basis.params()]).unwrap();
    let k = basis.k.clone();
    let (table, pairs) = (Table::new(&go, k.iter().flat_map(|&i| k.iter().map(move |&j| (i, j)))), Pairs::new(&go.ops));
    let bits = |e: Element| [e.s, e.t, e.t_ti, e.v].map(f64::to_bits);
    for images in [1, 4, 6] {
        let side = Side::new(&go, &sym[..images], &basis.params()).unwrap();
        for (bra, (ket, coef)) in side.functions.iter().zip(side.images.iter().zip(std::iter::repeat(&side.coef))) {
            let mut one_by_one = Element::zero();
            for (k, c) in ket.iter().zip(coef) {
                one_by_one += (*c, kernel::element::<4, 4>(bra, k, &table, &pairs, go.ops.cm_mass));
            }
            let lanes = kernel::symmetrised::<4, 4>(bra, ket, coef, &table, &pairs, go.ops.cm_mass);
            assert_eq!(bits(lanes), bits(one_by_one), "{images} images");
        }
    }
    let side = Side::new(&go, &sym[..4], &basis.params()).unwrap();
    let mut images = side.images[1].clone();
    images[2].a = std::array::from_fn(|i| std::array::from_fn(|j| -2.0 * side.functions[0].a[i][j]));
    let bra = &side.functions[0];
    let each: Vec<Element> =
        images.iter().map(|k| kernel::element::<4, 4>(bra, k, &table, &pairs, go.ops.cm_mass)).collect();
    assert!(each[2].s.is_nan() && each.iter().enumerate().all(|(i, e)| i == 2 || e.s.is_finite()));
    let mut one_by_one = Element::zero();
    for (e, c) in each.into_iter().zip(&side.coef) {
        one_by_one += (*c, e);
    }
    let lanes = kernel::symmetrised::<4, 4>(bra, &images, &side.coef, &table, &pairs, go.ops.cm_mass);
    assert_eq!(bits(lanes), bits(one_by_one));
}
