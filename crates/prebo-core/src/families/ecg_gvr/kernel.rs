//! The f64 ECG-GVR kernel of `EcgGvr::matrices` and `EcgGvr::rows`: the maths of
//! `element::element` (module docs there, docs/gvr.md) without allocation, logarithms of the
//! series or `powi` libcalls per element.
//!
//! - Per call, once: every function and symmetry image as a [`Prepared`] (`A`, `u`, `AΛ`, `Λu`,
//!   its normalisation), and the series and rules of the pairs (K_I, K_J) the call meets
//!   (`tau::Table`).
//! - Per element: `B = A_I + A_J = L D Lᵀ` (root-free Cholesky), `B⁻¹ = L⁻ᵀ D⁻¹ L⁻¹`,
//!   `ln|B| = ln Π d_k`; `x, y, z`, Ω and its derivatives by Horner in `ρ²` (`series`), the
//!   kinetic scalars of the `element` formula; per Coulomb pair `c = wᵀB⁻¹w` and `γ_I, γ_J`. This algebra
//!   runs on [`MAX_LANES`] symmetry images of a ket at once, structure of arrays (`lanes`), each
//!   lane with the bits of the one-image kernel; the Coulomb τ-integrals in `tau`.
//!
//! The lanes are `[f64; W]` arrays (no fused multiply-add), instantiated per instruction set
//! (`build`, chosen with `isa::best_isa`): every path gives the same bits.
#![allow(clippy::needless_range_loop)]
use std::f64::consts::PI;

use super::element::{functions, log_s0, GvrFunction, GvrOps, GvrParams};
use super::series::{cm_kinetic, omega};
use crate::ecg::{Element, Operators};
use crate::error::Result;
use crate::params::Symmetry;
use crate::images::Images;
use crate::lanes::{Lane, Lanes};
use super::tau::{integrals, Table, MAX_PAIRS};

/// One function (or symmetry image) prepared for the kernel.
#[derive(Clone, Debug)]
pub struct Prepared<const D: usize> {
    pub a: [[f64; D]; D],
    pub u: [f64; D],
    /// `A Λ`
    pub a_lambda: [[f64; D]; D],
    /// `Λ u`
    pub lambda_u: [f64; D],
    pub k: u32,
    pub log_norm: f64,
    pub c_a: f64,
    pub c_u: f64,
}

impl<const D: usize> Prepared<D> {
    pub fn new(f: &GvrFunction<D>, ops: &Operators<D>) -> Self {
        let a: [[f64; D]; D] = std::array::from_fn(|i| std::array::from_fn(|j| f.a[(i, j)]));
        let u: [f64; D] = std::array::from_fn(|i| f.u[i]);
        let lam = &ops.lambda;
        let a_lambda = std::array::from_fn(|i| std::array::from_fn(|j| (0..D).map(|k| a[i][k] * lam[(k, j)]).sum()));
        let lambda_u = std::array::from_fn(|i| (0..D).map(|k| lam[(i, k)] * u[k]).sum());
        Self { a, u, a_lambda, lambda_u, k: f.k, log_norm: f.log_norm, c_a: f.c_a, c_u: f.c_u }
    }
}

/// Functions with their images (as `path::images`), prepared for the kernel: the basis side of
/// builds, rows and row gradients.
pub(crate) struct Side<const D: usize> {
    pub(crate) functions: Vec<Prepared<D>>,
    pub(crate) images: Vec<Vec<Prepared<D>>>,
    pub(crate) coef: Vec<f64>,
}

impl<const D: usize> Side<D> {
    pub(crate) fn new(go: &GvrOps<D>, sym: &Symmetry<D>, p: &GvrParams) -> Result<Self> {
        let f: Images<GvrFunction<D>> = Images::new(functions(p, go)?, sym, go)?;
        let prep = |g: &GvrFunction<D>| Prepared::new(g, &go.ops);
        Ok(Self {
            functions: f.functions.iter().map(prep).collect(),
            images: f.images.iter().map(|im| im.iter().map(prep).collect()).collect(),
            coef: f.coef,
        })
    }

