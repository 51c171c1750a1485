//! Flat-slice entry points: row-major arrays in, row-major arrays out, the
//! coordinate dimension `n` dispatched once to the const-generic kernels.
use crate::assemble;
use crate::build::{self, Matrices, Symmetrised};
use crate::fecg::{self, Centres, Fecg};
use crate::gradient::{self, Dual};
use crate::gvr::{self, Gvr, GvrOps};
use crate::images::Images;
use crate::ecg::{Element, Gaussian, Mat, Operators, Vector};
use crate::error::{CoreError, Result};

/// Largest number of coordinates compiled (laboratory frame: particles).
pub const MAX_DIM: usize = 8;

/// The operators and the symmetry of a system, in one coordinate representation.
pub struct Setup<'a> {
    /// number of coordinates `n` (particles in the laboratory frame)
    pub n: usize,
    /// `n x n` kinetic matrix `Λ`
    pub lambda: &'a [f64],
    /// `n_pairs x n` Coulomb vectors `w`
    pub pair_w: &'a [f64],
    /// `n_pairs` charge products
    pub pair_q: &'a [f64],
    /// `n_ops x n x n` symmetry transformations `T` (`A -> T^T A T`)
    pub sym_t: &'a [f64],
    /// `n_ops` Young-operator coefficients
    pub sym_c: &'a [f64],
    /// total mass for the CM elimination, or `None`
    pub cm_mass: Option<f64>,
}

/// A set of functions: `k x n x n` exponent matrices and `k` values of `c_A`.
pub struct Functions<'a> {
    pub a: &'a [f64],
    pub c_a: &'a [f64],
}

fn check(len: usize, want: usize, what: &str) -> Result<()> {
    if len == want {
        Ok(())
    } else {
        Err(CoreError::ShapeMismatch(format!("{what}: {len} values, expected {want}")))
    }
}

impl Setup<'_> {
    fn operators<const D: usize>(&self) -> Result<(Operators<D>, Vec<(Mat<D>, f64)>)> {
        check(self.lambda.len(), D * D, "kinetic matrix")?;
        check(self.pair_w.len(), self.pair_q.len() * D, "Coulomb vectors")?;
        check(self.sym_t.len(), self.sym_c.len() * D * D, "symmetry transformations")?;
        if self.sym_c.is_empty() {
            return Err(CoreError::ShapeMismatch("no symmetry operations (need at least the identity)".into()));
        }
        let pairs = self
            .pair_q
            .iter()
            .enumerate()
            .map(|(p, q)| (Vector::<D>::from_row_slice(&self.pair_w[p * D..(p + 1) * D]), *q))
            .collect();
        let ops = Operators { lambda: Mat::<D>::from_row_slice(self.lambda), pairs, cm_mass: self.cm_mass };
        let sym = self
            .sym_c
            .iter()
            .enumerate()
            .map(|(p, c)| (Mat::<D>::from_row_slice(&self.sym_t[p * D * D..(p + 1) * D * D]), *c))
            .collect();
        Ok((ops, sym))
    }
}

fn gaussians<const D: usize>(f: &Functions) -> Result<Vec<Gaussian<D>>> {
    check(f.a.len(), f.c_a.len() * D * D, "exponent matrices")?;
    f.c_a
        .iter()
        .enumerate()
        .map(|(i, c)| Gaussian::new(Mat::<D>::from_row_slice(&f.a[i * D * D..(i + 1) * D * D]), *c, i))
        .collect()
}

macro_rules! dispatch {
    ($n:expr, $f:ident ( $($arg:expr),* )) => {
        match $n {
            1 => $f::<1>($($arg),*),
            2 => $f::<2>($($arg),*),
            3 => $f::<3>($($arg),*),
            4 => $f::<4>($($arg),*),
            5 => $f::<5>($($arg),*),
            6 => $f::<6>($($arg),*),
            7 => $f::<7>($($arg),*),
            8 => $f::<8>($($arg),*),
            n => Err(CoreError::Unsupported(format!("{n} coordinates (at most {MAX_DIM})"))),
        }
    };
}

