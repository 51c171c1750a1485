//! The row gradient of a plain ECG with hand-derived derivatives, in the lanes of the `pecg`
//! kernel: the trial `phi_I` as bra against `W` basis images `P phi_J` at a time, derivatives
//! along directions `dA_p` (symmetric) of `A_I` (issue 15).
//!
//! With `B = (A_I + A_J)^{-1}` (`kernel`, same factorisation) and `Z = B A_J`:
//! - `ln S = ¾ ln|A_I| + ¾ ln|A_J| − (3/2) ln|A_I + A_J| + const`, so
//!   `dS = ¾ Tr(A_I^{-1} dA) S − (3/2) Tr(B dA) S` (the first term once per trial and direction);
//! - `T = 6 τ S`, `τ = Tr(B A_I Λ A_J) = Σ_ac Z_ac (A_I Λ)_ac`; as `B A_I = 1 − Z`,
//!   `τ = Tr(Λ A_J) − Tr(Z Λ A_J)` and `dτ = Tr(dA Z Λ Z^T)`;
//! - `V = Σ_w 2 q_w / sqrt(π c_w) S`, `c_w = w^T B w`, `dc_w = −h_w^T dA h_w` with `h_w = B w`,
//!   so `d(2 q / sqrt(π c)) = 2 q / sqrt(π c) / (2 c) Tr(dA h h^T)`;
//! - `T_TI = T − cm S` with the constant `cm` of `kernel::cm_terms`.
//!
//! Summed over the images with `c_P`, every derivative is `dX = ¾ Tr(A_I^{-1} dA) X + Tr(dA G_X)`
//! with the symmetric matrices (upper triangles, accumulated per image)
//! `G_S = −(3/2) Σ c S B`, `G_T = 6 Σ c S (Z Λ Z^T − (3/2) τ B)`,
//! `G_V = Σ c S (Σ_w 2 q / sqrt(π c_w) / (2 c_w) h_w h_w^T − (3/2) v B)` with `v = V / S`,
//! contracted once per element and direction. The operations are the same, in the same order,
//! on every instruction set (`build`), so every path gives the same bits.
// index loops read best in these small dense kernels
#![allow(clippy::needless_range_loop)]
use std::f64::consts::PI;

use nalgebra::Cholesky;
use rayon::prelude::*;

use super::kernel::{self, Accumulator, Bra, KetLanes, Prepared};
use crate::ecg::{Element, Gaussian, Mat, Operators};
use crate::images::Images;
use crate::isa::{isa_available, Isa};
use crate::matrices::Matrices;

/// `W` lanes of each entry of a symmetric `D x D` matrix (upper triangle used).
type Sym<const D: usize, const W: usize> = [[[f64; W]; D]; D];

/// The operators in the gradient's form: the kernel's (`Prepared`), the non-zero `Λ_cd`, and
/// per Coulomb vector `2 q` with the non-zero `w_a`.
struct Ops<const D: usize> {
    prep: Prepared<D>,
    lambda: Vec<(usize, usize, f64)>,
    pairs: Vec<(f64, Vec<(usize, f64)>)>,
}

impl<const D: usize> Ops<D> {
    fn new(ops: &Operators<D>) -> Self {
        let nonzero = |i: usize, x: f64| (x != 0.0).then_some((i, x));
        Self {
            prep: Prepared::new(ops),
            lambda: (0..D * D)
                .filter_map(|k| nonzero(k, ops.lambda[(k / D, k % D)]))
                .map(|(k, x)| (k / D, k % D, x))
                .collect(),
            pairs: ops
                .pairs
                .iter()
                .map(|(w, q)| (2.0 * q, (0..D).filter_map(|a| nonzero(a, w[a])).collect()))
                .collect(),
        }
    }
}

/// The trial with its directions: `¾ Tr(A_I^{-1} dA_p)` (the derivative of `ln n_I`), and the
/// weights `ω_p` with `Tr(dA_p G) = Σ_{a <= b} ω_p,ab G_ab` for symmetric `G`.
struct Trial<const D: usize> {
    bra: Bra<D>,
    dlog_norm: Vec<f64>,
    weights: Vec<[[f64; D]; D]>,
}

