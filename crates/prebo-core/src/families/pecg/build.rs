//! Symmetrised plain-ECG matrices and candidate rows with the SIMD kernel (`kernel`), parallel
//! over rows with rayon: the overrides of `Family::matrices` and `Family::rows` for `Pecg`.
//!
//! A symmetrised element is `Σ_P c_P <phi_I| O |P phi_J>` with the Young-operator
//! coefficients `c_P` (python/prebo/system/symmetry.py) and `P phi_J` represented by the
//! transformed exponent `P^T A_J P`, precomputed once per function and permutation.
//!
//! The builds evaluate one bra against `W` kets at a time with `kernel::lanes`: the images
//! `P^T A_J P` are stored in structure-of-arrays blocks of `W` functions, and each row is
//! computed by a function compiled for the best instruction set the CPU has (AVX-512:
//! `W = 8`, AVX2: `W = 4`, otherwise plain x86-64 / other targets: `W = 4`; `isa`), chosen
//! once per build. All of them give the same bits (see `pecg`).
//!
//! Element `(i, j)`, `i <= j`, of a full build has function `i` as bra and the images of `j` as
//! kets. Rows of a trial that will sit at `position` keep that orientation: before it, `W` basis
//! functions in lanes are the bras of the trial's images (`col`); after it, the trial is the bra
//! (`row`). Patched into the matrices they give the bits of a full build.
use rayon::prelude::*;

use super::kernel::{self, bra_lanes, Accumulator, Bra, Ket, KetLanes, Prepared};
use crate::ecg::{Element, Gaussian, Mat, Operators};
use crate::error::Result;
use crate::images::{Images, Transform};
use crate::isa::{best_isa, isa_available, Isa};
use crate::matrices::Matrices;

/// Plain ECGs with their images under every symmetry operation.
pub type Symmetrised<const D: usize> = Images<Gaussian<D>>;

impl<const D: usize, Ctx> Transform<D, Ctx> for Gaussian<D> {
    /// The permuted (or otherwise linearly transformed) function `phi(T r)`: `A -> T^T A T`.
    fn transformed(&self, t: &Mat<D>, _: &Ctx, index: usize) -> Result<Self> {
        Self::new(t.transpose() * self.a * t, self.c_a, index)
    }
}

/// The kets of a build: every image of the functions from block `first` on in blocks of `W`,
/// and the coefficients.
struct Kets<const D: usize, const W: usize> {
    /// `blocks[(c - first) * n_ops + p]`: functions `c W .. c W + W - 1` under operation `p`
    blocks: Vec<KetLanes<D, W>>,
    coef: Vec<f64>,
    first: usize,
    n_blocks: usize,
}

impl<const D: usize, const W: usize> Kets<D, W> {
    fn new(basis: &Symmetrised<D>, first: usize) -> Self {
        let nb = basis.len();
        let n_ops = basis.coef.len();
        let n_blocks = nb.div_ceil(W);
        let mut blocks = Vec::with_capacity(n_blocks.saturating_sub(first) * n_ops);
        for c in first..n_blocks {
            for p in 0..n_ops {
                let kets: Vec<&Gaussian<D>> = (c * W..((c + 1) * W).min(nb)).map(|j| &basis.images[j][p]).collect();
                blocks.push(KetLanes::from_gaussians(&kets));
            }
        }
        Self {
            blocks,
            coef: basis.coef.clone(),
            first,
            n_blocks,
        }
    }
}

/// One row: the symmetrised elements of `bra` against ket blocks `first..first + out.len()`.
type RowFn<const D: usize, const W: usize> =
    unsafe fn(&Kets<D, W>, &Prepared<D>, &Bra<D>, usize, &mut [Accumulator<W>]);

/// One column: the symmetrised elements of bra blocks `first..first + out.len()` against one
/// ket's images (with their coefficients).
type ColFn<const D: usize, const W: usize> =
    unsafe fn(&[Bra<D, [f64; W]>], &[Ket<D>], &[f64], &Prepared<D>, usize, &mut [Accumulator<W>]);

