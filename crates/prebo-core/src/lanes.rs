//! Values of the ECG-GVR kernel (`families::ecg_gvr::kernel::element`): one element (`f64`), or
//! the elements of one bra with `L` symmetry images of a ket at once ([`Lanes`]), structure of
//! arrays. Every operation is the scalar one, lane by lane (no fused multiply-add, the libm
//! `ln`/`exp` called per lane), so each lane has the bits of the scalar kernel on every
//! instruction set.
use std::ops::{Add, Div, Mul, Neg, Sub};

use crate::scalar::{binary_power, Scalar};

/// A value of the kernel: `f64` or [`Lanes`].
pub trait Lane: Scalar + Neg<Output = Self> + Sub<f64, Output = Self> + Div<f64, Output = Self> {
    /// Lanes
    const L: usize;
    /// The value with lane `l` equal to `f(l)`.
    fn from_lanes(f: impl Fn(usize) -> f64) -> Self;
    /// Lane `l`.
    fn lane(self, l: usize) -> f64;

    fn splat(x: f64) -> Self {
        Self::from_lanes(|_| x)
    }
    fn map(self, f: impl Fn(f64) -> f64) -> Self {
        Self::from_lanes(|l| f(self.lane(l)))
    }
    /// Whether `p` holds in every lane.
    fn all(self, p: impl Fn(f64) -> bool) -> bool {
        (0..Self::L).all(|l| p(self.lane(l)))
    }
}

impl Lane for f64 {
    const L: usize = 1;
    #[inline(always)]
    fn from_lanes(f: impl Fn(usize) -> f64) -> Self {
        f(0)
    }
    #[inline(always)]
    fn lane(self, _: usize) -> f64 {
        self
    }
}

/// `L` values in lanes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lanes<const L: usize>(pub [f64; L]);

impl<const L: usize> Lane for Lanes<L> {
    const L: usize = L;
    #[inline(always)]
    fn from_lanes(f: impl Fn(usize) -> f64) -> Self {
        Self(std::array::from_fn(f))
    }
    #[inline(always)]
    fn lane(self, l: usize) -> f64 {
        self.0[l]
    }
}

impl<const L: usize> Scalar for Lanes<L> {
    #[inline(always)]
    fn of(x: f64) -> Self {
        Self::splat(x)
    }
    #[inline(always)]
    fn sqrt(x: Self) -> Self {
        x.map(f64::sqrt)
    }
    #[inline(always)]
    fn ln(x: Self) -> Self {
        x.map(f64::ln)
    }
    #[inline(always)]
    fn clamp_unit(x: Self) -> Self {
        x.map(|v| v.clamp(-1.0, 1.0))
    }
    #[inline(always)]
    fn powu(x: Self, k: u32) -> Self {
        binary_power(x, k, Self::splat(1.0))
    }
}

/// The lane-by-lane operators `$op` of `Lanes` with `Lanes` and with `f64` on the right.
macro_rules! lane_op {
    ($trait:ident, $method:ident, $op:tt) => {
        impl<const L: usize> $trait for Lanes<L> {
            type Output = Self;
            #[inline(always)]
            fn $method(self, o: Self) -> Self {
                Self(std::array::from_fn(|l| self.0[l] $op o.0[l]))
            }
        }
        impl<const L: usize> $trait<f64> for Lanes<L> {
            type Output = Self;
            #[inline(always)]
            fn $method(self, o: f64) -> Self {
                Self(std::array::from_fn(|l| self.0[l] $op o))
            }
        }
    };
}

lane_op!(Add, add, +);
lane_op!(Sub, sub, -);
lane_op!(Mul, mul, *);
lane_op!(Div, div, /);

impl<const L: usize> Neg for Lanes<L> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self(self.0.map(|v| -v))
    }
}

/// `[f(0), …, f(N−1)]` in a loop that inlines into the kernels compiled per instruction set
/// (`std::array::from_fn` does not always).
#[inline(always)]
pub fn array<T: Lane, const N: usize>(f: impl Fn(usize) -> T) -> [T; N] {
    let mut v = [T::splat(0.0); N];
    for (i, x) in v.iter_mut().enumerate() {
        *x = f(i);
    }
    v
}

/// `[[f(i, j)]]`, `N × N`, in loops that inline (as `array`).
#[inline(always)]
pub fn matrix<T: Lane, const N: usize>(f: impl Fn(usize, usize) -> T) -> [[T; N]; N] {
    let mut m = [[T::splat(0.0); N]; N];
    for (i, row) in m.iter_mut().enumerate() {
        *row = array(|j| f(i, j));
    }
    m
}
