//! The engine: one basis family in one coordinate representation, with every build the
//! binding offers. Flat row-major arrays in and out, a basis as the arrays of its family's
//! parameter tuple (`params::Column`, read by `Family::params`); the coordinate dimension `n`
//! and the family are dispatched once per call to the const-generic, family-generic builds.
use crate::cache::Cache;
use crate::ecg::{Element, Mat, Operators, Vector, MAX_DIM};
use crate::error::{CoreError, Result};
use crate::path::KetElement;
use crate::families::fecg::Fecg;
use crate::families::ecg_gvr::transition::Form;
use crate::families::ecg_gvr::EcgGvr;
use crate::families::pecg::Pecg;
use crate::families::Family;
use crate::params::{check, Column, Directions, Field, Parameters};
use crate::matrices::Matrices;
use crate::operators::{density, Specialised};
use crate::registry;
use crate::path;

/// The basis families.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Pecg,
    EcgGvr,
    Fecg,
}

impl Kind {
    pub fn from_name(name: &str) -> Result<Self> {
        [Kind::Pecg, Kind::EcgGvr, Kind::Fecg]
            .into_iter()
            .find(|k| k.name() == name)
            .ok_or_else(|| CoreError::Unsupported(format!("basis family {name:?} (pecg, ecg-gvr or fecg)")))
    }

    pub fn name(self) -> &'static str {
        match self {
            Kind::Pecg => <Pecg as Family<1>>::NAME,
            Kind::EcgGvr => <EcgGvr as Family<1>>::NAME,
            Kind::Fecg => <Fecg as Family<1>>::NAME,
        }
    }

    /// The registered operators the family evaluates (`registry::derived`).
    pub fn operators(self) -> Vec<&'static str> {
        match self {
            Kind::Pecg => registry::derived::<Pecg>(),
            Kind::EcgGvr => registry::derived::<EcgGvr>(),
            Kind::Fecg => registry::derived::<Fecg>(),
        }
    }

    /// The arrays of the family's parameter tuple (`Family::FIELDS`).
    pub fn fields(self) -> &'static [Field] {
        match self {
            Kind::Pecg => <Pecg as Family<1>>::FIELDS,
            Kind::EcgGvr => <EcgGvr as Family<1>>::FIELDS,
            Kind::Fecg => <Fecg as Family<1>>::FIELDS,
        }
    }

    /// Whether rows reproduce full-build bits (`Family::ORIENTED`).
    pub fn oriented(self) -> bool {
        match self {
            Kind::Pecg => <Pecg as Family<1>>::ORIENTED,
            Kind::EcgGvr => <EcgGvr as Family<1>>::ORIENTED,
            Kind::Fecg => <Fecg as Family<1>>::ORIENTED,
        }
    }
}

/// The operators and the symmetry of a system in one coordinate representation (owned).
#[derive(Clone, Debug)]
pub struct Representation {
    /// number of coordinates `n` (particles in the laboratory frame)
    pub n: usize,
    /// `n x n` kinetic matrix `Λ`
    pub lambda: Vec<f64>,
    /// `n_pairs x n` Coulomb vectors `w`
    pub pair_w: Vec<f64>,
    /// `n_pairs` charge products
    pub pair_q: Vec<f64>,
    /// `n_ops x n x n` symmetry transformations `T` (`A -> T^T A T`)
    pub sym_t: Vec<f64>,
    /// `n_ops` Young-operator coefficients
    pub sym_c: Vec<f64>,
    /// total mass for the CM elimination, or `None`
    pub cm_mass: Option<f64>,
}

impl Representation {
    fn check(&self) -> Result<()> {
        let n = self.n;
        if n == 0 || n > MAX_DIM {
            return Err(CoreError::Unsupported(format!("{n} coordinates (at most {MAX_DIM})")));
        }
        check(self.lambda.len(), n * n, "kinetic matrix")?;
        check(self.pair_w.len(), self.pair_q.len() * n, "Coulomb vectors")?;
        check(self.sym_t.len(), self.sym_c.len() * n * n, "symmetry transformations")?;
        if self.sym_c.is_empty() {
            return Err(CoreError::ShapeMismatch(
                "no symmetry operations (need at least the identity)".into(),
            ));
        }
        Ok(())
    }

    fn operators<const D: usize>(&self) -> (Operators<D>, Vec<(Mat<D>, f64)>) {
        let pairs = self
            .pair_w
            .chunks_exact(D)
            .map(Vector::<D>::from_row_slice)
            .zip(self.pair_q.iter().copied());
        let ops = Operators {
            lambda: Mat::<D>::from_row_slice(&self.lambda),
            pairs: pairs.collect(),
            cm_mass: self.cm_mass,
        };
        let sym = self
            .sym_t
            .chunks_exact(D * D)
            .map(Mat::<D>::from_row_slice)
            .zip(self.sym_c.iter().copied());
        (ops, sym.collect())
    }
}

