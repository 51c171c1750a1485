//! Parallel assembly of symmetric matrices and of rows from an element function (rayon).
use rayon::prelude::*;

use crate::ecg::Element;
use crate::matrices::Matrices;

/// The `nb x nb` symmetric matrices: `element(i, j)` for `j >= i`, mirrored.
pub fn symmetric(nb: usize, element: impl Fn(usize, usize) -> Element + Sync) -> Matrices {
    let mut m = Matrices::zeros(nb, nb);
    mirror(&upper(nb, element), |i, j, e| m.set(i, j, e));
    m
}

/// The upper triangle `element(i, j)`, `j >= i`, row by row (rows in parallel).
pub fn upper<E: Send>(nb: usize, element: impl Fn(usize, usize) -> E + Sync) -> Vec<Vec<E>> {
    (0..nb).into_par_iter().map(|i| (i..nb).map(|j| element(i, j)).collect()).collect()
}

/// `set(i, j, e)` and `set(j, i, e)` for each element `e` at `(i, j)` of an `upper` triangle.
pub fn mirror<E>(upper: &[Vec<E>], mut set: impl FnMut(usize, usize, &E)) {
    for (i, row) in upper.iter().enumerate() {
        for (k, e) in row.iter().enumerate() {
            set(i, i + k, e);
            set(i + k, i, e);
        }
    }
}

/// `k x nb` rows `row(t, j)` and the diagonals `diag(t)`.
pub fn rows(
    k: usize,
    nb: usize,
    row: impl Fn(usize, usize) -> Element + Sync,
    diag: impl Fn(usize) -> Element + Sync,
) -> (Matrices, Vec<Element>) {
    let computed: Vec<(Vec<Element>, Element)> = (0..k)
        .into_par_iter()
        .map(|t| ((0..nb).into_par_iter().map(|j| row(t, j)).collect(), diag(t)))
        .collect();
    let mut m = Matrices::zeros(k, nb);
    let mut d = Vec::with_capacity(k);
    for (t, (r, e)) in computed.iter().enumerate() {
        for (j, x) in r.iter().enumerate() {
            m.set(t, j, x);
        }
        d.push(*e);
    }
    (m, d)
}
