//! prebo-core: explicitly correlated Gaussian integrals, symmetrised matrix and
//! row builds for pre-Born–Oppenheimer calculations. Pure Rust, no Python.
//!
//! Pipeline position: integrals (`pecg`) → symmetrised builds (`build`) → flat
//! array entry points (`api`) used by the `prebo._core` binding.
pub mod api;
pub mod assemble;
pub mod build;
pub mod ecg;
pub mod eigenpair;
pub mod error;
pub mod fecg;
pub mod gradient;
pub mod gvr;
pub mod images;
pub mod pecg;
pub mod secular;

pub use error::{CoreError, Result};
