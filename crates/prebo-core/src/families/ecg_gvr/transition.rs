//! Vector operators between a basis of N = 0 and one of N = 1: the electric dipole in length
//! form, `d = Σ_k w_k r_k` with `w_k = q_k − Q m_k/m_tot` (the charges' dipole about the centre of
//! mass; `Q`, `m_tot` the total charge and mass), and in velocity form, `Σ_k w'_k ∇_k` with
//! `w'_k = q_k/m_k − Q/m_tot`; both vectors in the representation's coordinates (`w` like the
//! Coulomb vectors, `w'` like a momentum). Their elements are reduced ones (Wigner–Eckart,
//! Edmonds' convention `<N' M'|O_q|N M> = (−1)^{N'−M'} (N' 1 N; −M' q M) <N'‖O‖N>`), one per pair
//! of a function of N = 0 (bra) and one of N = 1 (ket), each normalised:
//!
//! ```text
//!     <1‖O‖0>_IJ = <p̂_J| v_J·O |φ̂_I> / <p̂_J| v_J² |p̂_J>^{1/2},
//! ```
//!
//! where `p_J = |v|^{2K} exp(−r^T A r)`, `v_J = u^T r`, is the N = 0 partner of the ket
//! `φ'_J = v_+ p_J` (ECG-GVR, M = N; a plain ECG is K = N = 0). Derivation (docs/transitions.md):
//! `p_J φ_I` is invariant under rotations and reflections, so `∫ (v_J)_a O_b p_J φ_I =
//! δ_ab ∫ v_J·O p_J φ_I / 3`; hence `<1 1|O_{+1}|0 0> = −(√2/3) <p_J|v_J·O|φ_I> / ‖φ'_J‖` with
//! `‖φ'_J‖² = (2/3) <p_J|v_J²|p_J>`, and `<1‖O‖0> = √3 <1 1|O_{+1}|0 0>`; the overall sign,
//! like an eigenvector's, is a convention (dropped here). For the length form `v_J·d` is the
//! quadratic form `r^T (u_J w^T ⊗ I_3) r`; for the velocity form, with
//! `φ_I = |v_I|^{2K_I} exp(−r^T A_I r)`,
//!
//! ```text
//!     v_J·∇_w' φ_I = −2 (u_J^T r)·((A_I w')^T r) φ_I + 2 K_I (w'·u_I) (v_J·v_I) |v_I|^{2K_I−2} e^{−r^T A_I r},
//! ```
//!
//! the second term a quadratic form against the function of power `K_I − 1`, whose norm is
//! `x_I √((4K_I+1)(4K_I−1))` times smaller (`x_I = u_I^T A_I^{-1} u_I / 4`, the variance of each
//! component of `v_I` under `|φ_I|²`'s Gaussian; `E|v|^{2p} = (2x)^p Γ(p+3/2)/Γ(3/2)`). Every
//! quadratic form `<f| r^T (M ⊗ I_3) r |g>` is `−∂/∂α <f| g exp(−α r^T M r)>` at α = 0 (as `r2`).
//!
//! For exact states `<f‖∇_w'‖i> = −(E_f − E_i) <f‖d‖i>` (`[H, d] = −∇_w'`); the ratio of the two
//! forms is the usual convergence diagnostic.
//!
//! The acceleration form, `∇_w' V` with `V = Σ_{a<b} q_a q_b / r_ab` the context's Coulomb
//! potential: for exact states `<f‖∇_w' V‖i> = (E_f − E_i)² <f‖d‖i>` (`[H, [H, d]] = −[V, ∇_w'] =
//! ∇_w' V`). Integrated by parts (the force's singularities are integrable), with
//! `∇_w'·v_J = 3 (w'·u_J)` and `v_J·∇_w' p_J = (2 K_J (w'·u_J) − 2 (u_J^T r)·((A_J w')^T r)) p_J`,
//!
//! ```text
//!     <p_J| v_J·∇_w' V |φ_I> = −(3 + 2K_J)(w'·u_J) <p_J|V|φ_I> + 2 <p_J| (u_J^T r)·(((A_I + A_J) w')^T r) V |φ_I>
//!                              − 2 K_I (w'·u_I) <p_J| (v_J·v_I) V |v_I|^{2K_I−2} e^{−r^T A_I r}>,
//! ```
//!
//! each quadratic form with `V` inside again `−∂/∂α` at α = 0, now of the Coulomb element of the
//! damped pair (`damped`), and the last with the velocity form's norm ratio.
//!
//! Derivatives along the ket's parameters (`Form`, `path::between_gradient`; docs/transitions.md):
//! the ket of dual numbers carries them through its normalisation and `‖v_J p_J‖`, and each
//! quadratic form, a derivative in α itself, through hyper-dual numbers (`Damping`).
//!
//! The electric quadrupole about the centre of mass between a basis of N = 0 and one of N = 2,
//! `Q_2q = Σ_k q_k |ρ_k|² C_2q(ρ̂_k)`, `ρ_k = r_k − R_CM = m_k^T r` (`m_k = e_k − m/m_tot`): its
//! Cartesian tensor is `T = Σ_ij M_ij r_i r_j^T` with `M = Σ_k q_k m_k m_k^T` (`v`: the D columns
//! of `M`, in the representation's coordinates on both sides, like the Coulomb vectors), and
//!
//! ```text
//!     <2‖Q‖0>_IJ = <p̂_J| (3/2) Σ_ij M_ij (v_J·r_i)(v_J·r_j) − (1/2) v_J² r^T M r |φ̂_I> / <p̂_J| v_J⁴ |p̂_J>^{1/2}
//! ```
//!
//! for the ket `φ'_J = v_+² p_J` (M = N = 2). Derivation (docs/transitions.md): `<2 M|Q_M|0 0> =
//! <2‖Q‖0>/√5` for every M, so the element is a fifth of the sum over M, and the addition theorem
//! `Σ_M C_2M(â)^* C_2M(b̂) = P_2(â·b̂)` turns `Σ_M (|v|² C_2M(v̂))^* Q_2M` into the invariant
//! `(3/2) Σ_k q_k (v·ρ_k)² − (1/2) v² Σ_k q_k ρ_k²`; the norm `‖|v|² C_2M(v̂) p_J‖² =
//! <p_J|v⁴|p_J>/5` likewise. Each product of two quadratic forms is `∂²/∂α∂β` of the overlap of
//! `φ_I` and `p_J exp(−α r^T M_1 r − β r^T M_2 r)` at 0, exact with a hyper-dual number (`second`),
//! `D + 2` overlaps per pair. Length form only (`quadrupole`, registered of rank 2).
use nalgebra::{Const, SMatrix, SVector, U1};
use num_dual::{Derivative, HyperDualSVec64};

