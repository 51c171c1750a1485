//! The one build path for every (family, operator): symmetrised matrices, rows oriented as in a
//! full build, row gradients by dual numbers, and the matrices of extra operators.
//!
//! A symmetrised element is `Σ_P c_P <phi_I| O |P phi_J>` over the images `P phi_J`
//! (`images::Images`); the matrices are evaluated with the lower index as bra and mirrored.
use std::sync::Arc;

use crate::assemble;
use crate::cache::Cache;
use crate::ecg::{Element, Mat, Vector};
use crate::error::Result;
use crate::families::Family;
use crate::params::{check, Directions, Parameters, Symmetry};
use crate::gradient::{self, Dual, MAX_LANES};
use crate::images::Images;
use crate::matrices::Matrices;
use nalgebra::{Const, U1};
use rayon::prelude::*;

/// The functions of `p` with their images under `sym`.
pub fn images<const D: usize, F: Family<D>>(
    ctx: &F::Context,
    sym: &Symmetry<D>,
    p: &F::Params<'_>,
) -> Result<Images<F::Function<f64>>> {
    Images::new(F::functions(p, ctx)?, sym, ctx)
}

/// `images` of a basis, kept in `cache` between calls against it.
pub fn basis_images<const D: usize, F: Family<D>>(
    ctx: &F::Context,
    sym: &Symmetry<D>,
    p: &F::Params<'_>,
    cache: &Cache,
) -> Result<Arc<Images<F::Function<f64>>>> {
    cache.get(p, || images::<D, F>(ctx, sym, p))
}

/// The symmetrised `nb x nb` matrices of a basis.
pub fn matrices<const D: usize, F: Family<D>>(
    ctx: &F::Context,
    sym: &Symmetry<D>,
    basis: &F::Params<'_>,
) -> Result<Matrices> {
    let b = images::<D, F>(ctx, sym, basis)?;
    Ok(assemble::symmetric(b.len(), |i, j| {
        b.element(&b.functions[i], j, |x, y| F::element(x, y, ctx))
    }))
}

/// Rows of trials `t` against basis `b` (its images kept in `cache`) for a trial that will sit at
/// `position` (`None`: appended).
/// Element `j` is evaluated with the lower index as bra — `(b_j, t)` for `j < position`,
/// `(t, b_j)` after — exactly as `matrices` evaluates the full matrix, so a basis grown from such
/// rows has bit-for-bit the matrices of a fresh build.
pub fn rows<const D: usize, F: Family<D>>(
    ctx: &F::Context,
    sym: &Symmetry<D>,
    trials: &F::Params<'_>,
    basis: &F::Params<'_>,
    position: Option<usize>,
    cache: &Cache,
) -> Result<(Matrices, Vec<Element>)> {
    let t = images::<D, F>(ctx, sym, trials)?;
    let b = basis_images::<D, F>(ctx, sym, basis, cache)?;
    let el = |x: &F::Function<f64>, y: &F::Function<f64>| F::element(x, y, ctx);
    let pos = position.unwrap_or(b.len());
    Ok(assemble::rows(
        t.len(),
        b.len(),
        |i, j| {
            if j < pos {
                t.element(&b.functions[j], i, el)
            } else {
                b.element(&t.functions[i], j, el)
            }
        },
        |i| t.element(&t.functions[i], i, el),
    ))
}

/// Calls `$f::<D, F, W>` with the narrowest lane count W that holds `$count` directions. The
/// widths match the parameter counts of one function (GVR H2+ 5, pECG H2 6, GVR H2 and FECG
/// of 3 particles 9, FECG of 4 particles 15): a dual element costs about W times an f64 one.
macro_rules! lanes {
    ($count:expr, $f:ident ( $($arg:expr),* )) => {
        match $count {
            0..=4 => $f::<D, F, 4>($($arg),*),
            5 => $f::<D, F, 5>($($arg),*),
            6 => $f::<D, F, 6>($($arg),*),
            7..=8 => $f::<D, F, 8>($($arg),*),
            9 => $f::<D, F, 9>($($arg),*),
            10..=12 => $f::<D, F, 12>($($arg),*),
            _ => $f::<D, F, 16>($($arg),*),
        }
    };
}

