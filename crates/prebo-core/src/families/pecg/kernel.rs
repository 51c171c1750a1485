//! Plain ECG matrix elements (paper section "pECG"; Suzuki & Varga, Lect. Notes Phys. m54, ch. 6).
//!
//! With `phi = exp(-r^T A r)` (no 1/2, see `ecg`), `A_IJ = A_I + A_J`, `B = A_IJ^{-1}`:
//! - overlap      `S = (2^D |A_I|^{1/2} |A_J|^{1/2} / |A_IJ|)^{3/2}`           (normalised functions)
//! - kinetic      `T = 6 Tr(B A_I Λ A_J) S`                                      (paper: `6 R`)
//! - Coulomb      `<1/|w^T r|> = 2 / sqrt(pi w^T B w) S`
//! - CM removal   `T_TI = T - 3 c_I c_J / ((c_I + c_J) m_tot) S`
//!
//! The last line is paper eq. ecg-transl in this convention: the CM block of
//! `U_x B U_y^T` is `1/(c_I + c_J)`, of `U_y Λ U_x^T` is `1/(2 m_tot)`, so the CM
//! part of `6 Tr(B A_I Λ A_J)` is `6 c_I c_J / (2 m_tot (c_I + c_J))`
//! (= `3 c_A / (2 m_tot)` for a shared `c_A`, the kinetic energy of `exp(-c_A X^2)`).
//! It equals the kinetic element with `Λ = M - 1 1^T / (2 m_tot)` for every basis
//! whose functions are CM-separable, whatever their `c_A` (tests/test_elimination.py).
//!
//! # The kernel
//! [`lanes`] evaluates `W` elements at once, lane by lane in structure-of-arrays form, so that
//! the compiler vectorises it (`build` instantiates it for AVX-512, AVX2 and plain x86-64 and
//! picks one at run time): one bra against `W` kets (full builds, rows after the trial) or `W`
//! bras against one ket (rows before it). Either side is a scalar or `W` lanes ([`Lane`]) with
//! the same operations in the same order, so an element has the same bits either way. Per
//! element it needs no `ln`, no `exp` and no general inverse:
//! - `A_IJ = L D L^T` (root-free Cholesky), `|A_IJ| = Π d_k`, `B = L^{-T} D^{-1} L^{-1}`
//!   (upper triangle only);
//! - `S = n_I n_J / (|A_IJ| sqrt|A_IJ|)` with the per-function `n = (2^{D/2} |A|^{1/2})^{3/2}`
//!   (lanes whose determinant leaves the normal range fall back to the logarithmic form);
//! - `Tr(B A_I Λ A_J) = Σ_ab B_ab (A_I Λ A_J)_ba` with `A_I Λ` precomputed per bra;
//! - `w^T B w` from the non-zero products `w_a w_b` only (three terms per pair in the
//!   laboratory frame, where `w = e_i - e_j`).
//!
//! The operations are plain IEEE additions, multiplications, divisions and square roots
//! in a fixed order (no fused multiply-add), so every lane width and instruction set
//! gives the same bits. [`element`] is the same kernel with one lane; the tests compare it with
//! the former direct implementation (nalgebra Cholesky and inverse).
// index loops read best in these small dense kernels
#![allow(clippy::needless_range_loop, clippy::type_complexity)]
use std::f64::consts::{LN_2, PI};

use nalgebra::Cholesky;

use crate::ecg::{CoulombTerms, Element, Gaussian, Operators};

/// `<phi_I| 1, T, V |phi_J>` for one pair of normalised plain ECGs.
#[inline]
pub fn element<const D: usize>(bra: &Gaussian<D>, ket: &Gaussian<D>, ops: &Operators<D>) -> Element {
    let pre = Prepared::new(ops);
    let b = Bra::new(bra, &pre);
    let k = KetLanes::<D, 1>::from_gaussians(&[ket]);
    let mut out = Accumulator::<1>::default();
    let cm = cm_terms(&b, &k, &pre);
    lanes::<D, 1>(&b, &k, &pre, &cm, 1.0, &mut out);
    Element {
        s: out.s[0],
        t: out.t[0],
        t_ti: out.t_ti[0],
        v: out.v[0],
    }
}

