//! The ECG-GVR row gradient by hand-derived reverse mode (issue 15): one trial function (the
//! bra, un-transformed) against every basis image, with the derivatives along P directions
//! `(dA_p, du_p)` of its `A` and `u`. Same layout as `path::row_gradient`'s row.
//!
//! # Derivation (notation of `element` and docs/gvr.md)
//! Every output `O ∈ {S, T, T_TI, V}` of one image is `O = e^{ln S_0 − n_I − n_J} F_O`, where
//! `F_O` depends on the bra through `x, y, z`, `g_I = B⁻¹u_I`, `g_J = B⁻¹u_J`, `A_I` and `u_I`.
//! With `M = B⁻¹`, `dM = −M dA M`, `d ln|B| = Tr(M dA)`, and the adjoints `x̄, ȳ, z̄` (of the
//! covariances), `ḡ_I, ḡ_J` (of the vectors `g`), `Ḡ, ū` (explicit dependence on `A_I, u_I`):
//!
//! ```text
//!     dO = ⟨G_O, dA⟩ + g_O·du − O dn_I,
//!     G_O = Ḡ − 3/2 O M − (M ḡ_I') g_Iᵀ − (M ḡ_J') g_Jᵀ,     ⟨G, dA⟩ = Σ_ab G_ab dA_ab,
//!     g_O = ū + x̄ g_I/2 + z̄ g_J/2 + M ḡ_I',
//!     ḡ_I' = ḡ_I + x̄ u_I/2,   ḡ_J' = ḡ_J + (ȳ u_J + z̄ u_I)/2,
//! ```
//!
//! from `x = u_Iᵀg_I/2`, `y = u_Jᵀg_J/2`, `z = u_Iᵀg_J/2`, `dg_I = −M dA g_I + M du_I`,
//! `dg_J = −M dA g_J`. `G_O` and `g_O` are summed over the images (with `c_P`) and contracted with
//! each direction once per symmetrised element; `dn_I` (the bra's normalisation) once per call.
//!
//! - `S = e^{...} Ω`: `x̄ = s ω_x` etc. (`s` the element's `scale`, `ω_· = Ω_·/e^L`).
//! - `T = e^{...} (c_Ω Ω + c_x Ω_x + c_y Ω_y + c_z Ω_z)` (`element` module docs): `x̄ = s(c_Ω ω_x +
//!   c_x ω_xx + c_y ω_xy + c_z ω_xz)` etc. with Ω's second derivatives (`hessian`); the scalars of
//!   the `c`'s are bilinear in `g_I, g_J, u_I, A_I` (`kinetic`), and `Tr(A_IΛA_J M)` has the full
//!   gradient `M A_J Λ A_J M` (explicit `M A_J Λ` plus `−M A_J Λ A_I M` through `M`).
//! - `T_TI = T − T_cm`: the `c`'s of `cm_kinetic` subtracted, and `c_UI = 1ᵀu_I` adds to `ū`.
//! - `V = s Σ_w 2q/√(πc) Q(x, y, z, γ_I, γ_J)` with `Q` the τ-integral over `e^L` and its
//!   partials (`build::coulomb_partials`): `x̄ = V L_x + s Σ 2q/√(πc) Q_x` (`L_x = (K_I+N/2)/x`),
//!   `γ = g·w/√(2c)` gives `ḡ += γ̄ w/√(2c)`, and `c = wᵀMw`, `dc = −(Mw)ᵀdA(Mw)`, with
//!   `c̄ = −s 2q/√(πc) Q/(2c) − (γ̄_Iγ_I + γ̄_Jγ_J)/(2c)`.
//!
//! The algebra of one image runs on [`MAX_LANES`] symmetry images of a ket at once, structure of
//! arrays (`lanes`, as `kernel::elements`; each lane with the bits of the one-image path),
//! compiled per instruction set (`kernel`). The trial's diagonal (both sides move) stays on the
//! dual-number path (`EcgGvr::row_gradient`).
use std::f64::consts::PI;

use rayon::prelude::*;

