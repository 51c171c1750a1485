//! ECG-GVR's own operator elements (`operators::Specialised`): the momentum operators and the
//! orbit–orbit operator from the overlap's generating function (eqs. 26–26c, `momentum`; `p_g²`
//! the kinetic element with `Λ = g g^T`), and Drachmann's two elements with every damped element
//! read off one factorisation (`drachmann`), and the dipole's three forms (length and velocity
//! between bases of N = L and N = L + 1, acceleration between N = 0 and N = 1) and
//! the quadrupole between N = 0 and N = 2 (`transition`, no generic element), where the generic elements assume a Gaussian's
//! gradients or integrate over damped functions one by one.
use super::element::{element, GvrFunction, GvrOps};
use super::{drachmann, momentum as own, transition, EcgGvr};
use crate::operators::drachmann::{coulomb, COULOMB, GRADIENT};
use crate::ecg::Vector;
use crate::operators::{momentum, orbit, Elements, Specialised};

impl<const D: usize> Specialised<D> for EcgGvr {
    fn specialised() -> Vec<(&'static str, Elements<D, Self>)> {
        use Elements::{All, Each};
        vec![
            (momentum::P2, Each(p2::<D>)),
            (momentum::P4, Each(|bra, ket, go, v| momentum::p4_of::<D, Self>(own::momentum::<D>, bra, ket, go, &v[0]))),
            (momentum::P2P2, Each(|bra, ket, go, v| momentum::p2p2_of::<D, Self>(own::momentum::<D>, bra, ket, go, v))),
            (COULOMB, All(|bra, ket, go, v| coulomb::all_of::<D, Self>(drachmann::inverse_products::<D>, bra, ket, go, v))),
            (GRADIENT, Each(drachmann::gradient_inv_r::<D>)),
            (orbit::NAME, Each(own::orbit::<D>)),
            (transition::DIPOLE, Each(transition::dipole::<D, f64>)),
            (transition::VELOCITY, Each(transition::velocity::<D, f64>)),
            (transition::ACCELERATION, Each(transition::acceleration::<D>)),
            (transition::QUADRUPOLE, Each(transition::quadrupole::<D>)),
        ]
    }
}

/// `<φ_I| p_g² |φ_J>`, `v = [g]`: the kinetic element with `Λ = g g^T`, cheaper than the momentum
/// elements' hyper-dual numbers.
fn p2<const D: usize>(bra: &GvrFunction<D>, ket: &GvrFunction<D>, go: &GvrOps<D>, v: &[Vector<D>]) -> f64 {
    element(bra, ket, &go.with_kinetic(v[0] * v[0].transpose())).t
}