/// The operators in the kernel's form: `Λ` as rows, Coulomb pairs as sparse `w_a w_b` terms.
#[derive(Clone, Debug)]
pub struct Prepared<const D: usize> {
    pub lambda: [[f64; D]; D],
    pub pairs: CoulombTerms,
    pub cm_mass: Option<f64>,
}

impl<const D: usize> Prepared<D> {
    pub fn new(ops: &Operators<D>) -> Self {
        let mut lambda = [[0.0; D]; D];
        for (a, row) in lambda.iter_mut().enumerate() {
            for (b, x) in row.iter_mut().enumerate() {
                *x = ops.lambda[(a, b)];
            }
        }
        Self {
            lambda,
            pairs: ops.coulomb_terms(),
            cm_mass: ops.cm_mass,
        }
    }
}

/// `(2^{D/2} |A|^{1/2})^{3/2}`, the factor of a normalised function in `S`, from the
/// Cholesky diagonal (`|A|^{1/2} = Π L_kk`); from `ln|A|` if that product leaves the normal range.
pub fn norm_factor<const D: usize>(g: &Gaussian<D>) -> f64 {
    if let Some(chol) = Cholesky::new(g.a) {
        let l = chol.l_dirty();
        let mut p = (D as f64 * 0.5 * LN_2).exp();
        for k in 0..D {
            p *= l[(k, k)];
        }
        let n = p * p.sqrt();
        if p.is_normal() && n.is_normal() {
            return n;
        }
    }
    (0.75 * (D as f64 * LN_2 + g.log_det)).exp()
}

/// A value of the kernel's operands: one scalar for every lane (`f64`) or one per lane (`[f64; W]`).
pub trait Lane<const W: usize>: Copy {
    fn at(&self, l: usize) -> f64;
}

impl<const W: usize> Lane<W> for f64 {
    #[inline(always)]
    fn at(&self, _: usize) -> f64 {
        *self
    }
}

impl<const W: usize> Lane<W> for [f64; W] {
    #[inline(always)]
    fn at(&self, l: usize) -> f64 {
        self[l]
    }
}

/// A bra with its per-function precomputations: one function (`X = f64`) or `W` (`X = [f64; W]`).
#[derive(Clone, Debug)]
pub struct Bra<const D: usize, X = f64> {
    pub a: [[X; D]; D],
    /// `A Λ`
    pub a_lambda: [[X; D]; D],
    pub norm: X,
    pub log_det: X,
    pub c_a: X,
}

/// Lanes of `W` bras from up to `W` bras (`Bra::new`, same bits); missing lanes repeat the last.
pub fn bra_lanes<const D: usize, const W: usize>(bras: &[Bra<D>]) -> Bra<D, [f64; W]> {
    assert!(!bras.is_empty() && bras.len() <= W);
    let lane = |f: &dyn Fn(&Bra<D>) -> f64| std::array::from_fn(|l| f(&bras[l.min(bras.len() - 1)]));
    Bra {
        a: std::array::from_fn(|i| std::array::from_fn(|j| lane(&|b| b.a[i][j]))),
        a_lambda: std::array::from_fn(|i| std::array::from_fn(|j| lane(&|b| b.a_lambda[i][j]))),
        norm: lane(&|b| b.norm),
        log_det: lane(&|b| b.log_det),
        c_a: lane(&|b| b.c_a),
    }
}

impl<const D: usize> Bra<D> {
    pub fn new(g: &Gaussian<D>, ops: &Prepared<D>) -> Self {
        let mut a = [[0.0; D]; D];
        let mut al = [[0.0; D]; D];
        for i in 0..D {
            for j in 0..D {
                a[i][j] = g.a[(i, j)];
            }
        }
        for i in 0..D {
            for j in 0..D {
                let mut x = 0.0;
                for k in 0..D {
                    x += a[i][k] * ops.lambda[k][j];
                }
                al[i][j] = x;
            }
        }
        Self {
            a,
            a_lambda: al,
            norm: norm_factor(g),
            log_det: g.log_det,
            c_a: g.c_a,
        }
    }
}

/// A ket: one function (`X = f64`) or `W` in structure-of-arrays form (`X = [f64; W]`,
/// `a[i][j][lane]`); the upper triangle of `a` is used.
#[derive(Clone, Debug)]
pub struct Ket<const D: usize, X = f64> {
    pub a: [[X; D]; D],
    pub norm: X,
    pub log_det: X,
    pub c_a: X,
}

