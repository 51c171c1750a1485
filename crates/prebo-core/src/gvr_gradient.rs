//! The ECG-GVR row gradient by hand-derived reverse mode (issue 15): one trial function (the
//! bra, un-transformed) against every basis image, with the derivatives along P directions
//! `(dA_p, du_p)` of its `A` and `u`. Same layout as `path::row_gradient`.
//!
//! # Derivation (notation of `gvr` and docs/gvr.md)
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
//! - `T = e^{...} (c_Ω Ω + c_x Ω_x + c_y Ω_y + c_z Ω_z)` (`gvr` module docs): `x̄ = s(c_Ω ω_x +
//!   c_x ω_xx + c_y ω_xy + c_z ω_xz)` etc. with Ω's second derivatives (`hessian`); the scalars of
//!   the `c`'s are bilinear in `g_I, g_J, u_I, A_I` (`kinetic`), and `Tr(A_IΛA_J M)` has the full
//!   gradient `M A_J Λ A_J M` (explicit `M A_J Λ` plus `−M A_J Λ A_I M` through `M`).
//! - `T_TI = T − T_cm`: the `c`'s of `cm_kinetic` subtracted, and `c_UI = 1ᵀu_I` adds to `ū`.
//! - `V = s Σ_w 2q/√(πc) Q(x, y, z, γ_I, γ_J)` with `Q` the τ-integral over `e^L` and its
//!   partials (`gvr::coulomb_partials`): `x̄ = V L_x + s Σ 2q/√(πc) Q_x` (`L_x = (K_I+N/2)/x`),
//!   `γ = g·w/√(2c)` gives `ḡ += γ̄ w/√(2c)`, and `c = wᵀMw`, `dc = −(Mw)ᵀdA(Mw)`, with
//!   `c̄ = −s 2q/√(πc) Q/(2c) − (γ̄_Iγ_I + γ̄_Jγ_J)/(2c)`.
//!
//! The trial's diagonal (both sides move) stays on the dual-number path (one element).
use std::f64::consts::PI;

use rayon::prelude::*;

use crate::cache::Cache;
use crate::ecg::{inverse_log_det, mul, Element, Mat, Vector};
use crate::error::Result;
use crate::family::{check, matrices_of, Directions, Family, Params, Symmetry};
use crate::gvr::{omega, series_coefficients, Coefficients, EcgGvr, Gvr, GvrOps};
use crate::gvr_build;
use crate::gvr_kernel::{derivative_series, padded_rule, MAX_PAIRS};
use crate::matrices::Matrices;
use crate::path;

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

    fn nan() -> Self {
        Self { a: Mat::repeat(f64::NAN), u: Vector::repeat(f64::NAN) }
    }

    fn add_scaled(&mut self, c: f64, o: &Self) {
        self.a += o.a * c;
        self.u += o.u * c;
    }

    fn along(&self, da: &Mat<D>, du: &Vector<D>) -> f64 {
        self.a.dot(da) + self.u.dot(du)
    }
}

/// The adjoints of one output of one image: `x̄, ȳ, z̄`, the explicit `Ḡ, ū`, and `ḡ_I, ḡ_J`.
#[derive(Clone, Copy)]
struct Adjoint<const D: usize> {
    xyz: [f64; 3],
    a: Mat<D>,
    u: Vector<D>,
    gi: Vector<D>,
    gj: Vector<D>,
}

impl<const D: usize> Adjoint<D> {
    fn of_xyz(xyz: [f64; 3]) -> Self {
        Self { xyz, a: Mat::zeros(), u: Vector::zeros(), gi: Vector::zeros(), gj: Vector::zeros() }
    }
}

