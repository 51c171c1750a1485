//! The Coulomb τ-quadrature of the ECG-GVR kernel (`kernel`; the integral in `element::quadrature`,
//! docs/gvr.md).
//!
//! - Per call, once: a [`Table`] with, for every pair (K_I, K_J) the call meets, the series ĉ_k
//!   and the coefficients of G_x, G_y, G_z (`series::Coefficients`), and the even Gauss–Legendre
//!   rule of degree K_I + K_J + N as `τ²` and weights, padded with zero weights to a multiple of
//!   [`MAX_W`] nodes.
//! - The τ-integrals (`integrals`) in lanes of `W` nodes, several pairs and node blocks at once:
//!   at a node, with `α_I = γ_I²/x`, `α_J = γ_J²/y`, `β = z/√(xy)`, `δ = γ_Iγ_J/√(xy)`,
//!   `a = 1 − α_I τ²`, `b = 1 − α_J τ²`, `ζ = β − δ τ²`, the integrand is
//!   `a^{K_I} b^{K_J} ζ^N G(ζ²/(ab))` (`element::quadrature_partials`); the integer powers by
//!   binary exponentiation ([`pow`]), the same squarings and products in every lane. The lane
//!   values are summed node by node in order, so the integral has the same bits for every `W`.
//! - The row gradient's τ-quadrature with partial derivatives (`integral_partials`) has `W`
//!   inputs (pairs and images) in lanes instead, each lane summing its nodes in order.
#![allow(clippy::needless_range_loop)]

use super::element::GvrOps;
use super::series::{Coefficients, Terms};
use crate::ecg::MAX_DIM;

/// The widest lane count (AVX-512); rules are padded to a multiple of it.
pub const MAX_W: usize = 8;

/// Most Coulomb pairs of a call (stack storage): the pairs of `MAX_DIM` particles.
pub const MAX_PAIRS: usize = MAX_DIM * (MAX_DIM - 1) / 2;

/// A slice of the table's storage.
#[derive(Clone, Copy, Debug, Default)]
struct Span(usize, usize);

/// The series and the rule of one pair (K_I, K_J) (module docs).
#[derive(Clone, Copy, Debug, Default)]
struct Entry {
    c: Span,
    cx: Span,
    cy: Span,
    cz: Span,
    tau2: Span,
    weight: Span,
}

/// The coefficients `(k+1) ĉ_{k+1}` of G' from those of G.
pub fn derivative_series(c: &[f64]) -> Vec<f64> {
    c.iter().enumerate().skip(1).map(|(k, ck)| k as f64 * ck).collect()
}

/// A rule as `(τ², weight)`, padded with zero weights to a multiple of [`MAX_W`] nodes.
pub fn padded_rule(rule: &[(f64, f64)]) -> (Vec<f64>, Vec<f64>) {
    let padded = rule.len().div_ceil(MAX_W) * MAX_W;
    (0..padded).map(|i| rule.get(i).map_or((0.0, 0.0), |&(t, w)| (t * t, w))).unzip()
}

/// Series and rules of the pairs (K_I, K_J) met in one call, in one flat storage.
pub struct Table {
    n: u32,
    /// `index[K_I * stride + K_J]`: the entry of the pair, if tabulated
    index: Vec<Option<Entry>>,
    stride: usize,
    data: Vec<f64>,
}

/// One pair's series and rule as slices.
pub struct Series<'a> {
    pub ki: u32,
    pub kj: u32,
    pub n: u32,
    pub c: &'a [f64],
    pub cx: &'a [f64],
    pub cy: &'a [f64],
    pub cz: &'a [f64],
    pub tau2: &'a [f64],
    pub weight: &'a [f64],
}

impl Series<'_> {
    /// The series of Ω (`series::omega`).
    #[inline(always)]
    pub(crate) fn terms(&self) -> Terms<'_> {
        Terms { ki: self.ki, kj: self.kj, n: self.n, c: self.c, cx: self.cx, cy: self.cy, cz: self.cz }
    }
}

impl Table {
    /// The table for the pairs (K_I, K_J) of `pairs` (repeats are tabulated once).
    pub fn new<const D: usize>(go: &GvrOps<D>, pairs: impl Iterator<Item = (u32, u32)> + Clone) -> Self {
        let stride = pairs.clone().map(|(ki, kj)| ki.max(kj)).max().unwrap_or(0) as usize + 1;
        let mut table = Self { n: go.n_ang, index: vec![None; stride * stride], stride, data: Vec::new() };
        for (ki, kj) in pairs {
            let at = ki as usize * stride + kj as usize;
            if table.index[at].is_none() {
                table.index[at] = Some(table.push(go, ki, kj));
            }
        }
        table
    }