use super::element::{functions, log_s0, series_coefficients, GvrFunction, GvrOps, GvrParams};
use super::kernel::{dot, inverse_log_det, mat_vec, Ket, Prepared, Side, MAX_LANES};
use super::tau::{derivative_series, integral_partials, padded_rule, MAX_PAIRS};
use super::series::{horner, omega, Coefficients};
use crate::cache::Cache;
use crate::ecg::{Element, Mat, Vector};
use crate::error::Result;
use crate::params::{check, matrices_of, Directions, Parameters, Symmetry};
use crate::isa::{process_isa, Isa};
use crate::lanes::{array as vector, matrix, Lane, Lanes};
use crate::matrices::Matrices;

type V<T, const D: usize> = [T; D];
type M<T, const D: usize> = [[T; D]; D];

/// `Σ_k f(k)`, summed from `k = 0`.
#[inline(always)]
fn sum<T: Lane, const D: usize>(f: impl Fn(usize) -> T) -> T {
    (0..D).fold(T::splat(0.0), |acc, k| acc + f(k))
}

/// `P Q`.
#[inline(always)]
fn mat_mul<T: Lane, const D: usize>(p: &M<T, D>, q: &M<T, D>) -> M<T, D> {
    matrix(|i, j| sum::<T, D>(|k| p[i][k] * q[k][j]))
}

/// `Pᵀ v`.
#[inline(always)]
fn tr_mul<T: Lane, const D: usize>(p: &M<T, D>, v: &V<T, D>) -> V<T, D> {
    vector(|i| sum::<T, D>(|k| p[k][i] * v[k]))
}

/// The gradient of one output with respect to the bra: `dO = ⟨G, dA⟩ + g·du` (without `dn_I`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Grad<const D: usize> {
    pub(crate) a: Mat<D>,
    pub(crate) u: Vector<D>,
}

impl<const D: usize> Grad<D> {
    fn zero() -> Self {
        Self { a: Mat::zeros(), u: Vector::zeros() }
    }

    fn along(&self, da: &Mat<D>, du: &Vector<D>) -> f64 {
        self.a.dot(da) + self.u.dot(du)
    }
}

/// `Grad` of `T::L` images in lanes.
#[derive(Clone, Copy)]
struct Gradient<T, const D: usize> {
    a: M<T, D>,
    u: V<T, D>,
}

/// The adjoints of one output of one image: `x̄, ȳ, z̄`, the explicit `Ḡ, ū`, and `ḡ_I, ḡ_J`.
#[derive(Clone, Copy)]
struct Adjoint<T, const D: usize> {
    xyz: [T; 3],
    a: M<T, D>,
    u: V<T, D>,
    gi: V<T, D>,
    gj: V<T, D>,
}

impl<T: Lane, const D: usize> Adjoint<T, D> {
    fn of_xyz(xyz: [T; 3]) -> Self {
        let zero = T::splat(0.0);
        Self { xyz, a: [[zero; D]; D], u: [zero; D], gi: [zero; D], gj: [zero; D] }
    }
}

/// The pair's series: Ω's (`Coefficients`), its second derivatives' (`hessian`), and the
/// Coulomb quadrature's `ĉ_k`, `(k+1) ĉ_{k+1}` and padded rule (`tau::padded_rule`).
pub(crate) struct Series {
    coef: Coefficients,
    c: Vec<f64>,
    /// `(k+1) ĉ_{k+1}`, the series of G' (`kernel::derivative_series`)
    dc: Vec<f64>,
    /// `ĉ_k f(K_I−k, K_J−k, N+2k)` from `k = k_0` for the six second derivatives (`hessian`),
    /// with the power of ρ that multiplies each sum
    h: [(Vec<f64>, u32); 6],
    ki: u32,
    kj: u32,
    n: u32,
    tau2: Vec<f64>,
    weight: Vec<f64>,
}