use crate::ecg::{re, Mat, Real, Vector};
use crate::error::{CoreError, Result};
use super::element::{GvrFunction, GvrOps};
use super::EcgGvr;
use crate::families::Family;
use crate::gradient::{seed, Dual};
use crate::path::KetElement;

/// The length form, `v = [w]`.
pub const DIPOLE: &str = "dipole";
/// The velocity form, `v = [w']`.
pub const VELOCITY: &str = "velocity";
/// The electric quadrupole, `v` the D columns of `M = Σ_k q_k m_k m_k^T`.
pub const QUADRUPOLE: &str = "quadrupole";
/// The acceleration form, `v = [w']`, with the Coulomb potential of the context.
pub const ACCELERATION: &str = "acceleration";

/// A scalar with one derivative more, along the damping α of `quadratic`'s overlap: `f64` →
/// `Dual<1>`; `Dual<W>` (W parameter directions θ_p) → the hyper-dual `HyperDualSVec64<W, 1>`,
/// whose `ε_1 ε_2` part is `∂²/∂θ_p ∂α` (exact through `ecg::inverse_log_det`'s second order).
pub trait Damping: Real {
    type Damped: Real;
    /// `x` with no α-derivative.
    fn lift(x: Self) -> Self::Damped;
    /// α = 0, `∂α/∂α = 1`.
    fn alpha() -> Self::Damped;
    /// `∂x/∂α` with its derivatives along the parameters.
    fn slope(x: &Self::Damped) -> Self;
}

impl Damping for f64 {
    type Damped = Dual<1>;
    fn lift(x: f64) -> Dual<1> {
        Dual::from(x)
    }
    fn alpha() -> Dual<1> {
        seed(0.0, std::iter::once(1.0))
    }
    fn slope(x: &Dual<1>) -> f64 {
        x.eps.unwrap_generic(Const::<1>, U1)[0]
    }
}

impl<const W: usize> Damping for Dual<W> {
    type Damped = HyperDualSVec64<W, 1>;
    fn lift(x: Dual<W>) -> Self::Damped {
        HyperDualSVec64::new(x.re, x.eps, Derivative::none(), Derivative::none())
    }
    fn alpha() -> Self::Damped {
        HyperDualSVec64::new(0.0, Derivative::none(), Derivative::some(SMatrix::<f64, 1, 1>::new(1.0)), Derivative::none())
    }
    fn slope(x: &Self::Damped) -> Dual<W> {
        let mixed = x.eps1eps2.unwrap_generic(Const::<W>, Const::<1>);
        Dual::new(x.eps2.unwrap_generic(U1, Const::<1>)[0], Derivative::some(mixed))
    }
}