/// The pair's series: `ĉ_k` for the Hessian and the Coulomb quadrature (with G''s),
/// `Coefficients` for `gvr::omega`, and the quadrature's padded rule (`gvr_kernel::padded_rule`).
pub(crate) struct Series {
    coef: Coefficients,
    c: Vec<f64>,
    /// `(k+1) ĉ_{k+1}`, the series of G' (`gvr_kernel::derivative_series`)
    dc: Vec<f64>,
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
        Self { coef, c, dc, ki, kj, n: go.n_ang, tau2, weight }
    }

    /// `e^{-L}` times Ω's second derivatives, `[ω_xx, ω_xy, ω_yy, ω_xz, ω_yz, ω_zz]`: from
    /// `Ω = Σ ĉ_k x^{a} y^{b} z^{n}` (`a = K_I−k`, `b = K_J−k`, `n = N+2k`),
    /// `e^{-L} x^{a−i} y^{b−j} z^{n−l} = ρ^{n−l} x^{−i} y^{−j} (xy)^{−l/2}`.
    fn hessian(&self, x: f64, y: f64, z: f64) -> [f64; 6] {
        let rt = (x * y).sqrt();
        let rho = (z / rt).clamp(-1.0, 1.0);
        let r = rho * rho;
        let (ki, kj, n) = (self.ki as f64, self.kj as f64, self.n);
        // Σ_k f(a, b, n) ĉ_k ρ^{n−l}; a term of negative power has f = 0 (n < l), so the sum
        // starts at k = 1 when N < l
        let sum = |l: u32, f: &dyn Fn(f64, f64, f64) -> f64| {
            let k0 = usize::from(n < l);
            let h = self.c.iter().enumerate().skip(k0).rev().fold(0.0, |acc, (k, ck)| {
                let k = k as f64;
                acc * r + ck * f(ki - k, kj - k, n as f64 + 2.0 * k)
            });
            h * rho.powi((n + 2 * k0 as u32 - l) as i32)
        };
        let sxx = sum(0, &|a, _, _| a * (a - 1.0));
        let sxy = sum(0, &|a, b, _| a * b);
        let syy = sum(0, &|_, b, _| b * (b - 1.0));
        let sxz = sum(1, &|a, _, m| a * m);
        let syz = sum(1, &|_, b, m| b * m);
        let szz = sum(2, &|_, _, m| m * (m - 1.0));
        [sxx / (x * x), sxy / (x * y), syy / (y * y), sxz / (x * rt), syz / (y * rt), szz / (x * y)]
    }
}

/// `s (c_Ω ∇ω + c_x ∇ω_x + c_y ∇ω_y + c_z ∇ω_z)` for `∇ = (∂_x, ∂_y, ∂_z)`.
fn xyz_bar(c: [f64; 4], first: [f64; 3], h: &[f64; 6], s: f64) -> [f64; 3] {
    let [xx, xy, yy, xz, yz, zz] = *h;
    [
        s * (c[0] * first[0] + c[1] * xx + c[2] * xy + c[3] * xz),
        s * (c[0] * first[1] + c[1] * xy + c[2] * yy + c[3] * yz),
        s * (c[0] * first[2] + c[1] * xz + c[2] * yz + c[3] * zz),
    ]
}

/// `u vᵀ`.
#[inline]
fn outer<const D: usize>(u: &Vector<D>, v: &Vector<D>) -> Mat<D> {
    Mat::from_fn(|i, j| u[i] * v[j])
}

