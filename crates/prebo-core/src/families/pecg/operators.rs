//! Plain ECGs' own operator elements (`operators::Specialised`): `V/|r_w|` from the products
//! `<1/(|r_w| |r_w'|)>` in closed form (eq. 19, `drachmann::coulomb::inverse_products`) instead of
//! eq. (38)'s quadrature over damped functions.
use super::Pecg;
use crate::operators::drachmann::{self, coulomb};
use crate::operators::{Elements, Specialised};

impl<const D: usize> Specialised<D> for Pecg {
    fn specialised() -> Vec<(&'static str, Elements<D, Self>)> {
        vec![(drachmann::COULOMB, Elements::All(|bra, ket, ctx, v| coulomb::all_of::<D, Self>(coulomb::inverse_products::<D, Self>, bra, ket, ctx, v)))]
    }
}