impl<const D: usize> Trial<D> {
    fn new(f: &Gaussian<D>, da: &[Mat<D>], ops: &Ops<D>) -> Self {
        let a_inv = Cholesky::new(f.a)
            .expect("a checked positive-definite exponent")
            .inverse();
        Self {
            bra: Bra::new(f, &ops.prep),
            dlog_norm: da
                .iter()
                .map(|d| 0.75 * a_inv.component_mul(&d.transpose()).sum())
                .collect(),
            weights: da
                .iter()
                .map(|d| {
                    std::array::from_fn(|a| {
                        std::array::from_fn(|b| if a == b { d[(a, a)] } else { d[(a, b)] + d[(b, a)] })
                    })
                })
                .collect(),
        }
    }
}

/// Per-lane sums over the images of one block: the elements, `Σ c S B`, `Σ c S (Z Λ Z^T − (3/2) τ B)`
/// and `Σ c S (Σ_w ... h_w h_w^T − (3/2) v B)` (module docs).
struct Sums<const D: usize, const W: usize> {
    el: Accumulator<W>,
    gs: Sym<D, W>,
    gt: Sym<D, W>,
    gv: Sym<D, W>,
}

/// Entry `(i, j)` of a symmetric matrix stored as its upper triangle.
#[inline(always)]
fn at<const D: usize, const W: usize>(x: &Sym<D, W>, i: usize, j: usize) -> &[f64; W] {
    if i <= j {
        &x[i][j]
    } else {
        &x[j][i]
    }
}

/// Adds `coef <phi_I| 1, T, T_TI, V |ket_l>` and the image's parts of the `G_X` to `sums`.
#[inline(always)]
fn image<const D: usize, const W: usize>(
    bra: &Bra<D>,
    ket: &KetLanes<D, W>,
    ops: &Ops<D>,
    cm: &[f64; W],
    coef: f64,
    sums: &mut Sums<D, W>,
) {
    let mut m = [[[0.0f64; W]; D]; D];
    for i in 0..D {
        for j in i..D {
            for l in 0..W {
                m[i][j][l] = bra.a[i][j] + ket.a[i][j][l];
            }
        }
    }
    let (b, det, dk) = kernel::inverse::<D, W>(&m);
    // Z = B A_J and τ = Σ_ac Z_ac (A_I Λ)_ac
    let mut z = [[[0.0f64; W]; D]; D];
    let mut tau = [0.0f64; W];
    for a in 0..D {
        for c in 0..D {
            let mut x = [0.0f64; W];
            for k in 0..D {
                let (bak, akc) = (at(&b, a, k), at(&ket.a, k, c));
                for l in 0..W {
                    x[l] += bak[l] * akc[l];
                }
            }
            for l in 0..W {
                tau[l] += x[l] * bra.a_lambda[a][c];
            }
            z[a][c] = x;
        }
    }
    // Z Λ
    let mut zl = [[[0.0f64; W]; D]; D];
    for &(c, d, lam) in &ops.lambda {
        for a in 0..D {
            for l in 0..W {
                zl[a][d][l] += z[a][c][l] * lam;
            }
        }
    }
    // Coulomb: h = B w, c = w^T h, v = Σ 2 q / sqrt(π c), H = Σ 2 q / sqrt(π c) / (2 c) h h^T
    let mut v = [0.0f64; W];
    let mut hh = [[[0.0f64; W]; D]; D];
    for (q2, w) in &ops.pairs {
        let mut h = [[0.0f64; W]; D];
        for a in 0..D {
            for &(k, wk) in w {
                let bak = at(&b, a, k);
                for l in 0..W {
                    h[a][l] += bak[l] * wk;
                }
            }
        }
        let mut c = [0.0f64; W];
        for &(k, wk) in w {
            for l in 0..W {
                c[l] += wk * h[k][l];
            }
        }
        let mut kw = [0.0f64; W];
        for l in 0..W {
            let vw = q2 / (PI * c[l]).sqrt();
            v[l] += vw;
            kw[l] = 0.5 * vw / c[l];
        }
        for a in 0..D {
            for bb in a..D {
                for l in 0..W {
                    hh[a][bb][l] += kw[l] * h[a][l] * h[bb][l];
                }
            }
        }
    }
    let s = kernel::overlap::<D, W>(bra, ket, &det, &dk);
    let (mut sc, mut tb, mut vb) = ([0.0f64; W], [0.0f64; W], [0.0f64; W]);
    for l in 0..W {
        let t = 6.0 * tau[l] * s[l];
        let t_ti = t - cm[l] * s[l];
        sums.el.s[l] += coef * s[l];
        sums.el.t[l] += coef * t;
        sums.el.t_ti[l] += coef * t_ti;
        sums.el.v[l] += coef * (v[l] * s[l]);
        sc[l] = coef * s[l];
        tb[l] = 1.5 * tau[l];
        vb[l] = 1.5 * v[l];
    }
    for a in 0..D {
        for bb in a..D {
            // (Z Λ Z^T)_ab
            let mut g = [0.0f64; W];
            for d in 0..D {
                for l in 0..W {
                    g[l] += zl[a][d][l] * z[bb][d][l];
                }
            }
            for l in 0..W {
                let bab = b[a][bb][l];
                sums.gs[a][bb][l] += sc[l] * bab;
                sums.gt[a][bb][l] += sc[l] * (g[l] - tb[l] * bab);
                sums.gv[a][bb][l] += sc[l] * (hh[a][bb][l] - vb[l] * bab);
            }
        }
    }
}