fn matrices_d<const D: usize>(setup: &Setup, basis: &Functions) -> Result<Matrices> {
    let (ops, sym) = setup.operators::<D>()?;
    let basis = Symmetrised::new(gaussians::<D>(basis)?, &sym)?;
    Ok(build::matrices(&basis, &ops))
}

fn rows_d<const D: usize>(setup: &Setup, trials: &Functions, basis: &Functions) -> Result<(Matrices, Vec<Element>)> {
    let (ops, sym) = setup.operators::<D>()?;
    let trials = Symmetrised::new(gaussians::<D>(trials)?, &sym)?;
    let basis = Symmetrised::new(gaussians::<D>(basis)?, &sym)?;
    Ok(build::rows(&trials, &basis, &ops))
}

/// Overlap, kinetic (lab and translation-free) and Coulomb matrices of a basis.
pub fn matrices(setup: &Setup, basis: &Functions) -> Result<Matrices> {
    dispatch!(setup.n, matrices_d(setup, basis))
}

/// Rows of trial functions against a basis, with the trials' diagonal elements.
pub fn rows(setup: &Setup, trials: &Functions, basis: &Functions) -> Result<(Matrices, Vec<Element>)> {
    dispatch!(setup.n, rows_d(setup, trials, basis))
}

/// ECG-GVR functions: `k x n x n` exponents, `k x n` global vectors, `k` powers K, `k` values of c_A.
pub struct GvrFunctions<'a> {
    pub a: &'a [f64],
    pub u: &'a [f64],
    pub k: &'a [u32],
    pub c_a: &'a [f64],
}

fn gvr_functions<const D: usize>(f: &GvrFunctions, go: &GvrOps<D>) -> Result<Vec<Gvr<D>>> {
    let nb = f.c_a.len();
    check(f.a.len(), nb * D * D, "exponent matrices")?;
    check(f.u.len(), nb * D, "global vectors")?;
    check(f.k.len(), nb, "powers K")?;
    (0..nb)
        .map(|i| {
            let a = Mat::<D>::from_row_slice(&f.a[i * D * D..(i + 1) * D * D]);
            let u = Vector::<D>::from_row_slice(&f.u[i * D..(i + 1) * D]);
            Gvr::new(a, u, f.k[i], f.c_a[i], go, i)
        })
        .collect()
}

fn gvr_ops<const D: usize>(setup: &Setup, n_ang: u32, k_max: u32) -> Result<(GvrOps<D>, Vec<(Mat<D>, f64)>)> {
    let (ops, sym) = setup.operators::<D>()?;
    Ok((GvrOps::new(ops, n_ang, k_max)?, sym))
}

fn gvr_matrices_d<const D: usize>(setup: &Setup, n_ang: u32, basis: &GvrFunctions) -> Result<Matrices> {
    let k_max = basis.k.iter().copied().max().unwrap_or(0);
    let (go, sym) = gvr_ops::<D>(setup, n_ang, k_max)?;
    let b = Images::new(gvr_functions(basis, &go)?, &sym, &go)?;
    Ok(assemble::symmetric(b.len(), |i, j| b.element(&b.functions[i], j, |x, y| gvr::element(x, y, &go))))
}

fn gvr_rows_d<const D: usize>(
    setup: &Setup,
    n_ang: u32,
    trials: &GvrFunctions,
    basis: &GvrFunctions,
    position: Option<usize>,
) -> Result<(Matrices, Vec<Element>)> {
    let k_max = basis.k.iter().chain(trials.k).copied().max().unwrap_or(0);
    let (go, sym) = gvr_ops::<D>(setup, n_ang, k_max)?;
    let t = Images::new(gvr_functions(trials, &go)?, &sym, &go)?;
    let b = Images::new(gvr_functions(basis, &go)?, &sym, &go)?;
    let el = |x: &Gvr<D>, y: &Gvr<D>| gvr::element(x, y, &go);
    Ok(oriented_rows(&t, &b, position, el))
}