/// The values `[S, T, T_TI, V]` of one (bra, image) pair and their gradients (module docs).
fn image<const D: usize>(bra: &Gvr<D>, ket: &Gvr<D>, go: &GvrOps<D>, ser: &Series) -> ([f64; 4], [Grad<D>; 4]) {
    let ops = &go.ops;
    let Some((m, log_det)) = inverse_log_det(&(bra.a + ket.a)) else {
        return ([f64::NAN; 4], [Grad::nan(); 4]);
    };
    let (ui, uj) = (&bra.u, &ket.u);
    let gi = mul(&m, ui);
    let gj = mul(&m, uj);
    let x = ui.dot(&gi) * 0.5;
    let y = uj.dot(&gj) * 0.5;
    let z = ui.dot(&gj) * 0.5;
    let log_s0 = (log_det - D as f64 * PI.ln()) * -1.5;
    let (l, om, ox, oy, oz) = omega(&ser.coef, x, y, z);
    let scale = (log_s0 + l - bra.log_norm - ket.log_norm).exp();
    let hess = ser.hessian(x, y, z);
    let first = [ox, oy, oz];
    let s = scale * om;

    // kinetic (gvr::element): T/scale = λ ω_z − 4 p2 ω_x − 2 p3 ω_z − 4 p4 ω_y − 2 p5 ω_z
    //                                    + 12 tr ω + 8 p7 ω_x + 4 p8 ω_z + 8 p9 ω_y
    let lam = &ops.lambda;
    let lam_ui = mul(lam, ui);
    let lam_uj = mul(lam, uj);
    let zl = mul(&ket.a, &lam_ui); // A_J Λ u_I
    let zr = mul(&bra.a, &lam_uj); // A_I Λ u_J
    let lam_aj = mul(lam, &ket.a); // Λ A_J
    let w = mul(&bra.a, &lam_aj); // W = A_I Λ A_J
    let tr = m.component_mul(&w.transpose()).sum() * 0.5;
    let (hi, hj) = (gi * 0.5, gj * 0.5);
    let (w_hi, w_hj) = (mul(&w, &hi), mul(&w, &hj));
    let p = [
        ui.dot(&lam_uj),
        zl.dot(&hi),
        zl.dot(&hj),
        zr.dot(&hj),
        zr.dot(&hi),
        hi.dot(&w_hi),
        hi.dot(&w_hj) + hj.dot(&w_hi),
        hj.dot(&w_hj),
    ];
    let t = p[0] * oz - p[1] * 4.0 * ox - p[2] * 2.0 * oz - p[3] * 4.0 * oy - p[4] * 2.0 * oz
        + tr * 12.0 * om
        + p[5] * 8.0 * ox
        + p[6] * 4.0 * oz
        + p[7] * 8.0 * oy;
    let t = scale * t;
    let c_t = [12.0 * tr, 8.0 * p[5] - 4.0 * p[1], 8.0 * p[7] - 4.0 * p[3], p[0] - 2.0 * p[2] - 2.0 * p[4] + 4.0 * p[6]];
    let kin = kinetic(ket, lam, &m, &gi, &gj, [scale * om, scale * ox, scale * oy, scale * oz], (&lam_uj, &zl, &zr, &lam_aj, &w));
    let mut adj_t = kin;
    adj_t.xyz = xyz_bar(c_t, first, &hess, scale);

    // T_TI = T − T_cm: T_cm/scale = Σ c_cm · (ω, ω_x, ω_y, ω_z) (gvr::cm_kinetic)
    let (t_ti, adj_ti) = match ops.cm_mass {
        Some(mt) => {
            let (ci, cj, cui, cuj) = (bra.c_a, ket.c_a, bra.c_u, ket.c_u);
            let (ms, ms2) = (mt * (ci + cj), mt * (ci + cj) * (ci + cj));
            let (fx, fy) = (ci * cj / ms2 - cj / ms, ci * cj / ms2 - ci / ms);
            let c_cm = [3.0 * ci * cj / ms, cui * cui * fx, cuj * cuj * fy, ci * cj * cui * cuj / ms2];
            let t_cm = scale * (c_cm[0] * om + c_cm[1] * ox + c_cm[2] * oy + c_cm[3] * oz);
            let mut adj = kin;
            adj.xyz = xyz_bar(std::array::from_fn(|k| c_t[k] - c_cm[k]), first, &hess, scale);
            let cui_bar = scale * (ox * 2.0 * cui * fx + oz * ci * cj * cuj / ms2);
            adj.u.add_scalar_mut(-cui_bar);
            (t - t_cm, adj)
        }
        None => (t, adj_t),
    };

    let (v, adj_v) = coulomb(go, ser, &m, &gi, &gj, [x, y, z], scale);
    let adj_s = Adjoint::of_xyz(xyz_bar([1.0, 0.0, 0.0, 0.0], first, &hess, scale));
    let values = [s, t, t_ti, v];
    let adjs = [adj_s, adj_t, adj_ti, adj_v];
    let grads = std::array::from_fn(|o| fold(&adjs[o], values[o], &m, ui, uj, &gi, &gj));
    (values, grads)
}