impl Series {
    fn new<const D: usize>(go: &GvrOps<D>, ki: u32, kj: u32) -> Self {
        let (tau2, weight) = padded_rule(go.rule(ki + kj + go.n_ang));
        let (coef, c) = (Coefficients::new(ki, kj, go.n_ang), series_coefficients(go, ki, kj));
        let dc = derivative_series(&c);
        let n = go.n_ang;
        // `l` = the derivatives in z; a term of negative power has f = 0 (n < l), so the sum
        // starts at k = 1 when N < l
        let moment = |l: u32, f: fn(f64, f64, f64) -> f64| {
            let k0 = usize::from(n < l);
            let terms = c.iter().enumerate().skip(k0).map(|(k, ck)| {
                let k = k as f64;
                ck * f(ki as f64 - k, kj as f64 - k, n as f64 + 2.0 * k)
            });
            (terms.collect(), n + 2 * k0 as u32 - l)
        };
        let h = [
            moment(0, |a, _, _| a * (a - 1.0)),
            moment(0, |a, b, _| a * b),
            moment(0, |_, b, _| b * (b - 1.0)),
            moment(1, |a, _, m| a * m),
            moment(1, |_, b, m| b * m),
            moment(2, |_, _, m| m * (m - 1.0)),
        ];
        Self { coef, c, dc, h, ki, kj, n, tau2, weight }
    }

    /// `e^{-L}` times Ω's second derivatives, `[ω_xx, ω_xy, ω_yy, ω_xz, ω_yz, ω_zz]`: from
    /// `Ω = Σ ĉ_k x^{a} y^{b} z^{n}` (`a = K_I−k`, `b = K_J−k`, `n = N+2k`),
    /// `e^{-L} x^{a−i} y^{b−j} z^{n−l} = ρ^{n−l} x^{−i} y^{−j} (xy)^{−l/2}`.
    #[inline(always)]
    fn hessian<T: Lane>(&self, x: T, y: T, z: T) -> [T; 6] {
        let rt = T::sqrt(x * y);
        let rho = T::clamp_unit(z / rt);
        let r = rho * rho;
        let s: [T; 6] = vector(|k| horner(&self.h[k].0, r) * T::powu(rho, self.h[k].1));
        [s[0] / (x * x), s[1] / (x * y), s[2] / (y * y), s[3] / (x * rt), s[4] / (y * rt), s[5] / (x * y)]
    }
}

/// `s (c_Ω ∇ω + c_x ∇ω_x + c_y ∇ω_y + c_z ∇ω_z)` for `∇ = (∂_x, ∂_y, ∂_z)`.
#[inline(always)]
fn xyz_bar<T: Lane>(c: [T; 4], first: [T; 3], h: &[T; 6], s: T) -> [T; 3] {
    let [xx, xy, yy, xz, yz, zz] = *h;
    [
        s * (c[0] * first[0] + c[1] * xx + c[2] * xy + c[3] * xz),
        s * (c[0] * first[1] + c[1] * xy + c[2] * yy + c[3] * yz),
        s * (c[0] * first[2] + c[1] * xz + c[2] * yz + c[3] * zz),
    ]
}

