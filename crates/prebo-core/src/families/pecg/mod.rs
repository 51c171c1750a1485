//! The plain-ECG family. Its matrices and rows come from the SIMD kernel (`kernel`, with the
//! builds of `build`), its row gradients from the hand-derived kernel in the same lanes
//! (`gradient`). Its generic elements (the diagonal of a row gradient by dual numbers where
//! `diagonal` does not apply, extra operators) are the ECG-GVR elements at K = N = 0 with
//! `u = e_1` (`ecg_gvr::element`), where `u` drops out and the elements are those of plain ECGs
//! (`element` module docs: "For K = N = 0 this is the plain-ECG ..."): one generic element
//! for both families, so the dual-number values stay those of that one code. Its own operator
//! element (`V/|r_w|` by eq. 19) is in `operators`.
use nalgebra::SMatrix;

use super::ecg_gvr::element::{self, GvrFunction, GvrOps};
use crate::cache::Cache;
use crate::ecg::{Element, Gaussian, Mat, Operators, Real, Vector};
use crate::error::Result;
use crate::families::{Family, Shape};
use crate::params::{check, columns, Column, Directions, Exponents, Field, Parameters, Symmetry};
use crate::gradient::{seed_matrix, Dual};
use crate::images::Images;
use crate::isa::best_isa;
use crate::matrices::Matrices;
use crate::path;

pub mod build;
pub mod gradient;
pub mod kernel;
pub mod operators;

/// The plain-ECG family: parameters `A` (`k x n x n`) and `c_A` (`Exponents`).
pub struct Pecg;

/// The plain ECGs of `p` with their images under `sym`, for the SIMD kernel.
fn gaussians<const D: usize>(p: &Exponents, sym: &Symmetry<D>) -> Result<Images<Gaussian<D>>> {
    let a = p.exponents::<D>()?;
    let f = a
        .into_iter()
        .zip(p.c_a)
        .enumerate()
        .map(|(i, (a, c))| Gaussian::new(a, *c, i))
        .collect::<Result<_>>()?;
    Images::new(f, sym, &())
}

impl<const D: usize> Family<D> for Pecg {
    const NAME: &'static str = "pecg";
    const FIELDS: &'static [Field] = &[Field::floats("A"), Field::floats("c_A")];
    /// Rows in full-build orientation from the SIMD kernel (`build::rows`).
    const ORIENTED: bool = true;
    type Function<T: Real> = GvrFunction<D, T>;
    type Context = GvrOps<D>;
    type Params<'a> = Exponents<'a>;

