//! prebo-core: explicitly correlated Gaussian integrals, symmetrised matrix and
//! row builds for pre-Born–Oppenheimer calculations. Pure Rust, no Python.
//!
//! Two axes: basis families (`families`: `plain`, `gvr`, `floating`, one folder each with its
//! kernels and gradients) and operators (the Hamiltonian in each family's element, further ones
//! in `operators`). One path (`path`) builds symmetrised matrices, oriented rows, row gradients
//! and operator matrices for any family from its elements; a family with its own kernels (plain
//! ECGs, ECG-GVR) uses them instead. `engine` is the flat-array entry point of the `prebo._core`
//! binding.
//!
//! The modules form layers, each using only those before it (no import circle):
//! 1. shared maths and infrastructure: `error`, `scalar`, `ecg`, `lanes`, `gradient`, `images`,
//!    `matrices`, `assemble`, `cache`, `isa`, and the eigenvalue tools `eigenpair`, `secular`;
//! 2. the family axis: `families` (the trait and the parameter views), `path` (the generic
//!    builds), then each family's folder;
//! 3. `operators` and `engine`.
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
pub mod path;
pub mod scalar;
pub mod secular;
#[cfg(test)]
pub(crate) mod test_support;

pub use error::{CoreError, Result};