/// `f` over the scalar of one derivative more (`Damping`), none of it along α.
fn lift<const D: usize, T: Damping>(f: &GvrFunction<D, T>) -> GvrFunction<D, T::Damped> {
    GvrFunction { a: f.a.map(T::lift), u: f.u.map(T::lift), k: f.k, c_a: f.c_a, c_u: T::lift(f.c_u), log_norm: T::lift(f.log_norm) }
}

/// `(<f| q |g>, <f| q V |g>)` of normalised functions, `q = r^T (M ⊗ I_3) r` for a symmetric `M`
/// and `V` the context's Coulomb potential (0 without pairs): `−∂/∂α` of the overlap and the
/// Coulomb element of `f` and `g exp(−α q)` at α = 0; for `T` of dual numbers with its derivatives.
fn damped<const D: usize, T: Damping>(f: &GvrFunction<D, T>, g: &GvrFunction<D, T>, go: &GvrOps<D>, m: &SMatrix<T, D, D>) -> (T, T) {
    let alpha = T::alpha();
    let mut damped = lift(g);
    damped.a += m.map(|x| alpha * T::lift(x));
    let e = <EcgGvr as Family<D>>::element(&lift(f), &damped, go);
    (-T::slope(&e.s), -T::slope(&e.v))
}

/// `<f| r^T (M ⊗ I_3) r |g>` of normalised functions (`damped`).
pub fn quadratic<const D: usize, T: Damping>(f: &GvrFunction<D, T>, g: &GvrFunction<D, T>, go: &GvrOps<D>, m: &SMatrix<T, D, D>) -> T {
    damped(f, g, go, m).0
}

/// `(a b^T + b a^T)/2`: the quadratic form of `(a^T r)·(b^T r)`.
fn outer<const D: usize, T: Real>(a: &SVector<T, D>, b: &SVector<T, D>) -> SMatrix<T, D, D> {
    SMatrix::from_fn(|i, j| (a[i] * b[j] + a[j] * b[i]) * 0.5)
}

/// `<p̂_J| v_J² |p̂_J>^{1/2}` of the ket's partner.
fn norm<const D: usize, T: Damping>(ket: &GvrFunction<D, T>, go: &GvrOps<D>) -> T {
    quadratic(ket, ket, go, &outer(&ket.u, &ket.u)).sqrt()
}

/// `<1‖d‖0>_IJ`, `v = [w]` (module docs); `bra` of N = 0, `ket` the partner of N = 1's function
/// (of dual numbers for the derivatives along its parameters, `between_gradient`).
pub fn dipole<const D: usize, T: Damping>(bra: &GvrFunction<D>, ket: &GvrFunction<D, T>, go: &GvrOps<D>, v: &[Vector<D>]) -> T {
    quadratic(&bra.cast(), ket, go, &outer(&ket.u, &v[0].map(re))) / norm(ket, go)
}

/// `<1‖∇_w'‖0>_IJ`, `v = [w']` (module docs); `bra` and `ket` as for `dipole`.
pub fn velocity<const D: usize, T: Damping>(bra: &GvrFunction<D>, ket: &GvrFunction<D, T>, go: &GvrOps<D>, v: &[Vector<D>]) -> T {
    let w = &v[0];
    let mut e = quadratic(&bra.cast(), ket, go, &outer(&ket.u, &(bra.a * w).map(re))) * -2.0;
    if bra.k > 0 {
        let (lower, ratio) = lowered(bra, go);
        e += quadratic(&lower.cast(), ket, go, &outer(&ket.u, &bra.u.map(re))) * (2.0 * bra.k as f64 * w.dot(&bra.u) * ratio);
    }
    e / norm(ket, go)
}

/// The bra's function of power `K_I − 1` and the ratio of its norm to the bra's,
/// `1/(x_I √((4K_I+1)(4K_I−1)))` (module docs); `bra.k > 0`.
fn lowered<const D: usize>(bra: &GvrFunction<D>, go: &GvrOps<D>) -> (GvrFunction<D>, f64) {
    let k = bra.k as f64;
    let lower = GvrFunction::new(bra.a, bra.u, bra.k - 1, bra.c_a, go, 0).expect("K − 1 of a checked function");
    let x = bra.u.dot(&bra.a.cholesky().expect("a checked exponent").solve(&bra.u)) * 0.25;
    (lower, 1.0 / (x * ((4.0 * k + 1.0) * (4.0 * k - 1.0)).sqrt()))
}

