//! `r_w² = |Σ_k w_k r_k|²`, the square of a linear combination of the coordinates' 3-vectors; in
//! the laboratory frame with `w = e_i − e_j` the squared distance `r_ij²` of particles i and j.
//!
//! `exp(−α r_w²) = exp(−r^T (α w w^T ⊗ I_3) r)` is a Gaussian factor, so for every family
//! `<φ_I|r_w²|φ_J> = −∂/∂α <φ_I|φ_J exp(−α r_w²)>` at α = 0 with the normalisation constants
//! held fixed (`Family::damped`): one dual number through the family's overlap, exact; for a
//! polynomial profile (profile.rs) the same as its moment n = 2, `q Σ_k g_k (k + 3/2)`, which is
//! what is evaluated then (docs/properties-derivations.md, eq. 33).
use nalgebra::{Const, U1};

use super::profile::Profile;
use crate::ecg::Vector;
use crate::families::Family;
use crate::gradient::{seed, Dual};

pub const NAME: &str = "r2";

/// `<φ_I| r_w² |φ_J>` for normalised functions (units of the coordinates squared).
pub fn element<const D: usize, F: Family<D>>(
    bra: &F::Function<f64>,
    ket: &F::Function<f64>,
    ctx: &F::Context,
    w: &Vector<D>,
) -> f64 {
    Profile::<D, F>::of(bra, ket, ctx, w).moment(2).unwrap_or_else(|| {
        let alpha: Dual<1> = seed(0.0, std::iter::once(1.0));
        let damping = (w * w.transpose()).map(|x| alpha * x);
        let s = F::overlap(&F::cast::<Dual<1>>(bra), &F::damped(ket, &damping), ctx);
        -s.eps.unwrap_generic(Const::<1>, U1)[0]
    })
}

#[cfg(test)]
mod tests {
    //! Plain ECGs against the closed form `(3/2) wᵀ(A_I + A_J)⁻¹w S_IJ`; floating ECGs against
    //! the Gaussian second moment `(3/2 wᵀB⁻¹w + |wᵀr̄|²) S_IJ`; ECG-GVR at K = N = 0 equal to
    //! plain ECGs, and for K, N > 0 against central differences of the damped overlap in α.
    use super::*;
    use crate::ecg::Gaussian;
    use crate::families::fecg::kernel::{Centres, FecgFunction};
    use crate::families::fecg::{self, Fecg};
    use crate::families::ecg_gvr::element::{GvrFunction, GvrOps};
    use crate::families::ecg_gvr::EcgGvr;
    use crate::families::pecg::{self, Pecg};
    use crate::operators::fixtures::{close, exponent, w, D};

    fn operators() -> crate::ecg::Operators<D> {
        crate::operators::fixtures::operators(vec![])
    }

    #[test]
    fn plain_ecgs_match_the_closed_form() {
        let go = GvrOps::new(operators(), 0, 0).unwrap();
        let u = Vector::<D>::new(1.0, 0.0, 0.0);
        for (si, sj) in [(0.1, 0.9), (1.3, 2.2), (0.4, 0.4)] {
            let (ai, aj) = (exponent(si), exponent(sj));
            let (gi, gj) = (GvrFunction::new(ai, u, 0, 1.0, &go, 0).unwrap(), GvrFunction::new(aj, u, 0, 1.0, &go, 1).unwrap());
            let s = pecg::kernel::element(&Gaussian::new(ai, 1.0, 0).unwrap(), &Gaussian::new(aj, 1.0, 1).unwrap(), &go.ops).s;
            let b = (ai + aj).try_inverse().unwrap();
            let want = 1.5 * (w().transpose() * b * w())[(0, 0)] * s;
            let got = element::<D, Pecg>(&gi, &gj, &go, &w());
            assert!(close(got, want, 1e-13), "{got} vs {want}");
            // the ECG-GVR family at K = N = 0 is the same function
            assert!(close(element::<D, EcgGvr>(&gi, &gj, &go, &w()), want, 1e-13));
        }
    }

    #[test]
    fn floating_ecgs_match_the_second_moment() {
        let ops = operators();
        let centres = |x: f64| Centres::<D>::from_fn(|i, c| (x + i as f64 * 1.1 + c as f64 * 0.37).cos());
        let (fi, fj) = (
            FecgFunction::new(exponent(0.2), centres(0.3), 1.0, 0).unwrap(),
            FecgFunction::new(exponent(1.7), centres(2.1), 1.0, 1).unwrap(),
        );
        let b = (fi.a + fj.a).try_inverse().unwrap();
        let rbar = b * (fi.a * fi.s + fj.a * fj.s);
        let m = w().transpose() * rbar;
        let s = fecg::kernel::element(&fi, &fj, &ops).s;
        let want = (1.5 * (w().transpose() * b * w())[(0, 0)] + m.norm_squared()) * s;
        let got = element::<D, Fecg>(&fi, &fj, &ops, &w());
        assert!(close(got, want, 1e-12), "{got} vs {want}");
    }

    #[test]
    fn global_vector_functions_match_a_central_difference() {
        for n_ang in [0, 1, 2] {
            let go = GvrOps::new(operators(), n_ang, 3).unwrap();
            let gi = GvrFunction::new(exponent(0.5), Vector::<D>::new(0.3, 1.0, -0.4), 2, 1.0, &go, 0).unwrap();
            let gj = GvrFunction::new(exponent(1.1), Vector::<D>::new(-0.7, 0.2, 0.9), 3, 1.0, &go, 1).unwrap();
            let ww = w() * w().transpose();
            let damped = |a: f64| <EcgGvr as Family<D>>::overlap(&gi, &<EcgGvr as Family<D>>::damped(&gj, &(ww * a)), &go);
            // central differences at h and h/2, Richardson-extrapolated (error O(h⁴))
            let central = |h: f64| -(damped(h) - damped(-h)) / (2.0 * h);
            let h = 1e-3;
            let want = (4.0 * central(h / 2.0) - central(h)) / 3.0;
            let got = element::<D, EcgGvr>(&gi, &gj, &go, &w());
            assert!(close(got, want, 1e-9), "N = {n_ang}: {got} vs {want}");
        }
    }
}
