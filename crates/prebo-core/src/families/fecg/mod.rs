//! The floating-ECG family (paper section FECG): ECGs with centres,
//! `exp(-(r - s)^T (A ⊗ I_3) (r - s))`.
//!
//! - `kernel`: the function (`FecgFunction`), the generic element over `f64` or dual numbers (the formulas
//!   are in its docs) and `<N_TI²>` (`angular`);
//! - `gradient`: the row gradient by hand-derived derivatives;
//! - `operators`: `<N_TI²>` for the registry.
//!
//! Matrices and rows come from the generic path (`path`).
use nalgebra::SMatrix;

use crate::cache::Cache;
use crate::ecg::{re, Element, Mat, Operators, Real, Vector};
use crate::error::Result;
use crate::families::{Family, Shape};
use crate::params::{columns, matrices_of, Column, Directions, Exponents, Field, Symmetry};
use crate::gradient::{seed_matrix, Dual};
use crate::matrices::Matrices;
use crate::path;
use kernel::{element, functions, pair, Centres, FecgFunction, FecgParams};

pub mod gradient;
pub mod kernel;
pub mod operators;

/// The floating-ECG family: parameters `A` (`k x n x n`), centres `s` (`k x n x 3`), `c_A`
/// (`FecgParams`).
pub struct Fecg;

impl<const D: usize> Family<D> for Fecg {
    const NAME: &'static str = "fecg";
    const FIELDS: &'static [Field] = &[Field::floats("A"), Field::floats("s"), Field::floats("c_A")];
    type Function<T: Real> = FecgFunction<D, T>;
    type Context = Operators<D>;
    type Params<'a> = FecgParams<'a>;

    fn params(c: &[Column]) -> Result<FecgParams<'_>> {
        let c = columns(<Self as Family<D>>::NAME, <Self as Family<D>>::FIELDS, c)?;
        Ok(FecgParams { e: Exponents { a: c[0].floats()?, c_a: c[2].floats()? }, s: c[1].floats()? })
    }

    fn context(ops: Operators<D>, _: u32, _: &[&FecgParams]) -> Result<Operators<D>> {
        Ok(ops)
    }

    fn functions(p: &FecgParams, _: &Operators<D>) -> Result<Vec<FecgFunction<D>>> {
        functions(p)
    }

    fn element<T: Real>(bra: &FecgFunction<D, T>, ket: &FecgFunction<D, T>, ops: &Operators<D>) -> Element<T> {
        element(bra, ket, ops)
    }

    fn overlap<T: Real>(bra: &FecgFunction<D, T>, ket: &FecgFunction<D, T>, _: &Operators<D>) -> T {
        pair(bra, ket).map_or(re(f64::NAN), |(s, _, _)| s)
    }

    fn cast<T: Real>(f: &FecgFunction<D>) -> FecgFunction<D, T> {
        f.cast()
    }

    fn seeded<const W: usize>(f: &FecgFunction<D>, da: &[Mat<D>], ds: &[f64], _: &Operators<D>) -> Result<FecgFunction<D, Dual<W>>> {
        let ds: Vec<Centres<D>> = matrices_of::<D, 3>(ds, da.len(), "centre directions")?;
        FecgFunction::new(seed_matrix(&f.a, da), seed_matrix(&f.s, &ds), f.c_a, 0)
    }

    fn exponent(f: &FecgFunction<D>) -> &Mat<D> {
        &f.a
    }

    fn centres(f: &FecgFunction<D>) -> Centres<D> {
        f.s
    }

    fn operators(ctx: &Self::Context) -> &Operators<D> {
        ctx
    }

    fn kinetic_only(ctx: &Self::Context) -> Self::Context {
        Operators { pairs: vec![], ..ctx.clone() }
    }

    fn shape(_bra: &FecgFunction<D>, _ket: &FecgFunction<D>, _ctx: &Operators<D>, _w: &Vector<D>) -> Shape {
        Shape::Exponential
    }

    fn damped<T: Real>(f: &FecgFunction<D>, m: &SMatrix<T, D, D>) -> FecgFunction<D, T> {
        f.damped(m)
    }

    fn matrices(ops: &Operators<D>, sym: &Symmetry<D>, basis: &FecgParams) -> Result<Matrices> {
        path::matrices::<D, Self>(ops, sym, basis)
    }

    fn rows(
        ops: &Operators<D>,
        sym: &Symmetry<D>,
        trials: &FecgParams,
        basis: &FecgParams,
        position: Option<usize>,
        cache: &Cache,
    ) -> Result<(Matrices, Vec<Element>)> {
        path::rows::<D, Self>(ops, sym, trials, basis, position, cache)
    }

    /// The row from the hand-derived gradient (`gradient`); the diagonal, where both sides
    /// move, by dual numbers (`path::row_gradient` against no basis).
    fn row_gradient(
        ops: &Operators<D>,
        sym: &Symmetry<D>,
        trial: &FecgParams,
        dir: &Directions,
        basis: &FecgParams,
        cache: &Cache,
    ) -> Result<(Matrices, Vec<Element>)> {
        let row = gradient::row_gradient(ops, sym, trial, dir, basis, cache)?;
        let (_, diag) = path::row_gradient::<D, Self>(ops, sym, trial, dir, &FecgParams::default(), &Cache::default())?;
        Ok((row, diag))
    }
}
