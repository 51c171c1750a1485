//! Gauss–Legendre rules: the n-point rule on [−1, 1] and the even rules on [0, 1] of the Coulomb
//! τ-integrals (ECG-GVR, docs/gvr.md) and of the damped-overlap profiles (`operators::profile`).
use std::f64::consts::PI;

/// Even Gauss–Legendre rules computed once per process (`legendre_rule`).
pub(crate) static RULES: [std::sync::OnceLock<Vec<(f64, f64)>>; 512] = [const { std::sync::OnceLock::new() }; 512];

/// `even_rule(m)`, computed on first use (m < 512, i.e. K up to ~500).
pub(crate) fn legendre_rule(m: usize) -> &'static [(f64, f64)] {
    RULES[m].get_or_init(|| even_rule(m))
}

/// The m positive nodes of the 2m-point Gauss–Legendre rule on [−1, 1] with their weights:
/// `Σ w f(τ) = ∫_0^1 f(τ) dτ` for every even polynomial f of degree ≤ 4m − 1.
pub fn even_rule(m: usize) -> Vec<(f64, f64)> {
    gauss_legendre(2 * m).into_iter().filter(|&(x, _)| x > 0.0).collect()
}

/// The n-point Gauss–Legendre rule on [−1, 1] (Newton iteration on P_n).
pub fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let mut x = (PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            let p = if n == 0 { 1.0 } else { p1 };
            dp = n as f64 * (x * p - p0) / (x * x - 1.0);
            let dx = p / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        out.push((x, w));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn legendre_integrates_polynomials_exactly() {
        for n in 1..60 {
            let rule = gauss_legendre(n);
            for deg in 0..(2 * n) {
                let integral: f64 = rule.iter().map(|(x, w)| w * x.powi(deg as i32)).sum();
                let exact = if deg % 2 == 0 { 2.0 / (deg as f64 + 1.0) } else { 0.0 };
                assert!((integral - exact).abs() < 1e-13, "n={n} deg={deg}");
            }
        }
    }

    #[test]
    fn even_rule_integrates_even_polynomials_exactly() {
        for m in 1..40 {
            let rule = even_rule(m);
            assert_eq!(rule.len(), m);
            for deg in (0..4 * m).step_by(2) {
                let integral: f64 = rule.iter().map(|(t, w)| w * t.powi(deg as i32)).sum();
                assert!((integral - 1.0 / (deg as f64 + 1.0)).abs() < 1e-13, "m={m} deg={deg}");
            }
        }
        // two degrees further the rule is no longer exact: the bound is sharp (the error of
        // τ^{4m} shrinks like 16^{-2m}, so it is visible for small m)
        for m in 1..6 {
            let integral: f64 = even_rule(m).iter().map(|(t, w)| w * t.powi(4 * m as i32)).sum();
            assert!((integral - 1.0 / (4 * m + 1) as f64).abs() > 1e-8, "m={m}");
        }
    }
}