/// Rows of trials `t` against basis `b` for a trial that will sit at `position` (`None`: appended).
/// Element `j` is evaluated with the lower index as bra — `(b_j, t)` for `j < position`,
/// `(t, b_j)` after — exactly as `assemble::symmetric` evaluates the full matrix, so a basis
/// grown from such rows has bit-for-bit the matrices of a fresh build.
fn oriented_rows<F: Sync>(
    t: &Images<F>,
    b: &Images<F>,
    position: Option<usize>,
    el: impl Fn(&F, &F) -> Element + Sync + Copy,
) -> (Matrices, Vec<Element>) {
    let pos = position.unwrap_or(b.len());
    assemble::rows(
        t.len(),
        b.len(),
        |i, j| if j < pos { t.element(&b.functions[j], i, el) } else { b.element(&t.functions[i], j, el) },
        |i| t.element(&t.functions[i], i, el),
    )
}

/// Symmetrised matrices of an ECG-GVR basis with total angular momentum `n_ang` (M = N).
pub fn gvr_matrices(setup: &Setup, n_ang: u32, basis: &GvrFunctions) -> Result<Matrices> {
    dispatch!(setup.n, gvr_matrices_d(setup, n_ang, basis))
}

/// Rows of ECG-GVR trial functions against a basis, with the trials' diagonal elements
/// (`position`: where the trial will sit, see `oriented_rows`).
pub fn gvr_rows(
    setup: &Setup,
    n_ang: u32,
    trials: &GvrFunctions,
    basis: &GvrFunctions,
    position: Option<usize>,
) -> Result<(Matrices, Vec<Element>)> {
    dispatch!(setup.n, gvr_rows_d(setup, n_ang, trials, basis, position))
}

/// P directions in one function's parameter space: `P x n x n` derivatives of `A` and
/// `P x n` of `u` (ECG-GVR) or `P x n x 3` of `s` (floating ECGs).
pub struct Directions<'a> {
    pub a: &'a [f64],
    pub v: &'a [f64],
}

impl Directions<'_> {
    /// The directions as matrices (`R x C` each for the vector part).
    fn split<const D: usize, const R: usize, const C: usize>(&self) -> Result<(Vec<Mat<D>>, Vec<nalgebra::SMatrix<f64, R, C>>)> {
        let p = self.a.len() / (D * D).max(1);
        check(self.a.len(), p * D * D, "exponent directions")?;
        check(self.v.len(), p * R * C, "vector directions")?;
        let a = (0..p).map(|k| Mat::<D>::from_row_slice(&self.a[k * D * D..(k + 1) * D * D])).collect();
        let v = (0..p).map(|k| nalgebra::SMatrix::<f64, R, C>::from_row_slice(&self.v[k * R * C..(k + 1) * R * C])).collect();
        Ok((a, v))
    }
}

/// Calls `$f::<W>` with the narrowest lane count W that holds `$count` directions. The
/// widths match the parameter counts of one function (GVR H2+ 5, pECG H2 6, GVR H2 and FECG
/// of 3 particles 9, FECG of 4 particles 15): a dual element costs about W times an f64 one.
macro_rules! lanes {
    ($count:expr, $f:ident ( $($arg:expr),* )) => {
        match $count {
            0..=4 => $f::<D, 4>($($arg),*),
            5 => $f::<D, 5>($($arg),*),
            6 => $f::<D, 6>($($arg),*),
            7..=8 => $f::<D, 8>($($arg),*),
            9 => $f::<D, 9>($($arg),*),
            10..=12 => $f::<D, 12>($($arg),*),
            _ => $f::<D, 16>($($arg),*),
        }
    };
}

