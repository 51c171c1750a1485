//! Plain ECG matrix elements (paper section "pECG"; Suzuki & Varga, Lect. Notes Phys. m54, ch. 6).
//!
//! With `phi = exp(-r^T A r)` (no 1/2, see `ecg.rs`), `A_IJ = A_I + A_J`, `B = A_IJ^{-1}`:
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
//! [`lanes`] evaluates one bra against `W` kets at once, lane by lane in structure-of-arrays
//! form, so that the compiler vectorises it (build.rs instantiates it for AVX-512, AVX2 and
//! plain x86-64 and picks one at run time). Per element it needs no `ln`, no `exp` and no
//! general inverse:
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
//! gives the same bits. [`element`] is the same kernel with one lane; [`element_reference`]
//! is the former direct implementation (nalgebra Cholesky and inverse), kept for tests.
// index loops read best in these small dense kernels
#![allow(clippy::needless_range_loop, clippy::type_complexity)]
use std::f64::consts::{LN_2, PI};

use nalgebra::Cholesky;

use crate::ecg::{Element, Gaussian, Operators};

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

/// The former implementation (Cholesky factor and inverse from nalgebra, `exp`/`ln` for `S`).
pub fn element_reference<const D: usize>(bra: &Gaussian<D>, ket: &Gaussian<D>, ops: &Operators<D>) -> Element {
    let a_ij = bra.a + ket.a;
    let chol = Cholesky::new(a_ij).expect("A_I + A_J of positive-definite A_I, A_J");
    let l = chol.l_dirty();
    let mut log_det_ij = 0.0;
    for k in 0..D {
        log_det_ij += 2.0 * l[(k, k)].ln();
    }
    let s = (1.5 * (D as f64 * LN_2 + 0.5 * (bra.log_det + ket.log_det) - log_det_ij)).exp();
    let b = chol.inverse();
    let x = bra.a * ops.lambda * ket.a;
    let r = b.component_mul(&x.transpose()).sum(); // Tr(B X)
    let t = 6.0 * r * s;
    let t_ti = match ops.cm_mass {
        Some(m_tot) => t - 3.0 * bra.c_a * ket.c_a / ((bra.c_a + ket.c_a) * m_tot) * s,
        None => t,
    };
    let mut v = 0.0;
    for (w, q) in &ops.pairs {
        let c = (w.transpose() * b * w)[(0, 0)];
        v += q * 2.0 / (PI * c).sqrt();
    }
    Element { s, t, t_ti, v: v * s }
}