/// The values `[S, T, T_TI, V]` of the bra against `T::L` images of one ket and their gradients
/// (module docs); `None` where some `A_I + A_J` is not positive definite.
#[inline(always)]
fn images<const D: usize, const W: usize, T: Lane>(
    bra: &Prepared<D>,
    kets: &[Prepared<D>],
    ser: &Series,
    lambda: &M<f64, D>,
    go: &GvrOps<D>,
) -> Option<([T; 4], [Gradient<T, D>; 4])> {
    let ket = Ket::<T, D>::new(kets);
    let splat = |m: &M<f64, D>| matrix(|i, j| T::splat(m[i][j]));
    let (a_i, ui): (M<T, D>, V<T, D>) = (splat(&bra.a), vector(|i| T::splat(bra.u[i])));
    let uj = &ket.u;
    let (m, log_det) = inverse_log_det(&matrix(|i, j| a_i[i][j] + ket.a[i][j]))?;
    let gi = mat_vec(&m, &ui);
    let gj = mat_vec(&m, uj);
    let x = dot(&ui, &gi) * 0.5;
    let y = dot(uj, &gj) * 0.5;
    let z = dot(&ui, &gj) * 0.5;
    let log_s0 = log_s0::<_, D>(log_det);
    let (l, om, ox, oy, oz) = omega(&ser.coef.terms(), x, y, z);
    let scale = (log_s0 + l - bra.log_norm - ket.log_norm).map(f64::exp);
    let hess = ser.hessian(x, y, z);
    let first = [ox, oy, oz];
    let s = scale * om;

    // kinetic (`element::element`): T/scale = λ ω_z − 4 p2 ω_x − 2 p3 ω_z − 4 p4 ω_y − 2 p5 ω_z
    //                                    + 12 tr ω + 8 p7 ω_x + 4 p8 ω_z + 8 p9 ω_y
    let lam_uj = &ket.lambda_u;
    let zl = mat_vec(&ket.a, &vector(|i| T::splat(bra.lambda_u[i]))); // A_J Λ u_I
    let zr = mat_vec(&a_i, lam_uj); // A_I Λ u_J
    let lam_aj = matrix(|i, j| T::from_lanes(|l| kets[l].a_lambda[j][i])); // Λ A_J = (A_J Λ)ᵀ
    let w = mat_mul(&splat(&bra.a_lambda), &ket.a); // W = A_I Λ A_J
    let tr = sum::<T, D>(|a| sum::<T, D>(|b| m[a][b] * w[b][a])) * 0.5;
    let (hi, hj): (V<T, D>, V<T, D>) = (vector(|k| gi[k] * 0.5), vector(|k| gj[k] * 0.5));
    let (w_hi, w_hj) = (mat_vec(&w, &hi), mat_vec(&w, &hj));
    let p = [
        dot(&ui, lam_uj),
        dot(&zl, &hi),
        dot(&zl, &hj),
        dot(&zr, &hj),
        dot(&zr, &hi),
        dot(&hi, &w_hi),
        dot(&hi, &w_hj) + dot(&hj, &w_hi),
        dot(&hj, &w_hj),
    ];
    let t = p[0] * oz - p[1] * 4.0 * ox - p[2] * 2.0 * oz - p[3] * 4.0 * oy - p[4] * 2.0 * oz
        + tr * 12.0 * om
        + p[5] * 8.0 * ox
        + p[6] * 4.0 * oz
        + p[7] * 8.0 * oy;
    let t = scale * t;
    let c_t = [tr * 12.0, p[5] * 8.0 - p[1] * 4.0, p[7] * 8.0 - p[3] * 4.0, p[0] - p[2] * 2.0 - p[4] * 2.0 + p[6] * 4.0];
    let sw = [scale * om, scale * ox, scale * oy, scale * oz];
    let kin = kinetic(&ket.a, &splat(lambda), &m, &gi, &gj, sw, (lam_uj, &zl, &zr, &lam_aj, &w));
    let mut adj_t = kin;
    adj_t.xyz = xyz_bar(c_t, first, &hess, scale);

    // T_TI = T − T_cm: T_cm/scale = Σ c_cm · (ω, ω_x, ω_y, ω_z) (`series::cm_kinetic`)
    let (t_ti, adj_ti) = match go.ops.cm_mass {
        Some(mt) => {
            let (ci, cj, cui, cuj) = (T::splat(bra.c_a), ket.c_a, T::splat(bra.c_u), ket.c_u);
            let (ms, ms2) = ((ci + cj) * mt, (ci + cj) * mt * (ci + cj));
            let (fx, fy) = (ci * cj / ms2 - cj / ms, ci * cj / ms2 - ci / ms);
            let c_cm = [ci * 3.0 * cj / ms, cui * cui * fx, cuj * cuj * fy, ci * cj * cui * cuj / ms2];
            let t_cm = scale * (c_cm[0] * om + c_cm[1] * ox + c_cm[2] * oy + c_cm[3] * oz);
            let mut adj = kin;
            adj.xyz = xyz_bar(vector(|k| c_t[k] - c_cm[k]), first, &hess, scale);
            let cui_bar = scale * (ox * cui * 2.0 * fx + oz * ci * cj * cuj / ms2);
            adj.u = vector(|k| adj.u[k] - cui_bar);
            (t - t_cm, adj)
        }
        None => (t, adj_t),
    };

    let (v, adj_v) = coulomb::<D, W, T>(go, ser, &m, &gi, &gj, [x, y, z], scale);
    let one = T::splat(1.0);
    let zero = T::splat(0.0);
    let adj_s = Adjoint::of_xyz(xyz_bar([one, zero, zero, zero], first, &hess, scale));
    let values = [s, t, t_ti, v];
    let adjs = [adj_s, adj_t, adj_ti, adj_v];
    let fold = |o: usize| fold(&adjs[o], values[o], &m, &ui, uj, &gi, &gj);
    Some((values, [fold(0), fold(1), fold(2), fold(3)]))
}

