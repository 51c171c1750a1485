//! The basis-family axis: what a kind of basis function is. A family names its function type,
//! generic over the scalar (`f64`, or a num-dual number that carries derivatives), reads its
//! parameters from the arrays of the binding's tuple (`FIELDS`, `params`; `crate::params`),
//! transforms a function under a symmetry operation (`images::Transform`), evaluates the
//! normalised element `<phi_I| 1, T, T_TI, V |phi_J>` and the primitives the generic operator
//! elements are built from (`overlap`, `damped`, `kinetic_only`, `shape`, `exponent`,
//! `centres`), and builds its symmetrised matrices, rows and row gradients (`path`'s generic
//! builds or its own kernels).
//!
//! One folder per family: plain ECG (`pecg::Pecg`), ECG-GVR (`ecg_gvr::EcgGvr`), floating ECG
//! (`fecg::Fecg`). In each, its kernels (below this trait), its `impl Family` in `mod.rs` (above
//! `path`) and its specialised operator elements in `operators.rs` (`operators::Specialised`,
//! beside the generic ones); the layers are in lib.rs's docs.
//!
//! A new family in the core: `families/<name>/mod.rs` with the family type and its
//! `impl Family` (its `Params` implementing `params::Parameters` and `cache::Keyed`, `FIELDS`
//! and `params` for the binding's tuple, the builds from `path` or its own kernels),
//! `families/<name>/operators.rs` with its `impl operators::Specialised` (an empty table: every
//! operator from its generic element), `pub mod` here, and in `engine` a `Kind` variant
//! (`from_name`, `name`, `fields`, `oriented`) with its arm of `dispatch!`. The binding reads any
//! family's tuple by its `FIELDS` (prebo-py `convert::columns`).
use nalgebra::SMatrix;

use crate::cache::Cache;
use crate::ecg::{Element, Mat, Operators, Real, Vector};
use crate::error::Result;
use crate::families::fecg::kernel::Centres;
use crate::gradient::Dual;
use crate::images::Transform;
use crate::matrices::Matrices;
use crate::params::{Column, Directions, Field, Parameters, Symmetry};

pub mod fecg;
pub mod ecg_gvr;
pub mod pecg;

/// How the profile `G(u)` of a damped overlap depends on `u` (`operators::profile`): what the
/// expectation values of `δ(r_w)`, of the powers of `|r_w|` and the density of `r_w` need to know
/// of a family.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// `G = Σ_k g_k (1 − u)^k`, the coefficients `g_k` (plain ECGs `[S_IJ]`, ECG-GVR of degree
    /// `K_I + K_J + N`).
    Polynomial(Vec<f64>),
    /// `S_IJ exp(−λ u)` (floating ECGs, `λ = |w^T r̄|²/q`).
    Exponential,
}

