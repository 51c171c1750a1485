//! The eigenvalues after adding one function, for many trial functions at once
//! (Suzuki & Varga, Lect. Notes Phys. m54, sec. 4.2, the secular equation).
//!
//! With S-orthonormal eigenvectors `C` (columns) and eigenvalues `E_k` of the current basis
//! and a trial with rows `h`, `s` and diagonal `h_nn`, `s_nn`: `d = C^T s`, `b = C^T h`, the
//! part of the trial orthogonal to the basis has norm² `ν = s_nn − d·d`, couplings
//! `γ_k = (b_k − E_k d_k)/√ν` and energy `h' = (h_nn − 2 b·d + Σ E_k d_k²)/ν`. The new eigenvalues
//! are the roots of `f(x) = h' − x − Σ γ_k²/(E_k − x)`, which falls strictly between its poles, so
//! they interlace with the old ones (Hylleraas–Undheim–MacDonald): root `r` lies in
//! `(E_{r−1}, E_r]` (`E_{−1} = −∞`, `E_kept = +∞`). The lowest is found by Newton's method from
//! the left (f is concave below `E_0`), any other from the middle of its bracket; bisection
//! whenever a step leaves the bracket. Cost per trial: O(N_b · N_kept) for the two products,
//! formed once for every root asked of it, and O(N_kept) per root iteration.
use rayon::prelude::*;

/// The secular function of one trial against the basis (module docstring): its couplings γ_k²
/// and energy h' in the orthogonal complement, shared by every root asked of the trial.
struct Secular<'a> {
    e: &'a [f64],
    gamma2: Vec<f64>,
    hp: f64,
}

impl<'a> Secular<'a> {
    /// The secular function of a trial; `None` if its orthogonal remainder is below
    /// `min_norm · s_nn` or its elements are not finite (a near-singular trial).
    #[allow(clippy::too_many_arguments)]
    fn of(e: &'a [f64], c: &[f64], kept: usize, h: &[f64], s: &[f64], h_nn: f64, s_nn: f64, min_norm: f64) -> Option<Self> {
        // d = C^T s, b = C^T h with C row-major nb x kept
        let (mut d, mut b) = (vec![0.0; kept], vec![0.0; kept]);
        for i in 0..h.len() {
            let row = &c[i * kept..(i + 1) * kept];
            let (si, hi) = (s[i], h[i]);
            for k in 0..kept {
                d[k] += row[k] * si;
                b[k] += row[k] * hi;
            }
        }
        let nu = s_nn - d.iter().map(|x| x * x).sum::<f64>();
        if !(nu > min_norm * s_nn) {
            return None;
        }
        let gamma2: Vec<f64> = (0..kept).map(|k| (b[k] - e[k] * d[k]).powi(2) / nu).collect();
        let bd: f64 = (0..kept).map(|k| b[k] * d[k]).sum();
        let edd: f64 = (0..kept).map(|k| e[k] * d[k] * d[k]).sum();
        let hp = (h_nn - 2.0 * bd + edd) / nu;
        if !hp.is_finite() || gamma2.iter().any(|g| !g.is_finite()) {
            return None;
        }
        Some(Secular { e, gamma2, hp })
    }

