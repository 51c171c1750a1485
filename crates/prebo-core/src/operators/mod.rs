//! The operator axis. The Hamiltonian's operators — overlap, kinetic energy with and without
//! the CM part (`T`, `T_TI`) and the Coulomb potential — are evaluated together by each family's
//! element (one pass over the shared `A_I + A_J` factorisation). Every further operator is one
//! module here with an element function generic over the family, built from the family's
//! primitives (`Family::overlap`, `Family::damped`, `Family::element`), and one line in
//! `registry`; `path::operator` symmetrises it and the binding exposes it by name
//! (`Engine.operator(name, params, w)`).
use crate::ecg::Vector;
use crate::error::{CoreError, Result};
use crate::families::plain::PlainEcg;
use crate::families::Family;

pub mod r2;

/// `<phi_I| O(w) |phi_J>` for normalised functions of family `F` and one operator vector `w`
/// (in the representation's coordinates, like the Coulomb vectors).
pub type ElementFn<const D: usize, F> = fn(
    &<F as Family<D>>::Function<f64>,
    &<F as Family<D>>::Function<f64>,
    &<F as Family<D>>::Context,
    &Vector<D>,
) -> f64;

/// The registered operators: name and element function.
fn registry<const D: usize, F: Family<D>>() -> Vec<(&'static str, ElementFn<D, F>)> {
    vec![(r2::NAME, r2::element::<D, F>)]
}

/// The names of the registered operators.
pub fn names() -> Vec<&'static str> {
    registry::<1, PlainEcg>().into_iter().map(|(name, _)| name).collect()
}

/// The element function of the operator `name`.
pub fn lookup<const D: usize, F: Family<D>>(name: &str) -> Result<ElementFn<D, F>> {
    registry::<D, F>()
        .into_iter()
        .find(|(n, _)| *n == name)
        .map(|(_, f)| f)
        .ok_or_else(|| CoreError::Unsupported(format!("operator {name:?} (registered: {:?})", names())))
}