/// A kind of basis function in `D` coordinates.
pub trait Family<const D: usize>: Sized + 'static {
    /// The name the binding uses (`"pecg"`, `"ecg-gvr"`, `"fecg"`).
    const NAME: &'static str;
    /// The arrays of the binding's parameter tuple, in order (`_core.pyi`).
    const FIELDS: &'static [Field];
    /// The families whose functions are functions of this one too (a plain ECG is the ECG-GVR
    /// function of K = 0): a basis of them may meet one of this family between two bases.
    const CONTAINS: &'static [&'static str] = &[];
    /// Whether `rows(.., position)` evaluates every element in the orientation of a full build
    /// (lower index as bra), so that rows patched into the matrices give the bits of `matrices`.
    const ORIENTED: bool = true;
    /// One function over the scalar `T`.
    type Function<T: Real>: Clone + Send + Sync + Transform<D, Self::Context>;
    /// What the elements need beside the functions (operators, quadrature rules, N).
    type Context: Sync;
    /// The parameters of `k` functions.
    type Params<'a>: Parameters;

    /// The parameters in the arrays of the binding's tuple (`FIELDS`; number and kinds checked).
    fn params(columns: &[Column]) -> Result<Self::Params<'_>>;

    /// The context for the operators `ops`, total angular momentum `n_ang`, and the function
    /// sets that will meet in one call.
    fn context(ops: Operators<D>, n_ang: u32, sets: &[&Self::Params<'_>]) -> Result<Self::Context>;

    /// The functions of `p` (checked: positive-definite `A`, the family's own conditions).
    fn functions(p: &Self::Params<'_>, ctx: &Self::Context) -> Result<Vec<Self::Function<f64>>>;

    /// `<phi_I| 1, T, T_TI, V |phi_J>` for normalised functions.
    fn element<T: Real>(bra: &Self::Function<T>, ket: &Self::Function<T>, ctx: &Self::Context) -> Element<T>;

    /// `<phi_I|phi_J>` alone (default: from `element`).
    fn overlap<T: Real>(bra: &Self::Function<T>, ket: &Self::Function<T>, ctx: &Self::Context) -> T {
        Self::element(bra, ket, ctx).s
    }

    /// `f` over another scalar, with zero derivatives.
    fn cast<T: Real>(f: &Self::Function<f64>) -> Self::Function<T>;

    /// `f` with its parameters seeded along the directions `da[p]` and `dv` (the vector part,
    /// `da.len()` of them, flat): the derivatives of every element then come out of `element`.
    fn seeded<const W: usize>(
        f: &Self::Function<f64>,
        da: &[Mat<D>],
        dv: &[f64],
        ctx: &Self::Context,
    ) -> Result<Self::Function<Dual<W>>>;

    /// `phi(r) exp(-r^T (M ⊗ I_3) r)` with the normalisation constants of `phi` kept: the ket
    /// of an overlap that generates Gaussian-weighted operators (e.g. `r_w²` as `-∂/∂α` of the
    /// overlap at `M = α w w^T`). Only its overlaps (`overlap`) are meaningful.
    fn damped<T: Real>(f: &Self::Function<f64>, m: &SMatrix<T, D, D>) -> Self::Function<T>;

    /// The Gaussian exponent `A` of `f`, `exp(−r^T (A ⊗ I_3) r)` (the representation's coordinates).
    fn exponent(f: &Self::Function<f64>) -> &Mat<D>;

    /// The centres `s` of the Gaussian of `f` (zero but for floating ECGs).
    fn centres(_f: &Self::Function<f64>) -> Centres<D> {
        Centres::<D>::zeros()
    }

    /// The Hamiltonian's operators (Λ, the Coulomb pairs, the CM mass) the context holds.
    fn operators(ctx: &Self::Context) -> &Operators<D>;

    /// `ctx` without the Coulomb pairs: its `element` is `S, T, T_TI` with `V = 0`, at no Coulomb
    /// cost (the kinetic elements of damped functions, `drachmann::gradient::gradient_inv_r`).
    fn kinetic_only(ctx: &Self::Context) -> Self::Context;

    /// How the damped overlap of `bra` and `ket` depends on the damping (`Shape`).
    fn shape(bra: &Self::Function<f64>, ket: &Self::Function<f64>, ctx: &Self::Context, w: &Vector<D>) -> Shape;

    /// The symmetrised matrices of a basis (`path::matrices`, or the family's kernel).
    fn matrices(ctx: &Self::Context, sym: &Symmetry<D>, basis: &Self::Params<'_>) -> Result<Matrices>;

    /// Rows of trials against a basis and the trials' diagonals (`path::rows`, or the family's
    /// kernel), oriented for a trial that will sit at `position` (`None`: appended) when
    /// `ORIENTED`. The basis side's preparations are kept in `cache` for the next call against
    /// the same basis.
    fn rows(
        ctx: &Self::Context,
        sym: &Symmetry<D>,
        trials: &Self::Params<'_>,
        basis: &Self::Params<'_>,
        position: Option<usize>,
        cache: &Cache,
    ) -> Result<(Matrices, Vec<Element>)>;

    /// The row of one function against a basis and its diagonal, with their derivatives along
    /// the directions `dir` (`path::row_gradient`: dual numbers through `element`; or the
    /// family's hand-derived kernel); `cache` as for `rows`.
    fn row_gradient(
        ctx: &Self::Context,
        sym: &Symmetry<D>,
        trial: &Self::Params<'_>,
        dir: &Directions,
        basis: &Self::Params<'_>,
        cache: &Cache,
    ) -> Result<(Matrices, Vec<Element>)>;
}