/// One basis family in one representation, with the total angular momentum N (ECG-GVR; M = N),
/// and the basis side of its last rows and row gradients (`cache`).
#[derive(Debug)]
pub struct Engine {
    pub kind: Kind,
    pub rep: Representation,
    pub n_ang: u32,
    cache: Cache,
}

/// Calls `$f::<D, F>($args)` for the engine's dimension and family (`$fam` limits the families).
macro_rules! dispatch {
    ($e:expr, $f:ident ( $($arg:expr),* )) => {
        match $e.kind {
            Kind::Pecg => dispatch!(@dim $e, $f, Pecg, ($($arg),*)),
            Kind::EcgGvr => dispatch!(@dim $e, $f, EcgGvr, ($($arg),*)),
            Kind::Fecg => dispatch!(@dim $e, $f, Fecg, ($($arg),*)),
        }
    };
    (@dim $e:expr, $f:ident, $fam:ty, ($($arg:expr),*)) => {
        match $e.rep.n {
            1 => $f::<1, $fam>($($arg),*),
            2 => $f::<2, $fam>($($arg),*),
            3 => $f::<3, $fam>($($arg),*),
            4 => $f::<4, $fam>($($arg),*),
            5 => $f::<5, $fam>($($arg),*),
            6 => $f::<6, $fam>($($arg),*),
            7 => $f::<7, $fam>($($arg),*),
            8 => $f::<8, $fam>($($arg),*),
            n => Err(CoreError::Unsupported(format!("{n} coordinates (at most {MAX_DIM})"))),
        }
    };
}

fn count_d<const D: usize, F: Family<D>>(basis: &[Column]) -> Result<usize> {
    Ok(F::params(basis)?.len())
}

fn matrices_d<const D: usize, F: Family<D>>(e: &Engine, basis: &[Column]) -> Result<Matrices> {
    let basis = F::params(basis)?;
    let (ops, sym) = e.rep.operators::<D>();
    F::matrices(&F::context(ops, e.n_ang, &[&basis])?, &sym, &basis)
}

fn rows_d<const D: usize, F: Family<D>>(
    e: &Engine,
    trials: &[Column],
    basis: &[Column],
    position: Option<usize>,
) -> Result<(Matrices, Vec<Element>)> {
    let (trials, basis) = (F::params(trials)?, F::params(basis)?);
    let (ops, sym) = e.rep.operators::<D>();
    F::rows(
        &F::context(ops, e.n_ang, &[&trials, &basis])?,
        &sym,
        &trials,
        &basis,
        position,
        &e.cache,
    )
}

fn row_gradient_d<const D: usize, F: Family<D>>(
    e: &Engine,
    trial: &[Column],
    dir: &Directions,
    basis: &[Column],
) -> Result<(Matrices, Vec<Element>)> {
    let (trial, basis) = (F::params(trial)?, F::params(basis)?);
    let (ops, sym) = e.rep.operators::<D>();
    F::row_gradient(&F::context(ops, e.n_ang, &[&trial, &basis])?, &sym, &trial, dir, &basis, &e.cache)
}

fn operator_d<const D: usize, F: Specialised<D>>(e: &Engine, name: &str, basis: &[Column], w: &[f64]) -> Result<Vec<f64>> {
    let (arity, elements) = registry::lookup::<D, F>(F::NAME, F::NAME, name)?;
    let basis = F::params(basis)?;
    let (ops, sym) = e.rep.operators::<D>();
    path::operator::<D, F>(&F::context(ops, e.n_ang, &[&basis])?, &sym, &basis, |bra, ket, ctx, v| elements.of(bra, ket, ctx, v), arity, w)
}

/// `between` for the family `F` of both bases (a contained family's columns as `F`'s,
/// `as_family`), the context at the N `registry::context_n` names.
fn between_d<const D: usize, F: Specialised<D>>(
    e: &Engine,
    name: &str,
    bra: &[Column],
    ket: &Engine,
    ket_params: &[Column],
    v: &[f64],
) -> Result<Vec<f64>> {
    let (arity, elements) = registry::lookup_between::<D, F>(e.kind.name(), ket.kind.name(), name)?;
    let (bra_columns, ket_columns) = (as_family::<D, F>(e.kind, bra)?, as_family::<D, F>(ket.kind, ket_params)?);
    let (bra, ket_p) = (F::params(&bra_columns)?, F::params(&ket_columns)?);
    let (ops, _) = e.rep.operators::<D>();
    let (_, ket_sym) = ket.rep.operators::<D>();
    let n = registry::context_n(name, e.n_ang, ket.n_ang);
    let full = F::context(ops, n, &[&bra, &ket_p])?;
    let ctx = if registry::coulomb_between(name) { full } else { F::kinetic_only(&full) };
    path::between::<D, F>(&ctx, &ket_sym, &bra, &ket_p, |x, y, ctx, v| elements.of(x, y, ctx, v), arity, v)
}