/// `(Λu_J, A_JΛu_I, A_IΛu_J, ΛA_J, A_IΛA_J)` of one image (lanes).
type KineticTerms<'a, T, const D: usize> = (&'a V<T, D>, &'a V<T, D>, &'a V<T, D>, &'a M<T, D>, &'a M<T, D>);

/// The explicit and `g`-adjoints of the kinetic scalars `p` (shared by `T` and `T_TI`) for
/// `sw = s [ω, ω_x, ω_y, ω_z]`; `xyz` left zero (module docs).
#[inline(always)]
fn kinetic<T: Lane, const D: usize>(
    a_j: &M<T, D>,
    lam: &M<T, D>,
    m: &M<T, D>,
    gi: &V<T, D>,
    gj: &V<T, D>,
    sw: [T; 4],
    (lam_uj, zl, zr, lam_aj, w): KineticTerms<T, D>,
) -> Adjoint<T, D> {
    let [s0, sx, sy, sz] = sw;
    // adjoints of λ, p2 .. p9 and tr
    let (b_lam, b2, b3, b4, b5) = (sz, sx * -4.0, sz * -2.0, sy * -4.0, sz * -2.0);
    let (b7, b8, b9, b_tr) = (sx * 8.0, sz * 4.0, sy * 8.0, s0 * 12.0);
    let ai = mat_vec(lam_aj, gi); // Λ A_J g_I
    let aj = mat_vec(lam_aj, gj);
    let (w_gi, w_gj) = (mat_vec(w, gi), mat_vec(w, gj));
    let (wt_gi, wt_gj) = (tr_mul(w, gi), tr_mul(w, gj));
    let sym_i: V<T, D> = vector(|k| w_gi[k] + wt_gi[k]); // (W + Wᵀ) g
    let sym_j: V<T, D> = vector(|k| w_gj[k] + wt_gj[k]);
    let u = vector(|k| lam_uj[k] * b_lam + (ai[k] * b2 + aj[k] * b3) * 0.5);
    let g_i = vector(|k| (zl[k] * b2 + zr[k] * b5) * 0.5 + (sym_i[k] * b7 + sym_j[k] * b8) * 0.25);
    let g_j = vector(|k| (zl[k] * b3 + zr[k] * b4) * 0.5 + (sym_i[k] * b8 + sym_j[k] * b9) * 0.25);
    // Tr(A_I Λ A_J M)/2: gradient M A_J Λ A_J M / 2 = qᵀ Λ q / 2, q = A_J M
    let q = mat_mul(a_j, m);
    let lq = mat_mul(lam, &q);
    let vi: V<T, D> = vector(|k| lam_uj[k] * (b5 * 0.5) + (ai[k] * b7 + aj[k] * b8) * 0.25);
    let vj: V<T, D> = vector(|k| lam_uj[k] * (b4 * 0.5) + (ai[k] * b8 + aj[k] * b9) * 0.25);
    let half_tr = b_tr * 0.5;
    let a = matrix(|r, c| gi[r] * vi[c] + gj[r] * vj[c] + sum::<T, D>(|k| q[k][r] * lq[k][c]) * half_tr);
    Adjoint { xyz: [T::splat(0.0); 3], a, u, gi: g_i, gj: g_j }
}