    pub(crate) fn powers(&self) -> Vec<u32> {
        let mut k: Vec<u32> = self.functions.iter().map(|f| f.k).collect();
        k.sort_unstable();
        k.dedup();
        k
    }
}

/// The Coulomb pairs in the kernel's form: `2q`, `w`, and the non-zero terms `(a, b, f)` of
/// `wᵀB⁻¹w = Σ f B⁻¹_ab` (`a <= b`, doubled off the diagonal).
pub struct Pairs<const D: usize> {
    pub pairs: Vec<(f64, [f64; D], Vec<(usize, usize, f64)>)>,
}

impl<const D: usize> Pairs<D> {
    pub fn new(ops: &Operators<D>) -> Self {
        let pairs = ops
            .pairs
            .iter()
            .zip(ops.coulomb_terms())
            .map(|((w, _), (q2, terms))| (q2, std::array::from_fn(|i| w[i]), terms))
            .collect::<Vec<_>>();
        assert!(pairs.len() <= MAX_PAIRS, "at most {MAX_PAIRS} Coulomb pairs");
        Self { pairs }
    }
}

/// `B⁻¹` (full) and `|B|` of `B = L D Lᵀ`, with the pivots; `None` unless every pivot of every
/// lane is positive and finite.
#[inline(always)]
fn inverse_det<T: Lane, const D: usize>(m: &[[T; D]; D]) -> Option<([[T; D]; D], T, [T; D])> {
    let zero = T::splat(0.0);
    let mut lo = [[zero; D]; D];
    let mut e = [[zero; D]; D];
    let mut rd = [zero; D];
    let mut dk = [zero; D];
    let mut det = T::splat(1.0);
    for k in 0..D {
        for i in k..D {
            let mut v = m[k][i];
            for r in 0..k {
                v = v - e[i][r] * lo[k][r];
            }
            if i == k {
                if !v.all(|v| v > 0.0 && v.is_finite()) {
                    return None;
                }
                rd[k] = T::splat(1.0) / v;
                dk[k] = v;
                det = det * v;
            } else {
                e[i][k] = v;
                lo[i][k] = v * rd[k];
            }
        }
    }
    // L⁻¹ (unit lower triangular)
    let mut inv = [[zero; D]; D];
    for k in 0..D {
        inv[k][k] = T::splat(1.0);
        for i in (k + 1)..D {
            let mut x = -lo[i][k];
            for r in (k + 1)..i {
                x = x - lo[i][r] * inv[r][k];
            }
            inv[i][k] = x;
        }
    }
    // B⁻¹_ab = Σ_{k >= max(a, b)} (L⁻¹)_ka (L⁻¹)_kb / d_k
    let mut b = [[zero; D]; D];
    for a in 0..D {
        for c in a..D {
            let mut x = zero;
            for k in c..D {
                x = x + inv[k][a] * inv[k][c] * rd[k];
            }
            b[a][c] = x;
            b[c][a] = x;
        }
    }
    Some((b, det, dk))
}

/// `B⁻¹` and `ln|B|` ([`inverse_det`]; the log of the product, or the sum of the pivots' logs
/// where the product under- or overflows).
#[inline(always)]
pub(crate) fn inverse_log_det<T: Lane, const D: usize>(m: &[[T; D]; D]) -> Option<([[T; D]; D], T)> {
    let (inv, det, dk) = inverse_det(m)?;
    let log_det = T::from_lanes(|l| {
        let det = det.lane(l);
        if det.is_normal() { det.ln() } else { dk.map(|d| d.lane(l)).iter().map(|d| d.ln()).sum() }
    });
    Some((inv, log_det))
}

#[inline(always)]
pub(crate) fn dot<T: Lane, const D: usize>(p: &[T; D], q: &[T; D]) -> T {
    (0..D).fold(T::splat(0.0), |acc, k| acc + p[k] * q[k])
}

#[inline(always)]
pub(crate) fn mat_vec<T: Lane, const D: usize>(m: &[[T; D]; D], v: &[T; D]) -> [T; D] {
    std::array::from_fn(|i| dot(&m[i], v))
}

