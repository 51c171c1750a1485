//! prebo-core: explicitly correlated Gaussian integrals, symmetrised matrix and
//! row builds for pre-Born–Oppenheimer calculations. Pure Rust, no Python.
//!
//! Two axes: basis families (`family`: `plain`, `gvr`, `fecg`) and operators (the Hamiltonian
//! in each family's element, further ones in `operators`). One path (`path`) builds symmetrised
//! matrices, oriented rows, row gradients and operator matrices for any pair; plain ECGs
//! specialise the builds with the SIMD kernel (`pecg`, `build`) and their row gradients
//! (`pecg_gradient`). `engine` is the flat-array
//! entry point of the `prebo._core` binding.
pub mod assemble;
pub mod build;
pub mod cache;
pub mod ecg;
pub mod eigenpair;
pub mod engine;
pub mod error;
pub mod family;
pub mod fecg;
pub mod fecg_gradient;
pub mod gradient;
pub mod gvr;
pub mod gvr_build;
/// The closed-form Coulomb τ-integral (docs/gvr.md): slower than the quadrature it checks.
#[cfg(test)]
mod gvr_coulomb;
pub mod gvr_gradient;
pub mod gvr_kernel;
pub mod images;
pub mod lanes;
pub mod matrices;
pub mod operators;
pub mod path;
pub mod pecg;
pub mod pecg_gradient;
pub mod plain;
pub mod secular;

pub use error::{CoreError, Result};