    fn push<const D: usize>(&mut self, go: &GvrOps<D>, ki: u32, kj: u32) -> Entry {
        let s = Coefficients::new(ki, kj, go.n_ang);
        let (tau2, weight) = padded_rule(go.rule(ki + kj + go.n_ang));
        let span = |data: &mut Vec<f64>, values: &mut dyn Iterator<Item = f64>| {
            let start = data.len();
            data.extend(values);
            Span(start, data.len())
        };
        let d = &mut self.data;
        Entry {
            c: span(d, &mut s.c.iter().copied()),
            cx: span(d, &mut s.cx.iter().copied()),
            cy: span(d, &mut s.cy.iter().copied()),
            cz: span(d, &mut s.cz.iter().copied()),
            tau2: span(d, &mut tau2.into_iter()),
            weight: span(d, &mut weight.into_iter()),
        }
    }

    /// The series and rule of (K_I, K_J); the pair must have been tabulated.
    #[inline]
    pub fn series(&self, ki: u32, kj: u32) -> Series<'_> {
        let e = self.index[ki as usize * self.stride + kj as usize].expect("pair (K_I, K_J) tabulated");
        let s = |sp: Span| &self.data[sp.0..sp.1];
        Series {
            ki,
            kj,
            n: self.n,
            c: s(e.c),
            cx: s(e.cx),
            cy: s(e.cy),
            cz: s(e.cz),
            tau2: s(e.tau2),
            weight: s(e.weight),
        }
    }
}

/// `x^k` by binary exponentiation for `B` blocks of `W` lanes, every lane with the same
/// operations (one loop over the bits of `k` for all blocks).
#[inline(always)]
pub fn pow<const W: usize, const B: usize>(x: [[f64; W]; B], k: u32) -> [[f64; W]; B] {
    let (mut r, mut base, mut k) = ([[1.0; W]; B], x, k);
    loop {
        if k & 1 == 1 {
            for j in 0..B {
                for l in 0..W {
                    r[j][l] *= base[j][l];
                }
            }
        }
        k >>= 1;
        if k == 0 {
            return r;
        }
        for j in 0..B {
            for l in 0..W {
                base[j][l] *= base[j][l];
            }
        }
    }
}

/// `r = ζ²/(ab)`, at most 1, and 1 where `ab` vanishes (`element::quadrature`): the quotient is
/// taken in every lane and selected (no `f64::min`, whose NaN rule keeps lanes scalar).
#[inline(always)]
fn ratio(a: f64, b: f64, zeta: f64) -> f64 {
    let (ab, q) = (a * b, zeta * zeta / (a * b));
    if ab > 0.0 && q < 1.0 { q } else { 1.0 }
}

/// `max(v, 0)` as a select (`ratio`); NaN gives 0 as `f64::max` does.
#[inline(always)]
fn positive(v: f64) -> f64 {
    if v > 0.0 { v } else { 0.0 }
}

/// Block `c` of `W` lanes of `v` (one bounds check, so the block's loops stay in vector lanes).
#[inline(always)]
fn lanes<const W: usize>(v: &[f64], c: usize) -> &[f64; W] {
    v[c * W..(c + 1) * W].try_into().expect("a block of W lanes")
}

/// The `W` slots of `MAX_W` that node block `c` adds into (node `i` in slot `i mod MAX_W`).
#[inline(always)]
fn slot_lanes<const W: usize>(slots: &mut [f64; MAX_W], c: usize) -> &mut [f64; W] {
    let at = (c * W) % MAX_W;
    (&mut slots[at..at + W]).try_into().expect("a block of W slots")
}

/// Lane blocks evaluated together: independent Horner chains that hide the latency.
const SLOTS: usize = 8;

