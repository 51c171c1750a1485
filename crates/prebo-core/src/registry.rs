//! The operator registry: every extra operator by name with its arity (D-vectors per instance),
//! and its elements for a key (bra family, ket family, operator) — the bra family's own
//! (`operators::Specialised`, in the family's folder) before the generic element in `operators`.
//! Pairs of one family have elements, and between two bases a family's pair with a family it
//! contains (`Family::CONTAINS`: a plain bra, an ECG-GVR ket); any other pair is refused in one
//! line naming the three. Operators of one basis (`generic`, symmetrised by `path::operator`) and between two
//! bases of a family, each with its own parameters and symmetriser (`two_bases`, `path::between`):
//! a new one is its module in `operators`, its line here and, where a family has its own element,
//! that family's `operators.rs`.
use crate::error::{CoreError, Result};
use crate::families::ecg_gvr::transition::{ACCELERATION, DIPOLE, QUADRUPOLE, VELOCITY};
use crate::families::pecg::Pecg;
use crate::families::Family;
use crate::operators::drachmann::{self, coulomb, gradient};
use crate::operators::{angular, araki_sucher, delta, distance, inverse, inverse_square, momentum, orbit, overlap, r2, ElementFn, Elements, Specialised};

/// An operator's element of one vector, as `Elements::Each` of arity 1.
macro_rules! one_vector {
    ($element:path) => {{
        let element: ElementFn<D, F> = |bra, ket, ctx, v| $element(bra, ket, ctx, &v[0]);
        Elements::Each(element)
    }};
}

/// The registered operators: name, arity, and the generic element over any family (`None`: none;
/// a family may have its own, `Specialised`).
fn generic<const D: usize, F: Family<D>>() -> Vec<(&'static str, usize, Option<Elements<D, F>>)> {
    use Elements::{All, Each};
    vec![
        (r2::NAME, 1, Some(one_vector!(r2::element::<D, F>))),
        (distance::NAME, 1, Some(one_vector!(distance::element::<D, F>))),
        (inverse::NAME, 1, Some(one_vector!(inverse::element::<D, F>))),
        (inverse_square::NAME, 1, Some(one_vector!(inverse_square::element::<D, F>))),
        (delta::NAME, 1, Some(one_vector!(delta::element::<D, F>))),
        (araki_sucher::NAME, 1, Some(one_vector!(araki_sucher::element::<D, F>))),
        (momentum::P2, 1, Some(one_vector!(momentum::p2::<D, F>))),
        (momentum::P4, 1, Some(one_vector!(momentum::p4::<D, F>))),
        (momentum::P2P2, 2, Some(Each(momentum::p2p2::<D, F>))),
        (drachmann::COULOMB, 1, Some(All(coulomb::all::<D, F>))),
        (drachmann::GRADIENT, 1, Some(Each(gradient::gradient_inv_r::<D, F>))),
        (orbit::NAME, 3, Some(Each(orbit::element::<D, F>))),
        (angular::NAME, 1, None),
    ]
}

/// The registered operators between two bases (`path::between`): name, arity, generic element
/// (`None`: a family's own, `Specialised`). The quadrupole's D vectors are the columns of its
/// D x D matrix (`transition`).
fn two_bases<const D: usize, F: Family<D>>() -> Vec<(&'static str, usize, Option<Elements<D, F>>)> {
    vec![
        (overlap::NAME, 0, Some(Elements::Each(overlap::element::<D, F>))),
        (DIPOLE, 1, None),
        (VELOCITY, 1, None),
        (ACCELERATION, 1, None),
        (QUADRUPOLE, D, None),
    ]
}

/// Whether the elements of the two-basis operator `name` need the Coulomb pairs (the acceleration
/// form's `∇ V`); the others are read off overlaps, whose context goes without them.
pub fn coulomb_between(name: &str) -> bool {
    name == ACCELERATION
}

/// Whether the two-basis operator `name` joins a bra basis of N = `bra` to a ket basis of
/// N = `ket`: the overlap two bases of one N, the dipole's length and velocity forms N = L to
/// N = L + 1 for every L, its acceleration form N = 0 to N = 1 and the quadrupole N = 0 to N = 2
/// (derived there alone); else a line saying which N its elements join.
pub fn joins(name: &str, bra: u32, ket: u32) -> Result<()> {
    let (joined, reach) = match name {
        DIPOLE | VELOCITY => (ket == bra + 1, "N = L to N = L + 1".to_string()),
        ACCELERATION => ((bra, ket) == (0, 1), "N = 0 to N = 1; derived there alone".to_string()),
        QUADRUPOLE => ((bra, ket) == (0, 2), "N = 0 to N = 2".to_string()),
        _ => (bra == ket, format!("N = {ket} to N = {ket}")),
    };
    if joined {
        return Ok(());
    }
    Err(CoreError::Unsupported(format!("operator {name:?} between a bra of N = {bra} and a ket of N = {ket} (its elements join {reach})")))
}

