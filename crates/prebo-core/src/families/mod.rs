//! The basis-family axis: what every kind of basis function provides to the builds. A family
//! names its function type, generic over the scalar (`f64`, or a num-dual number that carries
//! derivatives), reads its parameters from flat row-major arrays, transforms a function under a
//! symmetry operation (`images::Transform`) and evaluates the normalised element
//! `<phi_I| 1, T, T_TI, V |phi_J>`. It owns its parameters end to end: their type (`Params`,
//! with its cache key), their arrays in the binding's tuple (`FIELDS`, `params`). From these the generic path (`path`) builds matrices, rows
//! and row gradients for any family; each family's `matrices`, `rows` and `row_gradient` call it
//! or the family's own kernels.
//!
//! One folder per family, its kernels and gradients beside it: plain ECG (`pecg::Pecg`),
//! ECG-GVR (`gvr::EcgGvr`), floating ECG (`fecg::Fecg`). This module uses none of
//! them, nor `path`: a family uses the trait and the path, not the other way round.
//!
//! A new family in the core: `families/<name>/mod.rs` with the family type and its
//! `impl Family` (its `Params` implementing `Parameters` and `cache::Keyed`, `FIELDS` and
//! `params` for the binding's tuple, the builds from `path` or its own kernels), `pub mod` here,
//! and in `engine` a `Kind` variant (`from_name`, `name`, `fields`, `oriented`) with its arm of
//! `dispatch!`. The binding reads any family's tuple by its `FIELDS` (prebo-py `convert::columns`).
use nalgebra::SMatrix;

use crate::cache::{Cache, Keyed};
use crate::ecg::{Element, Mat, Operators, Real, Vector};
use crate::families::fecg::kernel::Centres;
use crate::error::{CoreError, Result};
use crate::gradient::Dual;
use crate::images::Transform;
use crate::matrices::Matrices;
use crate::operators::drachmann::coulomb::{self, InverseProducts};
use crate::operators::drachmann::gradient;
use crate::operators::{momentum, orbit, ElementFn};

pub mod fecg;
pub mod ecg_gvr;
pub mod pecg;

/// One array of a family's parameter tuple as the binding passes it (`Family::FIELDS`, in order).
#[derive(Clone, Debug, PartialEq)]
pub enum Column {
    Floats(Vec<f64>),
    /// non-negative integers (the powers K)
    Naturals(Vec<u32>),
}

impl Column {
    /// The values of a `Floats` column.
    pub fn floats(&self) -> Result<&[f64]> {
        match self {
            Column::Floats(v) => Ok(v),
            Column::Naturals(_) => Err(CoreError::ShapeMismatch("integers where floats are expected".into())),
        }
    }

    /// The values of a `Naturals` column.
    pub fn naturals(&self) -> Result<&[u32]> {
        match self {
            Column::Naturals(v) => Ok(v),
            Column::Floats(_) => Err(CoreError::ShapeMismatch("floats where integers are expected".into())),
        }
    }
}

/// One array of a family's parameter tuple: its name (in errors) and whether it holds integers.
#[derive(Clone, Copy, Debug)]
pub struct Field {
    pub name: &'static str,
    pub naturals: bool,
}

impl Field {
    pub const fn floats(name: &'static str) -> Self {
        Self { name, naturals: false }
    }

    pub const fn naturals(name: &'static str) -> Self {
        Self { name, naturals: true }
    }
}

/// The columns of a tuple, checked against the family's fields in number (each column's kind is
/// checked where it is read: `Column::floats`, `Column::naturals`).
pub fn columns<'a>(family: &str, fields: &[Field], columns: &'a [Column]) -> Result<&'a [Column]> {
    check(columns.len(), fields.len(), &format!("{family} parameter arrays"))?;
    Ok(columns)
}

/// A family's parameters of `k` functions (`Family::Params`): views of flat row-major arrays, with
/// their exact bits as the key of the basis side kept between calls (`cache`).
pub trait Parameters: Keyed + Default + Copy + Send + Sync {
    /// `k`, the number of functions.
    fn len(&self) -> usize;

    fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The part every family's parameters have: the exponent matrices `a` (`k x n x n`) and the CM
/// exponents `c_a` (`k`); the plain-ECG parameters.
#[derive(Clone, Copy, Debug, Default)]
pub struct Exponents<'a> {
    pub a: &'a [f64],
    pub c_a: &'a [f64],
}

impl Exponents<'_> {
    /// The exponent matrices, checked against `c_a`.
    pub fn exponents<const D: usize>(&self) -> Result<Vec<Mat<D>>> {
        check(self.a.len(), self.len() * D * D, "exponent matrices")?;
        Ok(self.a.chunks_exact(D * D).map(Mat::<D>::from_row_slice).collect())
    }

    /// The key's part of these arrays: their lengths, then every value's bits.
    pub fn bits(&self) -> impl Iterator<Item = u64> + '_ {
        let lengths = [self.a.len(), self.c_a.len()].map(|n| n as u64);
        lengths.into_iter().chain(self.a.iter().chain(self.c_a).map(|x| x.to_bits()))
    }
}

impl Parameters for Exponents<'_> {
    fn len(&self) -> usize {
        self.c_a.len()
    }
}

impl Keyed for Exponents<'_> {
    fn key(&self) -> Vec<u64> {
        self.bits().collect()
    }
}

/// P directions in one function's parameter space: `P x n x n` derivatives of `A` and the
/// derivatives of the family's vector part (`P x n` of `u`, `P x n x 3` of `s`; plain ECGs: none).
#[derive(Clone, Copy, Debug)]
pub struct Directions<'a> {
    pub a: &'a [f64],
    pub v: &'a [f64],
}