fn gvr_chunk<const D: usize, const W: usize>(
    go: &GvrOps<D>,
    sym: &[(Mat<D>, f64)],
    f: &Gvr<D>,
    da: &[Mat<D>],
    du: &[Vector<D>],
    b: &Images<Gvr<D>>,
) -> Result<(Vec<Vec<Element>>, Vec<Element>)> {
    let trial = Gvr::<D, Dual<W>>::new(gradient::seed_matrix(&f.a, da), gradient::seed_matrix(&f.u, du), f.k, f.c_a, go, 0)?;
    gradient::chunk(trial, sym, go, b, Gvr::cast, da.len(), |x, y| gvr::element(x, y, go))
}

fn gvr_row_gradient_d<const D: usize>(
    setup: &Setup,
    n_ang: u32,
    trial: &GvrFunctions,
    dir: &Directions,
    basis: &GvrFunctions,
) -> Result<(Matrices, Vec<Element>)> {
    check(trial.c_a.len(), 1, "trial functions")?;
    let k_max = basis.k.iter().chain(trial.k).copied().max().unwrap_or(0);
    let (go, sym) = gvr_ops::<D>(setup, n_ang, k_max)?;
    let f = gvr_functions(trial, &go)?.remove(0);
    let b = Images::new(gvr_functions(basis, &go)?, &sym, &go)?;
    let (da, du) = dir.split::<D, D, 1>()?;
    gradient::gather(b.len(), da.len(), |first, count| {
        let (da, du) = (&da[first..first + count], &du[first..first + count]);
        lanes!(count, gvr_chunk(&go, &sym, &f, da, du, &b))
    })
}

/// The row of one ECG-GVR function against a basis and its diagonal, with their derivatives
/// along the directions `dir`: `(1 + P) x nb` matrices (row 0 the values, the function as bra)
/// and `1 + P` diagonal elements (module `gradient`).
pub fn gvr_row_gradient(
    setup: &Setup,
    n_ang: u32,
    trial: &GvrFunctions,
    dir: &Directions,
    basis: &GvrFunctions,
) -> Result<(Matrices, Vec<Element>)> {
    dispatch!(setup.n, gvr_row_gradient_d(setup, n_ang, trial, dir, basis))
}

/// Floating ECGs: `k x n x n` exponents, `k x n x 3` centres, `k` values of c_A.
pub struct FecgFunctions<'a> {
    pub a: &'a [f64],
    pub s: &'a [f64],
    pub c_a: &'a [f64],
}

fn fecg_functions<const D: usize>(f: &FecgFunctions) -> Result<Vec<Fecg<D>>> {
    let nb = f.c_a.len();
    check(f.a.len(), nb * D * D, "exponent matrices")?;
    check(f.s.len(), nb * D * 3, "centres")?;
    (0..nb)
        .map(|i| {
            let a = Mat::<D>::from_row_slice(&f.a[i * D * D..(i + 1) * D * D]);
            let s = Centres::<D>::from_row_slice(&f.s[i * D * 3..(i + 1) * D * 3]);
            Fecg::new(a, s, f.c_a[i], i)
        })
        .collect()
}

fn fecg_matrices_d<const D: usize>(setup: &Setup, basis: &FecgFunctions) -> Result<Matrices> {
    let (ops, sym) = setup.operators::<D>()?;
    let b = Images::new(fecg_functions::<D>(basis)?, &sym, &())?;
    Ok(assemble::symmetric(b.len(), |i, j| b.element(&b.functions[i], j, |x, y| fecg::element(x, y, &ops))))
}

fn fecg_rows_d<const D: usize>(
    setup: &Setup,
    trials: &FecgFunctions,
    basis: &FecgFunctions,
    position: Option<usize>,
) -> Result<(Matrices, Vec<Element>)> {
    let (ops, sym) = setup.operators::<D>()?;
    let t = Images::new(fecg_functions::<D>(trials)?, &sym, &())?;
    let b = Images::new(fecg_functions::<D>(basis)?, &sym, &())?;
    let el = |x: &Fecg<D>, y: &Fecg<D>| fecg::element(x, y, &ops);
    Ok(oriented_rows(&t, &b, position, el))
}

