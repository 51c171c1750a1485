//! The series of Ω (`element` module docs, docs/gvr.md) and the formulas built on it alone,
//! written once for every value they are evaluated in (`Scalar`): `f64` and dual numbers in the
//! generic element (`element::element`), lanes of symmetry images in the f64 kernel
//! (`kernel`) and its row gradient (`gradient`). Each is one sequence of operations, so
//! every instance has the bits of the others.
use std::ops::{Div, Mul};

use crate::scalar::Scalar;

/// `ĉ_k`, k = 0..=min(K_I, K_J) (`element` module docs), and the coefficients of the series of Ω's
/// derivatives (`omega`, `quadrature_partials`), for one pair (K_I, K_J) and N; all non-negative.
/// At `r = ρ²`: `G = Σ ĉ_k r^k`, `G_x = Σ ĉ_k (K_I−k) r^k`, `G_y = Σ ĉ_k (K_J−k) r^k`,
/// `G_z = Σ ĉ_k (N+2k) r^k`, for N = 0 divided by r (its k = 0 term vanishes).
pub(crate) struct Coefficients {
    pub(crate) ki: u32,
    pub(crate) kj: u32,
    pub(crate) n: u32,
    /// `ĉ_k`
    pub(crate) c: Vec<f64>,
    /// `ĉ_k (K_I − k)`, `ĉ_k (K_J − k)`
    pub(crate) cx: Vec<f64>,
    pub(crate) cy: Vec<f64>,
    /// `ĉ_k (N + 2k)`; for N = 0 shifted by one, `ĉ_{k+1} 2(k+1)` (G_z / r)
    pub(crate) cz: Vec<f64>,
}

impl Coefficients {
    pub(crate) fn new(ki: u32, kj: u32, n: u32) -> Self {
        let alpha = n as f64 + 0.5;
        let mut c = Vec::with_capacity(ki.min(kj) as usize + 1);
        let mut ck = 1.0;
        for k in 0..=ki.min(kj) {
            c.push(ck);
            ck *= ((ki - k) as f64) * ((kj - k) as f64) / (((k + 1) as f64) * (k as f64 + 1.0 + alpha));
        }
        let scaled = |f: &dyn Fn(u32) -> f64| c.iter().enumerate().map(|(k, ck)| ck * f(k as u32)).collect::<Vec<_>>();
        let (cx, cy) = (scaled(&|k| (ki - k) as f64), scaled(&|k| (kj - k) as f64));
        let cz = if n == 0 { scaled(&|k| (2 * k) as f64)[1..].to_vec() } else { scaled(&|k| (n + 2 * k) as f64) };
        Self { ki, kj, n, c, cx, cy, cz }
    }

    /// The series as `omega` reads them.
    #[inline(always)]
    pub(crate) fn terms(&self) -> Terms<'_> {
        Terms { ki: self.ki, kj: self.kj, n: self.n, c: &self.c, cx: &self.cx, cy: &self.cy, cz: &self.cz }
    }
}

/// `G(1) = Σ_k ĉ_k` of the pair (K, K) (`Coefficients`), summed from the top as `horner` at 1,
/// without allocation for K < 64.
pub(crate) fn series_at_one(k: u32, n: u32) -> f64 {
    if k >= 64 {
        return horner(&Coefficients::new(k, k, n).c, 1.0);
    }
    let alpha = n as f64 + 0.5;
    let mut c = [0.0f64; 64];
    let mut ck = 1.0;
    for i in 0..=k {
        c[i as usize] = ck;
        ck *= ((k - i) as f64) * ((k - i) as f64) / (((i + 1) as f64) * (i as f64 + 1.0 + alpha));
    }
    horner(&c[..=k as usize], 1.0)
}

/// `Σ_k coef_k r^k` (Horner).
#[inline(always)]
pub(crate) fn horner<T: Scalar>(coef: &[f64], r: T) -> T {
    coef.iter().rev().fold(T::of(0.0), |acc, &ck| acc * r + ck)
}

/// One pair's series of Ω and of its first derivatives (`Coefficients`), borrowed: what `omega`
/// reads, from `Coefficients::terms` or from the f64 kernel's table (`kernel::Series::terms`).
#[derive(Clone, Copy)]
pub(crate) struct Terms<'a> {
    pub(crate) ki: u32,
    pub(crate) kj: u32,
    pub(crate) n: u32,
    pub(crate) c: &'a [f64],
    pub(crate) cx: &'a [f64],
    pub(crate) cy: &'a [f64],
    pub(crate) cz: &'a [f64],
}

/// Ω and its derivatives divided by `e^L`, `L = (K_I+N/2) ln x + (K_J+N/2) ln y`:
/// returns `(L, ω, ω_x, ω_y, ω_z)`.
#[inline(always)]
pub(crate) fn omega<T: Scalar>(s: &Terms, x: T, y: T, z: T) -> (T, T, T, T, T) {
    let nf = s.n as f64;
    let rt = T::sqrt(x * y);
    let rho = T::clamp_unit(z / rt);
    let r2 = rho * rho;
    let (g, gx, gy, gz) = (horner(s.c, r2), horner(s.cx, r2), horner(s.cy, r2), horner(s.cz, r2));
    let rho_n = T::powu(rho, s.n);
    let l = T::ln(x) * (s.ki as f64 + 0.5 * nf) + T::ln(y) * (s.kj as f64 + 0.5 * nf);
    // Ω_z = x^{K_I} y^{K_J} Σ ĉ_k (N+2k) z^{N+2k-1} (xy)^{-k} = e^L Σ ĉ_k (N+2k) ρ^{N+2k-1} / √(xy);
    // for N = 0, G_z is stored divided by ρ² (`Coefficients::cz`), so ρ^{2k-1} = ρ · ρ^{2(k-1)}.
    let omega_z = if s.n == 0 { rho * gz / rt } else { T::powu(rho, s.n - 1) * gz / rt };
    (l, rho_n * g, rho_n * gx / x, rho_n * gy / y, omega_z)
}

/// Closed form of the kinetic element with `Λ = 1 1^T/(2 m_tot)` over `e^L S_0` (docs/gvr.md):
/// `3 c_I c_J/(m s) Ω − (c_UI² c_J Ω_x + c_UJ² c_I Ω_y)/(m s) + c_I c_J (c_UI² Ω_x + c_UI c_UJ Ω_z + c_UJ² Ω_y)/(m s²)`,
/// `s = c_I + c_J`. `c_I, c_J` are `f64` in the generic element and lanes in the kernel (`C`).
#[inline(always)]
pub(crate) fn cm_kinetic<T, C>(ci: C, cj: C, ui: T, uj: T, m: f64, w: (T, T, T, T)) -> T
where
    C: Scalar,
    T: Scalar + Mul<C, Output = T> + Div<C, Output = T>,
{
    let (om, ox, oy, oz) = w;
    let s = ci + cj;
    om * (ci * 3.0 * cj / (s * m)) - (ui * ui * cj * ox + uj * uj * ci * oy) / (s * m)
        + (ui * ui * ox + ui * uj * oz + uj * uj * oy) * (ci * cj) / (s * m * s)
}