/// The fields of `T::L` kets (symmetry images of one function) in lanes.
pub(crate) struct Ket<T, const D: usize> {
    pub(crate) a: [[T; D]; D],
    pub(crate) u: [T; D],
    pub(crate) lambda_u: [T; D],
    pub(crate) log_norm: T,
    pub(crate) c_a: T,
    pub(crate) c_u: T,
}

impl<T: Lane, const D: usize> Ket<T, D> {
    #[inline(always)]
    pub(crate) fn new(kets: &[Prepared<D>]) -> Self {
        let v = |f: &dyn Fn(&Prepared<D>) -> f64| T::from_lanes(|l| f(&kets[l]));
        Self {
            a: std::array::from_fn(|i| std::array::from_fn(|j| v(&|k| k.a[i][j]))),
            u: std::array::from_fn(|i| v(&|k| k.u[i])),
            lambda_u: std::array::from_fn(|i| v(&|k| k.lambda_u[i])),
            log_norm: v(&|k| k.log_norm),
            c_a: v(&|k| k.c_a),
            c_u: v(&|k| k.c_u),
        }
    }
}

/// `<φ_I| 1, T, T_TI, V |φ_J>` of `bra` with each of `kets` (`T::L` of them, one power K), in
/// lanes (`element::element`'s formulas); `None` where some `A_I + A_J` is not positive definite.
#[inline(always)]
fn elements<const D: usize, const W: usize, T: Lane>(
    bra: &Prepared<D>,
    kets: &[Prepared<D>],
    table: &Table,
    pairs: &Pairs<D>,
    cm_mass: Option<f64>,
) -> Option<Element<T>> {
    let ket = Ket::<T, D>::new(kets);
    let bra_u = bra.u.map(T::splat);
    let bsum: [[T; D]; D] = std::array::from_fn(|i| std::array::from_fn(|j| ket.a[i][j] + bra.a[i][j]));
    let (binv, log_det) = inverse_log_det(&bsum)?;
    let gi = mat_vec(&binv, &bra_u);
    let gj = mat_vec(&binv, &ket.u);
    let x = dot(&bra_u, &gi) * 0.5;
    let y = dot(&ket.u, &gj) * 0.5;
    let z = dot(&bra_u, &gj) * 0.5;
    let log_s0 = log_s0::<_, D>(log_det);
    let s = table.series(bra.k, kets[0].k);
    let (l, om, ox, oy, oz) = omega(&s.terms(), x, y, z);
    let scale = (log_s0 + l - bra.log_norm - ket.log_norm).map(f64::exp);

    // kinetic with Λ (`element` module docs)
    let zl = mat_vec(&ket.a, &bra.lambda_u.map(T::splat)); // A_J Λ u_I
    let zr = mat_vec(&bra.a.map(|r| r.map(T::splat)), &ket.lambda_u); // A_I Λ u_J
    let w: [[T; D]; D] = std::array::from_fn(|i| {
        std::array::from_fn(|j| (0..D).fold(T::splat(0.0), |acc, k| acc + ket.a[k][j] * bra.a_lambda[i][k]))
    });
    let mut tr_wc = T::splat(0.0);
    for a in 0..D {
        for b in 0..D {
            tr_wc = tr_wc + binv[a][b] * w[b][a];
        }
    }
    let tr_wc = tr_wc * 0.5;
    let hi: [T; D] = std::array::from_fn(|k| gi[k] * 0.5);
    let hj: [T; D] = std::array::from_fn(|k| gj[k] * 0.5);
    let (w_hi, w_hj) = (mat_vec(&w, &hi), mat_vec(&w, &hj));
    let t = dot(&bra_u, &ket.lambda_u) * oz - dot(&zl, &hi) * 4.0 * ox - dot(&zl, &hj) * 2.0 * oz
        - dot(&zr, &hj) * 4.0 * oy
        - dot(&zr, &hi) * 2.0 * oz
        + tr_wc * 12.0 * om
        + dot(&hi, &w_hi) * 8.0 * ox
        + (dot(&hi, &w_hj) + dot(&hj, &w_hi)) * 4.0 * oz
        + dot(&hj, &w_hj) * 8.0 * oy;
    let t = scale * t;
    let t_ti = match cm_mass {
        Some(m) => t - scale * cm_kinetic(T::splat(bra.c_a), ket.c_a, T::splat(bra.c_u), ket.c_u, m, (om, ox, oy, oz)),
        None => t,
    };

    // Coulomb: the τ-quadrature of every pair, lane by lane
    let rt = (x * y).map(f64::sqrt);
    let np = pairs.pairs.len();
    let mut inputs = [[[0.0f64; 4]; MAX_PAIRS]; MAX_LANES];
    let mut factor = [T::splat(0.0); MAX_PAIRS];
    for (p, (q2, wv, terms)) in pairs.pairs.iter().enumerate() {
        let c = terms.iter().fold(T::splat(0.0), |acc, &(a, b, f)| acc + binv[a][b] * f);
        let sq = (c * 2.0).map(f64::sqrt);
        let wv = wv.map(T::splat);
        let (gam_i, gam_j) = (dot(&gi, &wv) / sq, dot(&gj, &wv) / sq);
        let (al_i, al_j, beta, delta) = (gam_i * gam_i / x, gam_j * gam_j / y, z / rt, gam_i * gam_j / rt);
        for (l, input) in inputs.iter_mut().take(T::L).enumerate() {
            input[p] = [al_i.lane(l), al_j.lane(l), beta.lane(l), delta.lane(l)];
        }
        factor[p] = T::splat(*q2) / (c * PI).map(f64::sqrt);
    }
    let mut integral = [[0.0f64; MAX_PAIRS]; MAX_LANES];
    for (input, out) in inputs.iter().zip(integral.iter_mut()).take(T::L) {
        integrals::<W>(&s, &input[..np], &mut out[..np]);
    }
    let v = (0..np).fold(T::splat(0.0), |acc, p| acc + factor[p] * T::from_lanes(|l| integral[l][p]));
    Some(Element { s: scale * om, t, t_ti, v: scale * v })
}