/// The operators in the kernel's form: `Λ` as rows, Coulomb pairs as sparse `w_a w_b` terms.
#[derive(Clone, Debug)]
pub struct Prepared<const D: usize> {
    pub lambda: [[f64; D]; D],
    /// per pair: `2 q` and the terms `(a, b, f)` with `a <= b`, `f = w_a w_b` (doubled off the diagonal)
    pub pairs: Vec<(f64, Vec<(usize, usize, f64)>)>,
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
        let pairs = ops
            .pairs
            .iter()
            .map(|(w, q)| {
                let mut terms = Vec::new();
                for a in 0..D {
                    for b in a..D {
                        let f = if a == b { w[a] * w[a] } else { 2.0 * w[a] * w[b] };
                        if f != 0.0 {
                            terms.push((a, b, f));
                        }
                    }
                }
                (2.0 * q, terms)
            })
            .collect();
        Self {
            lambda,
            pairs,
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

/// A bra with its per-function precomputations.
#[derive(Clone, Debug)]
pub struct Bra<const D: usize> {
    pub a: [[f64; D]; D],
    /// `A Λ`
    pub a_lambda: [[f64; D]; D],
    pub norm: f64,
    pub log_det: f64,
    pub c_a: f64,
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

/// `W` kets in structure-of-arrays form: `a[i][j][lane]` (upper triangle used).
#[derive(Clone, Debug)]
pub struct KetLanes<const D: usize, const W: usize> {
    pub a: [[[f64; W]; D]; D],
    pub norm: [f64; W],
    pub log_det: [f64; W],
    pub c_a: [f64; W],
}

impl<const D: usize, const W: usize> KetLanes<D, W> {
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
pub fn cm_terms<const D: usize, const W: usize>(bra: &Bra<D>, ket: &KetLanes<D, W>, ops: &Prepared<D>) -> [f64; W] {
    let mut cm = [0.0f64; W];
    if let Some(m_tot) = ops.cm_mass {
        for l in 0..W {
            cm[l] = 3.0 * bra.c_a * ket.c_a[l] / ((bra.c_a + ket.c_a[l]) * m_tot);
        }
    }
    cm
}

/// Adds `coef * <bra| 1, T, V |ket_l>` for every lane `l` to `acc`; `cm` from [`cm_terms`].
///
/// D = 2, 3, 4 run unrolled copies of the generic code below (same operations, same order,
/// same bits), which keep the lanes in registers; other D run the loops.
#[inline(always)]
pub fn lanes<const D: usize, const W: usize>(
    bra: &Bra<D>,
    ket: &KetLanes<D, W>,
    ops: &Prepared<D>,
    cm: &[f64; W],
    coef: f64,
    acc: &mut Accumulator<W>,
) {
    // Safety of the casts: the types are identical when D is the matched value.
    unsafe {
        match D {
            2 => lanes_d2::<W>(cast(bra), cast(ket), cast(ops), cm, coef, acc),
            3 => lanes_d3::<W>(cast(bra), cast(ket), cast(ops), cm, coef, acc),
            4 => lanes_d4::<W>(cast(bra), cast(ket), cast(ops), cm, coef, acc),
            _ => lanes_generic::<D, W>(bra, ket, ops, cm, coef, acc),
        }
    }
}

#[inline(always)]
unsafe fn cast<T, U>(x: &T) -> &U {
    debug_assert_eq!(std::mem::size_of::<T>(), std::mem::size_of::<U>());
    &*(x as *const T as *const U)
}

/// The kernel with loops over the coordinates (any D); the reference for the unrolled copies.
#[inline(always)]
pub fn lanes_generic<const D: usize, const W: usize>(
    bra: &Bra<D>,
    ket: &KetLanes<D, W>,
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
                m[i][j][l] = bra.a[i][j] + ket.a[i][j][l];
            }
        }
    }
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
    // Tr(B A_I Λ A_J) = Σ_ab B_ab Σ_c (A_I Λ)_bc (A_J)_ca
    let mut tr = [0.0f64; W];
    for a in 0..D {
        for bb in 0..D {
            let bab = if a <= bb { &b[a][bb] } else { &b[bb][a] };
            let mut y = [0.0f64; W];
            for c in 0..D {
                let ajc = if c <= a { &ket.a[c][a] } else { &ket.a[a][c] };
                for l in 0..W {
                    y[l] += bra.a_lambda[bb][c] * ajc[l];
                }
            }
            for l in 0..W {
                tr[l] += bab[l] * y[l];
            }
        }
    }
    finish::<D, W>(bra, ket, ops, cm, coef, acc, &b, &det, &dk, &tr);
}

/// Coulomb terms, S (with the logarithmic fallback), T, T_TI; adds to `acc`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn finish<const D: usize, const W: usize>(
    bra: &Bra<D>,
    ket: &KetLanes<D, W>,
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
    // S from the determinants; lanes outside the normal range use logarithms
    let mut s = [0.0f64; W];
    let mut bad = false;
    for l in 0..W {
        s[l] = bra.norm * ket.norm[l] / (det[l] * det[l].sqrt());
        bad |=
            !((det[l] >= f64::MIN_POSITIVE) & (det[l] <= f64::MAX) & (s[l] >= f64::MIN_POSITIVE) & (s[l] <= f64::MAX));
    }
    if bad {
        for l in 0..W {
            if !(det[l].is_normal() && s[l].is_normal()) {
                let log_det: f64 = dk.iter().map(|d| d[l].ln()).sum();
                s[l] = (1.5 * (D as f64 * LN_2 + 0.5 * (bra.log_det + ket.log_det[l]) - log_det)).exp();
            }
        }
    }
    for l in 0..W {
        let t = 6.0 * tr[l] * s[l];
        let t_ti = t - cm[l] * s[l];
        acc.s[l] += coef * s[l];
        acc.t[l] += coef * t;
        acc.t_ti[l] += coef * t_ti;
        acc.v[l] += coef * (v[l] * s[l]);
    }
}

