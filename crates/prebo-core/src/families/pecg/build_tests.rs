//! Every instruction set gives the same bits; matrices, rows and `Symmetrised::element` agree.
use super::*;
use crate::ecg::{Mat, Vector};

fn lcg(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    ((*state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
}

/// `nb` random functions of 4 particles, two protons and two electrons (1 ± P12)(1 + P34).
fn setup(nb: usize, seed: u64) -> (Symmetrised<4>, Operators<4>) {
    let mut s = seed;
    let funcs: Vec<Gaussian<4>> = (0..nb)
        .map(|i| {
            let l = Mat::<4>::from_fn(|r, c| if c <= r { lcg(&mut s) } else { 0.0 });
            Gaussian::new(l * l.transpose() + Mat::<4>::identity() * 0.05, 1.0, i).unwrap()
        })
        .collect();
    let perm = |p: [usize; 4]| Mat::<4>::from_fn(|i, j| if p[i] == j { 1.0 } else { 0.0 });
    let sym = [
        (perm([0, 1, 2, 3]), 1.0),
        (perm([1, 0, 2, 3]), -1.0),
        (perm([0, 1, 3, 2]), 1.0),
        (perm([1, 0, 3, 2]), -1.0),
    ];
    let masses = [1836.15, 1836.15, 1.0, 1.0];
    let mut pairs = Vec::new();
    let q = [1.0, 1.0, -1.0, -1.0];
    for i in 0..4 {
        for j in (i + 1)..4 {
            let mut w = Vector::<4>::zeros();
            w[i] = 1.0;
            w[j] = -1.0;
            pairs.push((w, q[i] * q[j]));
        }
    }
    let lambda = Mat::<4>::from_fn(|i, j| if i == j { 0.5 / masses[i] } else { 0.0 });
    let ops = Operators {
        lambda,
        pairs,
        cm_mass: Some(masses.iter().sum()),
    };
    (Symmetrised::new(funcs, &sym, &()).unwrap(), ops)
}

fn bits(m: &Matrices) -> Vec<u64> {
    [&m.s, &m.t, &m.t_ti, &m.v]
        .iter()
        .flat_map(|v| v.iter().map(|x| x.to_bits()))
        .collect()
}

#[test]
fn instruction_sets_agree_bit_for_bit() {
    for nb in [1, 7, 19] {
        let (basis, ops) = setup(nb, 11 + nb as u64);
        let plain = matrices_with(&basis, &ops, Isa::Plain);
        for isa in [Isa::Avx2, Isa::Avx512] {
            assert_eq!(bits(&matrices_with(&basis, &ops, isa)), bits(&plain), "{isa:?}");
        }
        let (trials, _) = setup(3, 5);
        for pos in [None, Some(0), Some(nb / 2)] {
            let (r0, d0) = rows_with(&trials, &basis, &ops, pos, Isa::Plain);
            for isa in [Isa::Avx2, Isa::Avx512] {
                let (r, d) = rows_with(&trials, &basis, &ops, pos, isa);
                assert_eq!(bits(&r), bits(&r0), "{isa:?}");
                assert_eq!(d, d0);
            }
        }
    }
}

#[test]
fn matrices_rows_and_elements_agree() {
    let (basis, ops) = setup(21, 3);
    let m = matrices(&basis, &ops);
    let nb = basis.len();
    for i in 0..nb {
        for j in 0..nb {
            let k = i * nb + j;
            let e = basis.element(&basis.functions[i.min(j)], i.max(j), |x, y| kernel::element(x, y, &ops));
            assert_eq!(
                [m.s[k], m.t[k], m.t_ti[k], m.v[k]],
                [e.s, e.t, e.t_ti, e.v],
                "({i}, {j})"
            );
        }
    }
    // rows of the basis's own functions at position 0 (the trial as bra) are its matrix rows
    // (bit for bit on and above the diagonal; below it the matrix holds the mirrored element)
    let (trials, _) = setup(21, 3);
    let (r, d) = rows(&trials, &basis, &ops, Some(0));
    for i in 0..nb {
        for j in 0..nb {
            let k = i * nb + j;
            for (x, y) in [(&r.s, &m.s), (&r.t, &m.t), (&r.t_ti, &m.t_ti), (&r.v, &m.v)] {
                if j >= i {
                    assert_eq!(x[k].to_bits(), y[k].to_bits(), "({i}, {j})");
                } else {
                    assert!((x[k] - y[k]).abs() <= 1e-13 * (y[i * nb + i] * y[j * nb + j]).abs().sqrt());
                }
            }
        }
    }
    for (i, e) in d.iter().enumerate() {
        assert_eq!(
            [e.s, e.t, e.t_ti, e.v],
            [m.s[i * nb + i], m.t[i * nb + i], m.t_ti[i * nb + i], m.v[i * nb + i]]
        );
    }
}

#[test]
fn empty_basis() {
    let (basis, ops) = setup(0, 1);
    let m = matrices(&basis, &ops);
    assert_eq!((m.rows, m.cols, m.s.len()), (0, 0, 0));
    let (trials, _) = setup(2, 1);
    for pos in [None, Some(0)] {
        let (r, d) = rows(&trials, &basis, &ops, pos);
        assert_eq!((r.rows, r.cols, d.len()), (2, 0, 2));
    }
}

/// `nb` random functions of `D` particles (random `c_A`) with charges `q`, masses `m` and the
/// symmetriser `Σ c_P P` of the permutations `sym`, in the laboratory frame with CM removal.
fn system<const D: usize>(
    nb: usize,
    seed: u64,
    q: [f64; D],
    m: [f64; D],
    sym: &[([usize; D], f64)],
) -> (Symmetrised<D>, Operators<D>) {
    let mut s = seed;
    let funcs: Vec<Gaussian<D>> = (0..nb)
        .map(|i| {
            let l = Mat::<D>::from_fn(|r, c| if c <= r { lcg(&mut s) } else { 0.0 });
            let c_a = 0.3 + lcg(&mut s).abs();
            Gaussian::new(l * l.transpose() + Mat::<D>::identity() * 0.05, c_a, i).unwrap()
        })
        .collect();
    let sym: Vec<(Mat<D>, f64)> = sym
        .iter()
        .map(|(p, c)| (Mat::<D>::from_fn(|i, j| if p[i] == j { 1.0 } else { 0.0 }), *c))
        .collect();
    let mut pairs = Vec::new();
    for i in 0..D {
        for j in (i + 1)..D {
            let mut w = Vector::<D>::zeros();
            w[i] = 1.0;
            w[j] = -1.0;
            pairs.push((w, q[i] * q[j]));
        }
    }
    let ops = Operators {
        lambda: Mat::<D>::from_fn(|i, j| if i == j { 0.5 / m[i] } else { 0.0 }),
        pairs,
        cm_mass: Some(m.iter().sum()),
    };
    (Symmetrised::new(funcs, &sym, &()).unwrap(), ops)
}

/// The functions `keep` of `b`, with their images.
fn subset<const D: usize>(b: &Symmetrised<D>, keep: impl Iterator<Item = usize>) -> Symmetrised<D> {
    let keep: Vec<usize> = keep.collect();
    Images {
        functions: keep.iter().map(|&j| b.functions[j].clone()).collect(),
        images: keep.iter().map(|&j| b.images[j].clone()).collect(),
        coef: b.coef.clone(),
    }
}

/// The bits of `m` with row and column `p` replaced (`insert`: inserted) by `row` and `diag`,
/// as python/prebo/optimise/expansion.py `put` patches them.
fn patched(m: &Matrices, row: &Matrices, diag: &Element, p: usize, insert: bool) -> Vec<u64> {
    let n = if insert { m.rows + 1 } else { m.rows };
    let old = |i: usize| if insert && i > p { i - 1 } else { i };
    let mut out = Vec::new();
    let parts = [(&m.s, &row.s, diag.s), (&m.t, &row.t, diag.t), (&m.t_ti, &row.t_ti, diag.t_ti), (&m.v, &row.v, diag.v)];
    for (x, r, d) in parts {
        for i in 0..n {
            for j in 0..n {
                let y = match (i == p, j == p) {
                    (true, true) => d,
                    (true, false) => r[old(j)],
                    (false, true) => r[old(i)],
                    _ => x[old(i) * m.rows + old(j)],
                };
                out.push(y.to_bits());
            }
        }
    }
    out
}

/// Rows at every position, patched into the matrices of the basis without the trial (inserted)
/// or holding another function there (replaced), give the bits of a full build, for every
/// instruction set.
fn oriented<const D: usize>(q: [f64; D], m: [f64; D], sym: &[([usize; D], f64)]) {
    for nb in [1, 6, 13] {
        let (full, ops) = system::<D>(nb + 1, 7 + nb as u64, q, m, sym);
        let (other, _) = system::<D>(1, 99, q, m, sym);
        for isa in [Isa::Plain, Isa::Avx2, Isa::Avx512] {
            let want = bits(&matrices_with(&full, &ops, isa));
            for p in 0..=nb {
                let trial = subset(&full, p..p + 1);
                let rest = subset(&full, (0..=nb).filter(|&j| j != p));
                let (r, d) = rows_with(&trial, &rest, &ops, Some(p), isa);
                let got = patched(&matrices_with(&rest, &ops, isa), &r, &d[0], p, true);
                assert_eq!(got, want, "inserted: D = {D}, nb = {nb}, p = {p}, {isa:?}");
                let mut held = subset(&full, 0..=nb);
                held.functions[p] = other.functions[0].clone();
                held.images[p] = other.images[0].clone();
                let (r, d) = rows_with(&trial, &held, &ops, Some(p), isa);
                let got = patched(&matrices_with(&held, &ops, isa), &r, &d[0], p, false);
                assert_eq!(got, want, "replaced: D = {D}, nb = {nb}, p = {p}, {isa:?}");
            }
        }
    }
}

#[test]
fn oriented_rows_give_the_bits_of_a_full_build() {
    // e e with (1 + P12); p p e with (1 - P12); p p e e with (1 - P12)(1 + P34)
    oriented::<2>([-1.0, -1.0], [1.0, 1.0], &[([0, 1], 1.0), ([1, 0], 1.0)]);
    let mp = 1836.15;
    oriented::<3>([1.0, 1.0, -1.0], [mp, mp, 1.0], &[([0, 1, 2], 1.0), ([1, 0, 2], -1.0)]);
    oriented::<4>(
        [1.0, 1.0, -1.0, -1.0],
        [mp, mp, 1.0, 1.0],
        &[([0, 1, 2, 3], 1.0), ([1, 0, 2, 3], -1.0), ([0, 1, 3, 2], 1.0), ([1, 0, 3, 2], -1.0)],
    );
}