/// The N of the context the elements of the two-basis operator `name` read both bases' functions
/// at (`path::between`): the ket's for the dipole's length and velocity forms (the bra raised to it,
/// `transition`), else the bra's (the acceleration form's and the quadrupole's ket as its partner
/// of N = 0).
pub fn context_n(name: &str, bra: u32, ket: u32) -> u32 {
    match name {
        DIPOLE | VELOCITY => ket,
        _ => bra,
    }
}

/// The names of the registered operators between two bases.
pub fn names_between() -> Vec<&'static str> {
    two_bases::<1, Pecg>().into_iter().map(|(name, ..)| name).collect()
}

/// The registered operators of the family `F` (bra and ket of that family): name, arity, and the
/// family's own element, else the generic one.
fn registry<const D: usize, F: Specialised<D>>(
    operators: Vec<(&'static str, usize, Option<Elements<D, F>>)>,
) -> Vec<(&'static str, usize, Option<Elements<D, F>>)> {
    let mut own = F::specialised();
    operators
        .into_iter()
        .map(|(name, arity, element)| {
            let at = own.iter().position(|(n, _)| *n == name);
            (name, arity, at.map(|i| own.swap_remove(i).1).or(element))
        })
        .collect()
}

/// The names of the registered operators.
pub fn names() -> Vec<&'static str> {
    generic::<1, Pecg>().into_iter().map(|(name, ..)| name).collect()
}

/// The names of the registered operators the family `F` evaluates.
pub fn derived<F: Specialised<1>>() -> Vec<&'static str> {
    registry::<1, F>(generic::<1, F>()).into_iter().filter(|(.., element)| element.is_some()).map(|(name, ..)| name).collect()
}

/// The arity and elements of operator `name` between a bra of family `bra` and a ket of family
/// `ket`, both `F` (the engine's one family; `Family::NAME`), in one basis.
pub fn lookup<const D: usize, F: Specialised<D>>(bra: &str, ket: &str, name: &str) -> Result<(usize, Elements<D, F>)> {
    find(registry::<D, F>(generic::<D, F>()), bra, ket, name, names())
}

/// The arity and elements of operator `name` between a bra basis of family `bra` and a ket basis
/// of family `ket` (`path::between`).
pub fn lookup_between<const D: usize, F: Specialised<D>>(bra: &str, ket: &str, name: &str) -> Result<(usize, Elements<D, F>)> {
    let ours = |family: &str| family == F::NAME || F::CONTAINS.contains(&family);
    let (bra, ket) = if ours(bra) && ours(ket) { (F::NAME, F::NAME) } else { (bra, ket) };
    find(registry::<D, F>(two_bases::<D, F>()), bra, ket, name, names_between())
}

/// The entry `name` of `operators` for the key (bra family, ket family, operator).
fn find<const D: usize, F: Family<D>>(
    operators: Vec<(&'static str, usize, Option<Elements<D, F>>)>,
    bra: &str,
    ket: &str,
    name: &str,
    names: Vec<&'static str>,
) -> Result<(usize, Elements<D, F>)> {
    let (_, arity, element) = operators
        .into_iter()
        .find(|(n, ..)| *n == name)
        .ok_or_else(|| CoreError::Unsupported(format!("operator {name:?} (registered: {names:?})")))?;
    if (bra, ket) != (F::NAME, F::NAME) {
        return Err(CoreError::Unsupported(format!("operator {name:?}: no element between a {bra} bra and a {ket} ket")));
    }
    let element =
        element.ok_or_else(|| CoreError::Unsupported(format!("operator {name:?} is not derived for {} functions", F::NAME)))?;
    Ok((arity, element))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::families::ecg_gvr::EcgGvr;
    use crate::families::fecg::Fecg;

    #[test]
    fn a_pair_of_two_families_is_refused_naming_the_three() {
        let err = lookup::<3, Pecg>("pecg", "fecg", r2::NAME).err().unwrap().to_string();
        assert!(err.contains("\"r2\"") && err.contains("pecg bra") && err.contains("fecg ket"), "{err}");
    }

    #[test]
    fn every_family_evaluates_every_operator_but_n2_where_its_functions_are_eigenfunctions() {
        let all = names();
        let eigen: Vec<_> = all.iter().copied().filter(|n| *n != angular::NAME).collect();
        assert_eq!((derived::<Pecg>(), derived::<EcgGvr>(), derived::<Fecg>()), (eigen.clone(), eigen, all));
    }

    #[test]
    fn a_family_declares_only_registered_operators() {
        fn own<F: Specialised<1>>() -> Vec<&'static str> {
            F::specialised().into_iter().map(|(name, _)| name).collect()
        }
        for name in [own::<Pecg>(), own::<EcgGvr>(), own::<Fecg>()].concat() {
            assert!(names().contains(&name) || names_between().contains(&name), "{name}");
        }
    }
}