/// `∫_0^1 a^{K_I} b^{K_J} ζ^N G(ζ²/(ab)) dτ` (module docs) for every pair `p` of `inputs` =
/// `[α_I, α_J, β, δ]`, into `out[p]`. The jobs (pair, block of `W` nodes) run `SLOTS` at a time;
/// each pair's nodes are summed in `MAX_W` slots (node `i` in slot `i mod MAX_W`) and the slots
/// in order at the end, so `out` has the same bits for every `W`.
#[inline(always)]
pub fn integrals<const W: usize>(s: &Series, inputs: &[[f64; 4]], out: &mut [f64]) {
    let blocks = s.tau2.len() / W;
    let jobs = inputs.len() * blocks;
    let mut slots = [[0.0f64; MAX_W]; MAX_PAIRS];
    let mut a = [[0.0f64; W]; SLOTS];
    let mut b = [[0.0f64; W]; SLOTS];
    let mut zeta = [[0.0f64; W]; SLOTS];
    let mut first = 0;
    while first < jobs {
        let n = SLOTS.min(jobs - first);
        let mut r = [[0.0f64; W]; SLOTS];
        for j in 0..n {
            let (p, c) = ((first + j) / blocks, (first + j) % blocks);
            let [al_i, al_j, beta, delta] = inputs[p];
            let t2 = lanes::<W>(s.tau2, c);
            for l in 0..W {
                a[j][l] = positive(1.0 - al_i * t2[l]);
                b[j][l] = positive(1.0 - al_j * t2[l]);
                zeta[j][l] = beta - delta * t2[l];
                r[j][l] = ratio(a[j][l], b[j][l], zeta[j][l]);
            }
        }
        // all SLOTS blocks (unused ones at r = 0): a fixed trip count keeps the blocks in registers
        let mut g = [[0.0f64; W]; SLOTS];
        for ck in s.c.iter().rev() {
            for j in 0..SLOTS {
                for l in 0..W {
                    g[j][l] = g[j][l] * r[j][l] + ck;
                }
            }
        }
        // all SLOTS blocks (unused ones hold earlier or zero values, never read)
        let (pa, pb, pz) = (pow(a, s.ki), pow(b, s.kj), pow(zeta, s.n));
        for j in 0..n {
            let (p, c) = ((first + j) / blocks, (first + j) % blocks);
            let wt = lanes::<W>(s.weight, c);
            let term: [f64; W] = std::array::from_fn(|l| wt[l] * pa[j][l] * pb[j][l] * pz[j][l] * g[j][l]);
            let slot = slot_lanes::<W>(&mut slots[p], c);
            for l in 0..W {
                slot[l] += term[l];
            }
        }
        first += n;
    }
    for (o, slot) in out.iter_mut().zip(&slots) {
        *o = slot.iter().fold(0.0, |acc, v| acc + v);
    }
}

/// `∫_0^1 P dτ` with its partial derivatives with respect to `[x, y, z, γ_I, γ_J]`
/// (`element::quadrature_partials`: the same chain rule through `a`, `b`, `ζ`) for each of `inputs`,
/// into `out`, `W` inputs at a time in lanes (`partial_sums`); `tau2`, `weight` = the padded rule
/// (`padded_rule`), `c` = the series `ĉ_k` and its derivative's (`derivative_series`). The
/// series of `P_a`, `P_b`, `P_ζ` come from G and G' alone: `Σ ĉ_k(K_I−k) r^k = K_I G − r G'`,
/// likewise K_J, and `Σ ĉ_k(N+2k) r^k = N G + 2 r G'` (for N = 0 over r: `2 G'`). The
/// derivatives' node sums carry no division: with `α_I = γ_I²/x`, `α_J = γ_J²/y`,
///
/// ```text
///     ∂_x = (α_I/x) Σ P_a τ² − Σ P_ζ ζ/(2x),       ∂_γI = −(2γ_I/x) Σ P_a τ² − (γ_J/√(xy)) Σ P_ζ τ²,
///     ∂_y = (α_J/y) Σ P_b τ² − Σ P_ζ ζ/(2y),       ∂_γJ = −(2γ_J/y) Σ P_b τ² − (γ_I/√(xy)) Σ P_ζ τ²,
///     ∂_z = Σ P_ζ/√(xy).
/// ```
///
/// Each lane is one input, its nodes summed in order, so `out` has the same bits for every `W`.
#[inline(always)]
pub fn integral_partials<const W: usize>(
    c: (&[f64], &[f64]),
    k: (u32, u32, u32),
    tau2: &[f64],
    weight: &[f64],
    inputs: &[[f64; 5]],
    out: &mut [(f64, [f64; 5])],
) {
    // the rule's nodes in whole groups of NODES (the padding has zero weights: each adds +0)
    let nodes = weight.iter().rposition(|&w| w != 0.0).map_or(0, |i| i + 1).div_ceil(NODES) * NODES;
    let (tau2, weight) = (&tau2[..nodes], &weight[..nodes]);
    for (inputs, out) in inputs.chunks(W).zip(out.chunks_mut(W)) {
        // lanes beyond the inputs repeat the first (their sums are not read)
        let lanes: [[f64; W]; 5] = std::array::from_fn(|t| std::array::from_fn(|l| inputs[if l < inputs.len() { l } else { 0 }][t]));
        let sums = partial_sums::<W>(c, k, tau2, weight, &lanes);
        for (l, (o, &[x, y, _, gam_i, gam_j])) in out.iter_mut().zip(inputs).enumerate() {
            let rt = (x * y).sqrt();
            let [f, pa_t, pb_t, pz, pz_zeta, pz_t] = sums.map(|s| s[l]);
            let [al_i, al_j] = [gam_i * gam_i / x, gam_j * gam_j / y];
            *o = (
                f,
                [
                    al_i / x * pa_t - pz_zeta / (2.0 * x),
                    al_j / y * pb_t - pz_zeta / (2.0 * y),
                    pz / rt,
                    -(2.0 * gam_i / x) * pa_t - gam_j / rt * pz_t,
                    -(2.0 * gam_j / y) * pb_t - gam_i / rt * pz_t,
                ],
            );
        }
    }
}

