//! The operator axis. The Hamiltonian's operators — overlap, kinetic energy with and without
//! the CM part (`T`, `T_TI`) and the Coulomb potential — are evaluated together by each family's
//! element (one pass over the shared `A_I + A_J` factorisation). Every further operator is one
//! module here with an element function generic over the family, built from the family's
//! primitives (`Family::overlap`, `Family::damped`, `Family::element`; for the operators of one
//! pair vector beyond r², the damped overlap's profile in `profile`, which needs of a family only
//! its exponent and the `Shape` of that profile). A family with a cheaper or exact element of its
//! own declares it in its folder (`families/<name>/operators.rs`, `Specialised`); the registry
//! (`crate::registry`) takes that before the generic one, and gives each operator its arity, the
//! number of D-vectors it takes (a pair operator one, `w`; `p_g² p_h²` two momentum vectors; the
//! orbit–orbit operator the pair vector and two momentum vectors). `path::operator` symmetrises
//! it and the binding exposes it by name (`Engine.operator(name, params, v)`, `arity` vectors
//! per instance).
use crate::ecg::Vector;
use crate::families::Family;

pub mod angular;
pub mod araki_sucher;
pub mod delta;
pub mod density;
pub mod distance;
pub mod drachmann;
pub mod inverse;
pub mod inverse_square;
pub mod momentum;
pub mod orbit;
pub mod overlap;
pub mod profile;
pub mod r2;

/// `<phi_I| O(v) |phi_J>` for normalised functions of family `F` and the operator's vectors `v`
/// (its arity of them, in the representation's coordinates, like the Coulomb vectors; a pair
/// operator has one, `w`).
pub type ElementFn<const D: usize, F> = fn(
    &<F as Family<D>>::Function<f64>,
    &<F as Family<D>>::Function<f64>,
    &<F as Family<D>>::Context,
    &[Vector<D>],
) -> f64;

/// An operator's elements of all its instances at once (`instances`, each `arity` vectors), one
/// value per instance, for an operator whose instances share work (`drachmann::coulomb::all`).
pub type BatchFn<const D: usize, F> =
    fn(&<F as Family<D>>::Function<f64>, &<F as Family<D>>::Function<f64>, &<F as Family<D>>::Context, &[Vec<Vector<D>>]) -> Vec<f64>;

/// How an operator evaluates its instances for one pair of functions: each alone by its
/// `ElementFn`, or all at once by a `BatchFn`.
pub enum Elements<const D: usize, F: Family<D>> {
    Each(ElementFn<D, F>),
    All(BatchFn<D, F>),
}

impl<const D: usize, F: Family<D>> Elements<D, F> {
    /// `<phi_I| O(v) |phi_J>` for every instance `v` of `instances`.
    pub fn of(&self, bra: &F::Function<f64>, ket: &F::Function<f64>, ctx: &F::Context, instances: &[Vec<Vector<D>>]) -> Vec<f64> {
        match self {
            Elements::Each(element) => instances.iter().map(|v| element(bra, ket, ctx, v)).collect(),
            Elements::All(elements) => elements(bra, ket, ctx, instances),
        }
    }
}

/// The operator elements a family has of its own (in its folder, `families/<name>/operators.rs`):
/// by operator name, cheaper or exact where the generic element is slower or approximate, or for
/// an operator without a generic element (`angular`). The registry consults them first.
pub trait Specialised<const D: usize>: Family<D> {
    fn specialised() -> Vec<(&'static str, Elements<D, Self>)>;
}

/// What the operators' tests share: three coordinates, random exponents and centres, plain ECGs
/// of the ECG-GVR form, the pair vector `e_1 − e_2`.
#[cfg(test)]
pub(crate) mod fixtures {
    use crate::ecg::{Mat, Operators, Vector};
    use crate::families::fecg::kernel::Centres;
    use crate::families::ecg_gvr::element::{GvrFunction, GvrOps};

    pub const D: usize = 3;

    /// A positive-definite exponent `L Lᵀ + 0.3` with `L` lower-triangular, varied by `seed` (for
    /// N < 3 the leading block of N = 3's).
    pub fn exponent<const N: usize>(seed: f64) -> Mat<N> {
        let l = Mat::<N>::from_fn(|i, j| if j <= i { ((i * 3 + j) as f64 * 0.7 + seed).sin() } else { 0.0 });
        l * l.transpose() + Mat::<N>::identity() * 0.3
    }

    /// `a0` made CM-separable, `A 1 = c_A μ`: `A = Pᵀ a0 P + c_A μ μᵀ`, `P = I − 1 μᵀ`.
    pub fn separable<const N: usize>(a0: &Mat<N>, mu: &Vector<N>, c_a: f64) -> Mat<N> {
        let p = Mat::<N>::identity() - Vector::<N>::repeat(1.0) * mu.transpose();
        p.transpose() * a0 * p + mu * mu.transpose() * c_a
    }

    /// Centres `s` of spread `spread`, varied by `x`.
    pub fn centres<const N: usize>(x: f64, spread: f64) -> Centres<N> {
        Centres::<N>::from_fn(|i, c| spread * (x + i as f64 * 1.1 + c as f64 * 0.37).cos())
    }

    /// A plain ECG of the `Pecg` family (an ECG-GVR function at K = N = 0, `u` irrelevant).
    pub fn plain<const N: usize>(a: Mat<N>, c_a: f64, go: &GvrOps<N>, index: usize) -> GvrFunction<N> {
        GvrFunction::new(a, Vector::<N>::from_fn(|i, _| if i == 0 { 1.0 } else { 0.0 }), 0, c_a, go, index).unwrap()
    }

    /// Kinetic `Λ = ½` and the Coulomb `pairs`.
    pub fn operators(pairs: Vec<(Vector<D>, f64)>) -> Operators<D> {
        Operators { lambda: Mat::<D>::identity() * 0.5, pairs, cm_mass: None }
    }

    pub fn w() -> Vector<D> {
        Vector::<D>::new(1.0, -1.0, 0.0)
    }

    /// The nodes and weights of the M-point Gauss–Hermite rule, `∫ e^{−y²} f(y) dy` (Golub–Welsch).
    pub fn gauss_hermite<const M: usize>() -> [(f64, f64); M] {
        let off = |i: usize, j: usize| (i.max(j) as f64 / 2.0).sqrt(); // (J)_{k−1,k} = √(k/2)
        let jacobi = nalgebra::DMatrix::<f64>::from_fn(M, M, |i, j| if i.abs_diff(j) == 1 { off(i, j) } else { 0.0 });
        let eig = nalgebra::SymmetricEigen::new(jacobi);
        std::array::from_fn(|k| (eig.eigenvalues[k], std::f64::consts::PI.sqrt() * eig.eigenvectors[(0, k)].powi(2)))
    }

    /// `got` within `tol` of `want`, relative.
    pub fn close(got: f64, want: f64, tol: f64) -> bool {
        (got - want).abs() <= tol * want.abs()
    }
}