/// `<1‖∇_w' V‖0>_IJ`, `v = [w']`, `V` the context's Coulomb potential (module docs); `bra` and
/// `ket` as for `dipole`.
pub fn acceleration<const D: usize>(bra: &GvrFunction<D>, ket: &GvrFunction<D>, go: &GvrOps<D>, v: &[Vector<D>]) -> f64 {
    let (w, u) = (&v[0], &ket.u);
    let plain = <EcgGvr as Family<D>>::element(bra, ket, go).v;
    let (_, coupled) = damped(bra, ket, go, &outer(u, &((bra.a + ket.a) * w)));
    let mut e = 2.0 * coupled - plain * ((3 + 2 * ket.k) as f64 * w.dot(u));
    if bra.k > 0 {
        let (lower, ratio) = lowered(bra, go);
        e -= damped(&lower, ket, go, &outer(u, &bra.u)).1 * (2.0 * bra.k as f64 * w.dot(&bra.u) * ratio);
    }
    e / norm(ket, go)
}

/// `<f| (r^T (M_1 ⊗ I_3) r)(r^T (M_2 ⊗ I_3) r) |g>` of normalised functions: `∂²/∂α∂β` of the
/// overlap of `f` and `g exp(−α r^T M_1 r − β r^T M_2 r)` at 0, the `ε_1 ε_2` part of a hyper-dual
/// number (ε_1 ↔ α, ε_2 ↔ β; exact through `ecg::inverse_log_det`'s second order).
pub fn second<const D: usize>(f: &GvrFunction<D>, g: &GvrFunction<D>, go: &GvrOps<D>, m1: &Mat<D>, m2: &Mat<D>) -> f64 {
    type Hyper = HyperDualSVec64<1, 1>;
    let alpha = Hyper::new(0.0, Derivative::some(SVector::<f64, 1>::new(1.0)), Derivative::none(), Derivative::none());
    let beta = Hyper::new(0.0, Derivative::none(), Derivative::some(SMatrix::<f64, 1, 1>::new(1.0)), Derivative::none());
    let mut damped: GvrFunction<D, Hyper> = g.cast();
    damped.a += SMatrix::from_fn(|i, j| alpha * m1[(i, j)] + beta * m2[(i, j)]);
    let s = <EcgGvr as Family<D>>::overlap(&f.cast(), &damped, go);
    s.eps1eps2.unwrap_generic(Const::<1>, Const::<1>)[(0, 0)]
}

/// `<2‖Q‖0>_IJ`, `v` the D columns of the symmetric `M` (module docs); `bra` of N = 0, `ket` the
/// partner of N = 2's function.
pub fn quadrupole<const D: usize>(bra: &GvrFunction<D>, ket: &GvrFunction<D>, go: &GvrOps<D>, v: &[Vector<D>]) -> f64 {
    let (u, m) = (&ket.u, Mat::<D>::from_columns(v));
    let uu = outer(u, u);
    let contracted: f64 = (0..D).map(|i| second(bra, ket, go, &outer(u, &Vector::<D>::from_fn(|k, _| f64::from(k == i))), &outer(u, &m.column(i).into_owned()))).sum();
    (1.5 * contracted - 0.5 * second(bra, ket, go, &uu, &m)) / second(ket, ket, go, &uu, &uu).sqrt()
}

/// The two forms as elements of a ket that carries directions (`path::between_gradient`).
#[derive(Clone, Copy, Debug)]
pub enum Form {
    Length,
    Velocity,
}

impl Form {
    /// The form of the two-basis operator `name`.
    pub fn of(name: &str) -> Result<Self> {
        match name {
            DIPOLE => Ok(Form::Length),
            VELOCITY => Ok(Form::Velocity),
            _ => Err(CoreError::Unsupported(format!("operator {name:?}: no derivatives along the ket's parameters ({DIPOLE}, {VELOCITY})"))),
        }
    }
}

impl<const D: usize> KetElement<D, EcgGvr> for Form {
    fn element<const W: usize>(&self, bra: &GvrFunction<D>, ket: &GvrFunction<D, Dual<W>>, go: &GvrOps<D>, v: &[Vector<D>]) -> Dual<W> {
        match self {
            Form::Length => dipole(bra, ket, go, v),
            Form::Velocity => velocity(bra, ket, go, v),
        }
    }
}

