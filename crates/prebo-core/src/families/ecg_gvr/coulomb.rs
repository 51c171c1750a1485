//! Closed form of the ECG-GVR Coulomb τ-integral (docs/gvr.md, "Coulomb: closed form").
//!
//! `element` reduces `<φ_I| 1/|wᵀr| |φ_J>` to `∫_0^1 Ω(x − τ²γ_I², y − τ²γ_J², z − τ²γ_Iγ_J) dτ`.
//! With `t = τ²`, `s = 1 − t`, the argument is the convex combination `s P + t P'` of
//! `P = (x, y, z)` and `P' = (x − γ_I², y − γ_J², z − γ_Iγ_J)` (the covariances of `a`, `b` given
//! `wᵀr`). `Ω` is homogeneous of degree `M = K_I + K_J + N`, so
//!
//! ```text
//!     Ω(sP + tP') = Σ_j e_j s^j t^{M−j},      ∫_0^1 Ω dτ = Σ_j e_j β_j,
//!     β_j = ∫_0^1 (1 − τ²)^j τ^{2(M−j)} dτ = B(j + 1, M − j + 1/2)/2,
//!     β_0 = 1/(2M + 1),  β_j = β_{j−1} 2j/(2M − 2j + 1),
//! ```
//!
//! a finite sum of positive weights. The `e_j` come from `Ω = X^{K_I−m} Y^{K_J−m} Z^N
//! Σ_k ĉ_k (XY)^{m−k} (Z²)^k`, `m = min(K_I, K_J)`, with `X = s x + t x'` etc. linear forms:
//! Horner in `k` over polynomials in `(s, t)`. `X, Y` and `XY` have non-negative coefficients;
//! after the sign flip `z → −z` (`Ω(x, y, −z) = (−1)^N Ω`) so that `z ≥ 0`, only a negative
//! `z'` brings signs into `Z`. Like `element::quadrature` the result is divided by
//! `e^L = x^{K_I+N/2} y^{K_J+N/2}`: `P` and `P'` enter scaled by `(1/x, 1/y, 1/√(xy))`.
use super::element::{series_coefficients, GvrOps};

/// Scratch length kept on the stack (`M + 3 ≤ STACK`, K up to about 45); larger `M` use the heap.
const STACK: usize = 96;

/// The closed form for one pair `(K_I, K_J)` and the context's `N`: `ĉ_k` and `β_j`.
pub struct ClosedForm {
    ki: u32,
    kj: u32,
    n: u32,
    /// `ĉ_k`, k = 0..=min(K_I, K_J) (`series::Coefficients`)
    c: Vec<f64>,
    /// `β_j`, j = 0..=M
    beta: Vec<f64>,
    /// `C(|K_I − K_J|, j)`, j = 0..=|K_I − K_J|
    binomial: Vec<f64>,
}

impl ClosedForm {
    pub fn new<const D: usize>(go: &GvrOps<D>, ki: u32, kj: u32) -> Self {
        let degree = (ki + kj + go.n_ang) as usize; // M
        let mut beta = Vec::with_capacity(degree + 1);
        let mut b = 1.0 / (2 * degree + 1) as f64;
        for j in 0..=degree {
            if j > 0 {
                b *= (2 * j) as f64 / (2 * (degree - j) + 1) as f64;
            }
            beta.push(b);
        }
        let q = ki.abs_diff(kj) as usize;
        let mut binomial = vec![1.0; q + 1];
        for j in 1..=q {
            binomial[j] = binomial[j - 1] * (q + 1 - j) as f64 / j as f64;
        }
        Self { ki, kj, n: go.n_ang, c: series_coefficients(go, ki, kj), beta, binomial }
    }

    /// `∫_0^1 Ω(x − τ²γ_I², y − τ²γ_J², z − τ²γ_Iγ_J) dτ / e^L` for the inputs `[x, y, z, γ_I, γ_J]`,
    /// the value of `build::coulomb_partials`.
    pub fn integral(&self, inputs: [f64; 5]) -> f64 {
        let len = self.beta.len() + 2;
        if len <= STACK {
            let (mut e, mut p) = ([0.0; STACK], [0.0; STACK]);
            self.sum(inputs, &mut e[..len], &mut p[..len])
        } else {
            self.sum(inputs, &mut vec![0.0; len], &mut vec![0.0; len])
        }
    }

