//! Floating ECGs' own operator elements (`operators::Specialised`): `N_TI²`, of which they are not
//! eigenfunctions (`kernel::angular`; there is no generic element).
use super::{kernel, Fecg};
use crate::operators::{angular, Elements, Specialised};

impl<const D: usize> Specialised<D> for Fecg {
    fn specialised() -> Vec<(&'static str, Elements<D, Self>)> {
        vec![(angular::NAME, Elements::Each(|bra, ket, _, v| kernel::angular::<D>(bra, ket, &v[0])))]
    }
}