/// `V` of `T::L` images and its adjoints (module docs): every pair of every lane in one call of
/// the quadrature with partials (`kernel::integral_partials`).
#[inline(always)]
fn coulomb<const D: usize, const W: usize, T: Lane>(
    go: &GvrOps<D>,
    ser: &Series,
    m: &M<T, D>,
    gi: &V<T, D>,
    gj: &V<T, D>,
    [x, y, z]: [T; 3],
    scale: T,
) -> (T, Adjoint<T, D>) {
    let pairs = &go.ops.pairs;
    let np = pairs.len();
    assert!(np <= MAX_PAIRS, "at most {MAX_PAIRS} Coulomb pairs");
    let zero = T::splat(0.0);
    let mut mw = [[zero; D]; MAX_PAIRS];
    let mut c = [zero; MAX_PAIRS];
    let mut gam = [[zero; 2]; MAX_PAIRS];
    let mut inputs = [[0.0; 5]; MAX_LANES * MAX_PAIRS];
    for (k, (w, _)) in pairs.iter().enumerate() {
        mw[k] = vector(|i| sum::<T, D>(|j| m[i][j] * w[j]));
        c[k] = sum::<T, D>(|i| mw[k][i] * w[i]);
        let sq = (c[k] * 2.0).map(f64::sqrt);
        gam[k] = [sum::<T, D>(|i| gi[i] * w[i]) / sq, sum::<T, D>(|i| gj[i] * w[i]) / sq];
        for l in 0..T::L {
            inputs[l * np + k] = [x.lane(l), y.lane(l), z.lane(l), gam[k][0].lane(l), gam[k][1].lane(l)];
        }
    }
    let mut out = [(0.0, [0.0; 5]); MAX_LANES * MAX_PAIRS];
    let all = T::L * np;
    integral_partials::<W>((&ser.c, &ser.dc), (ser.ki, ser.kj, ser.n), &ser.tau2, &ser.weight, &inputs[..all], &mut out[..all]);
    let mut v = zero;
    let mut adj = Adjoint::of_xyz([zero; 3]);
    for (k, (w, q)) in pairs.iter().enumerate() {
        let f = T::from_lanes(|l| out[l * np + k].0);
        let d: [T; 5] = vector(|t| T::from_lanes(|l| out[l * np + k].1[t]));
        let pref = T::splat(q * 2.0) / (c[k] * PI).map(f64::sqrt);
        v = v + pref * f;
        let sp = scale * pref;
        adj.xyz = vector(|t| adj.xyz[t] + sp * d[t]);
        let sq = (c[k] * 2.0).map(f64::sqrt);
        let (bgi, bgj) = (sp * d[3], sp * d[4]);
        let (bi, bj) = (bgi / sq, bgj / sq);
        adj.gi = vector(|i| adj.gi[i] + bi * w[i]);
        adj.gj = vector(|i| adj.gj[i] + bj * w[i]);
        let c_bar = -(sp * f + bgi * gam[k][0] + bgj * gam[k][1]) / (c[k] * 2.0);
        adj.a = matrix(|i, j| adj.a[i][j] - mw[k][i] * mw[k][j] * c_bar);
    }
    let v = scale * v;
    let half_n = 0.5 * go.n_ang as f64;
    adj.xyz[0] = adj.xyz[0] + v * (ser.ki as f64 + half_n) / x;
    adj.xyz[1] = adj.xyz[1] + v * (ser.kj as f64 + half_n) / y;
    (v, adj)
}

/// `(G_O, g_O)` of one output of value `o` from its adjoints (module docs).
#[inline(always)]
fn fold<T: Lane, const D: usize>(
    adj: &Adjoint<T, D>,
    o: T,
    m: &M<T, D>,
    ui: &V<T, D>,
    uj: &V<T, D>,
    gi: &V<T, D>,
    gj: &V<T, D>,
) -> Gradient<T, D> {
    let [xb, yb, zb] = adj.xyz;
    let m_gi = mat_vec(m, &vector(|k| adj.gi[k] + ui[k] * (xb * 0.5)));
    let m_gj = mat_vec(m, &vector(|k| adj.gj[k] + uj[k] * (yb * 0.5) + ui[k] * (zb * 0.5)));
    let om = o * -1.5;
    Gradient {
        a: matrix(|i, j| adj.a[i][j] + m[i][j] * om - m_gi[i] * gi[j] - m_gj[i] * gj[j]),
        u: vector(|k| adj.u[k] + gi[k] * (xb * 0.5) + gj[k] * (zb * 0.5) + m_gi[k]),
    }
}