/// One block of `W` basis functions: `out[0]` the symmetrised elements, `out[1 + p]` their
/// derivatives along direction `p`; `kets` the block under every operation, `coef` the `c_P`.
#[inline(always)]
fn block_generic<const D: usize, const W: usize>(
    trial: &Trial<D>,
    kets: &[KetLanes<D, W>],
    coef: &[f64],
    ops: &Ops<D>,
    out: &mut [[Element; W]],
) {
    let cm = kernel::cm_terms(&trial.bra, &kets[0], &ops.prep);
    let zero = [[[0.0f64; W]; D]; D];
    let mut sums = Sums {
        el: Accumulator::<W>::default(),
        gs: zero,
        gt: zero,
        gv: zero,
    };
    for (ket, c) in kets.iter().zip(coef) {
        image(&trial.bra, ket, ops, &cm, *c, &mut sums);
    }
    let e = &sums.el;
    for l in 0..W {
        out[0][l] = Element {
            s: e.s[l],
            t: e.t[l],
            t_ti: e.t_ti[l],
            v: e.v[l],
        };
    }
    for (p, (g0, w)) in trial.dlog_norm.iter().zip(&trial.weights).enumerate() {
        let (mut ds, mut dt, mut dv) = ([0.0f64; W], [0.0f64; W], [0.0f64; W]);
        for a in 0..D {
            for bb in a..D {
                for l in 0..W {
                    ds[l] += w[a][bb] * sums.gs[a][bb][l];
                    dt[l] += w[a][bb] * sums.gt[a][bb][l];
                    dv[l] += w[a][bb] * sums.gv[a][bb][l];
                }
            }
        }
        for l in 0..W {
            let s = g0 * e.s[l] - 1.5 * ds[l];
            let t = g0 * e.t[l] + 6.0 * dt[l];
            out[1 + p][l] = Element {
                s,
                t,
                t_ti: t - cm[l] * s,
                v: g0 * e.v[l] + dv[l],
            };
        }
    }
}