#[cfg(test)]
mod tests {
    //! Against Gauss–Hermite quadrature of the Cartesian elements with the ket's M = 0 component
    //! `v_z p_J` (`<1‖O‖0> = √3 <1 0|O_z|0 0>`, Edmonds), for two and three coordinates and K up
    //! to 1: the length form exactly (a polynomial under the Gaussian weight), the velocity form
    //! by a central difference of the bra along `w'` inside the quadrature.
    use super::*;
    use crate::ecg::{Mat, Operators};
    use crate::engine::{Engine, Kind, Representation};
    use crate::operators::fixtures::{exponent, gauss_hermite};
    use crate::params::{Column, Directions};
    use crate::test_support::Rng;

    /// `∫ g(r) exp(−Σ_c r_c^T B r_c) dr` (`r_c` the coordinates' component c) with `M` Gauss–Hermite
    /// nodes per dimension after `r_c = L^{−T} y_c`, `B = L L^T`: exact for `g` a polynomial of degree < 2M.
    fn integrate<const D: usize, const M: usize>(b: &Mat<D>, g: impl Fn(&[Vector<D>; 3]) -> f64) -> f64 {
        let rule = gauss_hermite::<M>();
        let l = b.cholesky().unwrap().l();
        let (back, det) = (l.transpose().try_inverse().unwrap(), l.diagonal().product().powi(2));
        let mut index = vec![0; 3 * D];
        let mut total = 0.0;
        loop {
            let r: [Vector<D>; 3] = std::array::from_fn(|c| back * Vector::<D>::from_fn(|i, _| rule[index[c * D + i]].0));
            total += index.iter().map(|&k| rule[k].1).product::<f64>() * g(&r);
            match index.iter().position(|&k| k + 1 < M) {
                Some(d) => {
                    index[d] += 1;
                    index[..d].fill(0);
                }
                None => return total * det.powf(-1.5),
            }
        }
    }

    /// `|u^T r|^{2K}`.
    fn power<const D: usize>(u: &Vector<D>, k: u32, r: &[Vector<D>; 3]) -> f64 {
        r.iter().map(|rc| u.dot(rc).powi(2)).sum::<f64>().powi(k as i32)
    }

    struct Pair<const D: usize> {
        bra: (Mat<D>, Vector<D>, u32),
        ket: (Mat<D>, Vector<D>, u32),
    }

    impl<const D: usize> Pair<D> {
        fn new(seeds: (f64, f64), ks: (u32, u32)) -> Self {
            let u = |s: f64| Vector::<D>::from_fn(|i, _| (1.3 * i as f64 + s).cos());
            Self { bra: (exponent::<D>(seeds.0), u(seeds.0), ks.0), ket: (exponent::<D>(seeds.1), u(seeds.1 + 0.4), ks.1) }
        }

        fn functions(&self) -> (GvrFunction<D>, GvrFunction<D>, GvrOps<D>) {
            let go = GvrOps::new(Operators { lambda: Mat::<D>::identity() * 0.5, pairs: vec![], cm_mass: None }, 0, 2).unwrap();
            let f = |(a, u, k): (Mat<D>, Vector<D>, u32), i| GvrFunction::new(a, u, k, 1.0, &go, i).unwrap();
            (f(self.bra, 0), f(self.ket, 1), go)
        }

        /// `√3 ∫ (v_z p_J)(r) φ_I(r + s) dr / (‖v_z p_J‖ ‖φ_I‖)`, `s = h w' ẑ` and `O_z` = `o(r)`.
        fn cartesian<const M: usize>(&self, o: impl Fn(&[Vector<D>; 3]) -> f64, h: f64, w: &Vector<D>) -> f64 {
            let ((ai, ui, ki), (aj, uj, kj)) = (self.bra, self.ket);
            let shift = |r: &[Vector<D>; 3]| [r[0], r[1], r[2] + w * h];
            let x = integrate::<D, M>(&(ai + aj), |r| {
                let decay = (-2.0 * h * (ai * w).dot(&r[2]) - h * h * w.dot(&(ai * w))).exp();
                uj.dot(&r[2]) * power(&uj, kj, r) * o(r) * power(&ui, ki, &shift(r)) * decay
            });
            let nj = integrate::<D, M>(&(aj * 2.0), |r| (uj.dot(&r[2]) * power(&uj, kj, r)).powi(2));
            let ni = integrate::<D, M>(&(ai * 2.0), |r| power(&ui, ki, r).powi(2));
            3f64.sqrt() * x / (nj * ni).sqrt()
        }
    }

    fn length<const D: usize>(seeds: (f64, f64), ks: (u32, u32)) {
        let pair = Pair::<D>::new(seeds, ks);
        let (bra, ket, go) = pair.functions();
        let w = Vector::<D>::from_fn(|i, _| [1.0, -2.0, 0.5][i % 3]);
        let got = dipole(&bra, &ket, &go, &[w]);
        let want = pair.cartesian::<4>(|r| w.dot(&r[2]), 0.0, &w);
        assert!((got - want).abs() <= 1e-11 * want.abs(), "{ks:?}: {got} vs {want}");
    }