/// The kernels of one instruction set.
#[derive(Clone, Copy)]
struct Kernels<const D: usize, const W: usize> {
    row: RowFn<D, W>,
    col: ColFn<D, W>,
}

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
        let base = (first + k - kets.first) * n_ops;
        let mut a = Accumulator::<W>::default();
        let cm = kernel::cm_terms(bra, &kets.blocks[base], ops);
        for (p, coef) in kets.coef.iter().enumerate() {
            kernel::lanes::<D, W>(bra, &kets.blocks[base + p], ops, &cm, *coef, &mut a);
        }
        *acc = a;
    }
}

/// `row_generic` mirrored: the bras in lanes, the ket's images one at a time, in the same order.
#[inline(always)]
fn col_generic<const D: usize, const W: usize>(
    bras: &[Bra<D, [f64; W]>],
    images: &[Ket<D>],
    coef: &[f64],
    ops: &Prepared<D>,
    first: usize,
    out: &mut [Accumulator<W>],
) {
    for (k, acc) in out.iter_mut().enumerate() {
        let bra = &bras[first + k];
        let mut a = Accumulator::<W>::default();
        let cm = kernel::cm_terms(bra, &images[0], ops);
        for (ket, c) in images.iter().zip(coef) {
            kernel::lanes::<D, W>(bra, ket, ops, &cm, *c, &mut a);
        }
        *acc = a;
    }
}

