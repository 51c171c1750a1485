//! Mixed-precision refinement of eigenpairs of H c = E S c (Dongarra, Moler & Wilkinson,
//! SIAM J. Numer. Anal. 20, 23 (1983): iterative improvement of computed eigenpairs with
//! residuals in extended precision).
//!
//! LAPACK's eigenvalues of an ill-conditioned pencil move with the BLAS kernel (1e-8 relative
//! at an overlap condition of 5e12), although the pencil's own eigenvalues are well determined
//! by the stored matrices. Given the approximate eigenbasis (E_k, C_k) of a double-precision
//! solver (S-orthonormal columns), root m is refined by
//!
//! ```text
//! ρ = cᵀHc / cᵀSc,    r = (H − ρS) c,    c ← c − Σ_{k≠m} C_k (C_kᵀ r) / (E_k − ρ),
//! ```
//!
//! with Hc, Sc, the two quadratic forms and r in double-double (`twofloat`: error-free
//! products and sums, Joldes, Muller & Popescu, ACM TOMS 44, 22 (2017)). ρ is then the
//! Rayleigh quotient of the stored (H, S) at the stored c, second order in the error of c, and
//! for m = 0 an upper bound (to an ulp) to the lowest eigenvalue of (H, S): the forms are exact
//! to ~1e-30, the quotient to ~1e-16 relative (twofloat's double-double division, kept here so
//! that the refined energies keep their bits). The iteration stops when the energy change it
//! predicts, Σ_{k≠m} (C_kᵀ r)² / |E_k − ρ|, is at most one ulp of ρ. Rows are summed in column
//! order and reductions run in index order, so the result has the same bits for any number of
//! rayon threads; no BLAS is involved.
//!
//! Where the LAPACK eigenbasis is too poor for these corrections to converge (overlap condition
//! towards 1e15–1e16), `inverse_iteration` finds the lowest root without it (Wilkinson, The
//! Algebraic Eigenvalue Problem (1965), ch. 9; Golub & Van Loan, Matrix Computations, 4th ed.,
//! §8.2.2 inverse iteration, §4.1 LDLᵀ, §8.1 Sylvester's law of inertia). With S positive
//! definite, H − σS is positive definite, so has an LDLᵀ factorisation with positive pivots, iff
//! σ lies below the lowest eigenvalue λ₀ of the stored pencil. The shift starts a margin
//! μ = (E₁ − E₀)/8 below the Rayleigh quotient ρ of the LAPACK vector (μ ≥ 1.9e-9 max(|E₀|, 1)),
//! μ doubling while a pivot is not positive. With H − σS = L D Lᵀ factorised in double-double
//! (left-looking, n³/6 multiply-adds), x is iterated in double-double,
//!
//! ```text
//! x ← (H − σS)⁻¹ S x,    ρ = xᵀHx / xᵀSx,    δ = rᵀ(H − σS)⁻¹r / xᵀSx,   r = (H − ρS) x,
//! ```
//!
//! converging as ((λ₀ − σ)/(λ₁ − σ))² per step. With x = Σ a_k c_k (S-normalised eigenvectors),
//! δ = Σ_k a_k² (λ_k − ρ)² / (λ_k − σ): the energy error ρ − λ₀ to second order, times
//! (λ₁ − λ₀)/(λ₁ − σ) ≥ 0.8 while σ lies within 2μ of ρ (and E₁ − E₀ is near λ₁ − λ₀). The
//! iteration stops when δ is at most one ulp of ρ with σ within 2μ of ρ. A shift further away is
//! renewed once δ < μ, at ρ − μ or halfway to the lowest shift known not below λ₀ (a failed
//! factorisation, or ρ), the current factorisation kept where the new one fails: bisection on
//! the inertia, so the shift reaches the root's neighbourhood in as many factorisations as the
//! first one took. The energy is ρ at the double-double x (with an accurate double-double
//! division), rounded; the vector is x/√(xᵀSx) rounded to doubles. The stored S itself must
//! have an LDLᵀ factorisation in double-double (`Indefinite` otherwise); `MAX_SHIFTS`
//! factorisations without a shift, or `MAX_INVERSE_STEPS` steps, leave the root unconverged.
//! Every sum runs in index order (the rows below a pivot in parallel).
use rayon::prelude::*;
use twofloat::TwoFloat;

/// Iterations allowed before a root counts as not resolved in double precision.
pub const MAX_ITERATIONS: usize = 20;