// --- lane helpers for the unrolled kernels: one vector operation each --------------------
#[inline(always)]
fn adds<const W: usize>(x: f64, y: &[f64; W]) -> [f64; W] {
    std::array::from_fn(|l| x + y[l])
}
#[inline(always)]
fn muls<const W: usize>(x: f64, y: &[f64; W]) -> [f64; W] {
    std::array::from_fn(|l| x * y[l])
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

// --- unrolled copies of `lanes_generic` for D = 2, 3, 4 ------------------------------------
// Generated mechanically: each statement of `lanes_generic` with its loops over the
// coordinates unrolled, one `let` per intermediate, `0 + x` written `x` and `1 * x` written
// `x` (both exact). `unrolled_kernels_equal_the_loops_bit_for_bit` checks them against the
// loops; after a change to `lanes_generic`, regenerate or edit them to match.
/// `lanes` for D = 2, unrolled (generated from the generic kernel, same operations in the same order).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn lanes_d2<const W: usize>(
    bra: &Bra<2>,
    ket: &KetLanes<2, W>,
    ops: &Prepared<2>,
    cm: &[f64; W],
    coef: f64,
    acc: &mut Accumulator<W>,
) {
    let ka = &ket.a;
    let ba = &bra.a;
    let al = &bra.a_lambda;
    let m00 = adds(ba[0][0], &ka[0][0]);
    let m01 = adds(ba[0][1], &ka[0][1]);
    let m11 = adds(ba[1][1], &ka[1][1]);
    let det = [1.0f64; W];
    let rd0 = recip(&m00);
    let det = mul(&det, &m00);
    let lo10 = mul(&m01, &rd0);
    let v11_0 = sub(&m11, &mul(&m01, &lo10));
    let rd1 = recip(&v11_0);
    let det = mul(&det, &v11_0);
    let iv10 = neg(&lo10);
    let b00_0 = rd0;
    let b00_1 = add(&b00_0, &mul(&mul(&iv10, &iv10), &rd1));
    let b00 = b00_1;
    let b01_1 = mul(&iv10, &rd1);
    let b01 = b01_1;
    let b11_1 = rd1;
    let b11 = b11_1;
    let y00_0 = muls(al[0][0], &ka[0][0]);
    let y00_1 = add(&y00_0, &muls(al[0][1], &ka[0][1]));
    let tr00 = mul(&b00, &y00_1);
    let y01_0 = muls(al[1][0], &ka[0][0]);
    let y01_1 = add(&y01_0, &muls(al[1][1], &ka[0][1]));
    let tr01 = add(&tr00, &mul(&b01, &y01_1));
    let y10_0 = muls(al[0][0], &ka[0][1]);
    let y10_1 = add(&y10_0, &muls(al[0][1], &ka[1][1]));
    let tr10 = add(&tr01, &mul(&b01, &y10_1));
    let y11_0 = muls(al[1][0], &ka[0][1]);
    let y11_1 = add(&y11_0, &muls(al[1][1], &ka[1][1]));
    let tr11 = add(&tr10, &mul(&b11, &y11_1));
    let tr = tr11;
    let b = [[b00, b01], [b01, b11]];
    finish::<2, W>(bra, ket, ops, cm, coef, acc, &b, &det, &[m00, v11_0], &tr);
}