    /// Root `root` of the secular equation, in its interlacing bracket.
    fn root(&self, root: usize) -> f64 {
        let (e, gamma2, hp, kept) = (self.e, &self.gamma2, self.hp, self.e.len());
        let f = |x: f64| hp - x - (0..kept).map(|k| gamma2[k] / (e[k] - x)).sum::<f64>();
        let reach = gamma2.iter().sum::<f64>().sqrt();
        let (mut lo, mut hi) = if root == 0 { (f64::NEG_INFINITY, e[0]) } else if root < kept { (e[root - 1], e[root]) } else { (e[kept - 1], f64::INFINITY) };
        if root == 0 {
            lo = e[0].min(hp) - reach - 1e-3 * e[0].abs().max(1.0);
            while f(lo) < 0.0 {
                lo -= 2.0 * (e[0] - lo);
            }
        }
        if root == kept {
            let top = e[kept - 1];
            hi = top.max(hp) + reach + 1e-3 * top.abs().max(1.0);
            while f(hi) > 0.0 {
                hi += 2.0 * (hi - top);
            }
        }
        let mut x = if root == 0 { lo } else { 0.5 * (lo + hi) };
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
}

/// The roots `roots` (0: the lowest) of the basis with one trial added, the products C^T s,
/// C^T h formed once for all of them; each `f64::INFINITY` if the trial's orthogonal remainder is
/// below `min_norm · s_nn`, NaN for a root above `kept` (one trial adds one root).
#[allow(clippy::too_many_arguments)]
pub fn roots_with_added(
    e: &[f64],
    c: &[f64],
    kept: usize,
    h: &[f64],
    s: &[f64],
    h_nn: f64,
    s_nn: f64,
    min_norm: f64,
    roots: &[usize],
) -> Vec<f64> {
    let secular = if kept > 0 && roots.iter().any(|&r| r <= kept) { Secular::of(e, c, kept, h, s, h_nn, s_nn, min_norm) } else { None };
    roots
        .iter()
        .map(|&r| match (&secular, r) {
            (_, r) if r > kept => f64::NAN,
            (_, _) if kept == 0 => h_nn / s_nn,
            (Some(sec), r) => sec.root(r),
            (None, _) => f64::INFINITY,
        })
        .collect()
}

/// `roots_with_added` for `k` trials (rows `h`, `s` row-major k x nb), in parallel: row-major
/// k x roots.
#[allow(clippy::too_many_arguments)]
pub fn roots_with_added_many(
    e: &[f64],
    c: &[f64],
    kept: usize,
    h: &[f64],
    s: &[f64],
    h_nn: &[f64],
    s_nn: &[f64],
    min_norm: f64,
    roots: &[usize],
) -> Vec<f64> {
    let k = h_nn.len();
    let nb = if k == 0 { 0 } else { h.len() / k };
    (0..k)
        .into_par_iter()
        .flat_map_iter(|t| {
            roots_with_added(e, c, kept, &h[t * nb..(t + 1) * nb], &s[t * nb..(t + 1) * nb], h_nn[t], s_nn[t], min_norm, roots)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 4-function pencil (H, S) and its generalised eigenpairs by a dense solve of the 3 leading
    /// functions, the 4th as the trial: every root of the secular equation equals the dense
    /// solve's eigenvalue of the whole pencil, and every root asked in one call is the root asked alone.
    #[test]
    fn every_root_matches_the_dense_solve() {
        // S = B^T B (positive definite), H symmetric; functions: 3 in the basis, 1 trial
        let bm = [[1.0, 0.2, 0.1, 0.3], [0.0, 1.0, 0.4, 0.2], [0.0, 0.0, 1.0, 0.5], [0.0, 0.0, 0.0, 1.0]];
        let mut s = [[0.0; 4]; 4];
        for i in 0..4 {
            for j in 0..4 {
                s[i][j] = (0..4).map(|k| bm[k][i] * bm[k][j]).sum();
            }
        }
        let h = [[-1.0, 0.3, 0.2, 0.1], [0.3, 0.5, -0.2, 0.4], [0.2, -0.2, 1.5, 0.3], [0.1, 0.4, 0.3, 2.5]];
        let (e3, c3) = dense(&h, &s, 3);
        let (e4, _) = dense(&h, &s, 4);
        let row_h: Vec<f64> = (0..3).map(|i| h[3][i]).collect();
        let row_s: Vec<f64> = (0..3).map(|i| s[3][i]).collect();
        let all = roots_with_added(&e3, &c3, 3, &row_h, &row_s, h[3][3], s[3][3], 1e-12, &[0, 1, 2, 3, 4]);
        for (r, want) in e4.iter().enumerate() {
            let got = all[r];
            assert_eq!(got, roots_with_added(&e3, &c3, 3, &row_h, &row_s, h[3][3], s[3][3], 1e-12, &[r])[0]);
            assert!((got - want).abs() < 1e-12 * want.abs().max(1.0), "root {r}: {got} vs {want}");
            if r > 0 {
                assert!(e3[r - 1] <= got, "root {r} below E_{}", r - 1);
            }
            if r < 3 {
                assert!(got <= e3[r], "root {r} above E_{r}");
            }
        }
        assert!(all[4].is_nan());
    }

    /// Eigenvalues (ascending) and S-orthonormal eigenvectors (row-major n x n) of the leading
    /// n x n pencil, by Cholesky S = L L^T and Jacobi rotations of L^-1 H L^-T.
    fn dense(h: &[[f64; 4]; 4], s: &[[f64; 4]; 4], n: usize) -> (Vec<f64>, Vec<f64>) {
        let mut l = vec![vec![0.0; n]; n];
        for i in 0..n {
            for j in 0..=i {
                let sum: f64 = s[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>();
                l[i][j] = if i == j { sum.sqrt() } else { sum / l[j][j] };
            }
        }
        let mut li = vec![vec![0.0; n]; n]; // L^-1
        for col in 0..n {
            for i in 0..n {
                let rhs = if i == col { 1.0 } else { 0.0 };
                li[i][col] = (rhs - (0..i).map(|k| l[i][k] * li[k][col]).sum::<f64>()) / l[i][i];
            }
        }
        let mut a = vec![vec![0.0; n]; n]; // L^-1 H L^-T
        for i in 0..n {
            for j in 0..n {
                a[i][j] = (0..n).map(|p| (0..n).map(|q| li[i][p] * h[p][q] * li[j][q]).sum::<f64>()).sum();
            }
        }
        let mut v: Vec<Vec<f64>> = (0..n).map(|i| (0..n).map(|j| if i == j { 1.0 } else { 0.0 }).collect()).collect();
        for _ in 0..100 {
            for p in 0..n {
                for q in p + 1..n {
                    if a[p][q].abs() < 1e-300 {
                        continue;
                    }
                    let theta = 0.5 * (a[q][q] - a[p][p]) / a[p][q];
                    let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                    let (cs, sn) = (1.0 / (t * t + 1.0).sqrt(), t / (t * t + 1.0).sqrt());
                    for k in 0..n {
                        let (akp, akq) = (a[k][p], a[k][q]);
                        a[k][p] = cs * akp - sn * akq;
                        a[k][q] = sn * akp + cs * akq;
                    }
                    for k in 0..n {
                        let (apk, aqk) = (a[p][k], a[q][k]);
                        a[p][k] = cs * apk - sn * aqk;
                        a[q][k] = sn * apk + cs * aqk;
                    }
                    for k in 0..n {
                        let (vkp, vkq) = (v[k][p], v[k][q]);
                        v[k][p] = cs * vkp - sn * vkq;
                        v[k][q] = sn * vkp + cs * vkq;
                    }
                }
            }
        }
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&x, &y| a[x][x].partial_cmp(&a[y][y]).unwrap());
        let e: Vec<f64> = order.iter().map(|&k| a[k][k]).collect();
        let mut c = vec![0.0; n * n]; // C = L^-T V, row-major n x kept
        for i in 0..n {
            for (col, &k) in order.iter().enumerate() {
                c[i * n + col] = (0..n).map(|p| li[p][i] * v[p][k]).sum();
            }
        }
        (e, c)
    }
}
