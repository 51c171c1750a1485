//! Typed errors of the core; the binding maps each variant to one Python exception.
use thiserror::Error;

#[derive(Debug, Error, Clone, PartialEq)]
pub enum CoreError {
    /// An exponent matrix A (or a sum A_I + A_J) has no Cholesky factor.
    #[error("exponent matrix of basis function {function} is not positive definite")]
    NotPositiveDefinite { function: usize },
    /// Array sizes that do not fit together.
    #[error("shape mismatch: {0}")]
    ShapeMismatch(String),
    /// A request the core cannot serve (e.g. more coordinates than compiled for).
    #[error("unsupported: {0}")]
    Unsupported(String),
}

pub type Result<T> = std::result::Result<T, CoreError>;
