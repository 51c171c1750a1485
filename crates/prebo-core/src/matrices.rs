//! Row-major matrices (or rows) of the Hamiltonian's operators, filled from `Element`s.
use crate::ecg::Element;

/// Row-major `nb x nb` matrices (or `k x nb` rows) of every operator.
#[derive(Clone, Debug, Default)]
pub struct Matrices {
    pub rows: usize,
    pub cols: usize,
    /// overlap
    pub s: Vec<f64>,
    /// kinetic energy with the full Λ
    pub t: Vec<f64>,
    /// kinetic energy with the CM part eliminated
    pub t_ti: Vec<f64>,
    /// Coulomb potential energy
    pub v: Vec<f64>,
}

impl Matrices {
    /// Zero matrices: four separate zeroed allocations (calloc: fresh pages, no copying).
    pub fn zeros(rows: usize, cols: usize) -> Self {
        let z = || vec![0.0; rows * cols];
        Self {
            rows,
            cols,
            s: z(),
            t: z(),
            t_ti: z(),
            v: z(),
        }
    }

    /// Stores element `(i, j)` of every operator.
    #[inline]
    pub fn set(&mut self, i: usize, j: usize, e: &Element) {
        let k = i * self.cols + j;
        self.s[k] = e.s;
        self.t[k] = e.t;
        self.t_ti[k] = e.t_ti;
        self.v[k] = e.v;
    }
}