/// One chunk of at most W directions (`gradient::chunk`).
fn gradient_chunk<const D: usize, F: Family<D>, const W: usize>(
    ctx: &F::Context,
    sym: &Symmetry<D>,
    f: &F::Function<f64>,
    da: &[Mat<D>],
    dv: &[f64],
    b: &Images<F::Function<f64>>,
) -> Result<(Vec<Vec<Element>>, Vec<Element>)> {
    let trial = F::seeded::<W>(f, da, dv, ctx)?;
    gradient::chunk(trial, sym, ctx, b, F::cast::<Dual<W>>, da.len(), |x, y| {
        F::element(x, y, ctx)
    })
}

/// The row of one function against a basis and its diagonal, with their derivatives along the
/// directions `dir`: `(1 + P) x nb` matrices (row 0 the values, the function as bra) and `1 + P`
/// diagonal elements (module `gradient`); the basis images kept in `cache`.
pub fn row_gradient<const D: usize, F: Family<D>>(
    ctx: &F::Context,
    sym: &Symmetry<D>,
    trial: &F::Params<'_>,
    dir: &Directions,
    basis: &F::Params<'_>,
    cache: &Cache,
) -> Result<(Matrices, Vec<Element>)> {
    check(trial.len(), 1, "trial functions")?;
    let f = F::functions(trial, ctx)?.remove(0);
    let b = basis_images::<D, F>(ctx, sym, basis, cache)?;
    let (da, per) = dir.exponents::<D>()?;
    gradient::gather(b.len(), da.len(), |first, count| {
        let (da, dv) = (&da[first..first + count], &dir.v[first * per..(first + count) * per]);
        lanes!(count, gradient_chunk(ctx, sym, &f, da, dv, &b))
    })
}

/// The symmetrised matrix of one extra operator (`operators`, its elements `<phi_I| O(v) |phi_J>`
/// of every instance `v` at once, `arity` vectors each) for each instance (`p x arity x n`, flat):
/// `p` row-major `nb x nb` blocks, upper triangle evaluated, mirrored.
pub fn operator<const D: usize, F: Family<D>>(
    ctx: &F::Context,
    sym: &Symmetry<D>,
    basis: &F::Params<'_>,
    elements: impl Fn(&F::Function<f64>, &F::Function<f64>, &F::Context, &[Vec<Vector<D>>]) -> Vec<f64> + Sync,
    arity: usize,
    v: &[f64],
) -> Result<Vec<f64>> {
    let instances = instances::<D>(arity, v)?;
    let b = images::<D, F>(ctx, sym, basis)?;
    let (nb, p) = (b.len(), instances.len());
    let upper = assemble::upper(nb, |i, j| {
        b.images[j].iter().zip(&b.coef).fold(vec![0.0; p], |mut acc, (ket, c)| {
            for (a, x) in acc.iter_mut().zip(elements(&b.functions[i], ket, ctx, &instances)) {
                *a += c * x;
            }
            acc
        })
    });
    let mut out = vec![0.0; p * nb * nb];
    assemble::mirror(&upper, |i, j, values: &Vec<f64>| {
        for (m, x) in out.chunks_exact_mut(nb * nb).zip(values) {
            m[i * nb + j] = *x;
        }
    });
    Ok(out)
}