/// One refined eigenpair.
#[derive(Debug, Clone, PartialEq)]
pub struct Refined {
    /// Rayleigh quotient ρ of the stored matrices at `vector` (`inverse_iteration`: at the
    /// double-double vector that `vector` rounds).
    pub energy: f64,
    /// The eigenvector, scaled to cᵀSc = 1.
    pub vector: Vec<f64>,
    /// Steps taken.
    pub iterations: usize,
    /// Whether the predicted energy change (`refine`) or error (`inverse_iteration`) fell to one
    /// ulp of ρ within the steps allowed.
    pub converged: bool,
}

/// A coefficient of the vector being refined: a double (`refine`) or a double-double
/// (`inverse_iteration`); products with it are formed in double-double.
trait Coefficient: Copy + Send + Sync {
    fn times(self, a: f64) -> TwoFloat;
    fn times_dd(self, a: TwoFloat) -> TwoFloat;
}

impl Coefficient for f64 {
    fn times(self, a: f64) -> TwoFloat {
        TwoFloat::new_mul(a, self)
    }
    fn times_dd(self, a: TwoFloat) -> TwoFloat {
        a * self
    }
}

impl Coefficient for TwoFloat {
    fn times(self, a: f64) -> TwoFloat {
        self * a
    }
    fn times_dd(self, a: TwoFloat) -> TwoFloat {
        a * self
    }
}

/// (Hc)_i and (Sc)_i in double-double; `h`, `s` row-major n x n.
fn products<X: Coefficient>(h: &[f64], s: &[f64], c: &[X]) -> Vec<(TwoFloat, TwoFloat)> {
    let n = c.len();
    (0..n)
        .into_par_iter()
        .map(|i| {
            let (hr, sr) = (&h[i * n..(i + 1) * n], &s[i * n..(i + 1) * n]);
            let (mut hc, mut sc) = (TwoFloat::from(0.0), TwoFloat::from(0.0));
            for j in 0..n {
                hc += c[j].times(hr[j]);
                sc += c[j].times(sr[j]);
            }
            (hc, sc)
        })
        .collect()
}

/// cᵀHc and cᵀSc in double-double from the `products` of c, summed in index order.
fn quadratic_forms<X: Coefficient>(c: &[X], y: &[(TwoFloat, TwoFloat)]) -> (TwoFloat, TwoFloat) {
    let (mut num, mut den) = (TwoFloat::from(0.0), TwoFloat::from(0.0));
    for (ci, (hc, sc)) in c.iter().zip(y) {
        num += ci.times_dd(*hc);
        den += ci.times_dd(*sc);
    }
    (num, den)
}

/// Distance from |x| to the next larger double.
fn ulp(x: f64) -> f64 {
    let a = x.abs();
    f64::from_bits(a.to_bits() + 1) - a
}

/// Refine root `m` of the pencil (`h`, `s`, row-major n x n) from the approximate eigenvalues `e`
/// (`kept`, ascending) and S-orthonormal eigenvectors `c` (row-major n x kept).
pub fn refine(h: &[f64], s: &[f64], e: &[f64], c: &[f64], m: usize) -> Refined {
    let kept = e.len();
    let n = c.len().checked_div(kept).unwrap_or(0);
    let mut x: Vec<f64> = (0..n).map(|i| c[i * kept + m]).collect();
    let mut iterations = 0;
    loop {
        let y = products(h, s, &x);
        let (num, den) = quadratic_forms(&x, &y);
        let rho = num / den;
        let energy = f64::from(rho);
        let r: Vec<f64> = y.iter().map(|(hc, sc)| f64::from(hc - rho * sc)).collect();
        // a_k = C_kᵀ r, in row order
        let mut a = vec![0.0; kept];
        for (i, ri) in r.iter().enumerate() {
            for (ak, cik) in a.iter_mut().zip(&c[i * kept..(i + 1) * kept]) {
                *ak += cik * ri;
            }
        }
        let step: Vec<f64> = (0..kept).map(|k| if k == m { 0.0 } else { a[k] / (e[k] - energy) }).collect();
        let change: f64 = (0..kept).map(|k| (a[k] * step[k]).abs()).sum();
        let converged = change <= ulp(energy);
        if converged || iterations == MAX_ITERATIONS || !change.is_finite() {
            let norm = f64::from(den).sqrt();
            return Refined { energy, vector: x.iter().map(|v| v / norm).collect(), iterations, converged };
        }
        x.par_iter_mut().enumerate().for_each(|(i, xi)| {
            let row = &c[i * kept..(i + 1) * kept];
            *xi -= row.iter().zip(&step).map(|(cik, dk)| cik * dk).sum::<f64>();
        });
        iterations += 1;
    }
}

