//! The ECG-GVR family (paper eqs. globalvector, ecg-gvr): ECGs times a power of a global vector,
//! `|v|^{2K} (v_x + i v_y)^N exp(-r^T A r)`, `v = u^T r`.
//!
//! - `series`: the series Ω of the overlap and the formulas on it alone (`omega`,
//!   `cm_kinetic`), written once for the generic element and the kernels;
//! - `element`: the function (`GvrFunction`), its context (`GvrOps`: N and the Gauss–Legendre rules)
//!   and the generic element over `f64` or dual numbers (the derivation is in its docs);
//! - `kernel`: the same element in `f64` lanes without allocation, its Coulomb τ-quadratures in
//!   `tau`; `build`: matrices and rows with it, compiled per instruction set;
//! - `gradient`: the row gradient by hand-derived reverse mode in the kernel's lanes;
//! - `momentum`: `p_g²`, `p_g⁴` and the orbit–orbit operator from the overlap's generating
//!   function (eqs. 26–26c);
//! - `drachmann`: `V/|r_w|` (eq. 38) from the Coulomb elements of damped functions as
//!   rank-one updates of one factorisation;
//! - `transition`: the dipole's reduced elements between bases of N = L and N = L + 1 (length and
//!   velocity forms) from overlaps of functions of N = L + 1, the quadrupole's between N = 0 and
//!   N = 2 from second moments of N = 0 functions;
//! - `operators`: the family's own operator elements (`momentum`, `drachmann`) for the registry;
//! - `coulomb` (tests only): the closed form of the Coulomb τ-integral.
use nalgebra::SMatrix;

use crate::cache::Cache;
use crate::ecg::{Element, Mat, Operators, Real, Vector};
use crate::error::Result;
use crate::families::{Family, Shape};
use crate::params::{columns, matrices_of, Column, Directions, Exponents, Field, Symmetry};
use crate::gradient::{seed_matrix, Dual};
use crate::isa::best_isa;
use crate::matrices::Matrices;
use crate::path;
use element::{element, functions, GvrFunction, GvrOps, GvrParams};

pub mod build;
/// The closed-form Coulomb τ-integral (docs/gvr.md): slower than the quadrature it checks.
#[cfg(test)]
mod coulomb;
pub mod drachmann;
pub mod element;
pub mod gradient;
pub mod kernel;
pub mod momentum;
pub mod operators;
pub mod series;
pub mod tau;
pub mod transition;

/// The ECG-GVR family: parameters `A` (`k x n x n`), `u` (`k x n`), `K`, `c_A` (`GvrParams`); N is
/// the context's.
pub struct EcgGvr;

impl<const D: usize> Family<D> for EcgGvr {
    const NAME: &'static str = "ecg-gvr";
    const FIELDS: &'static [Field] =
        &[Field::floats("A"), Field::floats("u"), Field::naturals("K"), Field::floats("c_A")];
    const CONTAINS: &'static [&'static str] = &["pecg"];
    type Function<T: Real> = GvrFunction<D, T>;
    type Context = GvrOps<D>;
    type Params<'a> = GvrParams<'a>;

    fn params(c: &[Column]) -> Result<GvrParams<'_>> {
        let c = columns(<Self as Family<D>>::NAME, <Self as Family<D>>::FIELDS, c)?;
        let e = Exponents { a: c[0].floats()?, c_a: c[3].floats()? };
        Ok(GvrParams { e, u: c[1].floats()?, k: c[2].naturals()? })
    }

    fn context(ops: Operators<D>, n_ang: u32, sets: &[&GvrParams]) -> Result<GvrOps<D>> {
        let k_max = sets.iter().flat_map(|p| p.k.iter()).copied().max().unwrap_or(0);
        GvrOps::new(ops, n_ang, k_max)
    }

    fn functions(p: &GvrParams, go: &GvrOps<D>) -> Result<Vec<GvrFunction<D>>> {
        functions(p, go)
    }

    fn element<T: Real>(bra: &GvrFunction<D, T>, ket: &GvrFunction<D, T>, go: &GvrOps<D>) -> Element<T> {
        element(bra, ket, go)
    }

    fn cast<T: Real>(f: &GvrFunction<D>) -> GvrFunction<D, T> {
        f.cast()
    }

    fn seeded<const W: usize>(f: &GvrFunction<D>, da: &[Mat<D>], du: &[f64], go: &GvrOps<D>) -> Result<GvrFunction<D, Dual<W>>> {
        let du: Vec<Vector<D>> = matrices_of::<D, 1>(du, da.len(), "global-vector directions")?;
        GvrFunction::new(seed_matrix(&f.a, da), seed_matrix(&f.u, &du), f.k, f.c_a, go, 0)
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

    fn shape(bra: &GvrFunction<D>, ket: &GvrFunction<D>, go: &GvrOps<D>, w: &Vector<D>) -> Shape {
        Shape::Polynomial(element::profile(bra, ket, go, w))
    }

    fn damped<T: Real>(f: &GvrFunction<D>, m: &SMatrix<T, D, D>) -> GvrFunction<D, T> {
        f.damped(m)
    }

    /// The f64 kernel (`build`, `kernel`).
    fn matrices(go: &GvrOps<D>, sym: &Symmetry<D>, basis: &GvrParams) -> Result<Matrices> {
        build::matrices(go, sym, basis, best_isa())
    }

    /// The f64 kernel, oriented as `path::rows` (`build`).
    fn rows(
        go: &GvrOps<D>,
        sym: &Symmetry<D>,
        trials: &GvrParams,
        basis: &GvrParams,
        position: Option<usize>,
        cache: &Cache,
    ) -> Result<(Matrices, Vec<Element>)> {
        build::rows(go, sym, trials, basis, position, best_isa(), cache)
    }

    /// The row by hand-derived reverse mode (`gradient`); the diagonal, where both sides
    /// move, by dual numbers (`path::row_gradient` against no basis).
    fn row_gradient(
        go: &GvrOps<D>,
        sym: &Symmetry<D>,
        trial: &GvrParams,
        dir: &Directions,
        basis: &GvrParams,
        cache: &Cache,
    ) -> Result<(Matrices, Vec<Element>)> {
        let row = gradient::row_gradient(go, sym, trial, dir, basis, cache)?;
        let (_, diag) = path::row_gradient::<D, Self>(go, sym, trial, dir, &GvrParams::default(), &Cache::default())?;
        Ok((row, diag))
    }
}