    #[test]
    fn the_length_form_matches_quadrature_for_two_and_three_coordinates() {
        for ks in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            length::<2>((0.3, 1.7), ks);
        }
        for ks in [(0, 0), (1, 1)] {
            length::<3>((0.9, 2.4), ks);
        }
    }

    /// `P_12`: the first two coordinates swapped.
    fn swap<const D: usize>() -> Mat<D> {
        Mat::<D>::from_fn(|i, j| f64::from(match i { 0 => j == 1, 1 => j == 0, _ => i == j }))
    }

    /// Engines of `D` coordinates (no Coulomb pairs): the bra's of family `bra` and N = 0, the
    /// ket's of ECG-GVR and N = `n` with two images, `(1 − P_12)/2`.
    fn engines<const D: usize>(bra: Kind, n: u32) -> (Engine, Engine) {
        let swap = swap::<D>();
        let rep = |sym: Vec<(Mat<D>, f64)>| Representation {
            n: D,
            lambda: (Mat::<D>::identity() * 0.5).as_slice().to_vec(),
            pair_w: vec![],
            pair_q: vec![],
            sym_t: sym.iter().flat_map(|(t, _)| t.transpose().as_slice().to_vec()).collect(),
            sym_c: sym.iter().map(|(_, c)| *c).collect(),
            cm_mass: None,
        };
        let bra = Engine::new(bra, rep(vec![(Mat::<D>::identity(), 1.0)]), 0).unwrap();
        let ket = Engine::new(Kind::EcgGvr, rep(vec![(Mat::<D>::identity(), 0.5), (swap, -0.5)]), n).unwrap();
        (bra, ket)
    }

    /// The columns of functions `(A, u, K)` of family `kind` (`u`, `K` ignored for a plain ECG).
    fn columns<const D: usize>(kind: Kind, f: &[(Mat<D>, Vector<D>, u32)]) -> Vec<Column> {
        let a = f.iter().flat_map(|(a, ..)| a.transpose().as_slice().to_vec()).collect();
        let c_a = Column::Floats(vec![1.0; f.len()]);
        match kind {
            Kind::Pecg => vec![Column::Floats(a), c_a],
            _ => vec![
                Column::Floats(a),
                Column::Floats(f.iter().flat_map(|(_, u, _)| u.as_slice().to_vec()).collect()),
                Column::Naturals(f.iter().map(|(.., k)| *k).collect()),
                c_a,
            ],
        }
    }

    /// `between_gradient` of a one-function ket against a bra basis of three functions (K_I = `ks.0`,
    /// the ket's K_J = `ks.1`) along `p` random directions: row 0 has `between`'s bits, rows 1.. its
    /// derivatives by a fourth-order central difference of `between` (step 1e-3).
    fn derivatives<const D: usize>(bra_kind: Kind, ks: (u32, u32), p: usize, seed: u64) {
        let mut rng = Rng(seed);
        let u = |rng: &mut Rng| Vector::<D>::from_fn(|_, _| rng.signed());
        let bras: Vec<_> = (0..3).map(|i| (exponent::<D>(0.4 + 0.9 * i as f64), u(&mut rng), ks.0)).collect();
        let (a, uj) = (exponent::<D>(2.3) * 0.7, u(&mut rng));
        let da: Vec<Mat<D>> = (0..p).map(|_| Mat::<D>::from_fn(|_, _| rng.signed() * 0.3)).map(|m| m + m.transpose()).collect();
        let du: Vec<Vector<D>> = (0..p).map(|_| u(&mut rng)).collect();
        let (bra_engine, ket_engine) = engines::<D>(bra_kind, 1);
        let bra = columns(bra_kind, &bras);
        let w = Vector::<D>::from_fn(|i, _| [1.0, -2.0, 0.5][i % 3]);
        let flat = |m: &[Mat<D>]| m.iter().flat_map(|m| m.transpose().as_slice().to_vec()).collect::<Vec<_>>();
        let (dir_a, dir_u) = (flat(&da), du.iter().flat_map(|v| v.as_slice().to_vec()).collect::<Vec<_>>());
        let dir = Directions { a: &dir_a, v: &dir_u };
        for name in [DIPOLE, VELOCITY] {
            let between = |t: &[f64]| {
                let (a, uj) = t.iter().zip(da.iter().zip(&du)).fold((a, uj), |(a, u), (t, (d, e))| (a + d * *t, u + e * *t));
                let ket = columns(Kind::EcgGvr, &[(a, uj, ks.1)]);
                bra_engine.between(name, &bra, &ket_engine, &ket, w.as_slice()).unwrap()
            };
            let ket = columns(Kind::EcgGvr, &[(a, uj, ks.1)]);
            let got = bra_engine.between_gradient(name, &bra, &ket_engine, &ket, &dir, w.as_slice()).unwrap();
            assert_eq!(got.len(), (1 + p) * 3);
            let values = between(&vec![0.0; p]);
            assert_eq!(got[..3].iter().map(|x| x.to_bits()).collect::<Vec<_>>(), values.iter().map(|x| x.to_bits()).collect::<Vec<_>>(), "{name}: values");
            let h = 1e-3;
            for k in 0..p {
                let step = |s: f64| between(&(0..p).map(|l| if l == k { s * h } else { 0.0 }).collect::<Vec<_>>());
                let (p1, m1, p2, m2) = (step(1.0), step(-1.0), step(2.0), step(-2.0));
                for i in 0..3 {
                    let want = (8.0 * (p1[i] - m1[i]) - (p2[i] - m2[i])) / (12.0 * h);
                    let d = got[(1 + k) * 3 + i];
                    assert!((d - want).abs() <= 1e-8 * want.abs().max(1e-2), "{name} D={D} K={ks:?} direction {k}, bra {i}: {d} vs {want}");
                }
            }
        }
    }

    #[test]
    fn the_ket_derivatives_match_a_difference_of_the_elements() {
        for bra in [Kind::Pecg, Kind::EcgGvr] {
            for kj in [0, 1] {
                let ki = if bra == Kind::Pecg { 0 } else { 1 };
                derivatives::<2>(bra, (ki, kj), 4, 7 + kj as u64);
                derivatives::<3>(bra, (ki, kj), 5, 11 + kj as u64);
            }
        }
        derivatives::<3>(Kind::EcgGvr, (0, 1), 18, 5); // two chunks of directions
    }

    #[test]
    fn the_velocity_form_matches_a_central_difference_of_the_bra() {
        for ks in [(0, 0), (1, 0), (2, 1)] {
            let pair = Pair::<2>::new((0.6, 1.9), ks);
            let (bra, ket, go) = pair.functions();
            let w = Vector::<2>::new(0.7, -1.1);
            let got = velocity(&bra, &ket, &go, &[w]);
            let h = 1e-2;
            let at = |s: f64| pair.cartesian::<7>(|_| 1.0, s * h, &w);
            let want = (8.0 * (at(1.0) - at(-1.0)) - (at(2.0) - at(-2.0))) / (12.0 * h);
            assert!((got - want).abs() <= 1e-7 * want.abs(), "{ks:?}: {got} vs {want}");
        }
    }

    /// `Σ_c r_c^T M r_c` and `r_z^T M r_z`.
    fn trace_zz<const D: usize>(m: &Mat<D>, r: &[Vector<D>; 3]) -> (f64, f64) {
        (r.iter().map(|rc| rc.dot(&(m * rc))).sum(), r[2].dot(&(m * r[2])))
    }

    impl<const D: usize> Pair<D> {
        /// `√5 ∫ f_0 Q_0 φ_I / (‖f_0‖ ‖φ_I‖)` with the ket's M = 0 component `f_0 = |v|² C_20(v̂) p_J =
        /// (3 v_z² − v²)/2 p_J` and `Q_0 = (3 T_zz − Tr T)/2`, `T = Σ_ij M_ij r_i r_j^T` (Edmonds).
        fn quadrupole<const M: usize>(&self, m: &Mat<D>) -> f64 {
            let ((ai, ui, ki), (aj, uj, kj)) = (self.bra, self.ket);
            let f0 = |r: &[Vector<D>; 3]| {
                let (v2, vz) = (power(&uj, 1, r), uj.dot(&r[2]));
                (3.0 * vz * vz - v2) * 0.5 * power(&uj, kj, r)
            };
            let x = integrate::<D, M>(&(ai + aj), |r| {
                let (tr, zz) = trace_zz(m, r);
                f0(r) * (3.0 * zz - tr) * 0.5 * power(&ui, ki, r)
            });
            let nj = integrate::<D, M>(&(aj * 2.0), |r| f0(r).powi(2));
            let ni = integrate::<D, M>(&(ai * 2.0), |r| power(&ui, ki, r).powi(2));
            5f64.sqrt() * x / (nj * ni).sqrt()
        }
    }

    /// A symmetric `M` of mixed signs (a quadrupole's `Σ_k q_k m_k m_k^T`).
    fn quadrupole_matrix<const D: usize>() -> Mat<D> {
        let m = Mat::<D>::from_fn(|i, j| [0.8, -1.3, 0.4, 2.1, -0.6, 1.7, -0.9, 0.3, 1.1][(3 * i + j) % 9]);
        m + m.transpose()
    }

    #[test]
    fn second_moments_match_quadrature() {
        let pair = Pair::<3>::new((0.9, 2.4), (1, 1));
        let (bra, ket, go) = pair.functions();
        let ((ai, ui, ki), (aj, uj, kj)) = (pair.bra, pair.ket);
        let (m1, m2) = (quadrupole_matrix::<3>(), outer(&uj, &Vector::<3>::new(0.3, -1.0, 0.7)));
        let got = second(&bra, &ket, &go, &m1, &m2);
        let moment = |b: &Mat<3>, g: &dyn Fn(&[Vector<3>; 3]) -> f64| integrate::<3, 5>(b, g);
        let x = moment(&(ai + aj), &|r| power(&ui, ki, r) * power(&uj, kj, r) * trace_zz(&m1, r).0 * trace_zz(&m2, r).0);
        let norms = moment(&(ai * 2.0), &|r| power(&ui, ki, r).powi(2)) * moment(&(aj * 2.0), &|r| power(&uj, kj, r).powi(2));
        let want = x / norms.sqrt();
        assert!((got - want).abs() <= 1e-11 * want.abs(), "{got} vs {want}");
    }

    fn quadrupole_pair<const D: usize>(seeds: (f64, f64), ks: (u32, u32)) {
        let pair = Pair::<D>::new(seeds, ks);
        let (bra, ket, go) = pair.functions();
        let m = quadrupole_matrix::<D>();
        let got = quadrupole(&bra, &ket, &go, &m.column_iter().map(|c| c.into_owned()).collect::<Vec<_>>());
        let want = pair.quadrupole::<5>(&m);
        assert!((got - want).abs() <= 1e-11 * want.abs(), "D={D} {ks:?}: {got} vs {want}");
    }

    #[test]
    fn the_quadrupole_matches_quadrature_for_two_and_three_coordinates() {
        for ks in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            quadrupole_pair::<2>((0.3, 1.7), ks);
        }
        for ks in [(0, 0), (1, 1)] {
            quadrupole_pair::<3>((0.9, 2.4), ks);
        }
    }

    /// `Engine::between`'s quadrupole, a bra of family `kind` and K_I = `ks.0`, two bra functions,
    /// against the quadrature (`G` nodes) of each bra with the ket and its image under `P_12`,
    /// `(1 − P_12)/2`.
    fn symmetrised<const D: usize, const G: usize>(kind: Kind, ks: (u32, u32)) {
        let pairs = [Pair::<D>::new((0.6, 1.9), ks), Pair::<D>::new((1.4, 1.9), ks)];
        let (bra_engine, ket_engine) = engines::<D>(kind, 2);
        let bra = columns(kind, &pairs.iter().map(|p| p.bra).collect::<Vec<_>>());
        let ket = columns(Kind::EcgGvr, &[pairs[0].ket]);
        let m = quadrupole_matrix::<D>();
        let got = bra_engine.between(QUADRUPOLE, &bra, &ket_engine, &ket, m.as_slice()).unwrap();
        let p = swap::<D>();
        for (i, pair) in pairs.iter().enumerate() {
            let (aj, uj, kj) = pair.ket;
            let image = Pair { bra: pair.bra, ket: (p.transpose() * aj * p, p.transpose() * uj, kj) };
            let want = 0.5 * (pair.quadrupole::<G>(&m) - image.quadrupole::<G>(&m));
            assert!((got[i] - want).abs() <= 1e-11 * want.abs(), "D={D} {kind:?} {ks:?} bra {i}: {} vs {want}", got[i]);
        }
    }

    #[test]
    fn the_symmetrised_quadrupole_sums_the_kets_images() {
        for kind in [Kind::Pecg, Kind::EcgGvr] {
            symmetrised::<2, 5>(kind, (0, 1));
            symmetrised::<3, 3>(kind, (0, 0));
        }
        symmetrised::<2, 5>(Kind::EcgGvr, (1, 1));
        let (bra_engine, ket_engine) = engines::<2>(Kind::EcgGvr, 1);
        let one = columns(Kind::EcgGvr, &[Pair::<2>::new((0.6, 1.9), (0, 0)).bra]);
        let err = bra_engine.between(QUADRUPOLE, &one, &ket_engine, &one, &[0.0; 4]).unwrap_err().to_string();
        assert!(err.contains("N = 0 and a ket of N = 1") && err.contains("N = 0 to N = 2"), "{err}");
    }
}