/// `lanes` for D = 3, unrolled (generated from the generic kernel, same operations in the same order).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn lanes_d3<const W: usize>(
    bra: &Bra<3>,
    ket: &KetLanes<3, W>,
    ops: &Prepared<3>,
    cm: &[f64; W],
    coef: f64,
    acc: &mut Accumulator<W>,
) {
    let ka = &ket.a;
    let ba = &bra.a;
    let al = &bra.a_lambda;
    let m00 = adds(ba[0][0], &ka[0][0]);
    let m01 = adds(ba[0][1], &ka[0][1]);
    let m02 = adds(ba[0][2], &ka[0][2]);
    let m11 = adds(ba[1][1], &ka[1][1]);
    let m12 = adds(ba[1][2], &ka[1][2]);
    let m22 = adds(ba[2][2], &ka[2][2]);
    let det = [1.0f64; W];
    let rd0 = recip(&m00);
    let det = mul(&det, &m00);
    let lo10 = mul(&m01, &rd0);
    let lo20 = mul(&m02, &rd0);
    let v11_0 = sub(&m11, &mul(&m01, &lo10));
    let rd1 = recip(&v11_0);
    let det = mul(&det, &v11_0);
    let v12_0 = sub(&m12, &mul(&m02, &lo10));
    let lo21 = mul(&v12_0, &rd1);
    let v22_0 = sub(&m22, &mul(&m02, &lo20));
    let v22_1 = sub(&v22_0, &mul(&v12_0, &lo21));
    let rd2 = recip(&v22_1);
    let det = mul(&det, &v22_1);
    let iv10 = neg(&lo10);
    let iv20_0 = neg(&lo20);
    let iv20_1 = sub(&iv20_0, &mul(&lo21, &iv10));
    let iv20 = iv20_1;
    let iv21 = neg(&lo21);
    let b00_0 = rd0;
    let b00_1 = add(&b00_0, &mul(&mul(&iv10, &iv10), &rd1));
    let b00_2 = add(&b00_1, &mul(&mul(&iv20, &iv20), &rd2));
    let b00 = b00_2;
    let b01_1 = mul(&iv10, &rd1);
    let b01_2 = add(&b01_1, &mul(&mul(&iv20, &iv21), &rd2));
    let b01 = b01_2;
    let b02_2 = mul(&iv20, &rd2);
    let b02 = b02_2;
    let b11_1 = rd1;
    let b11_2 = add(&b11_1, &mul(&mul(&iv21, &iv21), &rd2));
    let b11 = b11_2;
    let b12_2 = mul(&iv21, &rd2);
    let b12 = b12_2;
    let b22_2 = rd2;
    let b22 = b22_2;
    let y00_0 = muls(al[0][0], &ka[0][0]);
    let y00_1 = add(&y00_0, &muls(al[0][1], &ka[0][1]));
    let y00_2 = add(&y00_1, &muls(al[0][2], &ka[0][2]));
    let tr00 = mul(&b00, &y00_2);
    let y01_0 = muls(al[1][0], &ka[0][0]);
    let y01_1 = add(&y01_0, &muls(al[1][1], &ka[0][1]));
    let y01_2 = add(&y01_1, &muls(al[1][2], &ka[0][2]));
    let tr01 = add(&tr00, &mul(&b01, &y01_2));
    let y02_0 = muls(al[2][0], &ka[0][0]);
    let y02_1 = add(&y02_0, &muls(al[2][1], &ka[0][1]));
    let y02_2 = add(&y02_1, &muls(al[2][2], &ka[0][2]));
    let tr02 = add(&tr01, &mul(&b02, &y02_2));
    let y10_0 = muls(al[0][0], &ka[0][1]);
    let y10_1 = add(&y10_0, &muls(al[0][1], &ka[1][1]));
    let y10_2 = add(&y10_1, &muls(al[0][2], &ka[1][2]));
    let tr10 = add(&tr02, &mul(&b01, &y10_2));
    let y11_0 = muls(al[1][0], &ka[0][1]);
    let y11_1 = add(&y11_0, &muls(al[1][1], &ka[1][1]));
    let y11_2 = add(&y11_1, &muls(al[1][2], &ka[1][2]));
    let tr11 = add(&tr10, &mul(&b11, &y11_2));
    let y12_0 = muls(al[2][0], &ka[0][1]);
    let y12_1 = add(&y12_0, &muls(al[2][1], &ka[1][1]));
    let y12_2 = add(&y12_1, &muls(al[2][2], &ka[1][2]));
    let tr12 = add(&tr11, &mul(&b12, &y12_2));
    let y20_0 = muls(al[0][0], &ka[0][2]);
    let y20_1 = add(&y20_0, &muls(al[0][1], &ka[1][2]));
    let y20_2 = add(&y20_1, &muls(al[0][2], &ka[2][2]));
    let tr20 = add(&tr12, &mul(&b02, &y20_2));
    let y21_0 = muls(al[1][0], &ka[0][2]);
    let y21_1 = add(&y21_0, &muls(al[1][1], &ka[1][2]));
    let y21_2 = add(&y21_1, &muls(al[1][2], &ka[2][2]));
    let tr21 = add(&tr20, &mul(&b12, &y21_2));
    let y22_0 = muls(al[2][0], &ka[0][2]);
    let y22_1 = add(&y22_0, &muls(al[2][1], &ka[1][2]));
    let y22_2 = add(&y22_1, &muls(al[2][2], &ka[2][2]));
    let tr22 = add(&tr21, &mul(&b22, &y22_2));
    let tr = tr22;
    let b = [[b00, b01, b02], [b01, b11, b12], [b02, b12, b22]];
    finish::<3, W>(bra, ket, ops, cm, coef, acc, &b, &det, &[m00, v11_0, v22_1], &tr);
}