    fn params(c: &[Column]) -> Result<Exponents<'_>> {
        let c = columns(<Self as Family<D>>::NAME, <Self as Family<D>>::FIELDS, c)?;
        Ok(Exponents { a: c[0].floats()?, c_a: c[1].floats()? })
    }

    fn context(ops: Operators<D>, _: u32, _: &[&Exponents]) -> Result<GvrOps<D>> {
        GvrOps::new(ops, 0, 0)
    }

    fn functions(p: &Exponents, go: &GvrOps<D>) -> Result<Vec<GvrFunction<D>>> {
        let a = p.exponents::<D>()?;
        let u = Vector::<D>::from_fn(|i, _| if i == 0 { 1.0 } else { 0.0 });
        a.into_iter()
            .zip(p.c_a)
            .enumerate()
            .map(|(i, (a, c))| GvrFunction::new(a, u, 0, *c, go, i))
            .collect()
    }

    fn element<T: Real>(bra: &GvrFunction<D, T>, ket: &GvrFunction<D, T>, go: &GvrOps<D>) -> Element<T> {
        element::element(bra, ket, go)
    }

    fn cast<T: Real>(f: &GvrFunction<D>) -> GvrFunction<D, T> {
        f.cast()
    }

    /// Directions of `A` only (`dv` is ignored: u drops out).
    fn seeded<const W: usize>(f: &GvrFunction<D>, da: &[Mat<D>], _: &[f64], go: &GvrOps<D>) -> Result<GvrFunction<D, Dual<W>>> {
        GvrFunction::new(seed_matrix(&f.a, da), seed_matrix(&f.u, &[]), 0, f.c_a, go, 0)
    }

    fn exponent(f: &GvrFunction<D>) -> &Mat<D> {
        &f.a
    }

    fn operators(ctx: &Self::Context) -> &Operators<D> {
        &ctx.ops
    }

    fn kinetic_only(ctx: &Self::Context) -> Self::Context {
        ctx.without_pairs()
    }

    fn shape(bra: &GvrFunction<D>, ket: &GvrFunction<D>, go: &GvrOps<D>, _w: &Vector<D>) -> Shape {
        Shape::Polynomial(vec![<Self as Family<D>>::overlap(bra, ket, go)])
    }

    fn damped<T: Real>(f: &GvrFunction<D>, m: &SMatrix<T, D, D>) -> GvrFunction<D, T> {
        f.damped(m)
    }

    fn matrices(go: &GvrOps<D>, sym: &Symmetry<D>, basis: &Exponents) -> Result<Matrices> {
        Ok(build::matrices(&gaussians(basis, sym)?, &go.ops))
    }

    fn rows(
        go: &GvrOps<D>,
        sym: &Symmetry<D>,
        trials: &Exponents,
        basis: &Exponents,
        position: Option<usize>,
        cache: &Cache,
    ) -> Result<(Matrices, Vec<Element>)> {
        let b = cache.get(basis, || gaussians(basis, sym))?;
        Ok(build::rows(&gaussians(trials, sym)?, &b, &go.ops, position))
    }

    /// The row from `gradient` (directions of `A` only, as `seeded`), the basis in its lanes
    /// kept in `cache`; the diagonal, where both sides move, from the same kernel (`diagonal`),
    /// or by dual numbers (`path::row_gradient` against no basis) where that does not apply.
    fn row_gradient(
        go: &GvrOps<D>,
        sym: &Symmetry<D>,
        trial: &Exponents,
        dir: &Directions,
        basis: &Exponents,
        cache: &Cache,
    ) -> Result<(Matrices, Vec<Element>)> {
        check(trial.len(), 1, "trial functions")?;
        let f = Gaussian::new(trial.exponents::<D>()?[0], trial.c_a[0], 0)?;
        let (da, _) = dir.exponents::<D>()?;
        let diag = match diagonal(&f, &da, sym, &go.ops)? {
            Some(diag) => diag,
            None => path::row_gradient::<D, Self>(go, sym, trial, dir, &Exponents::default(), &Cache::default())?.1,
        };
        let kets = cache.get(basis, || {
            Ok(gradient::Kets::new(&*cache.get(basis, || gaussians(basis, sym))?, best_isa()))
        })?;
        Ok((gradient::row_gradient(&f, &da, &kets, &go.ops), diag))
    }
}

/// Whether the operators commute with the permutation `p`: `Pᵀ Λ P = Λ`, and every Coulomb
/// vector maps to one of the same charge (up to sign).
fn commutes<const D: usize>(p: &Mat<D>, ops: &Operators<D>) -> bool {
    p.transpose() * ops.lambda * p == ops.lambda
        && ops.pairs.iter().all(|(w, q)| {
            let pw = p * w;
            ops.pairs.iter().any(|(v, r)| r == q && (pw == *v || pw == -v))
        })
}

/// The trial's diagonal `Σ_P c_P <φ|O|Pφ>` with its derivatives along `da`, both sides moving,
/// from the bra-side kernel: the operators commute with the operations, so `Σ_P c_P <φ|O|P dφ>
/// = Σ_P c_P <P⁻¹φ|O|dφ> = Σ_P c_{P⁻¹} <dφ|O|Pφ>`, the bra's derivative with the coefficients
/// `c_{P⁻¹}`, added to that with `c_P`. None where an operation does not commute with the
/// operators or its inverse is not among them.
pub(crate) fn diagonal<const D: usize>(
    f: &Gaussian<D>,
    da: &[Mat<D>],
    sym: &Symmetry<D>,
    ops: &Operators<D>,
) -> Result<Option<Vec<Element>>> {
    let inverse: Option<Vec<f64>> = sym
        .iter()
        .map(|(p, _)| sym.iter().find(|(q, _)| *q == p.transpose()).map(|&(_, c)| c))
        .collect();
    let Some(inverse) = inverse.filter(|_| sym.iter().all(|(p, _)| commutes(p, ops))) else {
        return Ok(None);
    };
    let mut own = Images::new(vec![f.clone()], sym, &())?;
    let isa = best_isa();
    let bra = gradient::row_gradient(f, da, &gradient::Kets::new(&own, isa), ops);
    own.coef = inverse;
    let ket = gradient::row_gradient(f, da, &gradient::Kets::new(&own, isa), ops);
    let at = |m: &Matrices, r: usize| Element { s: m.s[r], t: m.t[r], t_ti: m.t_ti[r], v: m.v[r] };
    Ok(Some(
        (0..bra.rows)
            .map(|r| {
                let mut e = at(&bra, r);
                if r > 0 {
                    e += (1.0, at(&ket, r));
                }
                e
            })
            .collect(),
    ))
}
