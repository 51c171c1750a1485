//! The lowest eigenvalue after adding one function, for many trial functions at once
//! (Suzuki & Varga, Lect. Notes Phys. m54, sec. 4.2, the secular equation).
//!
//! With S-orthonormal eigenvectors `C` (columns) and eigenvalues `E_k` of the current basis
//! and a trial with rows `h`, `s` and diagonal `h_nn`, `s_nn`: `d = C^T s`, `b = C^T h`, the
//! part of the trial orthogonal to the basis has norm² `ν = s_nn − d·d`, couplings
//! `γ_k = (b_k − E_k d_k)/√ν` and energy `h' = (h_nn − 2 b·d + Σ E_k d_k²)/ν`. The new lowest
//! eigenvalue is the root below `E_0` of `f(x) = h' − x − Σ γ_k²/(E_k − x)`, which is concave
//! and decreasing there: Newton from the left, bisection whenever a step leaves the bracket.
//! Cost per trial: O(N_b · N_kept) for the two products, O(N_kept) per root iteration.
use rayon::prelude::*;

/// Lowest root for one trial; `f64::INFINITY` if its orthogonal remainder is below `min_norm · s_nn`.
pub fn lowest_with_added(e: &[f64], c: &[f64], kept: usize, h: &[f64], s: &[f64], h_nn: f64, s_nn: f64, min_norm: f64) -> f64 {
    let nb = h.len();
    if kept == 0 {
        return h_nn / s_nn;
    }
    // d = C^T s, b = C^T h with C row-major nb x kept
    let (mut d, mut b) = (vec![0.0; kept], vec![0.0; kept]);
    for i in 0..nb {
        let row = &c[i * kept..(i + 1) * kept];
        let (si, hi) = (s[i], h[i]);
        for k in 0..kept {
            d[k] += row[k] * si;
            b[k] += row[k] * hi;
        }
    }
    let nu = s_nn - d.iter().map(|x| x * x).sum::<f64>();
    if !(nu > min_norm * s_nn) {
        return f64::INFINITY;
    }
    let gamma2: Vec<f64> = (0..kept).map(|k| (b[k] - e[k] * d[k]).powi(2) / nu).collect();
    let bd: f64 = (0..kept).map(|k| b[k] * d[k]).sum();
    let edd: f64 = (0..kept).map(|k| e[k] * d[k] * d[k]).sum();
    let hp = (h_nn - 2.0 * bd + edd) / nu;
    if !hp.is_finite() || gamma2.iter().any(|g| !g.is_finite()) {
        return f64::INFINITY; // NaN elements of a near-singular trial
    }
    let f = |x: f64| hp - x - (0..kept).map(|k| gamma2[k] / (e[k] - x)).sum::<f64>();
    let top = e[0];
    let mut lo = top.min(hp) - gamma2.iter().sum::<f64>().sqrt() - 1e-3 * top.abs().max(1.0);
    while f(lo) < 0.0 {
        lo -= 2.0 * (top - lo);
    }
    let mut hi = top;
    let mut x = lo;
    for _ in 0..200 {
        let fx = f(x);
        if fx == 0.0 || hi - lo < 1e-15 * x.abs().max(1.0) {
            break;
        }
        if fx > 0.0 {
            lo = x;
        } else {
            hi = x;
        }
        let df = -1.0 - (0..kept).map(|k| gamma2[k] / (e[k] - x).powi(2)).sum::<f64>();
        let step = x - fx / df;
        x = if lo < step && step < hi { step } else { 0.5 * (lo + hi) };
        if step == x && fx.abs() < 1e-15 * x.abs().max(1.0) {
            break;
        }
    }
    x
}

/// `lowest_with_added` for `k` trials (rows `h`, `s` row-major k x nb), in parallel.
#[allow(clippy::too_many_arguments)]
pub fn lowest_with_added_many(
    e: &[f64],
    c: &[f64],
    kept: usize,
    h: &[f64],
    s: &[f64],
    h_nn: &[f64],
    s_nn: &[f64],
    min_norm: f64,
) -> Vec<f64> {
    let k = h_nn.len();
    let nb = if k == 0 { 0 } else { h.len() / k };
    (0..k)
        .into_par_iter()
        .map(|t| {
            lowest_with_added(e, c, kept, &h[t * nb..(t + 1) * nb], &s[t * nb..(t + 1) * nb], h_nn[t], s_nn[t], min_norm)
        })
        .collect()
}