impl Directions<'_> {
    /// The `A` directions as matrices, and the number of vector values per direction.
    pub fn exponents<const D: usize>(&self) -> Result<(Vec<Mat<D>>, usize)> {
        let p = self.a.len() / (D * D).max(1);
        check(self.a.len(), p * D * D, "exponent directions")?;
        let per = self.v.len().checked_div(p).unwrap_or(0);
        check(self.v.len(), p * per, "vector directions")?;
        Ok((self.a.chunks_exact(D * D).map(Mat::<D>::from_row_slice).collect(), per))
    }
}

/// `count` matrices of `R x C` values each from a flat slice (the vector part of directions).
pub fn matrices_of<const R: usize, const C: usize>(
    v: &[f64],
    count: usize,
    what: &str,
) -> Result<Vec<SMatrix<f64, R, C>>> {
    check(v.len(), count * R * C, what)?;
    Ok(v.chunks_exact(R * C)
        .map(SMatrix::<f64, R, C>::from_row_slice)
        .collect())
}

pub fn check(len: usize, want: usize, what: &str) -> Result<()> {
    if len == want {
        Ok(())
    } else {
        Err(CoreError::ShapeMismatch(format!(
            "{what}: {len} values, expected {want}"
        )))
    }
}

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

/// `<phi_I| N_TI² |phi_J>` of normalised functions of family `F` (`operators::angular`), `μ` the
/// mass fractions.
pub type Angular<const D: usize, F> = fn(&<F as Family<D>>::Function<f64>, &<F as Family<D>>::Function<f64>, &Vector<D>) -> f64;

/// `(<phi_I| p_h² |phi_J>, <p_g² phi_I| p_h² phi_J>)` of normalised functions of family `F`, for
/// `p_g = −i Σ_k g_k ∇_k` with D-vectors `g` and `h` (`operators::momentum`;
/// docs/properties-derivations.md §5): at `h = g` the elements of `p_g²` and `p_g⁴`.
pub type Momentum<const D: usize, F> = fn(
    &<F as Family<D>>::Function<f64>,
    &<F as Family<D>>::Function<f64>,
    &<F as Family<D>>::Context,
    &Vector<D>,
    &Vector<D>,
) -> (f64, f64);

/// Symmetry operations `(T, c_P)`: `phi -> phi(T r)` with Young-operator coefficient `c_P`.
pub type Symmetry<const D: usize> = [(Mat<D>, f64)];

/// A kind of basis function in `D` coordinates.
pub trait Family<const D: usize>: Sized + 'static {
    /// The name the binding uses (`"pecg"`, `"ecg-gvr"`, `"fecg"`).
    const NAME: &'static str;
    /// The arrays of the binding's parameter tuple, in order (`_core.pyi`).
    const FIELDS: &'static [Field];
    /// Whether `rows(.., position)` evaluates every element in the orientation of a full build
    /// (lower index as bra), so that rows patched into the matrices give the bits of `matrices`.
    const ORIENTED: bool = true;
    /// The element of the momentum operators `p_h²` and `p_g² p_h²` (`Momentum`): by default that
    /// of a Gaussian about centres (plain and floating ECGs, `operators::momentum::gaussian`), for
    /// ECG-GVR its own.
    const MOMENTUM: Momentum<D, Self> = momentum::gaussian::<D, Self>;
    /// The element of the orbit–orbit operator `p_g·M(r_w)·p_h` (`operators::orbit`): by default
    /// that of functions whose gradients are a Gaussian times a linear polynomial (plain and
    /// floating ECGs), for ECG-GVR its own.
    const ORBIT: ElementFn<D, Self> = orbit::element::<D, Self>;
    /// The elements `1/(|r_w| |r_w'|)` of `V/|r_w|` per Coulomb pair `w'` (`operators::drachmann`,
    /// operator `coulomb_inv_r`): by default eq. (38) over the family's own `1/|r_w'|` element of
    /// its damped functions (`drachmann::products_by_damping`); plain ECGs have them in closed form
    /// (eq. 19), ECG-GVR reads the damped elements off one factorisation.
    const COULOMB: InverseProducts<D, Self> = coulomb::products_by_damping::<D, Self>;
    /// The element of `<∇φ_I| Λ/|r_w| |∇φ_J>` (`operators::drachmann`, operator `gradient_inv_r`):
    /// by default eq. (30) over the family's kinetic elements of its damped functions
    /// (`drachmann::gradient_inv_r`); ECG-GVR reads each node off one factorisation.
    const GRADIENT: ElementFn<D, Self> = gradient::gradient_inv_r::<D, Self>;
    /// The element of `N_TI²` where the functions are not its eigenfunctions (`Angular`), `None`
    /// where they are (`N_TI² φ = N(N + 1) φ`).
    const ANGULAR: Option<Angular<D, Self>> = None;
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
    /// cost (the kinetic elements of damped functions, `drachmann::gradient_inv_r`).
    fn kinetic_only(ctx: &Self::Context) -> Self::Context;

    /// `<phi_I| p_g² |phi_J>` (`operators::momentum`): `MOMENTUM`'s, where a family has no
    /// cheaper one (ECG-GVR: its kinetic element with `Λ = g g^T`).
    fn momentum_square(bra: &Self::Function<f64>, ket: &Self::Function<f64>, ctx: &Self::Context, g: &Vector<D>) -> f64 {
        (Self::MOMENTUM)(bra, ket, ctx, g, g).0
    }

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