/// `block_generic` compiled for one instruction set (lanes `W`, target feature), in module `$isa`.
macro_rules! isa_block {
    ($isa:ident, $w:literal $(, $feature:literal)?) => {
        mod $isa {
            use super::*;

            /// Safety: only on a CPU with the feature (checked in `row_gradient_with`).
            $(#[target_feature(enable = $feature)])?
            pub(super) unsafe fn block<const D: usize>(
                trial: &Trial<D>,
                kets: &[KetLanes<D, $w>],
                coef: &[f64],
                ops: &Ops<D>,
                out: &mut [[Element; $w]],
            ) {
                block_generic::<D, $w>(trial, kets, coef, ops, out)
            }
        }
    };
}

isa_block!(plain, 4);
#[cfg(target_arch = "x86_64")]
isa_block!(avx2, 4, "avx2");
#[cfg(target_arch = "x86_64")]
isa_block!(avx512, 8, "avx512f");

/// The basis in the gradient's lanes for one instruction set: blocks of `W` functions, each image
/// `P` in lanes (`KetLanes`), with the images' coefficients. It depends on the basis alone, so
/// the optimiser keeps it with the basis side (`cache`).
pub struct Kets<const D: usize> {
    isa: Isa,
    nb: usize,
    coef: Vec<f64>,
    w8: Vec<Vec<KetLanes<D, 8>>>,
    w4: Vec<Vec<KetLanes<D, 4>>>,
}

impl<const D: usize> Kets<D> {
    /// `basis` in the lanes of `isa` (plain code's where the CPU lacks it).
    pub fn new(basis: &Images<Gaussian<D>>, isa: Isa) -> Self {
        let isa = if isa_available(isa) { isa } else { Isa::Plain };
        let (w8, w4) = if isa == Isa::Avx512 { (lanes(basis), vec![]) } else { (vec![], lanes(basis)) };
        Self { isa, nb: basis.len(), coef: basis.coef.clone(), w8, w4 }
    }
}

/// Blocks of `W` functions of `basis`, each image in lanes (the last block repeats its last function).
fn lanes<const D: usize, const W: usize>(basis: &Images<Gaussian<D>>) -> Vec<Vec<KetLanes<D, W>>> {
    let nb = basis.len();
    (0..nb.div_ceil(W))
        .into_par_iter()
        .map(|c| {
            (0..basis.coef.len())
                .map(|p| {
                    let g: Vec<&Gaussian<D>> = (c * W..((c + 1) * W).min(nb)).map(|j| &basis.images[j][p]).collect();
                    KetLanes::from_gaussians(&g)
                })
                .collect()
        })
        .collect()
}

/// The row of the trial `f` (bra) against the symmetrised basis `kets` and its derivatives along
/// the directions `da` of `A`: `(1 + P) x nb` matrices, row 0 the values (`path::row_gradient`'s
/// layout), on the instruction set of `kets`.
pub fn row_gradient<const D: usize>(f: &Gaussian<D>, da: &[Mat<D>], kets: &Kets<D>, ops: &Operators<D>) -> Matrices {
    let ops = Ops::new(ops);
    let trial = Trial::new(f, da, &ops);
    let (nb, coef) = (kets.nb, &kets.coef[..]);
    match kets.isa {
        // Safety (each arm): `Kets::new` chose an instruction set the CPU has.
        #[cfg(target_arch = "x86_64")]
        Isa::Avx512 => blocks(&trial, &kets.w8, nb, coef, &ops, |t, k, c, o, out| unsafe {
            avx512::block::<D>(t, k, c, o, out)
        }),
        #[cfg(target_arch = "x86_64")]
        Isa::Avx2 => blocks(&trial, &kets.w4, nb, coef, &ops, |t, k, c, o, out| unsafe {
            avx2::block::<D>(t, k, c, o, out)
        }),
        _ => blocks(&trial, &kets.w4, nb, coef, &ops, |t, k, c, o, out| unsafe {
            plain::block::<D>(t, k, c, o, out)
        }),
    }
}

/// The blocks in parallel, gathered into the matrices.
fn blocks<const D: usize, const W: usize>(
    trial: &Trial<D>,
    kets: &[Vec<KetLanes<D, W>>],
    nb: usize,
    coef: &[f64],
    ops: &Ops<D>,
    block: impl Fn(&Trial<D>, &[KetLanes<D, W>], &[f64], &Ops<D>, &mut [[Element; W]]) + Sync,
) -> Matrices {
    let rows = 1 + trial.weights.len();
    let parts: Vec<Vec<[Element; W]>> = kets
        .par_iter()
        .map(|k| {
            let mut out = vec![[Element::default(); W]; rows];
            block(trial, k, coef, ops, &mut out);
            out
        })
        .collect();
    let mut m = Matrices::zeros(rows, nb);
    for (c, out) in parts.iter().enumerate() {
        for (r, lanes) in out.iter().enumerate() {
            for (l, e) in lanes.iter().enumerate().take(nb - c * W) {
                m.set(r, c * W + l, e);
            }
        }
    }
    m
}

#[cfg(test)]
#[path = "gradient_tests.rs"]
mod tests;
