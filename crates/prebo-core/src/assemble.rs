//! Parallel assembly of symmetric matrices and of rows from an element function (rayon).
use rayon::prelude::*;

use crate::build::Matrices;
use crate::ecg::Element;

fn store(m: &mut Matrices, i: usize, j: usize, e: &Element) {
    let k = i * m.cols + j;
    m.s[k] = e.s;
    m.t[k] = e.t;
    m.t_ti[k] = e.t_ti;
    m.v[k] = e.v;
}

fn zeros(rows: usize, cols: usize) -> Matrices {
    let z = vec![0.0; rows * cols];
    Matrices { rows, cols, s: z.clone(), t: z.clone(), t_ti: z.clone(), v: z }
}

/// The `nb x nb` symmetric matrices: `element(i, j)` for `j >= i`, mirrored.
pub fn symmetric(nb: usize, element: impl Fn(usize, usize) -> Element + Sync) -> Matrices {
    let upper: Vec<Vec<Element>> =
        (0..nb).into_par_iter().map(|i| (i..nb).map(|j| element(i, j)).collect()).collect();
    let mut m = zeros(nb, nb);
    for (i, row) in upper.iter().enumerate() {
        for (k, e) in row.iter().enumerate() {
            store(&mut m, i, i + k, e);
            store(&mut m, i + k, i, e);
        }
    }
    m
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
    let mut m = zeros(k, nb);
    let mut d = Vec::with_capacity(k);
    for (t, (r, e)) in computed.iter().enumerate() {
        for (j, x) in r.iter().enumerate() {
            store(&mut m, t, j, x);
        }
        d.push(*e);
    }
    (m, d)
}