/// Adds `c_P` times each lane (image `P`) of `(values, grads)` to `(o, g)`, in lane order.
#[inline(always)]
fn accumulate<T: Lane, const D: usize>(
    (o, g): (&mut [f64; 4], &mut [Grad<D>; 4]),
    (values, grads): &([T; 4], [Gradient<T, D>; 4]),
    coef: &[f64],
) {
    for (l, c) in coef.iter().enumerate().take(T::L) {
        for k in 0..4 {
            o[k] += values[k].lane(l) * c;
            g[k].a += Mat::from_fn(|i, j| grads[k].a[i][j].lane(l) * c);
            g[k].u += Vector::from_fn(|i, _| grads[k].u[i].lane(l) * c);
        }
    }
}

/// `Σ_P c_P` of the values and gradients of the bra against every image of one ket:
/// [`MAX_LANES`] images at a time in lanes (one by one where a lane's `A_I + A_J` is not positive
/// definite, giving NaN for that image), the rest one by one, summed in the order of the images.
#[inline(always)]
pub(crate) fn symmetrised<const D: usize, const W: usize>(
    bra: &Prepared<D>,
    kets: &[Prepared<D>],
    coef: &[f64],
    ser: &Series,
    lambda: &M<f64, D>,
    go: &GvrOps<D>,
) -> ([f64; 4], [Grad<D>; 4]) {
    let mut o = [0.0; 4];
    let mut g = [Grad::zero(); 4];
    let one_by_one = |(o, g): (&mut [f64; 4], &mut [Grad<D>; 4]), kets: &[Prepared<D>], coef: &[f64]| {
        for (ket, c) in kets.iter().zip(coef) {
            let nan = || ([f64::NAN; 4], [Gradient { a: [[f64::NAN; D]; D], u: [f64::NAN; D] }; 4]);
            let image = images::<D, W, f64>(bra, std::slice::from_ref(ket), ser, lambda, go).unwrap_or_else(nan);
            accumulate((o, g), &image, std::slice::from_ref(c));
        }
    };
    let whole = kets.len() / MAX_LANES * MAX_LANES;
    for (kets, c) in kets[..whole].chunks_exact(MAX_LANES).zip(coef.chunks_exact(MAX_LANES)) {
        match images::<D, W, Lanes<MAX_LANES>>(bra, kets, ser, lambda, go) {
            Some(image) => accumulate((&mut o, &mut g), &image, c),
            None => one_by_one((&mut o, &mut g), kets, c),
        }
    }
    one_by_one((&mut o, &mut g), &kets[whole..], &coef[whole..]);
    (o, g)
}