/// `between_gradient` for the family `F` of both bases (`as_family`), the context as for `between_d`.
fn between_gradient_d<const D: usize, F: Specialised<D>>(
    e: &Engine,
    name: &str,
    bra: &[Column],
    ket: &Engine,
    ket_params: &[Column],
    dir: &Directions,
    v: &[f64],
) -> Result<Vec<f64>>
where
    Form: KetElement<D, F>,
{
    let (arity, elements) = registry::lookup_between::<D, F>(e.kind.name(), ket.kind.name(), name)?;
    let (bra_columns, ket_columns) = (as_family::<D, F>(e.kind, bra)?, as_family::<D, F>(ket.kind, ket_params)?);
    let (bra, ket_p) = (F::params(&bra_columns)?, F::params(&ket_columns)?);
    let (ops, _) = e.rep.operators::<D>();
    let (_, ket_sym) = ket.rep.operators::<D>();
    let n = registry::context_n(name, e.n_ang, ket.n_ang);
    let ctx = F::kinetic_only(&F::context(ops, n, &[&bra, &ket_p])?);
    let elements = |x: &F::Function<f64>, y: &F::Function<f64>, ctx: &F::Context, v: &[Vec<Vector<D>>]| elements.of(x, y, ctx, v);
    path::between_gradient::<D, F>(&ctx, &ket_sym, &bra, &ket_p, dir, elements, &Form::of(name)?, arity, v)
}

/// The columns of a basis of family `kind` as those of `F`: as they are, or a plain ECG's `(A, c_A)`
/// as the ECG-GVR `(A, u = e_1, K = 0, c_A)` (`Family::CONTAINS`).
fn as_family<const D: usize, F: Family<D>>(kind: Kind, columns: &[Column]) -> Result<Vec<Column>> {
    if kind != Kind::Pecg || kind.name() == F::NAME {
        return Ok(columns.to_vec());
    }
    let count = <Pecg as Family<D>>::params(columns)?.len();
    let u = (0..count).flat_map(|_| (0..D).map(|i| f64::from(i == 0))).collect();
    Ok(vec![columns[0].clone(), Column::Floats(u), Column::Naturals(vec![0; count]), columns[1].clone()])
}

fn density_d<const D: usize, F: Family<D>>(e: &Engine, basis: &[Column], w: &[f64], c: &[f64], radii: &[f64]) -> Result<Vec<f64>> {
    check(w.len(), w.len() / D * D, "density vectors")?;
    let basis = F::params(basis)?;
    let (ops, sym) = e.rep.operators::<D>();
    let ctx = F::context(ops, e.n_ang, &[&basis])?;
    let b = path::images::<D, F>(&ctx, &sym, &basis)?;
    let mut out = Vec::new();
    for wk in w.chunks_exact(D) {
        let wk = Vector::<D>::from_row_slice(wk);
        out.extend(path::contracted(&b, c, radii.len(), |x, y| density::element::<D, F>(x, y, &ctx, &wk, radii))?);
    }
    Ok(out)
}

impl Engine {
    /// Checks the representation (shapes, `1 <= n <= MAX_DIM`); `n_ang` must be 0 except for ECG-GVR.
    pub fn new(kind: Kind, rep: Representation, n_ang: u32) -> Result<Self> {
        rep.check()?;
        if n_ang != 0 && kind != Kind::EcgGvr {
            return Err(CoreError::Unsupported(format!(
                "N = {n_ang} for {} functions (N = 0 only)",
                kind.name()
            )));
        }
        Ok(Self { kind, rep, n_ang, cache: Cache::default() })
    }

    /// The number of functions of a parameter tuple (checked as every build checks it).
    pub fn count(&self, params: &[Column]) -> Result<usize> {
        dispatch!(self, count_d(params))
    }

    /// Overlap, kinetic (full and translation-free) and Coulomb matrices of a basis.
    pub fn matrices(&self, basis: &[Column]) -> Result<Matrices> {
        dispatch!(self, matrices_d(self, basis))
    }