/// `lanes` for D = 4, unrolled (generated from the generic kernel, same operations in the same order).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn lanes_d4<const W: usize>(
    bra: &Bra<4>,
    ket: &KetLanes<4, W>,
    ops: &Prepared<4>,
    cm: &[f64; W],
    coef: f64,
    acc: &mut Accumulator<W>,
) {
    let ka = &ket.a;
    let ba = &bra.a;
    let al = &bra.a_lambda;
    let m00 = adds(ba[0][0], &ka[0][0]);
    let m01 = adds(ba[0][1], &ka[0][1]);
    let m02 = adds(ba[0][2], &ka[0][2]);
    let m03 = adds(ba[0][3], &ka[0][3]);
    let m11 = adds(ba[1][1], &ka[1][1]);
    let m12 = adds(ba[1][2], &ka[1][2]);
    let m13 = adds(ba[1][3], &ka[1][3]);
    let m22 = adds(ba[2][2], &ka[2][2]);
    let m23 = adds(ba[2][3], &ka[2][3]);
    let m33 = adds(ba[3][3], &ka[3][3]);
    let det = [1.0f64; W];
    let rd0 = recip(&m00);
    let det = mul(&det, &m00);
    let lo10 = mul(&m01, &rd0);
    let lo20 = mul(&m02, &rd0);
    let lo30 = mul(&m03, &rd0);
    let v11_0 = sub(&m11, &mul(&m01, &lo10));
    let rd1 = recip(&v11_0);
    let det = mul(&det, &v11_0);
    let v12_0 = sub(&m12, &mul(&m02, &lo10));
    let lo21 = mul(&v12_0, &rd1);
    let v13_0 = sub(&m13, &mul(&m03, &lo10));
    let lo31 = mul(&v13_0, &rd1);
    let v22_0 = sub(&m22, &mul(&m02, &lo20));
    let v22_1 = sub(&v22_0, &mul(&v12_0, &lo21));
    let rd2 = recip(&v22_1);
    let det = mul(&det, &v22_1);
    let v23_0 = sub(&m23, &mul(&m03, &lo20));
    let v23_1 = sub(&v23_0, &mul(&v13_0, &lo21));
    let lo32 = mul(&v23_1, &rd2);
    let v33_0 = sub(&m33, &mul(&m03, &lo30));
    let v33_1 = sub(&v33_0, &mul(&v13_0, &lo31));
    let v33_2 = sub(&v33_1, &mul(&v23_1, &lo32));
    let rd3 = recip(&v33_2);
    let det = mul(&det, &v33_2);
    let iv10 = neg(&lo10);
    let iv20_0 = neg(&lo20);
    let iv20_1 = sub(&iv20_0, &mul(&lo21, &iv10));
    let iv20 = iv20_1;
    let iv30_0 = neg(&lo30);
    let iv30_1 = sub(&iv30_0, &mul(&lo31, &iv10));
    let iv30_2 = sub(&iv30_1, &mul(&lo32, &iv20));
    let iv30 = iv30_2;
    let iv21 = neg(&lo21);
    let iv31_0 = neg(&lo31);
    let iv31_1 = sub(&iv31_0, &mul(&lo32, &iv21));
    let iv31 = iv31_1;
    let iv32 = neg(&lo32);
    let b00_0 = rd0;
    let b00_1 = add(&b00_0, &mul(&mul(&iv10, &iv10), &rd1));
    let b00_2 = add(&b00_1, &mul(&mul(&iv20, &iv20), &rd2));
    let b00_3 = add(&b00_2, &mul(&mul(&iv30, &iv30), &rd3));
    let b00 = b00_3;
    let b01_1 = mul(&iv10, &rd1);
    let b01_2 = add(&b01_1, &mul(&mul(&iv20, &iv21), &rd2));
    let b01_3 = add(&b01_2, &mul(&mul(&iv30, &iv31), &rd3));
    let b01 = b01_3;
    let b02_2 = mul(&iv20, &rd2);
    let b02_3 = add(&b02_2, &mul(&mul(&iv30, &iv32), &rd3));
    let b02 = b02_3;
    let b03_3 = mul(&iv30, &rd3);
    let b03 = b03_3;
    let b11_1 = rd1;
    let b11_2 = add(&b11_1, &mul(&mul(&iv21, &iv21), &rd2));
    let b11_3 = add(&b11_2, &mul(&mul(&iv31, &iv31), &rd3));
    let b11 = b11_3;
    let b12_2 = mul(&iv21, &rd2);
    let b12_3 = add(&b12_2, &mul(&mul(&iv31, &iv32), &rd3));
    let b12 = b12_3;
    let b13_3 = mul(&iv31, &rd3);
    let b13 = b13_3;
    let b22_2 = rd2;
    let b22_3 = add(&b22_2, &mul(&mul(&iv32, &iv32), &rd3));
    let b22 = b22_3;
    let b23_3 = mul(&iv32, &rd3);
    let b23 = b23_3;
    let b33_3 = rd3;
    let b33 = b33_3;
    let y00_0 = muls(al[0][0], &ka[0][0]);
    let y00_1 = add(&y00_0, &muls(al[0][1], &ka[0][1]));
    let y00_2 = add(&y00_1, &muls(al[0][2], &ka[0][2]));
    let y00_3 = add(&y00_2, &muls(al[0][3], &ka[0][3]));
    let tr00 = mul(&b00, &y00_3);
    let y01_0 = muls(al[1][0], &ka[0][0]);
    let y01_1 = add(&y01_0, &muls(al[1][1], &ka[0][1]));
    let y01_2 = add(&y01_1, &muls(al[1][2], &ka[0][2]));
    let y01_3 = add(&y01_2, &muls(al[1][3], &ka[0][3]));
    let tr01 = add(&tr00, &mul(&b01, &y01_3));
    let y02_0 = muls(al[2][0], &ka[0][0]);
    let y02_1 = add(&y02_0, &muls(al[2][1], &ka[0][1]));
    let y02_2 = add(&y02_1, &muls(al[2][2], &ka[0][2]));
    let y02_3 = add(&y02_2, &muls(al[2][3], &ka[0][3]));
    let tr02 = add(&tr01, &mul(&b02, &y02_3));
    let y03_0 = muls(al[3][0], &ka[0][0]);
    let y03_1 = add(&y03_0, &muls(al[3][1], &ka[0][1]));
    let y03_2 = add(&y03_1, &muls(al[3][2], &ka[0][2]));
    let y03_3 = add(&y03_2, &muls(al[3][3], &ka[0][3]));
    let tr03 = add(&tr02, &mul(&b03, &y03_3));
    let y10_0 = muls(al[0][0], &ka[0][1]);
    let y10_1 = add(&y10_0, &muls(al[0][1], &ka[1][1]));
    let y10_2 = add(&y10_1, &muls(al[0][2], &ka[1][2]));
    let y10_3 = add(&y10_2, &muls(al[0][3], &ka[1][3]));
    let tr10 = add(&tr03, &mul(&b01, &y10_3));
    let y11_0 = muls(al[1][0], &ka[0][1]);
    let y11_1 = add(&y11_0, &muls(al[1][1], &ka[1][1]));
    let y11_2 = add(&y11_1, &muls(al[1][2], &ka[1][2]));
    let y11_3 = add(&y11_2, &muls(al[1][3], &ka[1][3]));
    let tr11 = add(&tr10, &mul(&b11, &y11_3));
    let y12_0 = muls(al[2][0], &ka[0][1]);
    let y12_1 = add(&y12_0, &muls(al[2][1], &ka[1][1]));
    let y12_2 = add(&y12_1, &muls(al[2][2], &ka[1][2]));
    let y12_3 = add(&y12_2, &muls(al[2][3], &ka[1][3]));
    let tr12 = add(&tr11, &mul(&b12, &y12_3));
    let y13_0 = muls(al[3][0], &ka[0][1]);
    let y13_1 = add(&y13_0, &muls(al[3][1], &ka[1][1]));
    let y13_2 = add(&y13_1, &muls(al[3][2], &ka[1][2]));
    let y13_3 = add(&y13_2, &muls(al[3][3], &ka[1][3]));
    let tr13 = add(&tr12, &mul(&b13, &y13_3));
    let y20_0 = muls(al[0][0], &ka[0][2]);
    let y20_1 = add(&y20_0, &muls(al[0][1], &ka[1][2]));
    let y20_2 = add(&y20_1, &muls(al[0][2], &ka[2][2]));
    let y20_3 = add(&y20_2, &muls(al[0][3], &ka[2][3]));
    let tr20 = add(&tr13, &mul(&b02, &y20_3));
    let y21_0 = muls(al[1][0], &ka[0][2]);
    let y21_1 = add(&y21_0, &muls(al[1][1], &ka[1][2]));
    let y21_2 = add(&y21_1, &muls(al[1][2], &ka[2][2]));
    let y21_3 = add(&y21_2, &muls(al[1][3], &ka[2][3]));
    let tr21 = add(&tr20, &mul(&b12, &y21_3));
    let y22_0 = muls(al[2][0], &ka[0][2]);
    let y22_1 = add(&y22_0, &muls(al[2][1], &ka[1][2]));
    let y22_2 = add(&y22_1, &muls(al[2][2], &ka[2][2]));
    let y22_3 = add(&y22_2, &muls(al[2][3], &ka[2][3]));
    let tr22 = add(&tr21, &mul(&b22, &y22_3));
    let y23_0 = muls(al[3][0], &ka[0][2]);
    let y23_1 = add(&y23_0, &muls(al[3][1], &ka[1][2]));
    let y23_2 = add(&y23_1, &muls(al[3][2], &ka[2][2]));
    let y23_3 = add(&y23_2, &muls(al[3][3], &ka[2][3]));
    let tr23 = add(&tr22, &mul(&b23, &y23_3));
    let y30_0 = muls(al[0][0], &ka[0][3]);
    let y30_1 = add(&y30_0, &muls(al[0][1], &ka[1][3]));
    let y30_2 = add(&y30_1, &muls(al[0][2], &ka[2][3]));
    let y30_3 = add(&y30_2, &muls(al[0][3], &ka[3][3]));
    let tr30 = add(&tr23, &mul(&b03, &y30_3));
    let y31_0 = muls(al[1][0], &ka[0][3]);
    let y31_1 = add(&y31_0, &muls(al[1][1], &ka[1][3]));
    let y31_2 = add(&y31_1, &muls(al[1][2], &ka[2][3]));
    let y31_3 = add(&y31_2, &muls(al[1][3], &ka[3][3]));
    let tr31 = add(&tr30, &mul(&b13, &y31_3));
    let y32_0 = muls(al[2][0], &ka[0][3]);
    let y32_1 = add(&y32_0, &muls(al[2][1], &ka[1][3]));
    let y32_2 = add(&y32_1, &muls(al[2][2], &ka[2][3]));
    let y32_3 = add(&y32_2, &muls(al[2][3], &ka[3][3]));
    let tr32 = add(&tr31, &mul(&b23, &y32_3));
    let y33_0 = muls(al[3][0], &ka[0][3]);
    let y33_1 = add(&y33_0, &muls(al[3][1], &ka[1][3]));
    let y33_2 = add(&y33_1, &muls(al[3][2], &ka[2][3]));
    let y33_3 = add(&y33_2, &muls(al[3][3], &ka[3][3]));
    let tr33 = add(&tr32, &mul(&b33, &y33_3));
    let tr = tr33;
    let b = [
        [b00, b01, b02, b03],
        [b01, b11, b12, b13],
        [b02, b12, b22, b23],
        [b03, b13, b23, b33],
    ];
    finish::<4, W>(bra, ket, ops, cm, coef, acc, &b, &det, &[m00, v11_0, v22_1, v33_2], &tr);
}

