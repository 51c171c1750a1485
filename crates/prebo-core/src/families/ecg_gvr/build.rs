//! Symmetrised ECG-GVR matrices and oriented rows with the f64 kernel (`kernel`), in
//! parallel with rayon: the overrides of `Family::matrices` and `Family::rows` for `EcgGvr`.
//!
//! The functions and their symmetry images are built as by `path` (`path::images`), prepared
//! once per call, and every element is evaluated in the orientation of `path`: a full build has
//! function `i` as bra and the images of `j >= i` as kets; a trial's row has `(b_j, trial)` for
//! `j < position` and `(trial, b_j)` after, so rows patched into the matrices give the bits of a
//! full build. The kernel is compiled per instruction set (`isa_kernels!`, lanes of 8 for
//! AVX-512, 4 otherwise) and chosen by `isa::best_isa`; all give the same bits.
use rayon::prelude::*;

use super::element::{GvrOps, GvrParams};
use super::kernel::{symmetrised, Pairs, Prepared, Side};
use super::tau::Table;
#[cfg(test)]
use super::{series::Coefficients, tau::{derivative_series, integral_partials, padded_rule}};
use crate::assemble;
use crate::cache::Cache;
use crate::ecg::Element;
use crate::error::Result;
use crate::params::Symmetry;
#[cfg(test)]
use crate::isa::process_isa;
use crate::isa::Isa;
use crate::matrices::Matrices;

/// One symmetrised element `Σ_P c_P <bra| O |P ket>` from the images of the ket.
type ElementFn<const D: usize> =
    unsafe fn(&Prepared<D>, &[Prepared<D>], &[f64], &Table, &Pairs<D>, Option<f64>) -> Element;

/// The kernel compiled for one instruction set (lanes `W`, target feature), in module `$isa`.
macro_rules! isa_kernels {
    ($isa:ident, $w:literal $(, $feature:literal)?) => {
        mod $isa {
            use super::*;

            /// Safety: callers must pass only to a CPU with the feature (checked in `kernel`).
            $(#[target_feature(enable = $feature)])?
            pub(super) unsafe fn element<const D: usize>(
                bra: &Prepared<D>,
                images: &[Prepared<D>],
                coef: &[f64],
                table: &Table,
                pairs: &Pairs<D>,
                cm_mass: Option<f64>,
            ) -> Element {
                symmetrised::<D, $w>(bra, images, coef, table, pairs, cm_mass)
            }

            /// Safety: as `element`.
            #[cfg(test)]
            $(#[target_feature(enable = $feature)])?
            pub(super) unsafe fn partials(
                c: (&[f64], &[f64]),
                k: (u32, u32, u32),
                tau2: &[f64],
                weight: &[f64],
                inputs: &[[f64; 5]],
                out: &mut [(f64, [f64; 5])],
            ) {
                integral_partials::<$w>(c, k, tau2, weight, inputs, out)
            }
        }
    };
}

isa_kernels!(plain, 4);
#[cfg(target_arch = "x86_64")]
isa_kernels!(avx2, 4, "avx2");
#[cfg(target_arch = "x86_64")]
isa_kernels!(avx512, 8, "avx512f");

/// The kernel of `isa`, or of plain code where this CPU lacks it.
fn kernel<const D: usize>(isa: Isa) -> ElementFn<D> {
    #[cfg(target_arch = "x86_64")]
    {
        if isa == Isa::Avx512 && std::arch::is_x86_feature_detected!("avx512f") {
            return avx512::element::<D>;
        }
        if isa == Isa::Avx2 && std::arch::is_x86_feature_detected!("avx2") {
            return avx2::element::<D>;
        }
    }
    let _ = isa;
    plain::element::<D>
}

/// The Coulomb τ-integrals with their partial derivatives (`kernel::integral_partials`) for
/// each of `inputs`, on the best instruction set (`isa::best_isa`, read once per process): the
/// tests' entry point (the row gradient calls them inside its kernel).
#[cfg(test)]
pub(crate) fn partials(
    c: (&[f64], &[f64]),
    k: (u32, u32, u32),
    tau2: &[f64],
    weight: &[f64],
    inputs: &[[f64; 5]],
    out: &mut [(f64, [f64; 5])],
) {
    partials_with(process_isa(), c, k, tau2, weight, inputs, out)
}

/// `partials` on a chosen instruction set (plain code where this CPU lacks it).
#[cfg(test)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn partials_with(
    isa: Isa,
    c: (&[f64], &[f64]),
    k: (u32, u32, u32),
    tau2: &[f64],
    weight: &[f64],
    inputs: &[[f64; 5]],
    out: &mut [(f64, [f64; 5])],
) {
    // Safety: each kernel only on a CPU with its feature.
    unsafe {
        #[cfg(target_arch = "x86_64")]
        {
            if isa == Isa::Avx512 && std::arch::is_x86_feature_detected!("avx512f") {
                return avx512::partials(c, k, tau2, weight, inputs, out);
            }
            if isa == Isa::Avx2 && std::arch::is_x86_feature_detected!("avx2") {
                return avx2::partials(c, k, tau2, weight, inputs, out);
            }
        }
        let _ = isa;
        plain::partials(c, k, tau2, weight, inputs, out)
    }
}

/// The Coulomb τ-integral `∫_0^1 Ω(x − τ²γ_I², y − τ²γ_J², z − τ²γ_Iγ_J) dτ / e^L` of one pair
/// (K_I, K_J) for each of `inputs` = `[x, y, z, γ_I, γ_J]` (`element::quadrature`), with its partial
/// derivatives with respect to the five inputs (the maths of `element::quadrature_partials`), into
/// `out`: nodes in lanes of the f64 kernel (`kernel::integral_partials`, `partials`).
/// The tests' entry point; the row gradient keeps its rules per pair (`gradient`).
#[cfg(test)]
pub(crate) fn coulomb_partials<const D: usize>(
    go: &GvrOps<D>,
    ki: u32,
    kj: u32,
    inputs: &[[f64; 5]],
    out: &mut [(f64, [f64; 5])],
) {
    let c = Coefficients::new(ki, kj, go.n_ang).c;
    let (tau2, weight) = padded_rule(go.rule(ki + kj + go.n_ang));
    partials((&c, &derivative_series(&c)), (ki, kj, go.n_ang), &tau2, &weight, inputs, out);
}


/// Everything an element needs beside its two functions.
struct Kernel<'a, const D: usize> {
    element: ElementFn<D>,
    table: Table,
    pairs: Pairs<D>,
    cm_mass: Option<f64>,
    coef: &'a [f64],
}