    /// Rows of trial functions against a basis, with the trials' diagonal elements; oriented
    /// for a trial that will sit at `position` (`None`: appended) when `kind.oriented()`.
    pub fn rows(
        &self,
        trials: &[Column],
        basis: &[Column],
        position: Option<usize>,
    ) -> Result<(Matrices, Vec<Element>)> {
        dispatch!(self, rows_d(self, trials, basis, position))
    }

    /// The row of one function against a basis and its diagonal with their derivatives along
    /// `dir`: `(1 + P) x nb` matrices (row 0 the values, the function as bra), `1 + P` diagonals.
    pub fn row_gradient(
        &self,
        trial: &[Column],
        dir: &Directions,
        basis: &[Column],
    ) -> Result<(Matrices, Vec<Element>)> {
        dispatch!(self, row_gradient_d(self, trial, dir, basis))
    }

    /// The symmetrised matrices of the registered operator `name`, one per instance of its
    /// `arity` vectors `w` (`p x arity x n`).
    pub fn operator(&self, name: &str, basis: &[Column], w: &[f64]) -> Result<Vec<f64>> {
        dispatch!(self, operator_d(self, name, basis, w))
    }

    /// The `p x nb_bra x nb_ket` matrices (row-major) of the registered two-basis operator `name`
    /// (`registry::lookup_between`) between the basis `bra` of this engine and the basis
    /// `ket_params` of `ket` (its family, N and symmetry: the kets are symmetrised by `ket`'s
    /// operations), one per instance of its `arity` vectors `v` (`p x arity x n`), for the N it
    /// joins (`registry::joins`: the dipole's forms N = L to N = L + 1, the quadrupole N = 0 to
    /// N = 2, the overlap two bases of one N). The bra's operators (its representation) serve both.
    pub fn between(&self, name: &str, bra: &[Column], ket: &Engine, ket_params: &[Column], v: &[f64]) -> Result<Vec<f64>> {
        self.joins(name, ket)?;
        match (self.kind, ket.kind) {
            (Kind::Pecg, Kind::Pecg) => dispatch!(@dim self, between_d, Pecg, (self, name, bra, ket, ket_params, v)),
            (Kind::Fecg, _) | (_, Kind::Fecg) => dispatch!(@dim self, between_d, Fecg, (self, name, bra, ket, ket_params, v)),
            _ => dispatch!(@dim self, between_d, EcgGvr, (self, name, bra, ket, ket_params, v)),
        }
    }

    /// `between`'s column of a ket basis of one function `ket_params`, with its derivatives along
    /// the directions `dir` of that function's parameters: `p x (1 + P) x nb_bra` (row 0 of each
    /// instance the values, `path::between_gradient`), for the dipole's forms between a plain or
    /// ECG-GVR bra and an ECG-GVR ket (`transition::Form`).
    pub fn between_gradient(
        &self,
        name: &str,
        bra: &[Column],
        ket: &Engine,
        ket_params: &[Column],
        dir: &Directions,
        v: &[f64],
    ) -> Result<Vec<f64>> {
        self.joins(name, ket)?;
        if self.kind == Kind::Fecg || ket.kind != Kind::EcgGvr {
            return Err(CoreError::Unsupported(format!(
                "operator {name:?}: derivatives between a {} bra and a {} ket (a plain or ECG-GVR bra and an ECG-GVR ket)",
                self.kind.name(),
                ket.kind.name()
            )));
        }
        dispatch!(@dim self, between_gradient_d, EcgGvr, (self, name, bra, ket, ket_params, dir, v))
    }

    /// Whether this engine's bases meet those of `ket` under the two-basis operator `name`: the
    /// same coordinates, and the N its elements join (`registry::joins`).
    fn joins(&self, name: &str, ket: &Engine) -> Result<()> {
        if ket.rep.n != self.rep.n {
            return Err(CoreError::ShapeMismatch(format!("a bra of {} coordinates and a ket of {}", self.rep.n, ket.rep.n)));
        }
        registry::joins(name, self.n_ang, ket.n_ang)
    }

    /// The spherically averaged densities `<Ψ| ρ̄_w(r) |Ψ>` (operators/density.rs) of the states
    /// `Ψ = Σ_I c_I Yφ_I` (`c`: `nb x ns`, row-major) at `radii`, one block per vector `w`
    /// (`p x ns x radii`).
    pub fn density(&self, basis: &[Column], w: &[f64], c: &[f64], radii: &[f64]) -> Result<Vec<f64>> {
        dispatch!(self, density_d(self, basis, w, c, radii))
    }
}