/// The explicit and `g`-adjoints of the kinetic scalars `p` (shared by `T` and `T_TI`) for
/// `sw = s [ω, ω_x, ω_y, ω_z]`; `xyz` left zero (module docs).
fn kinetic<const D: usize>(
    ket: &Gvr<D>,
    lam: &Mat<D>,
    m: &Mat<D>,
    gi: &Vector<D>,
    gj: &Vector<D>,
    sw: [f64; 4],
    (lam_uj, zl, zr, lam_aj, w): (&Vector<D>, &Vector<D>, &Vector<D>, &Mat<D>, &Mat<D>),
) -> Adjoint<D> {
    let [s0, sx, sy, sz] = sw;
    // adjoints of λ, p2 .. p9 and tr
    let (b_lam, b2, b3, b4, b5) = (sz, -4.0 * sx, -2.0 * sz, -4.0 * sy, -2.0 * sz);
    let (b7, b8, b9, b_tr) = (8.0 * sx, 4.0 * sz, 8.0 * sy, 12.0 * s0);
    let ai = mul(lam_aj, gi); // Λ A_J g_I
    let aj = mul(lam_aj, gj);
    let (w_gi, w_gj) = (mul(w, gi), mul(w, gj));
    let (wt_gi, wt_gj) = (w.tr_mul(gi), w.tr_mul(gj));
    let (sym_i, sym_j) = (w_gi + wt_gi, w_gj + wt_gj); // (W + Wᵀ) g
    let u = lam_uj * b_lam + (ai * b2 + aj * b3) * 0.5;
    let g_i = (zl * b2 + zr * b5) * 0.5 + (sym_i * b7 + sym_j * b8) * 0.25;
    let g_j = (zl * b3 + zr * b4) * 0.5 + (sym_i * b8 + sym_j * b9) * 0.25;
    // Tr(A_I Λ A_J M)/2: gradient M A_J Λ A_J M / 2 = qᵀ Λ q / 2, q = A_J M
    let q = mul(&ket.a, m);
    let a = outer(gi, &(lam_uj * (b5 * 0.5) + (ai * b7 + aj * b8) * 0.25))
        + outer(gj, &(lam_uj * (b4 * 0.5) + (ai * b8 + aj * b9) * 0.25))
        + q.tr_mul(&mul(lam, &q)) * (b_tr * 0.5);
    Adjoint { xyz: [0.0; 3], a, u, gi: g_i, gj: g_j }
}

/// `V` of one image and its adjoints (module docs): all pairs in one call of the quadrature
/// with partials (`gvr_build::partials`, the maths of `gvr::coulomb_partials`).
#[allow(clippy::too_many_arguments)]
fn coulomb<const D: usize>(
    go: &GvrOps<D>,
    ser: &Series,
    m: &Mat<D>,
    gi: &Vector<D>,
    gj: &Vector<D>,
    [x, y, z]: [f64; 3],
    scale: f64,
) -> (f64, Adjoint<D>) {
    let pairs = &go.ops.pairs;
    let np = pairs.len();
    assert!(np <= MAX_PAIRS, "at most {MAX_PAIRS} Coulomb pairs");
    let mut mw = [Vector::<D>::zeros(); MAX_PAIRS];
    let mut c = [0.0; MAX_PAIRS];
    let mut inputs = [[0.0; 5]; MAX_PAIRS];
    for (k, (w, _)) in pairs.iter().enumerate() {
        mw[k] = mul(m, w);
        c[k] = mw[k].dot(w);
        let sq = (c[k] * 2.0).sqrt();
        inputs[k] = [x, y, z, gi.dot(w) / sq, gj.dot(w) / sq];
    }
    let mut out = [(0.0, [0.0; 5]); MAX_PAIRS];
    gvr_build::partials((&ser.c, &ser.dc), (ser.ki, ser.kj, ser.n), &ser.tau2, &ser.weight, &inputs[..np], &mut out[..np]);
    let mut v = 0.0;
    let mut adj = Adjoint::of_xyz([0.0; 3]);
    for k in 0..np {
        let ((w, q), (f, d), c) = (&pairs[k], &out[k], c[k]);
        let pref = q * 2.0 / (c * PI).sqrt();
        v += pref * f;
        let sp = scale * pref;
        adj.xyz[0] += sp * d[0];
        adj.xyz[1] += sp * d[1];
        adj.xyz[2] += sp * d[2];
        let sq = (c * 2.0).sqrt();
        let (bgi, bgj) = (sp * d[3], sp * d[4]);
        adj.gi += w * (bgi / sq);
        adj.gj += w * (bgj / sq);
        let c_bar = -(sp * f + bgi * inputs[k][3] + bgj * inputs[k][4]) / (2.0 * c);
        adj.a -= outer(&mw[k], &mw[k]) * c_bar;
    }
    let v = scale * v;
    let half_n = 0.5 * go.n_ang as f64;
    adj.xyz[0] += v * (ser.ki as f64 + half_n) / x;
    adj.xyz[1] += v * (ser.kj as f64 + half_n) / y;
    (v, adj)
}