/// Nodes evaluated together in `partial_sums` (independent Horner chains hide the latency).
const NODES: usize = 4;

/// The node sums of `integral_partials` for `W` inputs in lanes (`[x, y, z, γ_I, γ_J]`, each a
/// lane vector): `[Σ P, Σ P_a τ², Σ P_b τ², Σ P_ζ, Σ P_ζ ζ, Σ P_ζ τ²]` (weights included), node by
/// node in order, `a`, `b`, `ζ` rounded as in `element::quadrature_partials`. G and G' are two
/// Horner chains (`c` and `dc`, `dc_k = (k+1) ĉ_{k+1}`) over `NODES` nodes at once; the rule's
/// length is a multiple of `NODES`.
#[inline(always)]
fn partial_sums<const W: usize>(
    (c, dc): (&[f64], &[f64]),
    (ki, kj, n): (u32, u32, u32),
    tau2: &[f64],
    weight: &[f64],
    [x, y, z, gam_i, gam_j]: &[[f64; W]; 5],
) -> [[f64; W]; 6] {
    let (kif, kjf, nf) = (ki as f64, kj as f64, n as f64);
    let one = [[1.0f64; W]; NODES];
    let rt: [f64; W] = std::array::from_fn(|l| (x[l] * y[l]).sqrt());
    let gii: [f64; W] = std::array::from_fn(|l| gam_i[l] * gam_i[l]);
    let gjj: [f64; W] = std::array::from_fn(|l| gam_j[l] * gam_j[l]);
    let gij: [f64; W] = std::array::from_fn(|l| gam_i[l] * gam_j[l]);
    let mut s = [[0.0f64; W]; 6];
    for (t2, wt) in tau2.chunks_exact(NODES).zip(weight.chunks_exact(NODES)) {
        let mut a = [[0.0f64; W]; NODES];
        let mut b = [[0.0f64; W]; NODES];
        let mut zeta = [[0.0f64; W]; NODES];
        let mut r = [[0.0f64; W]; NODES];
        for q in 0..NODES {
            for l in 0..W {
                a[q][l] = positive(1.0 - gii[l] * t2[q] / x[l]);
                b[q][l] = positive(1.0 - gjj[l] * t2[q] / y[l]);
                zeta[q][l] = (z[l] - gij[l] * t2[q]) / rt[l];
                r[q][l] = ratio(a[q][l], b[q][l], zeta[q][l]);
            }
        }
        // G and G' in one loop (dc is one shorter), the chains of every node interleaved
        let (mut g, mut gp) = ([[0.0f64; W]; NODES], [[0.0f64; W]; NODES]);
        for k in (0..c.len()).rev() {
            for q in 0..NODES {
                for l in 0..W {
                    g[q][l] = g[q][l] * r[q][l] + c[k];
                }
            }
            if k > 0 {
                for q in 0..NODES {
                    for l in 0..W {
                        gp[q][l] = gp[q][l] * r[q][l] + dc[k - 1];
                    }
                }
            }
        }
        let pa1 = if ki > 0 { pow(a, ki - 1) } else { one };
        let pb1 = if kj > 0 { pow(b, kj - 1) } else { one };
        let pz1 = if n > 0 { pow(zeta, n - 1) } else { one };
        for q in 0..NODES {
            let (t2, w) = (t2[q], wt[q]);
            for l in 0..W {
                let (aq, bq, zq, gq) = (a[q][l], b[q][l], zeta[q][l], g[q][l]);
                let (pa1, pb1, pz1) = (pa1[q][l], pb1[q][l], pz1[q][l]);
                let pa = if ki > 0 { pa1 * aq } else { 1.0 };
                let pb = if kj > 0 { pb1 * bq } else { 1.0 };
                let pz = if n > 0 { pz1 * zq } else { 1.0 };
                s[0][l] += w * pa * pb * pz * gq;
                let rgp = r[q][l] * gp[q][l];
                let p_a = if ki > 0 { w * pa1 * pb * pz * (kif * gq - rgp) } else { 0.0 };
                let p_b = if kj > 0 { w * pa * pb1 * pz * (kjf * gq - rgp) } else { 0.0 };
                let p_z = match n {
                    0 if ki > 0 && kj > 0 => w * pa1 * pb1 * zq * (2.0 * gp[q][l]),
                    0 => 0.0,
                    _ => w * pa * pb * pz1 * (nf * gq + 2.0 * rgp),
                };
                s[1][l] += p_a * t2;
                s[2][l] += p_b * t2;
                s[3][l] += p_z;
                s[4][l] += p_z * zq;
                s[5][l] += p_z * t2;
            }
        }
    }
    s
}