/// `refine` for roots 0..`roots`, one after another.
pub fn refine_lowest(h: &[f64], s: &[f64], e: &[f64], c: &[f64], roots: usize) -> Vec<Refined> {
    (0..roots.min(e.len())).map(|m| refine(h, s, e, c, m)).collect()
}

/// a / b in double-double. (twofloat's `TwoFloat / TwoFloat` is good to ~1e-16 only: its
/// Algorithm 18 of Joldes et al. forms 1 − b_hi (1/b_hi) without a fused multiply-add.)
fn quotient(a: TwoFloat, b: TwoFloat) -> TwoFloat {
    let q = a.hi() / b.hi();
    TwoFloat::new_add(q, (a - b * q).hi() / b.hi())
}

/// LDLᵀ (root-free Cholesky) factorisation of a symmetric positive definite matrix in
/// double-double: `rows[i]` holds L_ik for k < i (L has a unit diagonal), `d` the pivots.
struct Ldl {
    rows: Vec<Vec<TwoFloat>>,
    d: Vec<TwoFloat>,
}

impl Ldl {
    /// The factorisation of the n x n matrix with lower-triangle elements `a(i, j)` (j ≤ i),
    /// column by column (left-looking: the rows below a pivot in parallel, every sum in index
    /// order), or the first pivot that is not positive, (index, value).
    fn new(n: usize, a: impl Fn(usize, usize) -> TwoFloat + Sync) -> Result<Self, (usize, f64)> {
        let mut rows: Vec<Vec<TwoFloat>> = (0..n).map(Vec::with_capacity).collect();
        let mut d: Vec<TwoFloat> = Vec::with_capacity(n);
        for j in 0..n {
            let (done, below) = rows.split_at_mut(j + 1);
            let v: Vec<TwoFloat> = done[j].iter().zip(&d).map(|(l, dk)| *l * *dk).collect();
            let pivot = done[j].iter().zip(&v).fold(a(j, j), |t, (l, vk)| t - *l * *vk);
            if pivot.hi().is_nan() || pivot.hi() <= 0.0 {
                return Err((j, pivot.hi()));
            }
            below.par_iter_mut().enumerate().for_each(|(k, row)| {
                let t = row.iter().zip(&v).fold(a(j + 1 + k, j), |t, (l, vk)| t - *l * *vk);
                row.push(quotient(t, pivot));
            });
            d.push(pivot);
        }
        Ok(Self { rows, d })
    }

    /// (L D Lᵀ)⁻¹ b by forward and back substitution in index order.
    fn solve(&self, b: &[TwoFloat]) -> Vec<TwoFloat> {
        let mut x = b.to_vec();
        for (i, row) in self.rows.iter().enumerate() {
            x[i] = row.iter().zip(&x).fold(x[i], |t, (l, xk)| t - *l * *xk);
        }
        for (xi, di) in x.iter_mut().zip(&self.d) {
            *xi = quotient(*xi, *di);
        }
        for (k, row) in self.rows.iter().enumerate().rev() {
            let xk = x[k];
            for (xi, l) in x.iter_mut().zip(row) {
                *xi -= *l * xk;
            }
        }
        x
    }
}

/// Factorisations of H − σS tried, for the first shift and nearer ones (module doc), before the
/// lowest root counts as not resolved.
pub const MAX_SHIFTS: usize = 64;
/// Inverse-iteration steps allowed.
pub const MAX_INVERSE_STEPS: usize = 100;

/// The stored overlap is not positive definite: pivot `index` of its double-double LDLᵀ
/// factorisation is `pivot` ≤ 0.
#[derive(Debug, Clone, PartialEq)]
pub struct Indefinite {
    pub index: usize,
    pub pivot: f64,
}

impl std::fmt::Display for Indefinite {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "overlap matrix is not positive definite: pivot {} of its double-double LDLT factorisation is {:.3e}",
            self.index, self.pivot
        )
    }
}