fn fecg_angular_d<const D: usize>(setup: &Setup, mu: &[f64], basis: &FecgFunctions) -> Result<Vec<f64>> {
    let (_, sym) = setup.operators::<D>()?;
    check(mu.len(), D, "mass fractions")?;
    let mu = Vector::<D>::from_row_slice(mu);
    let b = Images::new(fecg_functions::<D>(basis)?, &sym, &())?;
    // the N² element travels in the `s` slot of an Element
    let m = assemble::symmetric(b.len(), |i, j| {
        b.element(&b.functions[i], j, |x, y| Element { s: fecg::angular(x, y, &mu), ..Default::default() })
    });
    Ok(m.s)
}

fn fecg_chunk<const D: usize, const W: usize>(
    ops: &Operators<D>,
    sym: &[(Mat<D>, f64)],
    f: &Fecg<D>,
    da: &[Mat<D>],
    ds: &[Centres<D>],
    b: &Images<Fecg<D>>,
) -> Result<(Vec<Vec<Element>>, Vec<Element>)> {
    let trial = Fecg::<D, Dual<W>>::new(gradient::seed_matrix(&f.a, da), gradient::seed_matrix(&f.s, ds), f.c_a, 0)?;
    gradient::chunk(trial, sym, &(), b, Fecg::cast, da.len(), |x, y| fecg::element(x, y, ops))
}

fn fecg_row_gradient_d<const D: usize>(
    setup: &Setup,
    trial: &FecgFunctions,
    dir: &Directions,
    basis: &FecgFunctions,
) -> Result<(Matrices, Vec<Element>)> {
    check(trial.c_a.len(), 1, "trial functions")?;
    let (ops, sym) = setup.operators::<D>()?;
    let f = fecg_functions::<D>(trial)?.remove(0);
    let b = Images::new(fecg_functions::<D>(basis)?, &sym, &())?;
    let (da, ds) = dir.split::<D, D, 3>()?;
    gradient::gather(b.len(), da.len(), |first, count| {
        let (da, ds) = (&da[first..first + count], &ds[first..first + count]);
        lanes!(count, fecg_chunk(&ops, &sym, &f, da, ds, &b))
    })
}

/// `gvr_row_gradient` for floating ECGs (directions of `A` and of the centres `s`).
pub fn fecg_row_gradient(
    setup: &Setup,
    trial: &FecgFunctions,
    dir: &Directions,
    basis: &FecgFunctions,
) -> Result<(Matrices, Vec<Element>)> {
    dispatch!(setup.n, fecg_row_gradient_d(setup, trial, dir, basis))
}

/// Symmetrised matrices of a floating-ECG basis.
pub fn fecg_matrices(setup: &Setup, basis: &FecgFunctions) -> Result<Matrices> {
    dispatch!(setup.n, fecg_matrices_d(setup, basis))
}

/// Rows of floating-ECG trial functions against a basis, with the trials' diagonal elements
/// (`position`: where the trial will sit, see `oriented_rows`).
pub fn fecg_rows(
    setup: &Setup,
    trials: &FecgFunctions,
    basis: &FecgFunctions,
    position: Option<usize>,
) -> Result<(Matrices, Vec<Element>)> {
    dispatch!(setup.n, fecg_rows_d(setup, trials, basis, position))
}

/// The symmetrised `<phi_I|N_TI²|phi_J>` matrix (row-major) of a floating-ECG basis (LFCC only).
pub fn fecg_angular(setup: &Setup, mu: &[f64], basis: &FecgFunctions) -> Result<Vec<f64>> {
    dispatch!(setup.n, fecg_angular_d(setup, mu, basis))
}