/// `W` kets in lanes.
pub type KetLanes<const D: usize, const W: usize> = Ket<D, [f64; W]>;

impl<const D: usize> Ket<D> {
    pub fn new(g: &Gaussian<D>) -> Self {
        Self {
            a: std::array::from_fn(|i| std::array::from_fn(|j| g.a[(i, j)])),
            norm: norm_factor(g),
            log_det: g.log_det,
            c_a: g.c_a,
        }
    }
}

impl<const D: usize, const W: usize> Ket<D, [f64; W]> {
    /// Lanes from up to `W` functions; missing lanes repeat the last one.
    pub fn from_gaussians(kets: &[&Gaussian<D>]) -> Self {
        assert!(!kets.is_empty() && kets.len() <= W);
        let mut out = Self {
            a: [[[0.0; W]; D]; D],
            norm: [0.0; W],
            log_det: [0.0; W],
            c_a: [0.0; W],
        };
        for l in 0..W {
            let g = kets[l.min(kets.len() - 1)];
            for i in 0..D {
                for j in 0..D {
                    out.a[i][j][l] = g.a[(i, j)];
                }
            }
            out.norm[l] = norm_factor(g);
            out.log_det[l] = g.log_det;
            out.c_a[l] = g.c_a;
        }
        out
    }
}

/// Per-lane sums `Σ_P c_P <I|O|P J>`.
#[derive(Clone, Copy, Debug)]
pub struct Accumulator<const W: usize> {
    pub s: [f64; W],
    pub t: [f64; W],
    pub t_ti: [f64; W],
    pub v: [f64; W],
}

impl<const W: usize> Default for Accumulator<W> {
    fn default() -> Self {
        Self {
            s: [0.0; W],
            t: [0.0; W],
            t_ti: [0.0; W],
            v: [0.0; W],
        }
    }
}

/// `3 c_I c_J / ((c_I + c_J) m_tot)` per lane: the CM kinetic term of `T_TI` over `S` (zero without `cm_mass`).
#[inline(always)]
pub fn cm_terms<const D: usize, const W: usize>(
    bra: &Bra<D, impl Lane<W>>,
    ket: &Ket<D, impl Lane<W>>,
    ops: &Prepared<D>,
) -> [f64; W] {
    let mut cm = [0.0f64; W];
    if let Some(m_tot) = ops.cm_mass {
        for l in 0..W {
            let (ci, cj) = (bra.c_a.at(l), ket.c_a.at(l));
            cm[l] = 3.0 * ci * cj / ((ci + cj) * m_tot);
        }
    }
    cm
}

/// Adds `coef * <bra| 1, T, V |ket_l>` for every lane `l` to `acc`; `cm` from [`cm_terms`].
///
/// D = 2, 3, 4 run unrolled copies of the generic code below (`unrolled.rs`, generated by
/// `gen/unroll.py`: same operations, same order, same bits), which keep the lanes in registers;
/// other D run the loops.
#[inline(always)]
pub fn lanes<const D: usize, const W: usize>(
    bra: &Bra<D, impl Lane<W>>,
    ket: &Ket<D, impl Lane<W>>,
    ops: &Prepared<D>,
    cm: &[f64; W],
    coef: f64,
    acc: &mut Accumulator<W>,
) {
    // Safety of the casts: the types are identical when D is the matched value.
    unsafe {
        match D {
            2 => lanes_d2::<W>(bra.dim(), ket.dim(), cast(ops), cm, coef, acc),
            3 => lanes_d3::<W>(bra.dim(), ket.dim(), cast(ops), cm, coef, acc),
            4 => lanes_d4::<W>(bra.dim(), ket.dim(), cast(ops), cm, coef, acc),
            _ => lanes_generic::<D, W>(bra, ket, ops, cm, coef, acc),
        }
    }
}

#[inline(always)]
unsafe fn cast<T, U>(x: &T) -> &U {
    debug_assert_eq!(std::mem::size_of::<T>(), std::mem::size_of::<U>());
    &*(x as *const T as *const U)
}

impl<const D: usize, X> Bra<D, X> {
    /// Safety: only for `E == D`.
    #[inline(always)]
    unsafe fn dim<const E: usize>(&self) -> &Bra<E, X> {
        cast(self)
    }
}

