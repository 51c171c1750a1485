//! The one scalar interface of the generic elements' values (`ecg::Real`: `f64`, dual numbers)
//! and the f64 kernels' values (`lanes::Lane`: `f64`, lanes), for maths written once for both:
//! a formula generic over [`Scalar`] (e.g. `families::ecg_gvr::series::omega`) performs the same
//! operations in the same order on each, so every instance has the bits of the others' values.
use std::ops::{Add, Div, Mul, Sub};

use nalgebra::{ComplexField, RealField};
use num_dual::{Dual64, DualSVec64, HyperDual64, HyperDualSVec64};

/// Arithmetic with itself and with `f64` constants, and the few functions of one value the shared
/// formulas need. The functions are associated functions (`T::sqrt(x)`), not methods, so they do
/// not compete with nalgebra's in code generic over `Real`.
pub trait Scalar:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Add<f64, Output = Self>
    + Mul<f64, Output = Self>
{
    /// The constant `x` (zero derivatives).
    fn of(x: f64) -> Self;
    fn sqrt(x: Self) -> Self;
    fn ln(x: Self) -> Self;
    /// `x` clamped to `[−1, 1]`.
    fn clamp_unit(x: Self) -> Self;
    /// `x^k`: binary exponentiation for `f64` and lanes (the operations of `f64::powi`), the dual
    /// numbers' own `powi`.
    fn powu(x: Self, k: u32) -> Self;
}

/// `x^k` by binary exponentiation, the same squarings and products as `f64::powi`.
#[inline(always)]
pub fn binary_power<T: Copy + Mul<Output = T>>(x: T, k: u32, one: T) -> T {
    let (mut r, mut base, mut k) = (one, x, k);
    loop {
        if k & 1 == 1 {
            r = r * base;
        }
        k >>= 1;
        if k == 0 {
            return r;
        }
        base = base * base;
    }
}

impl Scalar for f64 {
    #[inline(always)]
    fn of(x: f64) -> Self {
        x
    }
    #[inline(always)]
    fn sqrt(x: Self) -> Self {
        f64::sqrt(x)
    }
    #[inline(always)]
    fn ln(x: Self) -> Self {
        f64::ln(x)
    }
    #[inline(always)]
    fn clamp_unit(x: Self) -> Self {
        x.clamp(-1.0, 1.0)
    }
    #[inline(always)]
    fn powu(x: Self, k: u32) -> Self {
        binary_power(x, k, 1.0)
    }
}

/// `Scalar` for a num-dual type `$t` (with generics `$g`): its own functions, and `clamp_unit`
/// given as a closure of one argument.
macro_rules! dual_scalar {
    ([$($g:tt)*] $t:ty, |$x:ident| $clamp:expr) => {
        impl<$($g)*> Scalar for $t {
            #[inline(always)]
            fn of(x: f64) -> Self {
                Self::from(x)
            }
            #[inline(always)]
            fn sqrt(x: Self) -> Self {
                ComplexField::sqrt(x)
            }
            #[inline(always)]
            fn ln(x: Self) -> Self {
                ComplexField::ln(x)
            }
            #[inline(always)]
            fn clamp_unit($x: Self) -> Self {
                $clamp
            }
            #[inline(always)]
            fn powu(x: Self, k: u32) -> Self {
                ComplexField::powi(x, k as i32)
            }
        }
    };
}

dual_scalar!([const W: usize] DualSVec64<W>, |x| RealField::clamp(x, Self::from(-1.0), Self::from(1.0)));
// Vector hyper-dual numbers, for the derivatives of Gaussian-weighted elements (the damping's
// derivative inside the parameters', `families::ecg_gvr::transition`), clamped as the dual ones.
dual_scalar!([const M: usize, const N: usize] HyperDualSVec64<M, N>, |x| RealField::clamp(x, Self::from(-1.0), Self::from(1.0)));

// Hyper-dual numbers (one mixed second derivative), for ECG-GVR's `p_g⁴` and orbit–orbit elements
// (`families::ecg_gvr::momentum`): `clamp_unit` clamps the value only, since the shared formulas
// are analytic where they clamp (ρ = z/√(xy), `series::omega`) and the derivatives stand.
dual_scalar!([] HyperDual64, |x| Self { re: x.re.clamp(-1.0, 1.0), ..x });
// Dual numbers where those elements need one derivative only (the isotropic part of orbit–orbit),
// clamped as the hyper-dual ones.
dual_scalar!([] Dual64, |x| Self { re: x.re.clamp(-1.0, 1.0), ..x });

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lanes::Lanes;

    #[test]
    fn powers_have_the_bits_of_powi() {
        let mut x = 0.3f64;
        for k in 0..200u32 {
            x = (x * 7.31 + 0.17).fract() * 2.0 - 1.0;
            assert_eq!(<f64 as Scalar>::powu(x, k).to_bits(), x.powi(k as i32).to_bits(), "{x}^{k}");
            let lanes = Lanes::<2>::powu(Lanes([x, -x]), k).0;
            assert_eq!(lanes.map(f64::to_bits), [x.powi(k as i32), (-x).powi(k as i32)].map(f64::to_bits));
        }
    }
}
