//! `<φ_I|φ'_J>`, the overlap of the functions of two bases (a bra basis and a ket basis of one
//! family, each with its own parameters and symmetriser; `path::between`): the first operator
//! between two bases, which transition moments between two states' bases need. No vectors.
use crate::ecg::Vector;
use crate::families::Family;

pub const NAME: &str = "overlap";

/// `<φ_I|φ'_J>` for normalised functions (`Family::overlap`).
pub fn element<const D: usize, F: Family<D>>(bra: &F::Function<f64>, ket: &F::Function<f64>, ctx: &F::Context, _: &[Vector<D>]) -> f64 {
    F::overlap(bra, ket, ctx)
}

#[cfg(test)]
mod tests {
    //! Plain ECGs of three coordinates: two bases that coincide give the overlap matrix of one
    //! (`path::matrices`); two different bases, the ket's with its own symmetriser, the closed
    //! form `<φ_I|φ_J> = (2^n √(|A_I||A_J|)/|A_I + A_J|)^{3/2}` of normalised Gaussians summed
    //! over the ket's images `A_J → T_Pᵀ A_J T_P` (|T_P| = ±1).
    use super::*;
    use crate::ecg::Mat;
    use crate::families::pecg::Pecg;
    use crate::operators::fixtures::{exponent, operators};
    use crate::params::Exponents;
    use crate::path;
    use crate::registry;

    const N: usize = 3;

    fn basis(seeds: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let a = seeds.iter().flat_map(|&s| exponent::<N>(s).transpose().iter().copied().collect::<Vec<_>>()).collect();
        (a, vec![1.0; seeds.len()])
    }

    fn swap() -> Mat<N> {
        Mat::<N>::from_row_slice(&[0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0])
    }

    fn between(bra: &Exponents, ket: &Exponents, ket_sym: &[(Mat<N>, f64)]) -> Vec<f64> {
        let ctx = <Pecg as Family<N>>::context(operators(vec![]), 0, &[bra, ket]).unwrap();
        let (arity, elements) = registry::lookup_between::<N, Pecg>("pecg", "pecg", NAME).unwrap();
        assert_eq!(arity, 0);
        path::between::<N, Pecg>(&ctx, ket_sym, bra, ket, |x, y, ctx, v| elements.of(x, y, ctx, v), 0, &[]).unwrap()
    }

    #[test]
    fn two_bases_that_coincide_give_the_overlap_matrix() {
        let (a, c_a) = basis(&[0.1, 0.7, 1.9, 2.6]);
        let b = Exponents { a: &a, c_a: &c_a };
        let sym = [(Mat::<N>::identity(), 0.5), (swap(), 0.5)];
        let got = between(&b, &b, &sym);
        let ctx = <Pecg as Family<N>>::context(operators(vec![]), 0, &[&b]).unwrap();
        let want = <Pecg as Family<N>>::matrices(&ctx, &sym, &b).unwrap().s;
        assert_eq!(got.len(), want.len());
        for (g, w) in got.iter().zip(&want) {
            assert!((g - w).abs() <= 1e-14 * w.abs().max(1e-3), "{g} vs {w}");
        }
    }

    #[test]
    fn two_bases_with_their_own_symmetrisers_give_the_closed_form() {
        let (a, c_a) = basis(&[0.3, 1.1, 2.2]);
        let (a2, c_a2) = basis(&[0.5, 1.4]);
        let (bra, ket) = (Exponents { a: &a, c_a: &c_a }, Exponents { a: &a2, c_a: &c_a2 });
        let ket_sym = [(Mat::<N>::identity(), 0.5), (swap(), -0.5)];
        let got = between(&bra, &ket, &ket_sym);
        assert_eq!(got.len(), 3 * 2);
        let (ai, aj) = (bra.exponents::<N>().unwrap(), ket.exponents::<N>().unwrap());
        for (i, a_i) in ai.iter().enumerate() {
            for (j, a_j) in aj.iter().enumerate() {
                let want: f64 = ket_sym
                    .iter()
                    .map(|(t, c)| {
                        let image = t.transpose() * a_j * t;
                        c * (8.0 * (a_i.determinant() * image.determinant()).sqrt() / (a_i + image).determinant()).powf(1.5)
                    })
                    .sum();
                let g = got[i * 2 + j];
                assert!((g - want).abs() <= 1e-13 * want.abs().max(1e-3), "({i}, {j}): {g} vs {want}");
            }
        }
    }

    #[test]
    fn a_bra_and_a_ket_of_two_families_are_refused_naming_the_three() {
        let err = registry::lookup_between::<N, Pecg>("pecg", "fecg", NAME).err().unwrap().to_string();
        assert!(err.contains("\"overlap\"") && err.contains("pecg bra") && err.contains("fecg ket"), "{err}");
    }
}
