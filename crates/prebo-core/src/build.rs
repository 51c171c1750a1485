//! Symmetrised matrices and candidate rows, parallel over rows with rayon.
//!
//! A symmetrised element is `Σ_P c_P <phi_I| O |P phi_J>` with the Young-operator
//! coefficients `c_P` (python/prebo/symmetry.py) and `P phi_J` represented by the
//! transformed exponent `P^T A_J P`, precomputed once per function and permutation.
//!
//! The builds evaluate one bra against `W` kets at a time with `pecg::lanes`: the images
//! `P^T A_J P` are stored in structure-of-arrays blocks of `W` functions, and each row is
//! computed by a function compiled for the best instruction set the CPU has (AVX-512:
//! `W = 8`, AVX2: `W = 4`, otherwise plain x86-64 / other targets: `W = 4`), chosen
//! once per build. All of them give the same bits (see `pecg`).
use rayon::prelude::*;

use crate::ecg::{Element, Gaussian, Operators};
use crate::images::Images;
use crate::matrices::Matrices;
use crate::pecg::{self, Accumulator, Bra, KetLanes, Prepared};

/// Plain ECGs with their images under every symmetry operation.
pub type Symmetrised<const D: usize> = Images<Gaussian<D>>;

/// The kets of a build: every image of every function in blocks of `W`, and the coefficients.
struct Kets<const D: usize, const W: usize> {
    /// `blocks[c * n_ops + p]`: functions `c W .. c W + W - 1` under operation `p`
    blocks: Vec<KetLanes<D, W>>,
    coef: Vec<f64>,
    n_blocks: usize,
}

impl<const D: usize, const W: usize> Kets<D, W> {
    fn new(basis: &Symmetrised<D>) -> Self {
        let nb = basis.len();
        let n_ops = basis.coef.len();
        let n_blocks = nb.div_ceil(W);
        let mut blocks = Vec::with_capacity(n_blocks * n_ops);
        for c in 0..n_blocks {
            for p in 0..n_ops {
                let kets: Vec<&Gaussian<D>> = (c * W..((c + 1) * W).min(nb)).map(|j| &basis.images[j][p]).collect();
                blocks.push(KetLanes::from_gaussians(&kets));
            }
        }
        Self {
            blocks,
            coef: basis.coef.clone(),
            n_blocks,
        }
    }
}

/// One row: the symmetrised elements of `bra` against ket blocks `first..first + out.len()`.
type RowFn<const D: usize, const W: usize> =
    unsafe fn(&Kets<D, W>, &Prepared<D>, &Bra<D>, usize, &mut [Accumulator<W>]);

#[inline(always)]
fn row_generic<const D: usize, const W: usize>(
    kets: &Kets<D, W>,
    ops: &Prepared<D>,
    bra: &Bra<D>,
    first: usize,
    out: &mut [Accumulator<W>],
) {
    let n_ops = kets.coef.len();
    for (k, acc) in out.iter_mut().enumerate() {
        let base = (first + k) * n_ops;
        let mut a = Accumulator::<W>::default();
        let cm = pecg::cm_terms(bra, &kets.blocks[base], ops);
        for (p, coef) in kets.coef.iter().enumerate() {
            pecg::lanes::<D, W>(bra, &kets.blocks[base + p], ops, &cm, *coef, &mut a);
        }
        *acc = a;
    }
}