/// The lowest eigenpair (m = 0) by inverse iteration in double-double (module doc), for a root
/// `refine` does not resolve: from the approximate eigenvalues `e` (kept ≥ 1, ascending) and
/// S-orthonormal eigenvectors `c` (row-major n x kept) of a double-precision solver.
/// `Indefinite` if the stored S has no LDLᵀ factorisation in double-double.
pub fn inverse_iteration(h: &[f64], s: &[f64], e: &[f64], c: &[f64]) -> Result<Refined, Indefinite> {
    let kept = e.len();
    let n = c.len() / kept;
    Ldl::new(n, |i, j| TwoFloat::from(s[i * n + j])).map_err(|(index, pivot)| Indefinite { index, pivot })?;
    let mut x: Vec<TwoFloat> = (0..n).map(|i| TwoFloat::from(c[i * kept])).collect();
    // an eighth of the gap to the next root (module doc)
    let least = e[0].abs().max(1.0) * f64::EPSILON.sqrt();
    let margin = e.get(1).map_or(least, |e1| (e1 - e[0]).max(least)) / 8.0;
    // σ lies below λ₀ iff H − σS has an LDLᵀ factorisation (Sylvester's law of inertia)
    let factorise = |sigma: f64| {
        Ldl::new(n, |i, j| TwoFloat::from(h[i * n + j]) - TwoFloat::new_mul(sigma, s[i * n + j])).ok()
    };
    let (mut iterations, mut tries) = (0, 0);
    let mut shift: Option<(f64, Ldl)> = None;
    let mut above = f64::INFINITY; // the lowest shift known not to lie below λ₀
    let mut reshift = true;
    loop {
        let y = products(h, s, &x);
        let (num, den) = quadratic_forms(&x, &y);
        let rho = quotient(num, den);
        let energy = f64::from(rho);
        above = above.min(energy);
        if reshift {
            // the first shift a margin below ρ, the margin doubling; later ones nearer: ρ − μ or
            // halfway to `above`, the factorisation so far kept where the new one fails
            let mut m = margin;
            loop {
                let sigma = match &shift {
                    None => energy - m,
                    Some((low, _)) if energy - margin < above => (energy - margin).max(0.5 * (low + above)),
                    Some((low, _)) => 0.5 * (low + above),
                };
                tries += 1;
                match factorise(sigma) {
                    Some(f) => shift = Some((sigma, f)),
                    None => above = sigma,
                }
                m *= 2.0;
                if shift.is_some() || tries == MAX_SHIFTS {
                    break;
                }
            }
        }
        let norm = den.sqrt();
        let refined = |converged| Refined {
            energy,
            vector: x.iter().map(|v| f64::from(quotient(*v, norm))).collect(),
            iterations,
            converged,
        };
        let Some((sigma, f)) = &shift else {
            return Ok(refined(false));
        };
        // δ = rᵀ(H − σS)⁻¹r / xᵀSx, r = (H − ρS)x: the energy error to second order (module doc)
        let r: Vec<TwoFloat> = y.iter().map(|(hx, sx)| *hx - rho * *sx).collect();
        let rw = r.iter().zip(&f.solve(&r)).fold(TwoFloat::from(0.0), |t, (ri, wi)| t + *ri * *wi);
        let delta = f64::from(quotient(rw, den));
        let near = energy - sigma <= 2.0 * margin;
        let converged = near && delta <= ulp(energy);
        if converged || iterations == MAX_INVERSE_STEPS || !delta.is_finite() {
            return Ok(refined(converged));
        }
        let z = f.solve(&y.iter().map(|(_, sx)| *sx).collect::<Vec<_>>());
        let big = z.iter().map(|v| v.hi().abs()).fold(0.0, f64::max);
        x = z.iter().map(|v| *v * (1.0 / big)).collect();
        iterations += 1;
        // a shift nearer the root once ρ is within the margin of it
        reshift = !near && delta <= margin && tries < MAX_SHIFTS;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// L diag(w) Lᵀ, row-major 3 x 3.
    fn congruence(l: &[[f64; 3]; 3], w: [f64; 3]) -> Vec<f64> {
        (0..9).map(|ij| (0..3).map(|k| l[ij / 3][k] * w[k] * l[ij % 3][k]).sum()).collect()
    }

    /// The L of `pencil`: exact small dyadic entries, unit diagonal.
    const L: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.5, 1.0, 0.0], [0.25, -0.5, 1.0]];

    /// Pencil with known eigenpairs: S = L Lᵀ (L lower triangular, exact small integers),
    /// H = L diag(λ) Lᵀ, whose eigenvectors are the columns of L⁻ᵀ with eigenvalues λ_k.
    fn pencil() -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
        let lambda = [-2.0, -1.0, 3.0];
        // L⁻ᵀ columns (exact: L has a unit diagonal and dyadic entries)
        let linv_t = [[1.0, -0.5, -0.5], [0.0, 1.0, 0.5], [0.0, 0.0, 1.0]];
        let c: Vec<f64> = (0..3).flat_map(|i| (0..3).map(move |k| linv_t[i][k])).collect();
        (congruence(&L, lambda), congruence(&L, [1.0; 3]), lambda.to_vec(), c)
    }

    #[test]
    fn exact_eigenpairs_are_fixed_points() {
        let (h, s, e, c) = pencil();
        for m in 0..3 {
            let r = refine(&h, &s, &e, &c, m);
            assert!(r.converged && r.iterations == 0);
            assert_eq!(r.energy, e[m]);
        }
    }

    /// The start `c`, `e` off by `by`: eigenvalues shifted, eigenvectors perturbed.
    fn perturbed(e: &[f64], c: &[f64], by: f64) -> (Vec<f64>, Vec<f64>) {
        let c2 = c.iter().enumerate().map(|(i, x)| x + by * ((i * 7 % 5) as f64 - 2.0)).collect();
        (e.iter().map(|x| x + by).collect(), c2)
    }

    /// xᵀ S y for row-major n x n S.
    fn s_product(s: &[f64], x: &[f64], y: &[f64]) -> f64 {
        let n = x.len();
        (0..n).map(|i| (0..n).map(|j| x[i] * s[i * n + j] * y[j]).sum::<f64>()).sum()
    }

    #[test]
    fn perturbed_eigenbasis_converges_to_the_exact_pair() {
        let (h, s, e, c) = pencil();
        let (e2, c2) = perturbed(&e, &c, 1e-3);
        for m in 0..3 {
            let r = refine(&h, &s, &e2, &c2, m);
            assert!(r.converged, "root {m}: {r:?}");
            assert!((r.energy - e[m]).abs() <= 4.0 * ulp(e[m]), "root {m}: {} vs {}", r.energy, e[m]);
            // S-normalised, parallel to the exact vector
            let exact: Vec<f64> = (0..3).map(|i| c[i * 3 + m]).collect();
            let dot = s_product(&s, &r.vector, &exact);
            assert!((dot.abs() - 1.0).abs() < 1e-14, "root {m}: overlap {dot}");
        }
    }

    /// A diagonally dominant random-ish 64 x 64 pencil with the eigenbasis of S = I, a poor start.
    fn dominant_pencil() -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
        let n = 64;
        let mut h = vec![0.0; n * n];
        let mut s = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                let x = ((i * 31 + j * 17) % 97) as f64 / 97.0 + ((j * 31 + i * 17) % 97) as f64 / 97.0;
                h[i * n + j] = if i == j { i as f64 } else { 1e-2 * x };
                s[i * n + j] = if i == j { 1.0 } else { 1e-3 * x };
            }
        }
        let e: Vec<f64> = (0..n).map(|i| i as f64).collect();
        let c: Vec<f64> = (0..n * n).map(|k| if k / n == k % n { 1.0 } else { 0.0 }).collect();
        (h, s, e, c)
    }

    /// `f` run on a rayon pool of `threads` threads.
    fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(f)
    }

    #[test]
    fn same_bits_for_any_thread_count() {
        let (h, s, e, c) = dominant_pencil();
        let one = on_threads(1, || refine_lowest(&h, &s, &e, &c, 2));
        assert!(one.iter().all(|r| r.converged && r.iterations > 0));
        assert_eq!(one, on_threads(3, || refine_lowest(&h, &s, &e, &c, 2)));
    }

    /// A pencil with exactly stored elements and overlap condition 1.8e16: S = L Lᵀ,
    /// H = L diag(λ) Lᵀ with L = [[1, 0, 0], [1, ε, 0], [1/2, 1/4, 1]], ε = 2⁻²⁵, λ = (−1, −2, 3).
    /// The lowest root's eigenvector is row 1 of L⁻¹, (−2²⁵, 2²⁵, 0): two nearly equal functions
    /// with large coefficients of opposite sign. Returns h, s and the exact eigenpairs in
    /// ascending order (columns of c, S-orthonormal).
    fn near_dependent_pencil() -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
        let eps = 2f64.powi(-25);
        let l = [[1.0, 0.0, 0.0], [1.0, eps, 0.0], [0.5, 0.25, 1.0]];
        let lambda = [-1.0, -2.0, 3.0];
        let linv = [[1.0, 0.0, 0.0], [-1.0 / eps, 1.0 / eps, 0.0], [-0.5 + 0.25 / eps, -0.25 / eps, 1.0]];
        let order = [1, 0, 2]; // ascending eigenvalues
        let c = (0..9).map(|ik| linv[order[ik % 3]][ik / 3]).collect();
        (congruence(&l, lambda), congruence(&l, [1.0; 3]), order.iter().map(|&k| lambda[k]).collect(), c)
    }

    #[test]
    fn quotient_is_double_double() {
        let q = quotient(TwoFloat::from(1.0), TwoFloat::from(3.0));
        assert!((q * 3.0 - 1.0).hi().abs() < 1e-31, "{q:?}");
    }

    #[test]
    fn inverse_iteration_finds_the_lowest_pair() {
        for (h, s, e, c) in [pencil(), near_dependent_pencil()] {
            // the highest root's vector first: ρ starts 5 above λ₀, the shift found by doubling
            let reversed: Vec<f64> = (0..9).map(|ik| c[ik - ik % 3 + 2 - ik % 3]).collect();
            for (start, by) in [(&c, 1e-3), (&c, 1e-1), (&reversed, 1e-3)] {
                let (e2, c2) = perturbed(&e, start, by);
                let r = inverse_iteration(&h, &s, &e2, &c2).unwrap();
                assert!(r.converged, "{r:?}");
                assert!((r.energy - e[0]).abs() <= 2.0 * ulp(e[0]), "{} vs {}", r.energy, e[0]);
                let exact: Vec<f64> = (0..3).map(|i| c[i * 3]).collect();
                let overlap = s_product(&s, &r.vector, &exact);
                assert!((overlap.abs() - 1.0).abs() < 1e-6, "overlap {overlap}");
            }
        }
    }

    #[test]
    fn inverse_iteration_resolves_what_refinement_does_not() {
        // every other root at E_0 + 1e-12: the corrections of `refine` diverge
        let (h, s, e, c) = pencil();
        let poor: Vec<f64> = e.iter().map(|_| e[0] + 1e-12).collect();
        let (_, c2) = perturbed(&e, &c, 1e-3);
        assert!(!refine(&h, &s, &poor, &c2, 0).converged);
        let r = inverse_iteration(&h, &s, &poor, &c2).unwrap();
        assert!(r.converged && (r.energy - e[0]).abs() <= 2.0 * ulp(e[0]), "{r:?}");
    }

    #[test]
    fn indefinite_overlap_is_refused() {
        let (h, s) = (vec![1.0, 0.0, 0.0, 1.0], vec![1.0, 2.0, 2.0, 1.0]);
        let err = inverse_iteration(&h, &s, &[0.0, 1.0], &[1.0, 0.0, 0.0, 1.0]).unwrap_err();
        assert_eq!(err, Indefinite { index: 1, pivot: -3.0 });
        assert!(err.to_string().starts_with("overlap matrix is not positive definite: pivot 1 "));
    }

    #[test]
    fn a_root_beyond_every_shift_is_not_converged() {
        // λ_0 = −1e12, the start the eigenvector of 3 and a degenerate start spectrum: the margin
        // doubles from 5.6e-9 for MAX_SHIFTS factorisations without reaching λ_0
        let (_, s, _, c) = pencil();
        let h = congruence(&L, [-1e12, -1.0, 3.0]);
        let start: Vec<f64> = (0..9).map(|ik| c[ik - ik % 3 + 2 - ik % 3]).collect(); // the roots reversed
        let r = inverse_iteration(&h, &s, &[3.0; 3], &start).unwrap();
        assert!(!r.converged && r.iterations == 0 && r.energy == 3.0, "{r:?}");
    }

    #[test]
    fn inverse_iteration_has_the_same_bits_for_any_thread_count() {
        let (h, s, e, c) = dominant_pencil();
        let one = on_threads(1, || inverse_iteration(&h, &s, &e, &c)).unwrap();
        assert!(one.converged && one.iterations > 0);
        assert_eq!(one, on_threads(3, || inverse_iteration(&h, &s, &e, &c)).unwrap());
    }
}