/// The kernels compiled for one instruction set (lanes `W`, target feature), in module `$isa`.
macro_rules! isa_kernels {
    ($isa:ident, $w:literal $(, $feature:literal)?) => {
        mod $isa {
            use super::*;

            /// Safety: callers must pass only to a CPU with the feature (checked in `dispatch`).
            $(#[target_feature(enable = $feature)])?
            unsafe fn row<const D: usize>(
                kets: &Kets<D, $w>,
                ops: &Prepared<D>,
                bra: &Bra<D>,
                first: usize,
                out: &mut [Accumulator<$w>],
            ) {
                row_generic::<D, $w>(kets, ops, bra, first, out)
            }

            /// Safety: as `row`.
            $(#[target_feature(enable = $feature)])?
            unsafe fn col<const D: usize>(
                bras: &[Bra<D, [f64; $w]>],
                images: &[Ket<D>],
                coef: &[f64],
                ops: &Prepared<D>,
                first: usize,
                out: &mut [Accumulator<$w>],
            ) {
                col_generic::<D, $w>(bras, images, coef, ops, first, out)
            }

            pub(super) fn kernels<const D: usize>() -> Kernels<D, $w> {
                Kernels { row: row::<D>, col: col::<D> }
            }
        }
    };
}

isa_kernels!(plain, 4);
#[cfg(target_arch = "x86_64")]
isa_kernels!(avx2, 4, "avx2");
#[cfg(target_arch = "x86_64")]
isa_kernels!(avx512, 8, "avx512f");

macro_rules! dispatch {
    ($isa:expr, $f:ident :: <$d:ident> ( $($arg:expr),* )) => {{
        match $isa {
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => $f::<$d, 8>($($arg,)* avx512::kernels::<$d>()),
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => $f::<$d, 4>($($arg,)* avx2::kernels::<$d>()),
            _ => $f::<$d, 4>($($arg,)* plain::kernels::<$d>()),
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

fn matrices_w<const D: usize, const W: usize>(
    basis: &Symmetrised<D>,
    ops: &Operators<D>,
    kernels: Kernels<D, W>,
) -> Matrices {
    let nb = basis.len();
    let mut m = Matrices::zeros(nb, nb);
    if nb == 0 {
        return m;
    }
    let prep = Prepared::new(ops);
    let kets = Kets::<D, W>::new(basis, 0);
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
            // Safety: the kernels were chosen for an instruction set this CPU has.
            unsafe { (kernels.row)(&kets, &prep, &bra, first, &mut acc) };
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


/// Rows of trial functions against a basis for a trial that will sit at `position` (`None`:
/// appended), oriented as in a full build (module docstring), and each trial's symmetrised
/// diagonal element.
pub fn rows<const D: usize>(
    trials: &Symmetrised<D>,
    basis: &Symmetrised<D>,
    ops: &Operators<D>,
    position: Option<usize>,
) -> (Matrices, Vec<Element>) {
    rows_with(trials, basis, ops, position, best_isa())
}

/// `rows` with a chosen instruction set (falls back to plain code where unavailable).
pub fn rows_with<const D: usize>(
    trials: &Symmetrised<D>,
    basis: &Symmetrised<D>,
    ops: &Operators<D>,
    position: Option<usize>,
    isa: Isa,
) -> (Matrices, Vec<Element>) {
    let isa = if isa_available(isa) { isa } else { Isa::Plain };
    let pos = position.unwrap_or(basis.len()).min(basis.len());
    dispatch!(isa, rows_w::<D>(trials, basis, ops, pos))
}

fn rows_w<const D: usize, const W: usize>(
    trials: &Symmetrised<D>,
    basis: &Symmetrised<D>,
    ops: &Operators<D>,
    pos: usize,
    kernels: Kernels<D, W>,
) -> (Matrices, Vec<Element>) {
    /// blocks per task: rows are split so that a few trials still use every thread
    const SPAN: usize = 16;
    let (k, nb) = (trials.len(), basis.len());
    let prep = Prepared::new(ops);
    // j < pos: basis functions as bras (blocks of W) against the trial's images
    let below: Vec<Bra<D>> = basis.functions[..pos].iter().map(|f| Bra::new(f, &prep)).collect();
    let bras: Vec<Bra<D, [f64; W]>> = below.chunks(W).map(bra_lanes).collect();
    let images: Vec<Vec<Ket<D>>> = trials.images.iter().map(|im| im.iter().map(Ket::new).collect()).collect();
    // j >= pos: the trial as bra against the images of the basis functions (blocks from `first_row`)
    let first_row = if pos < nb { pos / W } else { nb.div_ceil(W) };
    let kets = Kets::<D, W>::new(basis, first_row);
    let own = Kets::<D, W>::new(trials, 0);
    let trial_bras: Vec<Bra<D>> = trials.functions.iter().map(|f| Bra::new(f, &prep)).collect();
    // a trial's row is `n_col` bra blocks (j < pos), then the ket blocks from `first_row` on;
    // block `v` of that sequence is (mirrored, block index)
    let n_col = bras.len();
    let block = |v: usize| if v < n_col { (true, v) } else { (false, first_row + v - n_col) };
    let total = n_col + kets.n_blocks - first_row;
    let spans = total.div_ceil(SPAN);
    let parts: Vec<Vec<Accumulator<W>>> = (0..k * spans)
        .into_par_iter()
        .map(|task| {
            let (i, v0) = (task / spans, task % spans * SPAN);
            let v1 = (v0 + SPAN).min(total);
            let mut acc = vec![Accumulator::<W>::default(); v1 - v0];
            let (col, row) = acc.split_at_mut(n_col.clamp(v0, v1) - v0);
            // Safety: the kernels were chosen for an instruction set this CPU has.
            unsafe {
                (kernels.col)(&bras, &images[i], &trials.coef, &prep, v0, col);
                (kernels.row)(&kets, &prep, &trial_bras[i], block(v0.max(n_col)).1, row);
            }
            acc
        })
        .collect();
    let diag: Vec<Element> = (0..k)
        .into_par_iter()
        .map(|i| {
            let mut acc = [Accumulator::<W>::default()];
            // Safety: as above.
            unsafe { (kernels.row)(&own, &prep, &trial_bras[i], i / W, &mut acc) };
            lane(&acc[0], i % W)
        })
        .collect();
    let mut m = Matrices::zeros(k, nb);
    for (task, acc) in parts.iter().enumerate() {
        let (i, v0) = (task / spans, task % spans * SPAN);
        for (v, a) in acc.iter().enumerate() {
            let (col, c) = block(v0 + v);
            for l in 0..W {
                let j = c * W + l;
                if j < nb && (j < pos) == col {
                    m.set(i, j, &lane(a, l));
                }
            }
        }
    }
    (m, diag)
}

/// The element in lane `l` of `a`.
fn lane<const W: usize>(a: &Accumulator<W>, l: usize) -> Element {
    Element {
        s: a.s[l],
        t: a.t[l],
        t_ti: a.t_ti[l],
        v: a.v[l],
    }
}

#[cfg(test)]
#[path = "build_tests.rs"]
mod tests;