/// Safety: callers must pass only to a CPU with the feature (checked in `dispatch`).
unsafe fn row_plain<const D: usize, const W: usize>(
    kets: &Kets<D, W>,
    ops: &Prepared<D>,
    bra: &Bra<D>,
    first: usize,
    out: &mut [Accumulator<W>],
) {
    row_generic::<D, W>(kets, ops, bra, first, out)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn row_avx2<const D: usize>(
    kets: &Kets<D, 4>,
    ops: &Prepared<D>,
    bra: &Bra<D>,
    first: usize,
    out: &mut [Accumulator<4>],
) {
    row_generic::<D, 4>(kets, ops, bra, first, out)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
unsafe fn row_avx512<const D: usize>(
    kets: &Kets<D, 8>,
    ops: &Prepared<D>,
    bra: &Bra<D>,
    first: usize,
    out: &mut [Accumulator<8>],
) {
    row_generic::<D, 8>(kets, ops, bra, first, out)
}

/// The instruction sets a build can use, best first.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Isa {
    Avx512,
    Avx2,
    Plain,
}

/// The best instruction set of this CPU (`PREBO_ISA=avx512|avx2|plain` caps it, for tests).
pub fn best_isa() -> Isa {
    let cap = std::env::var("PREBO_ISA").unwrap_or_default().to_ascii_lowercase();
    #[cfg(target_arch = "x86_64")]
    {
        if cap != "avx2" && cap != "plain" && std::arch::is_x86_feature_detected!("avx512f") {
            return Isa::Avx512;
        }
        if cap != "plain" && std::arch::is_x86_feature_detected!("avx2") {
            return Isa::Avx2;
        }
    }
    let _ = cap;
    Isa::Plain
}

macro_rules! dispatch {
    ($isa:expr, $f:ident :: <$d:ident> ( $($arg:expr),* )) => {{
        match $isa {
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => $f::<$d, 8>($($arg,)* row_avx512::<$d>),
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => $f::<$d, 4>($($arg,)* row_avx2::<$d>),
            _ => $f::<$d, 4>($($arg,)* row_plain::<$d, 4>),
        }
    }};
}

/// The full symmetric matrices of a basis: upper triangle computed, lower mirrored.
pub fn matrices<const D: usize>(basis: &Symmetrised<D>, ops: &Operators<D>) -> Matrices {
    matrices_with(basis, ops, best_isa())
}

/// `matrices` with a chosen instruction set (falls back to plain code where unavailable).
pub fn matrices_with<const D: usize>(basis: &Symmetrised<D>, ops: &Operators<D>, isa: Isa) -> Matrices {
    let isa = if isa_available(isa) { isa } else { Isa::Plain };
    dispatch!(isa, matrices_w::<D>(basis, ops))
}

fn isa_available(isa: Isa) -> bool {
    match isa {
        Isa::Plain => true,
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 => std::arch::is_x86_feature_detected!("avx2"),
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 => std::arch::is_x86_feature_detected!("avx512f"),
        #[cfg(not(target_arch = "x86_64"))]
        _ => false,
    }
}

fn matrices_w<const D: usize, const W: usize>(
    basis: &Symmetrised<D>,
    ops: &Operators<D>,
    row: RowFn<D, W>,
) -> Matrices {
    let nb = basis.len();
    let mut m = Matrices::zeros(nb, nb);
    if nb == 0 {
        return m;
    }
    let prep = Prepared::new(ops);
    let kets = Kets::<D, W>::new(basis);
    let (s, t, t_ti, v) = (&mut m.s, &mut m.t, &mut m.t_ti, &mut m.v);
    s.par_chunks_mut(nb)
        .zip(t.par_chunks_mut(nb))
        .zip(t_ti.par_chunks_mut(nb))
        .zip(v.par_chunks_mut(nb))
        .enumerate()
        .with_max_len(1)
        .for_each(|(i, (((s, t), t_ti), v))| {
            let bra = Bra::new(&basis.functions[i], &prep);
            let first = i / W;
            let mut acc = vec![Accumulator::<W>::default(); kets.n_blocks - first];
            // Safety: `row` was chosen for an instruction set this CPU has.
            unsafe { row(&kets, &prep, &bra, first, &mut acc) };
            for (k, a) in acc.iter().enumerate() {
                let j0 = (first + k) * W;
                for l in 0..W {
                    let j = j0 + l;
                    if j >= i && j < nb {
                        s[j] = a.s[l];
                        t[j] = a.t[l];
                        t_ti[j] = a.t_ti[l];
                        v[j] = a.v[l];
                    }
                }
            }
        });
    mirror_upper(&mut m);
    m
}

/// Raw pointer to the matrices, shared by the mirror's tasks (each writes only its own rows).
#[derive(Clone, Copy)]
struct Shared([*mut f64; 4]);
unsafe impl Send for Shared {}
unsafe impl Sync for Shared {}

/// Copies the upper triangles of the four row-major `n x n` matrices to the lower ones, in
/// parallel over blocks of rows and in square tiles: the task of rows `J` writes tile `(J, I)`
/// (below the diagonal) from tile `(I, J)` (above it, only read), both a row at a time.
fn mirror_upper(m: &mut Matrices) {
    const T: usize = 32;
    let n = m.rows;
    debug_assert_eq!(m.cols, n);
    let ptrs = Shared([
        m.s.as_mut_ptr(),
        m.t.as_mut_ptr(),
        m.t_ti.as_mut_ptr(),
        m.v.as_mut_ptr(),
    ]);
    (0..n.div_ceil(T)).into_par_iter().for_each(move |jb| {
        let ptrs = ptrs;
        let (j0, j1) = (jb * T, ((jb + 1) * T).min(n));
        let mut tile = [[0.0f64; T]; T];
        for x in ptrs.0 {
            for i0 in (0..j1).step_by(T) {
                let i1 = (i0 + T).min(n);
                // Safety: all indices are below n; reads are at (i, j) with i < j (upper
                // triangle, never written here), writes at (j, i), i < j, in this task's rows.
                unsafe {
                    for i in i0..i1 {
                        for j in j0.max(i + 1)..j1 {
                            tile[j - j0][i - i0] = *x.add(i * n + j);
                        }
                    }
                    for j in j0..j1 {
                        for i in i0..i1.min(j) {
                            *x.add(j * n + i) = tile[j - j0][i - i0];
                        }
                    }
                }
            }
        }
    });
}

/// Rows of trial functions against a basis, and each trial's symmetrised diagonal element.
pub fn rows<const D: usize>(
    trials: &Symmetrised<D>,
    basis: &Symmetrised<D>,
    ops: &Operators<D>,
) -> (Matrices, Vec<Element>) {
    rows_with(trials, basis, ops, best_isa())
}

/// `rows` with a chosen instruction set (falls back to plain code where unavailable).
pub fn rows_with<const D: usize>(
    trials: &Symmetrised<D>,
    basis: &Symmetrised<D>,
    ops: &Operators<D>,
    isa: Isa,
) -> (Matrices, Vec<Element>) {
    let isa = if isa_available(isa) { isa } else { Isa::Plain };
    dispatch!(isa, rows_w::<D>(trials, basis, ops))
}

fn rows_w<const D: usize, const W: usize>(
    trials: &Symmetrised<D>,
    basis: &Symmetrised<D>,
    ops: &Operators<D>,
    row: RowFn<D, W>,
) -> (Matrices, Vec<Element>) {
    /// ket blocks per task: rows are split so that a few trials still use every thread
    const SPAN: usize = 16;
    let (k, nb) = (trials.len(), basis.len());
    let prep = Prepared::new(ops);
    let kets = Kets::<D, W>::new(basis);
    let own = Kets::<D, W>::new(trials);
    let bras: Vec<Bra<D>> = trials.functions.iter().map(|f| Bra::new(f, &prep)).collect();
    let spans = kets.n_blocks.div_ceil(SPAN);
    let parts: Vec<Vec<Accumulator<W>>> = (0..k * spans)
        .into_par_iter()
        .map(|task| {
            let (i, c) = (task / spans.max(1), task % spans.max(1));
            let first = c * SPAN;
            let mut acc = vec![Accumulator::<W>::default(); (kets.n_blocks - first).min(SPAN)];
            // Safety: `row` was chosen for an instruction set this CPU has.
            unsafe { row(&kets, &prep, &bras[i], first, &mut acc) };
            acc
        })
        .collect();
    let diag: Vec<Element> = (0..k)
        .into_par_iter()
        .map(|i| {
            let mut acc = [Accumulator::<W>::default()];
            // Safety: as above.
            unsafe { row(&own, &prep, &bras[i], i / W, &mut acc) };
            let l = i % W;
            Element {
                s: acc[0].s[l],
                t: acc[0].t[l],
                t_ti: acc[0].t_ti[l],
                v: acc[0].v[l],
            }
        })
        .collect();
    let mut m = Matrices::zeros(k, nb);
    for (task, acc) in parts.iter().enumerate() {
        let (i, c) = (task / spans, task % spans);
        for (b, a) in acc.iter().enumerate() {
            for l in 0..W {
                let j = (c * SPAN + b) * W + l;
                if j < nb {
                    m.set(
                        i,
                        j,
                        &Element {
                            s: a.s[l],
                            t: a.t[l],
                            t_ti: a.t_ti[l],
                            v: a.v[l],
                        },
                    );
                }
            }
        }
    }
    (m, diag)
}

#[cfg(test)]
mod tests {
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
            let (r0, d0) = rows_with(&trials, &basis, &ops, Isa::Plain);
            for isa in [Isa::Avx2, Isa::Avx512] {
                let (r, d) = rows_with(&trials, &basis, &ops, isa);
                assert_eq!(bits(&r), bits(&r0), "{isa:?}");
                assert_eq!(d, d0);
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
                let e = basis.element(&basis.functions[i.min(j)], i.max(j), |x, y| pecg::element(x, y, &ops));
                assert_eq!(
                    [m.s[k], m.t[k], m.t_ti[k], m.v[k]],
                    [e.s, e.t, e.t_ti, e.v],
                    "({i}, {j})"
                );
            }
        }
        // rows of the basis's own functions are its matrix rows (bit for bit on and above the
        // diagonal; below it the matrix holds the mirrored element); diagonals its diagonal
        let (trials, _) = setup(21, 3);
        let (r, d) = rows(&trials, &basis, &ops);
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
        let (r, d) = rows(&trials, &basis, &ops);
        assert_eq!((r.rows, r.cols, d.len()), (2, 0, 2));
    }
}