/// The matrices (`p x nb_bra x nb_ket`, row-major) of an operator between two bases of family
/// `F`, one per instance of its `arity` vectors `v` (`instances`): `Σ_P c_P <phi_I| O |P phi'_J>`,
/// the bras of `bra` as they are, the kets of `ket` with their images under the ket basis's own
/// symmetry `ket_sym` (its operations and coefficients c_P); `elements` gives
/// `<phi_I| O(v) |phi'_J>` of every instance (`registry::lookup_between`). Rows in parallel.
pub fn between<const D: usize, F: Family<D>>(
    ctx: &F::Context,
    ket_sym: &Symmetry<D>,
    bra: &F::Params<'_>,
    ket: &F::Params<'_>,
    elements: impl Fn(&F::Function<f64>, &F::Function<f64>, &F::Context, &[Vec<Vector<D>>]) -> Vec<f64> + Sync,
    arity: usize,
    v: &[f64],
) -> Result<Vec<f64>> {
    let instances = instances::<D>(arity, v)?;
    let bras = F::functions(bra, ctx)?;
    let kets = images::<D, F>(ctx, ket_sym, ket)?;
    let (nb, nk, p) = (bras.len(), kets.len(), instances.len());
    let rows: Vec<Vec<f64>> = bras
        .par_iter()
        .map(|b| {
            let mut row = vec![0.0; p * nk];
            for j in 0..nk {
                for (k, c) in kets.images[j].iter().zip(&kets.coef) {
                    for (q, x) in elements(b, k, ctx, &instances).into_iter().enumerate() {
                        row[q * nk + j] += c * x;
                    }
                }
            }
            row
        })
        .collect();
    let mut out = vec![0.0; p * nb * nk];
    for (i, row) in rows.iter().enumerate() {
        for q in 0..p {
            out[(q * nb + i) * nk..][..nk].copy_from_slice(&row[q * nk..][..nk]);
        }
    }
    Ok(out)
}

/// A two-basis element whose ket carries W directions (`path::between_gradient`):
/// `<phi_I| O(v) |phi'_J>` of a constant bra and a seeded ket, with its derivatives.
pub trait KetElement<const D: usize, F: Family<D>>: Sync {
    fn element<const W: usize>(
        &self,
        bra: &F::Function<f64>,
        ket: &F::Function<Dual<W>>,
        ctx: &F::Context,
        v: &[Vector<D>],
    ) -> Dual<W>;
}

/// One chunk of at most W directions of `between_gradient`: per bra, per instance, the derivatives
/// of the element along the `da.len()` directions.
#[allow(clippy::too_many_arguments)]
fn between_chunk<const D: usize, F: Family<D>, const W: usize>(
    ctx: &F::Context,
    ket_sym: &Symmetry<D>,
    bras: &[F::Function<f64>],
    f: &F::Function<f64>,
    da: &[Mat<D>],
    dv: &[f64],
    element: &impl KetElement<D, F>,
    instances: &[Vec<Vector<D>>],
) -> Result<Vec<Vec<f64>>> {
    let ket = Images::new(vec![F::seeded::<W>(f, da, dv, ctx)?], ket_sym, ctx)?;
    let count = da.len();
    Ok(bras
        .par_iter()
        .map(|b| {
            let mut out = Vec::with_capacity(instances.len() * count);
            for v in instances {
                let x = ket.images[0].iter().zip(&ket.coef).fold(Dual::<W>::from(0.0), |acc, (k, c)| acc + element.element(b, k, ctx, v) * *c);
                out.extend(x.eps.unwrap_generic(Const::<W>, U1).iter().take(count));
            }
            out
        })
        .collect())
}