/// Images of one ket evaluated together in lanes.
pub(crate) const MAX_LANES: usize = 4;

/// `<φ_I| 1, T, T_TI, V |φ_J>` of two prepared functions.
#[inline(always)]
pub fn element<const D: usize, const W: usize>(
    bra: &Prepared<D>,
    ket: &Prepared<D>,
    table: &Table,
    pairs: &Pairs<D>,
    cm_mass: Option<f64>,
) -> Element {
    elements::<D, W, f64>(bra, std::slice::from_ref(ket), table, pairs, cm_mass).unwrap_or_else(Element::nan)
}

/// `Σ_P c_P <bra| O |P ket>` over the images of one ket: [`MAX_LANES`] images at a time in lanes
/// (one by one where a lane's `A_I + A_J` is not positive definite), the rest one by one, summed
/// in the order of the images (each lane has the bits of [`element`]).
#[inline(always)]
pub fn symmetrised<const D: usize, const W: usize>(
    bra: &Prepared<D>,
    images: &[Prepared<D>],
    coef: &[f64],
    table: &Table,
    pairs: &Pairs<D>,
    cm_mass: Option<f64>,
) -> Element {
    let mut e = Element::zero();
    let whole = images.len() / MAX_LANES * MAX_LANES;
    for (kets, c) in images[..whole].chunks_exact(MAX_LANES).zip(coef.chunks_exact(MAX_LANES)) {
        match elements::<D, W, Lanes<MAX_LANES>>(bra, kets, table, pairs, cm_mass) {
            Some(v) => {
                for l in 0..MAX_LANES {
                    let lane = Element { s: v.s.0[l], t: v.t.0[l], t_ti: v.t_ti.0[l], v: v.v.0[l] };
                    e += (c[l], lane);
                }
            }
            None => {
                for (ket, c) in kets.iter().zip(c) {
                    e += (*c, element::<D, W>(bra, ket, table, pairs, cm_mass));
                }
            }
        }
    }
    for (ket, c) in images[whole..].iter().zip(&coef[whole..]) {
        e += (*c, element::<D, W>(bra, ket, table, pairs, cm_mass));
    }
    e
}
