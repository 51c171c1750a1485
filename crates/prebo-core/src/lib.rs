//! prebo-core: explicitly correlated Gaussian integrals, symmetrised matrix and
//! row builds for pre-Born–Oppenheimer calculations. Pure Rust, no Python.
//!
//! Two axes: basis families (`families`: `pecg`, `ecg_gvr`, `fecg`, one folder each with its
//! kernels, gradients and specialised operators) and operators (the Hamiltonian in each family's
//! element, further ones in `operators`, generic over the family). One path (`path`) builds
//! symmetrised matrices, oriented rows, row gradients and operator matrices for any family from
//! its elements; a family with its own kernels (plain ECGs, ECG-GVR) uses them instead. The
//! `registry` finds an operator's elements for a (bra family, ket family, operator); `engine` is
//! the flat-array entry point of the `prebo._core` binding.
//!
//! The modules form layers, each using only itself and those before it, without an import circle
//! (tests/test_rust_layers.py reads this list: a module belongs to the longest path listed that
//! is it or contains it):
//! 1. shared maths and types: `error`, `scalar`, `lanes`, `isa`, `ecg`, `images`, `matrices`,
//!    `assemble`, `cache`, `gradient`, `quadrature`, `params`, `eigenpair`, `secular`,
//!    `test_support`;
//! 2. element kernels: `families::pecg::{kernel, build, gradient}`,
//!    `families::ecg_gvr::{series, element, kernel, tau, build, gradient, momentum, coulomb}`,
//!    `families::fecg::{kernel, gradient}`;
//! 3. the family trait: `families`;
//! 4. the generic builds: `path`;
//! 5. the families: `families::pecg`, `families::ecg_gvr`, `families::fecg`;
//! 6. the operators, generic and each family's own: `operators`, `families::pecg::operators`,
//!    `families::ecg_gvr::{operators, drachmann, transition}`, `families::fecg::operators`;
//! 7. the registry and the engine: `registry`, `engine`.
pub mod assemble;
pub mod cache;
pub mod ecg;
pub mod eigenpair;
pub mod engine;
pub mod error;
pub mod families;
pub mod gradient;
pub mod images;
pub mod isa;
pub mod lanes;
pub mod matrices;
pub mod operators;
pub mod params;
pub mod path;
pub mod quadrature;
pub mod registry;
pub mod scalar;
pub mod secular;
#[cfg(test)]
pub(crate) mod test_support;

pub use error::{CoreError, Result};