/// `between`'s column of a ket basis of one function `ket` (`elements` as for `between`), with its
/// derivatives along the directions `dir` of that function's parameters: `p x (1 + P) x nb_bra`
/// (row-major; row 0 of each instance `between`'s values, row `1 + k` the derivative along
/// direction k). For the derivatives the function is seeded with the directions
/// (`Family::seeded`, chunks of at most `MAX_LANES`), its images taken under `ket_sym` and
/// `element` evaluated against each bra, whose functions carry none.
#[allow(clippy::too_many_arguments)]
pub fn between_gradient<const D: usize, F: Family<D>>(
    ctx: &F::Context,
    ket_sym: &Symmetry<D>,
    bra: &F::Params<'_>,
    ket: &F::Params<'_>,
    dir: &Directions,
    elements: impl Fn(&F::Function<f64>, &F::Function<f64>, &F::Context, &[Vec<Vector<D>>]) -> Vec<f64> + Sync,
    element: &impl KetElement<D, F>,
    arity: usize,
    v: &[f64],
) -> Result<Vec<f64>> {
    check(ket.len(), 1, "ket functions")?;
    let values = between::<D, F>(ctx, ket_sym, bra, ket, elements, arity, v)?;
    let instances = instances::<D>(arity, v)?;
    let bras = F::functions(bra, ctx)?;
    let f = F::functions(ket, ctx)?.remove(0);
    let (da, per) = dir.exponents::<D>()?;
    let (nb, rows) = (bras.len(), 1 + da.len());
    let mut out = vec![0.0; instances.len() * rows * nb];
    for (q, x) in values.chunks_exact(nb.max(1)).enumerate() {
        out[q * rows * nb..][..nb].copy_from_slice(x);
    }
    let mut first = 0;
    while first < da.len() {
        let count = (da.len() - first).min(MAX_LANES);
        let (a, u) = (&da[first..first + count], &dir.v[first * per..(first + count) * per]);
        let chunk = lanes!(count, between_chunk(ctx, ket_sym, &bras, &f, a, u, element, &instances))?;
        for (i, derivatives) in chunk.iter().enumerate() {
            for (q, d) in derivatives.chunks_exact(count).enumerate() {
                for (k, x) in d.iter().enumerate() {
                    out[(q * rows + first + 1 + k) * nb + i] = *x;
                }
            }
        }
        first += count;
    }
    Ok(out)
}

/// The instances of an operator's vectors `v` (`p x arity x n`, flat): `arity` D-vectors each; an
/// operator of no vectors (the overlap) has one instance and takes none.
pub fn instances<const D: usize>(arity: usize, v: &[f64]) -> Result<Vec<Vec<Vector<D>>>> {
    if arity == 0 {
        check(v.len(), 0, "operator vectors")?;
        return Ok(vec![vec![]]);
    }
    let per = arity * D;
    check(v.len(), v.len() / per * per, "operator vectors")?;
    Ok(v.chunks_exact(per).map(|vk| vk.chunks_exact(D).map(Vector::<D>::from_row_slice).collect()).collect())
}

/// `Σ_IJ c_I c_J Σ_P c_P <phi_I| O_k |P phi_J>` of an operator with `len` components `O_k`
/// (`element` returns them all), for each state `c` (the columns of `c`, `nb x ns` row-major):
/// `ns x len`, row-major. Rows `I` in parallel, `J >= I` mirrored as in `operator`,
/// summed in row order (the same bits for any number of threads).
pub fn contracted<G: Sync>(
    b: &Images<G>,
    c: &[f64],
    len: usize,
    element: impl Fn(&G, &G) -> Vec<f64> + Sync,
) -> Result<Vec<f64>> {
    let nb = b.len();
    check(c.len(), c.len() / nb.max(1) * nb, "coefficients (basis size x states)")?;
    let ns = c.len() / nb.max(1);
    let rows: Vec<Vec<f64>> = (0..nb)
        .into_par_iter()
        .map(|i| {
            let mut row = vec![0.0; ns * len];
            for j in i..nb {
                let mirror = if j == i { 1.0 } else { 2.0 };
                let mut o = vec![0.0; len];
                for (ket, cp) in b.images[j].iter().zip(&b.coef) {
                    for (acc, x) in o.iter_mut().zip(element(&b.functions[i], ket)) {
                        *acc += cp * x;
                    }
                }
                for s in 0..ns {
                    let weight = mirror * c[i * ns + s] * c[j * ns + s];
                    for (acc, x) in row[s * len..(s + 1) * len].iter_mut().zip(&o) {
                        *acc += weight * x;
                    }
                }
            }
            row
        })
        .collect();
    let mut out = vec![0.0; ns * len];
    for row in &rows {
        for (acc, x) in out.iter_mut().zip(row) {
            *acc += x;
        }
    }
    Ok(out)
}
