//! Symmetrised matrices and candidate rows, parallel over rows with rayon.
//!
//! A symmetrised element is `Σ_P c_P <phi_I| O |P phi_J>` with the Young-operator
//! coefficients `c_P` (python/prebo/symmetry.py) and `P phi_J` represented by the
//! transformed exponent `P^T A_J P`, precomputed once per function and permutation.
use rayon::prelude::*;

use crate::ecg::{Element, Gaussian, Mat, Operators};
use crate::error::Result;
use crate::pecg;

/// Basis functions with their images under every symmetry operation.
pub struct Symmetrised<const D: usize> {
    pub functions: Vec<Gaussian<D>>,
    /// `images[j][p]` = function `j` transformed by operation `p`.
    pub images: Vec<Vec<Gaussian<D>>>,
    pub coef: Vec<f64>,
}

impl<const D: usize> Symmetrised<D> {
    pub fn new(functions: Vec<Gaussian<D>>, ops: &[(Mat<D>, f64)]) -> Result<Self> {
        let images = functions
            .iter()
            .enumerate()
            .map(|(j, f)| ops.iter().map(|(t, _)| f.transformed(t, j)).collect())
            .collect::<Result<Vec<Vec<_>>>>()?;
        Ok(Self { functions, images, coef: ops.iter().map(|(_, c)| *c).collect() })
    }

    pub fn len(&self) -> usize {
        self.functions.len()
    }

    pub fn is_empty(&self) -> bool {
        self.functions.is_empty()
    }

    /// `Σ_P c_P <bra| O |P phi_j>`.
    #[inline]
    pub fn element(&self, bra: &Gaussian<D>, j: usize, ops: &Operators<D>) -> Element {
        let mut e = Element::default();
        for (ket, c) in self.images[j].iter().zip(&self.coef) {
            e += (*c, pecg::element(bra, ket, ops));
        }
        e
    }
}

/// Row-major `nb x nb` matrices (or `k x nb` rows) of every operator.
#[derive(Clone, Debug, Default)]
pub struct Matrices {
    pub rows: usize,
    pub cols: usize,
    pub s: Vec<f64>,
    pub t: Vec<f64>,
    pub t_ti: Vec<f64>,
    pub v: Vec<f64>,
}

impl Matrices {
    fn zeros(rows: usize, cols: usize) -> Self {
        let z = vec![0.0; rows * cols];
        Self { rows, cols, s: z.clone(), t: z.clone(), t_ti: z.clone(), v: z }
    }

    fn set(&mut self, i: usize, j: usize, e: &Element) {
        let k = i * self.cols + j;
        self.s[k] = e.s;
        self.t[k] = e.t;
        self.t_ti[k] = e.t_ti;
        self.v[k] = e.v;
    }
}

/// The full symmetric matrices of a basis: upper triangle computed, lower mirrored.
pub fn matrices<const D: usize>(basis: &Symmetrised<D>, ops: &Operators<D>) -> Matrices {
    let nb = basis.len();
    let upper: Vec<Vec<Element>> = (0..nb)
        .into_par_iter()
        .map(|i| (i..nb).map(|j| basis.element(&basis.functions[i], j, ops)).collect())
        .collect();
    let mut m = Matrices::zeros(nb, nb);
    for (i, row) in upper.iter().enumerate() {
        for (k, e) in row.iter().enumerate() {
            m.set(i, i + k, e);
            m.set(i + k, i, e);
        }
    }
    m
}

/// Rows of trial functions against a basis, and each trial's symmetrised diagonal element.
pub fn rows<const D: usize>(
    trials: &Symmetrised<D>,
    basis: &Symmetrised<D>,
    ops: &Operators<D>,
) -> (Matrices, Vec<Element>) {
    let (k, nb) = (trials.len(), basis.len());
    let computed: Vec<(Vec<Element>, Element)> = (0..k)
        .into_par_iter()
        .map(|i| {
            let bra = &trials.functions[i];
            let row = (0..nb).into_par_iter().map(|j| basis.element(bra, j, ops)).collect();
            (row, trials.element(bra, i, ops))
        })
        .collect();
    let mut m = Matrices::zeros(k, nb);
    let mut diag = Vec::with_capacity(k);
    for (i, (row, d)) in computed.iter().enumerate() {
        for (j, e) in row.iter().enumerate() {
            m.set(i, j, e);
        }
        diag.push(*d);
    }
    (m, diag)
}