impl<const D: usize, X> Ket<D, X> {
    /// Safety: only for `E == D`.
    #[inline(always)]
    unsafe fn dim<const E: usize>(&self) -> &Ket<E, X> {
        cast(self)
    }
}

/// The kernel with loops over the coordinates (any D); the reference for the unrolled copies.
#[inline(always)]
pub fn lanes_generic<const D: usize, const W: usize>(
    bra: &Bra<D, impl Lane<W>>,
    ket: &Ket<D, impl Lane<W>>,
    ops: &Prepared<D>,
    cm: &[f64; W],
    coef: f64,
    acc: &mut Accumulator<W>,
) {
    // A_IJ (upper triangle)
    let mut m = [[[0.0f64; W]; D]; D];
    for i in 0..D {
        for j in i..D {
            for l in 0..W {
                m[i][j][l] = bra.a[i][j].at(l) + ket.a[i][j].at(l);
            }
        }
    }
    let (b, det, dk) = inverse::<D, W>(&m);
    // Tr(B A_I Λ A_J) = Σ_ab B_ab Σ_c (A_I Λ)_bc (A_J)_ca
    let mut tr = [0.0f64; W];
    for a in 0..D {
        for bb in 0..D {
            let bab = if a <= bb { &b[a][bb] } else { &b[bb][a] };
            let mut y = [0.0f64; W];
            for c in 0..D {
                let ajc = if c <= a { &ket.a[c][a] } else { &ket.a[a][c] };
                for l in 0..W {
                    y[l] += bra.a_lambda[bb][c].at(l) * ajc.at(l);
                }
            }
            for l in 0..W {
                tr[l] += bab[l] * y[l];
            }
        }
    }
    finish::<D, W>(bra, ket, ops, cm, coef, acc, &b, &det, &dk, &tr);
}

/// `B = A_IJ^{-1}` (upper triangle), `|A_IJ|` and the pivots `d_k` from the upper triangle `m` of
/// `A_IJ = L D L^T` (root-free Cholesky; module docs): the factorisation of `lanes_generic`, shared
/// with the row gradient (`gradient`).
#[inline(always)]
pub(crate) fn inverse<const D: usize, const W: usize>(
    m: &[[[f64; W]; D]; D],
) -> ([[[f64; W]; D]; D], [f64; W], [[f64; W]; D]) {
    // A_IJ = L D L^T: e[i][k] = L_ik d_k, lo[i][k] = L_ik (i > k), rd[k] = 1/d_k
    let mut lo = [[[0.0f64; W]; D]; D];
    let mut e = [[[0.0f64; W]; D]; D];
    let mut rd = [[0.0f64; W]; D];
    let mut dk = [[0.0f64; W]; D];
    let mut det = [1.0f64; W];
    for k in 0..D {
        for i in k..D {
            let mut v = m[k][i];
            for r in 0..k {
                for l in 0..W {
                    v[l] -= e[i][r][l] * lo[k][r][l];
                }
            }
            if i == k {
                for l in 0..W {
                    rd[k][l] = 1.0 / v[l];
                    det[l] *= v[l];
                }
                dk[k] = v;
            } else {
                e[i][k] = v;
                for l in 0..W {
                    lo[i][k][l] = v[l] * rd[k][l];
                }
            }
        }
    }
    // L^{-1} (unit lower, stored below the diagonal of `inv`)
    let mut inv = [[[0.0f64; W]; D]; D];
    for k in 0..D {
        for i in (k + 1)..D {
            let mut x = [0.0f64; W];
            for l in 0..W {
                x[l] = -lo[i][k][l];
            }
            for r in (k + 1)..i {
                for l in 0..W {
                    x[l] -= lo[i][r][l] * inv[r][k][l];
                }
            }
            inv[i][k] = x;
        }
    }
    // B = L^{-T} D^{-1} L^{-1}, upper triangle: B_ab = Σ_{k >= b} M_ka M_kb / d_k (a <= b)
    let mut b = [[[0.0f64; W]; D]; D];
    for a in 0..D {
        for bb in a..D {
            let mut x = [0.0f64; W];
            for k in bb..D {
                for l in 0..W {
                    let mka = if k == a { 1.0 } else { inv[k][a][l] };
                    let mkb = if k == bb { 1.0 } else { inv[k][bb][l] };
                    x[l] += mka * mkb * rd[k][l];
                }
            }
            b[a][bb] = x;
        }
    }
    (b, det, dk)
}