impl<const D: usize> Kernel<'_, D> {
    fn eval(&self, bra: &Prepared<D>, images: &[Prepared<D>]) -> Element {
        // Safety: `kernel` chose an instruction set this CPU has.
        unsafe { (self.element)(bra, images, self.coef, &self.table, &self.pairs, self.cm_mass) }
    }
}

/// The symmetrised matrices of a basis (upper triangle evaluated, mirrored).
pub fn matrices<const D: usize>(go: &GvrOps<D>, sym: &Symmetry<D>, basis: &GvrParams, isa: Isa) -> Result<Matrices> {
    let b = Side::new(go, sym, basis)?;
    let k = b.powers();
    let table = Table::new(go, k.iter().flat_map(|&ki| k.iter().map(move |&kj| (ki, kj))));
    let kern = Kernel { element: kernel::<D>(isa), table, pairs: Pairs::new(&go.ops), cm_mass: go.ops.cm_mass, coef: &b.coef };
    Ok(assemble::symmetric(b.functions.len(), |i, j| kern.eval(&b.functions[i], &b.images[j])))
}

/// Rows of trials against a basis for a trial that will sit at `position` (`None`: appended),
/// oriented as `path::rows`, and the trials' diagonals; the prepared basis kept in `cache`.
pub fn rows<const D: usize>(
    go: &GvrOps<D>,
    sym: &Symmetry<D>,
    trials: &GvrParams,
    basis: &GvrParams,
    position: Option<usize>,
    isa: Isa,
    cache: &Cache,
) -> Result<(Matrices, Vec<Element>)> {
    let t = Side::new(go, sym, trials)?;
    let b = cache.get(basis, || Side::new(go, sym, basis))?;
    let (kt, mut kb) = (t.powers(), b.powers());
    kb.extend(&kt);
    let table = Table::new(go, kt.iter().flat_map(|&ki| kb.iter().flat_map(move |&kj| [(ki, kj), (kj, ki)])));
    let kern = Kernel { element: kernel::<D>(isa), table, pairs: Pairs::new(&go.ops), cm_mass: go.ops.cm_mass, coef: &t.coef };
    let (k, nb) = (t.functions.len(), b.functions.len());
    let pos = position.unwrap_or(nb);
    let row: Vec<Element> = (0..k * nb)
        .into_par_iter()
        .with_min_len(8)
        .map(|ij| {
            let (i, j) = (ij / nb, ij % nb);
            if j < pos {
                kern.eval(&b.functions[j], &t.images[i])
            } else {
                kern.eval(&t.functions[i], &b.images[j])
            }
        })
        .collect();
    let diag = (0..k).map(|i| kern.eval(&t.functions[i], &t.images[i])).collect();
    let mut m = Matrices::zeros(k, nb);
    for (ij, e) in row.iter().enumerate() {
        m.set(ij / nb, ij % nb, e);
    }
    Ok((m, diag))
}

#[cfg(test)]
#[path = "build_tests.rs"]
mod tests;