/// `(G_O, g_O)` of one output of value `o` from its adjoints (module docs).
fn fold<const D: usize>(
    adj: &Adjoint<D>,
    o: f64,
    m: &Mat<D>,
    ui: &Vector<D>,
    uj: &Vector<D>,
    gi: &Vector<D>,
    gj: &Vector<D>,
) -> Grad<D> {
    let [xb, yb, zb] = adj.xyz;
    let m_gi = mul(m, &(adj.gi + ui * (0.5 * xb)));
    let m_gj = mul(m, &(adj.gj + uj * (0.5 * yb) + ui * (0.5 * zb)));
    Grad {
        a: adj.a + m * (-1.5 * o) - outer(&m_gi, gi) - outer(&m_gj, gj),
        u: adj.u + gi * (0.5 * xb) + gj * (0.5 * zb) + m_gi,
    }
}

/// `(G_n, g_n)` of the bra's `n_I = ln <φ|φ>^{1/2}` (`Gvr::new`): with `h = A⁻¹u`,
/// `x_n = uᵀh/4`, `n_I = −3/4 ln|A| + (K + N/2) ln x_n + const`.
fn log_norm_gradient<const D: usize>(bra: &Gvr<D>, n_ang: u32) -> Grad<D> {
    let ainv = bra.a.cholesky().expect("a checked function").inverse();
    let h = ainv * bra.u;
    let xn = bra.u.dot(&h) * 0.25;
    let kn = (2 * bra.k + n_ang) as f64;
    Grad { a: ainv * -0.75 - outer(&h, &h) * (kn / (8.0 * xn)), u: h * (kn / (4.0 * xn)) }
}

/// `EcgGvr::row_gradient` (module docs): the `(1 + P) x nb` row and its derivatives, and the
/// `1 + P` diagonal (dual numbers, `path::row_gradient` against no basis); the basis images kept
/// in `cache`.
pub fn row_gradient<const D: usize>(
    go: &GvrOps<D>,
    sym: &Symmetry<D>,
    trial: &Params,
    dir: &Directions,
    basis: &Params,
    cache: &Cache,
) -> Result<(Matrices, Vec<Element>)> {
    check(trial.len(), 1, "trial functions")?;
    let bra = <EcgGvr as Family<D>>::functions(trial, go)?.remove(0);
    let b = path::basis_images::<D, EcgGvr>(go, sym, basis, cache)?;
    let (da, _) = dir.exponents::<D>()?;
    let du = matrices_of::<D, 1>(dir.v, da.len(), "global-vector directions")?;
    let (_, diag) = path::row_gradient::<D, EcgGvr>(go, sym, trial, dir, &Params::default(), &Cache::default())?;
    let k_max = b.functions.iter().map(|f| f.k).max().unwrap_or(0) as usize;
    let mut series: Vec<Option<Series>> = (0..=k_max).map(|_| None).collect();
    for f in &b.functions {
        series[f.k as usize].get_or_insert_with(|| Series::new(go, bra.k, f.k));
    }
    let gn = log_norm_gradient(&bra, go.n_ang);
    let dn: Vec<f64> = da.iter().zip(&du).map(|(a, u)| gn.along(a, u)).collect();
    let rows: Vec<Vec<Element>> = (0..b.len())
        .into_par_iter()
        .map(|j| {
            let ser = series[b.functions[j].k as usize].as_ref().expect("every K prepared");
            let mut o = [0.0; 4];
            let mut g = [Grad::zero(); 4];
            for (ket, c) in b.images[j].iter().zip(&b.coef) {
                let (oi, gi) = image(&bra, ket, go, ser);
                for k in 0..4 {
                    o[k] += oi[k] * c;
                    g[k].add_scaled(*c, &gi[k]);
                }
            }
            let el = |x: [f64; 4]| Element { s: x[0], t: x[1], t_ti: x[2], v: x[3] };
            std::iter::once(el(o))
                .chain(da.iter().zip(&du).zip(&dn).map(|((a, u), n)| el(std::array::from_fn(|k| g[k].along(a, u) - o[k] * n))))
                .collect()
        })
        .collect();
    let mut out = Matrices::zeros(1 + da.len(), b.len());
    for (j, r) in rows.iter().enumerate() {
        for (i, e) in r.iter().enumerate() {
            out.set(i, j, e);
        }
    }
    Ok((out, diag))
}

#[cfg(test)]
#[path = "gvr_gradient_tests.rs"]
mod tests;