#[cfg(test)]
mod tests {
    //! The lane kernel against the former implementation, the unrolled copies against the
    //! generic loops (bit for bit), and the logarithmic fallback of S.
    use super::*;
    use crate::ecg::{Mat, Vector};

    /// xorshift64*: deterministic numbers in [0, 1) without a dependency.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
        }
        fn normal(&mut self) -> f64 {
            self.next() * 2.0 - 1.0
        }
    }

    /// A positive-definite exponent: L L^T + 0.05 I with scaled random L, and c_A.
    fn gaussian<const D: usize>(rng: &mut Rng, scale: f64) -> Gaussian<D> {
        let mut l = Mat::<D>::zeros();
        for i in 0..D {
            for j in 0..=i {
                l[(i, j)] = rng.normal() * scale;
            }
        }
        let a = l * l.transpose() + Mat::<D>::identity() * 0.05;
        Gaussian::new(a, 0.3 + 2.0 * rng.next(), 0).unwrap()
    }

    /// Λ = diag(1/(2 m)) (laboratory) or a symmetric positive matrix (internal coordinates),
    /// LFCC-style pairs e_i - e_j with charges, or dense vectors.
    fn operators<const D: usize>(rng: &mut Rng, lab: bool) -> Operators<D> {
        let mut lambda = Mat::<D>::zeros();
        let mut pairs = Vec::new();
        if lab {
            for i in 0..D {
                lambda[(i, i)] = 0.5 / (1.0 + 3000.0 * rng.next());
                for j in (i + 1)..D {
                    let mut w = Vector::<D>::zeros();
                    w[i] = 1.0;
                    w[j] = -1.0;
                    pairs.push((w, if rng.next() < 0.5 { -1.0 } else { 2.0 }));
                }
            }
        } else {
            let mut b = Mat::<D>::zeros();
            for i in 0..D {
                for j in 0..D {
                    b[(i, j)] = rng.normal();
                }
            }
            lambda = b * b.transpose() * 0.1 + Mat::<D>::identity() * 0.01;
            for _ in 0..3 {
                let w = Vector::<D>::from_fn(|_, _| rng.normal());
                pairs.push((w, rng.normal()));
            }
        }
        Operators {
            lambda,
            pairs,
            cm_mass: if lab { Some(5000.0) } else { None },
        }
    }

    fn close(a: f64, b: f64, scale: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * scale.max(1e-300)
    }

    fn against_reference<const D: usize>() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15 ^ D as u64);
        for lab in [true, false] {
            let ops = operators::<D>(&mut rng, lab);
            for _ in 0..200 {
                let (x, y) = (gaussian::<D>(&mut rng, 1.0), gaussian::<D>(&mut rng, 2.0));
                let new = element(&x, &y, &ops);
                let old = element_reference(&x, &y, &ops);
                // T and V are compared on the scale of their parts (they can cancel)
                let tscale = (new.t.abs()).max(6.0 * new.s * ops.lambda.norm() * x.a.norm() * y.a.norm());
                let vscale: f64 = new.s * ops.pairs.iter().map(|(_, q)| q.abs()).sum::<f64>() * 10.0;
                assert!(close(new.s, old.s, old.s, 1e-13), "S {new:?} {old:?}");
                assert!(close(new.t, old.t, tscale, 1e-13), "T {new:?} {old:?}");
                assert!(close(new.t_ti, old.t_ti, tscale, 1e-13), "T_TI {new:?} {old:?}");
                assert!(close(new.v, old.v, vscale.max(old.v.abs()), 1e-13), "V {new:?} {old:?}");
            }
        }
    }

    #[test]
    fn kernel_matches_the_former_implementation() {
        against_reference::<1>();
        against_reference::<2>();
        against_reference::<3>();
        against_reference::<4>();
        against_reference::<5>();
        against_reference::<6>();
    }

    fn unrolled_equals_generic<const D: usize, const W: usize>() {
        let mut rng = Rng(0x1234_5678 + D as u64 * 7 + W as u64);
        for lab in [true, false] {
            let ops = operators::<D>(&mut rng, lab);
            let pre = Prepared::new(&ops);
            for _ in 0..50 {
                let bra = Bra::new(&gaussian::<D>(&mut rng, 1.5), &pre);
                let kets: Vec<Gaussian<D>> = (0..W).map(|_| gaussian::<D>(&mut rng, 1.0)).collect();
                let refs: Vec<&Gaussian<D>> = kets.iter().collect();
                let k = KetLanes::<D, W>::from_gaussians(&refs);
                let cm = cm_terms(&bra, &k, &pre);
                let (mut a, mut b) = (Accumulator::<W>::default(), Accumulator::<W>::default());
                lanes::<D, W>(&bra, &k, &pre, &cm, 0.7, &mut a);
                lanes_generic::<D, W>(&bra, &k, &pre, &cm, 0.7, &mut b);
                for l in 0..W {
                    assert_eq!(a.s[l].to_bits(), b.s[l].to_bits());
                    assert_eq!(a.t[l].to_bits(), b.t[l].to_bits());
                    assert_eq!(a.t_ti[l].to_bits(), b.t_ti[l].to_bits());
                    assert_eq!(a.v[l].to_bits(), b.v[l].to_bits());
                }
                // and every lane equals the one-lane kernel (`element`), bit for bit
                let bra_g = Gaussian {
                    a: bra_matrix(&bra),
                    log_det: bra.log_det,
                    c_a: bra.c_a,
                };
                for (l, g) in kets.iter().enumerate() {
                    let one = element(&bra_g, g, &ops);
                    assert_eq!((0.7 * one.s).to_bits(), a.s[l].to_bits());
                    assert_eq!((0.7 * one.t).to_bits(), a.t[l].to_bits());
                    assert_eq!((0.7 * one.t_ti).to_bits(), a.t_ti[l].to_bits());
                    assert_eq!((0.7 * one.v).to_bits(), a.v[l].to_bits());
                }
            }
        }
    }

    fn bra_matrix<const D: usize>(b: &Bra<D>) -> Mat<D> {
        Mat::<D>::from_fn(|i, j| b.a[i][j])
    }

    #[test]
    fn unrolled_kernels_equal_the_loops_bit_for_bit() {
        unrolled_equals_generic::<2, 1>();
        unrolled_equals_generic::<2, 8>();
        unrolled_equals_generic::<3, 1>();
        unrolled_equals_generic::<3, 4>();
        unrolled_equals_generic::<3, 8>();
        unrolled_equals_generic::<4, 1>();
        unrolled_equals_generic::<4, 4>();
        unrolled_equals_generic::<4, 8>();
    }

    #[test]
    fn overlap_falls_back_to_logarithms_outside_the_normal_range() {
        // |A_IJ| overflows for D = 8 with entries ~1e50: S still from ln|A|
        let mut rng = Rng(99);
        let ops = operators::<8>(&mut rng, true);
        let x = gaussian::<8>(&mut rng, 1.0);
        let big = Gaussian::new(x.a * 1e50, 1.0, 0).unwrap();
        let e = element(&big, &big, &ops);
        let r = element_reference(&big, &big, &ops);
        assert!(
            close(e.s, 1.0, 1.0, 1e-12) && close(r.s, 1.0, 1.0, 1e-12),
            "{e:?} {r:?}"
        );
        // a tiny overlap (far apart widths) stays finite and matches
        let small = Gaussian::new(x.a * 1e-30, 1.0, 0).unwrap();
        let e = element(&big, &small, &ops);
        let r = element_reference(&big, &small, &ops);
        assert!(close(e.s, r.s, r.s, 1e-10), "{e:?} {r:?}");
    }
}