/// `symmetrised` compiled for one instruction set (lanes `W`, target feature), in module `$isa`.
macro_rules! isa_kernels {
    ($isa:ident, $w:literal $(, $feature:literal)?) => {
        mod $isa {
            use super::*;

            /// Safety: callers must pass only to a CPU with the feature (checked in `kernel`).
            $(#[target_feature(enable = $feature)])?
            pub(super) unsafe fn gradient<const D: usize>(
                bra: &Prepared<D>,
                images: &[Prepared<D>],
                coef: &[f64],
                series: &Series,
                lambda: &[[f64; D]; D],
                go: &GvrOps<D>,
            ) -> ([f64; 4], [Grad<D>; 4]) {
                symmetrised::<D, $w>(bra, images, coef, series, lambda, go)
            }
        }
    };
}

isa_kernels!(plain, 4);
#[cfg(target_arch = "x86_64")]
isa_kernels!(avx2, 4, "avx2");
#[cfg(target_arch = "x86_64")]
isa_kernels!(avx512, 8, "avx512f");

/// The values `[S, T, T_TI, V]` of one trial against the images of one function and their
/// gradients (`symmetrised`).
type GradientFn<const D: usize> =
    unsafe fn(&Prepared<D>, &[Prepared<D>], &[f64], &Series, &[[f64; D]; D], &GvrOps<D>) -> ([f64; 4], [Grad<D>; 4]);

/// `symmetrised` on the best instruction set (`isa::process_isa`).
fn kernel<const D: usize>() -> GradientFn<D> {
    #[cfg(target_arch = "x86_64")]
    {
        let isa = process_isa();
        if isa == Isa::Avx512 && std::arch::is_x86_feature_detected!("avx512f") {
            return avx512::gradient::<D>;
        }
        if isa == Isa::Avx2 && std::arch::is_x86_feature_detected!("avx2") {
            return avx2::gradient::<D>;
        }
    }
    plain::gradient::<D>
}

/// `(G_n, g_n)` of the bra's `n_I = ln <φ|φ>^{1/2}` (`GvrFunction::new`): with `h = A⁻¹u`,
/// `x_n = uᵀh/4`, `n_I = −3/4 ln|A| + (K + N/2) ln x_n + const`.
fn log_norm_gradient<const D: usize>(bra: &GvrFunction<D>, n_ang: u32) -> Grad<D> {
    let ainv = bra.a.cholesky().expect("a checked function").inverse();
    let h = ainv * bra.u;
    let xn = bra.u.dot(&h) * 0.25;
    let kn = (2 * bra.k + n_ang) as f64;
    Grad { a: ainv * -0.75 - h * h.transpose() * (kn / (8.0 * xn)), u: h * (kn / (4.0 * xn)) }
}

/// The row of `EcgGvr::row_gradient` (module docs): the `(1 + P) x nb` row and its derivatives;
/// the prepared basis kept in `cache` (shared with `build::rows`).
pub fn row_gradient<const D: usize>(
    go: &GvrOps<D>,
    sym: &Symmetry<D>,
    trial: &GvrParams,
    dir: &Directions,
    basis: &GvrParams,
    cache: &Cache,
) -> Result<Matrices> {
    check(trial.len(), 1, "trial functions")?;
    let trial_fn = functions(trial, go)?.remove(0);
    let bra = Prepared::new(&trial_fn, &go.ops);
    let b = cache.get(basis, || Side::new(go, sym, basis))?;
    let (da, _) = dir.exponents::<D>()?;
    let du = matrices_of::<D, 1>(dir.v, da.len(), "global-vector directions")?;
    let k_max = b.functions.iter().map(|f| f.k).max().unwrap_or(0) as usize;
    let mut series: Vec<Option<Series>> = (0..=k_max).map(|_| None).collect();
    for f in &b.functions {
        series[f.k as usize].get_or_insert_with(|| Series::new(go, bra.k, f.k));
    }
    let gn = log_norm_gradient(&trial_fn, go.n_ang);
    let dn: Vec<f64> = da.iter().zip(&du).map(|(a, u)| gn.along(a, u)).collect();
    let lambda: M<f64, D> = matrix(|i, j| go.ops.lambda[(i, j)]);
    let kernel = kernel::<D>();
    let rows: Vec<Vec<Element>> = (0..b.functions.len())
        .into_par_iter()
        .map(|j| {
            let ser = series[b.functions[j].k as usize].as_ref().expect("every K prepared");
            // Safety: `kernel` chose an instruction set this CPU has.
            let (o, g) = unsafe { kernel(&bra, &b.images[j], &b.coef, ser, &lambda, go) };
            let el = |x: [f64; 4]| Element { s: x[0], t: x[1], t_ti: x[2], v: x[3] };
            std::iter::once(el(o))
                .chain(da.iter().zip(&du).zip(&dn).map(|((a, u), n)| el(std::array::from_fn(|k| g[k].along(a, u) - o[k] * n))))
                .collect()
        })
        .collect();
    let mut out = Matrices::zeros(1 + da.len(), b.functions.len());
    for (j, r) in rows.iter().enumerate() {
        for (i, e) in r.iter().enumerate() {
            out.set(i, j, e);
        }
    }
    Ok(out)
}

#[cfg(test)]
#[path = "gradient_tests.rs"]
mod tests;