/// Coulomb terms, S (with the logarithmic fallback), T, T_TI; adds to `acc`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn finish<const D: usize, const W: usize>(
    bra: &Bra<D, impl Lane<W>>,
    ket: &Ket<D, impl Lane<W>>,
    ops: &Prepared<D>,
    cm: &[f64; W],
    coef: f64,
    acc: &mut Accumulator<W>,
    b: &[[[f64; W]; D]; D],
    det: &[f64; W],
    dk: &[[f64; W]; D],
    tr: &[f64; W],
) {
    // Coulomb: Σ 2 q / sqrt(pi w^T B w)
    let mut v = [0.0f64; W];
    for (q2, terms) in &ops.pairs {
        let mut c = [0.0f64; W];
        for &(i, j, f) in terms {
            for l in 0..W {
                c[l] += f * b[i][j][l];
            }
        }
        for l in 0..W {
            v[l] += q2 / (PI * c[l]).sqrt();
        }
    }
    let s = overlap::<D, W>(bra, ket, det, dk);
    for l in 0..W {
        let t = 6.0 * tr[l] * s[l];
        let t_ti = t - cm[l] * s[l];
        acc.s[l] += coef * s[l];
        acc.t[l] += coef * t;
        acc.t_ti[l] += coef * t_ti;
        acc.v[l] += coef * (v[l] * s[l]);
    }
}

/// `S` per lane from `|A_IJ|` and its pivots `d_k`; lanes outside the normal range use logarithms.
#[inline(always)]
pub(crate) fn overlap<const D: usize, const W: usize>(
    bra: &Bra<D, impl Lane<W>>,
    ket: &Ket<D, impl Lane<W>>,
    det: &[f64; W],
    dk: &[[f64; W]; D],
) -> [f64; W] {
    let mut s = [0.0f64; W];
    let mut bad = false;
    for l in 0..W {
        s[l] = bra.norm.at(l) * ket.norm.at(l) / (det[l] * det[l].sqrt());
        bad |=
            !((det[l] >= f64::MIN_POSITIVE) & (det[l] <= f64::MAX) & (s[l] >= f64::MIN_POSITIVE) & (s[l] <= f64::MAX));
    }
    if bad {
        for l in 0..W {
            if !(det[l].is_normal() && s[l].is_normal()) {
                let log_det: f64 = dk.iter().map(|d| d[l].ln()).sum();
                s[l] = (1.5 * (D as f64 * LN_2 + 0.5 * (bra.log_det.at(l) + ket.log_det.at(l)) - log_det)).exp();
            }
        }
    }
    s
}

// --- lane helpers for the unrolled kernels: one vector operation each --------------------
#[inline(always)]
fn adds<const W: usize>(x: &impl Lane<W>, y: &impl Lane<W>) -> [f64; W] {
    std::array::from_fn(|l| x.at(l) + y.at(l))
}
#[inline(always)]
fn muls<const W: usize>(x: &impl Lane<W>, y: &impl Lane<W>) -> [f64; W] {
    std::array::from_fn(|l| x.at(l) * y.at(l))
}
#[inline(always)]
fn add<const W: usize>(x: &[f64; W], y: &[f64; W]) -> [f64; W] {
    std::array::from_fn(|l| x[l] + y[l])
}
#[inline(always)]
fn sub<const W: usize>(x: &[f64; W], y: &[f64; W]) -> [f64; W] {
    std::array::from_fn(|l| x[l] - y[l])
}
#[inline(always)]
fn mul<const W: usize>(x: &[f64; W], y: &[f64; W]) -> [f64; W] {
    std::array::from_fn(|l| x[l] * y[l])
}
#[inline(always)]
fn neg<const W: usize>(x: &[f64; W]) -> [f64; W] {
    std::array::from_fn(|l| -x[l])
}
#[inline(always)]
fn recip<const W: usize>(x: &[f64; W]) -> [f64; W] {
    std::array::from_fn(|l| 1.0 / x[l])
}

include!("unrolled.rs");

#[cfg(test)]
#[path = "kernel_tests.rs"]
pub(crate) mod tests;