    /// `Σ_j e_j β_j` with the zeroed scratch `e` (the coefficients) and `p` (powers of `XY`, then the tail).
    fn sum(&self, inputs: [f64; 5], e: &mut [f64], p: &mut [f64]) -> f64 {
        let [x, y, z, gam_i, gam_j] = inputs;
        let rt = (x * y).sqrt();
        // scaled P = (1, 1, ρ) and P' = (x'/x, y'/y, z'/√(xy)); x', y' >= 0 analytically
        let (xc, yc) = ((1.0 - gam_i * gam_i / x).max(0.0), (1.0 - gam_j * gam_j / y).max(0.0));
        let (rho, zc) = (z / rt, (z - gam_i * gam_j) / rt);
        let (rho, zc, sign) = if rho < 0.0 { (-rho, -zc, (-1f64).powi(self.n as i32)) } else { (rho, zc, 1.0) };
        // forms in (t, s): X = [x', 1], Y = [y', 1], Z = [z', ρ]; XY and Z² are quadratic
        let xy = [xc * yc, xc + yc, 1.0];
        let zz = [zc * zc, 2.0 * zc * rho, rho * rho];
        let m = self.ki.min(self.kj) as usize;
        e[0] = self.c[m];
        p[0] = 1.0;
        for k in (0..m).rev() {
            let d = 2 * (m - k - 1);
            times_quadratic(p, d, xy);
            times_quadratic(e, d, zz);
            for (ej, pj) in e[..=d + 2].iter_mut().zip(&p[..=d + 2]) {
                *ej += self.c[k] * pj;
            }
        }
        // the tail X^{K_I−m} Y^{K_J−m} Z^N into p (one power is zero): binomial coefficients, then Z
        let (form, q) = if self.ki > self.kj { (xc, self.ki - self.kj) } else { (yc, self.kj - self.ki) };
        let q = q as usize;
        let mut power = 1.0;
        for j in (0..=q).rev() {
            p[j] = self.binomial[j] * power;
            power *= form;
        }
        for d in q..q + self.n as usize {
            times_linear(p, d, [zc, rho]);
        }
        // Σ_j (e · tail)_j β_j = Σ_i e_i Σ_l tail_l β_{i+l}
        let tail = &p[..=q + self.n as usize];
        let total: f64 = e[..=2 * m]
            .iter()
            .enumerate()
            .map(|(i, ei)| ei * tail.iter().zip(&self.beta[i..]).map(|(tl, bl)| tl * bl).sum::<f64>())
            .sum();
        sign * total
    }
}

/// `e ← e · (f_0 t + f_1 s)` for `e` of degree `d` (`e[j]` the coefficient of `s^j t^{d−j}`).
#[inline]
fn times_linear(e: &mut [f64], d: usize, f: [f64; 2]) {
    e[d + 1] = f[1] * e[d];
    for j in (1..=d).rev() {
        e[j] = f[0] * e[j] + f[1] * e[j - 1];
    }
    e[0] *= f[0];
}

/// `e ← e · (q_0 t² + q_1 s t + q_2 s²)` for `e` of degree `d`, zero above `d`.
#[inline]
fn times_quadratic(e: &mut [f64], d: usize, q: [f64; 3]) {
    for j in (2..=d + 2).rev() {
        e[j] = q[0] * e[j] + q[1] * e[j - 1] + q[2] * e[j - 2];
    }
    e[1] = q[0] * e[1] + q[1] * e[0];
    e[0] *= q[0];
}

/// The closed form of `build::coulomb_partials`'s value for each of `inputs`, into `out`.
pub fn coulomb_values<const D: usize>(go: &GvrOps<D>, ki: u32, kj: u32, inputs: &[[f64; 5]], out: &mut [f64]) {
    let form = ClosedForm::new(go, ki, kj);
    for (x, o) in inputs.iter().zip(out.iter_mut()) {
        *o = form.integral(*x);
    }
}

#[cfg(test)]
#[path = "coulomb_tests.rs"]
mod tests;
