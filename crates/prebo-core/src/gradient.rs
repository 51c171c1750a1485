//! Derivatives of one function's symmetrised row and diagonal with respect to its parameters,
//! by forward-mode dual numbers (num-dual) through the integral kernels.
//!
//! The caller gives the function and P directions `(dA_p, du_p)` or `(dA_p, ds_p)` — the
//! derivatives of its laboratory-frame parameters with respect to the optimiser's θ_p. The
//! function is evaluated once per chunk of W directions with `A + Σ_p ε_p dA_p`, ... as a
//! `DualSVec64<W>`; the basis functions enter with zero derivatives. The result is the row
//! `<phi|O|phi_j>` (symmetrised, normalised; the trial is the bra) and `<phi|O|phi>`, each with
//! its P derivatives.
use nalgebra::{Const, SMatrix, SVector, U1};
use num_dual::{Derivative, DualSVec64};
use rayon::prelude::*;

use crate::ecg::{Element, Mat};
use crate::error::Result;
use crate::matrices::Matrices;
use crate::images::{Images, Transform};

/// Most directions carried by one pass (a longer direction list is chunked).
pub const MAX_LANES: usize = 16;

pub type Dual<const W: usize> = DualSVec64<W>;

/// `x + Σ_p ε_p dx_p` for the directions `dx` (at most W of them).
pub fn seed<const W: usize>(x: f64, dx: impl Iterator<Item = f64>) -> Dual<W> {
    let mut eps = SVector::<f64, W>::zeros();
    for (p, d) in dx.enumerate() {
        eps[p] = d;
    }
    Dual::new(x, Derivative::some(eps))
}

/// A matrix seeded with the directions `dm[p]`.
pub fn seed_matrix<const R: usize, const C: usize, const W: usize>(
    m: &SMatrix<f64, R, C>,
    dm: &[SMatrix<f64, R, C>],
) -> SMatrix<Dual<W>, R, C> {
    SMatrix::from_fn(|i, j| seed(m[(i, j)], dm.iter().map(|d| d[(i, j)])))
}

/// The value and derivatives of one element: `out[0]` the value, `out[1 + p]` its derivative along direction `p`.
fn unpack<const W: usize>(e: &Element<Dual<W>>, p: usize, out: &mut [Element]) {
    let parts = |x: &Dual<W>| (x.re, x.eps.unwrap_generic(Const::<W>, U1));
    let (s, t, t_ti, v) = (parts(&e.s), parts(&e.t), parts(&e.t_ti), parts(&e.v));
    out[0] = Element { s: s.0, t: t.0, t_ti: t_ti.0, v: v.0 };
    for k in 0..p {
        out[1 + k] = Element { s: s.1[k], t: t.1[k], t_ti: t_ti.1[k], v: v.1[k] };
    }
}

/// One chunk: the trial (seeded with ≤ W directions) with its images under `sym`, against the
/// basis cast to dual numbers of zero derivative. Returns `(row, diag)` with `1 + p` entries per
/// element (`p` directions in this chunk).
pub fn chunk<F, G, Ctx, const D: usize, const W: usize>(
    trial: G,
    sym: &[(Mat<D>, f64)],
    ctx: &Ctx,
    basis: &Images<F>,
    cast: impl Fn(&F) -> G,
    p: usize,
    el: impl Fn(&G, &G) -> Element<Dual<W>> + Sync,
) -> Result<(Vec<Vec<Element>>, Vec<Element>)>
where
    G: Transform<D, Ctx> + Sync,
{
    let trial = Images::new(vec![trial], sym, ctx)?;
    let basis = basis.map(cast);
    let bra = &trial.functions[0];
    let row = (0..basis.len())
        .into_par_iter()
        .map(|j| {
            let mut out = vec![Element::default(); 1 + p];
            unpack(&basis.element(bra, j, &el), p, &mut out);
            out
        })
        .collect();
    let mut diag = vec![Element::default(); 1 + p];
    unpack(&trial.element(bra, 0, &el), p, &mut diag);
    Ok((row, diag))
}

/// Runs `pass(first, count)` over chunks of at most `MAX_LANES` directions and gathers
/// `(1 + P) x nb` matrices (row 0 the values) and `1 + P` diagonal elements.
pub fn gather(
    nb: usize,
    n_dir: usize,
    mut pass: impl FnMut(usize, usize) -> Result<(Vec<Vec<Element>>, Vec<Element>)>,
) -> Result<(Matrices, Vec<Element>)> {
    let rows = 1 + n_dir;
    let mut m = Matrices::zeros(rows, nb);
    let mut diag = vec![Element::default(); rows];
    let mut first = 0;
    loop {
        let count = (n_dir - first).min(MAX_LANES);
        let (row, d) = pass(first, count)?;
        for (j, r) in row.iter().enumerate() {
            for (k, e) in r.iter().enumerate() {
                // k = 0 is the value (the same in every chunk), k >= 1 direction first + k - 1
                let target = if k == 0 { 0 } else { first + k };
                m.set(target, j, e);
            }
        }
        diag[0] = d[0];
        diag[1 + first..1 + first + count].copy_from_slice(&d[1..]);
        first += count;
        if first >= n_dir {
            return Ok((m, diag));
        }
    }
}
