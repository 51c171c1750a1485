//! Vector operators between a basis of N = L and one of N = L + 1, for every L ≥ 0: the electric
//! dipole in length form, `d = Σ_k w_k r_k` with `w_k = q_k − Q m_k/m_tot` (the charges' dipole
//! about the centre of mass; `Q`, `m_tot` the total charge and mass), and in velocity form,
//! `Σ_k w'_k ∇_k` with `w'_k = q_k/m_k − Q/m_tot`; both vectors in the representation's coordinates
//! (`w` like the Coulomb vectors, `w'` like a momentum). Their elements are reduced ones
//! (Wigner–Eckart, Edmonds' convention `<N' M'|O_q|N M> = (−1)^{N'−M'} (N' 1 N; −M' q M) <N'‖O‖N>`),
//! one per pair of a function of N = L (bra, `φ_I`) and one of N = L + 1 (ket, `φ'_J`), each
//! normalised. With `e = (1, i, 0)`, `v_+ = e·v` and `O_{+1} = −e·O/√2`, the stretched element
//! (M = N on both sides) and `(L+1 1 L; −L−1 1 L) = (2L+3)^{−1/2}` give
//!
//! ```text
//!     <L+1‖O‖L>_IJ = ((2L+3)/2)^{1/2} <φ̂'_J| e·O |φ̂_I>,
//! ```
//!
//! the overall sign, like an eigenvector's, a convention (dropped). Both functions are read as
//! functions of N = L + 1 (the context is the ket's, `registry::context_n`). For the bra
//! `φ_I = |v_I|^{2K} v_{I+}^L exp(−r^T A_I r)`, `v_I = u_I^T r`, and `d_+ = e·d = (w^T r)_+`,
//!
//! ```text
//!     v_{I+}^L d_+ = ∂_t (v_I + t d)_+^{L+1} / (L+1),   v_I + t d = (u_I + t w)^T r,
//!     |v_I|^{2K} = |v_I + t d|^{2K} − 2K t |v_I|^{2K−2} (v_I·d) + O(t²),
//! ```
//!
//! so `(L+1) d_+ φ_I = ∂_t χ_t − 2K (v_I·d) ψ_I` at t = 0, `χ_t` the function of N = L + 1, power K
//! and global vector `u_I + t w` (a dual number in t), `ψ_I` that of power K − 1 and `u_I`: the
//! t-derivative of an overlap, and a quadratic form `r^T (sym(u_I w^T) ⊗ I_3) r`, `−∂/∂α` of the
//! overlap of `ψ_I exp(−α r^T (sym(u_I w^T) ⊗ I_3) r)` at α = 0 (`quadratic`). Their norms relative
//! to `φ_I`'s are moments of the Gaussian vector `v_I` of component variance `x_I = u_I^T A_I^{-1} u_I / 4`
//! (`E|v|^{2p} = (2x)^p Γ(p+3/2)/Γ(3/2)`, and `sin^{2q}θ` averages to `2^q q!/(2q+1)!!`):
//!
//! ```text
//!     ‖χ_0‖²/‖φ_I‖² = 4 x_I (2K + L + 3/2)(L + 1)/(2L + 3),   ‖ψ_I‖²/‖φ_I‖² = (L + 1)/((2L + 3) x_I (2K + L + 1/2)).
//! ```
//!
//! A bra of N = 0 and K = 0 (every plain ECG) has no `v_I`: `d_+ φ_I` is itself the function of
//! N = 1 and global vector `w`, of norm `(2 x_w)^{1/2} ‖φ_I‖` (no derivative, nothing read of the
//! bra's `u`). For the velocity form `e·∇_k v_{I+}^L = L u_{Ik} (e·e) v_{I+}^{L−1} = 0`, so only the
//! gradients of the Gaussian and of `|v_I|^{2K}` remain:
//!
//! ```text
//!     e·∇_w' φ_I = −2 ((A_I w')^T r)_+ φ_I + 2K (w'·u_I) ψ_I,
//! ```
//!
//! the length form's with `w → A_I w'`, and an overlap.
//!
//! For exact states `<f‖∇_w'‖i> = −(E_f − E_i) <f‖d‖i>` (`[H, d] = −∇_w'`); the ratio of the two
//! forms is the usual convergence diagnostic.
//!
//! The acceleration form, `∇_w' V` with `V = Σ_{a<b} q_a q_b / r_ab` the context's Coulomb
//! potential, between a basis of N = 0 and one of N = 1 alone: for exact states
//! `<f‖∇_w' V‖i> = (E_f − E_i)² <f‖d‖i>` (`[H, [H, d]] = −[V, ∇_w'] = ∇_w' V`). It is read at the
//! bra's N = 0, the ket `φ'_J = v_{J+} p_J` as its partner `p_J = |v_J|^{2K_J} exp(−r^T A_J r)`,
//! `v_J = u_J^T r`: `p_J φ_I` is invariant under rotations and reflections, so
//! `∫ (v_J)_a O_b p_J φ_I = δ_ab ∫ v_J·O p_J φ_I / 3`, and with `‖φ'_J‖² = (2/3) <p_J|v_J²|p_J>`
//! the element above is `<1‖O‖0>_IJ = <p̂_J| v_J·O |φ̂_I> / <p̂_J| v_J² |p̂_J>^{1/2}`. Integrated by
//! parts (the force's singularities are integrable), with `∇_w'·v_J = 3 (w'·u_J)` and
//! `v_J·∇_w' p_J = (2 K_J (w'·u_J) − 2 (u_J^T r)·((A_J w')^T r)) p_J`,
//!
//! ```text
//!     <p_J| v_J·∇_w' V |φ_I> = −(3 + 2K_J)(w'·u_J) <p_J|V|φ_I> + 2 <p_J| (u_J^T r)·(((A_I + A_J) w')^T r) V |φ_I>
//!                              − 2 K_I (w'·u_I) <p_J| (v_J·v_I) V |v_I|^{2K_I−2} e^{−r^T A_I r}>,
//! ```
//!
//! each quadratic form with `V` inside `−∂/∂α` at α = 0 of the Coulomb element of the damped pair
//! (`damped`), the last against the bra's function of power `K_I − 1` and N = 0, whose norm is
//! `x_I √((4K_I+1)(4K_I−1))` times smaller.
//!
//! Derivatives along the ket's parameters (`Form`, `path::between_gradient`; docs/transitions.md):
//! the ket of dual numbers carries them through its normalisation, and each t-derivative and
//! quadratic form, a derivative itself, through hyper-dual numbers (`Damping`).
//!
//! The electric quadrupole about the centre of mass, `Q_2q = Σ_k q_k |ρ_k|² C_2q(ρ̂_k)`,
//! `ρ_k = r_k − R_CM = m_k^T r` (`m_k = e_k − m/m_tot`), between a basis of N = 0 and one of N = 2,
//! read at the bra's N = 0: the ket `φ'_J = v_+² p_J` as its partner of N = 0,
//! `p_J = |v|^{2K} exp(−r^T A_J r)`, `v = u_J^T r` (a plain ECG is K = N = 0). Its
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
//! `D + 2` overlaps per pair. Length form only (`quadrupole`, joining N = 0 to N = 2, `registry::joins`).
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

/// A scalar with one derivative more, along the damping α of `quadratic`'s overlap or the shift t
/// of `raised`'s global vector: `f64` →
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

/// `f` over the scalar of one derivative more (`Damping`), none of it along α (or t).
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

/// `u^T A^{-1} u / 4`: the variance of each Cartesian component of `u^T r` under `exp(−2 r^T A r)`.
fn variance<const D: usize>(a: &Mat<D>, u: &Vector<D>) -> f64 {
    u.dot(&a.cholesky().expect("a checked exponent").solve(u)) * 0.25
}

/// `ψ_I`, the bra's function of power K − 1 at the context's N = L + 1, and `‖ψ_I‖/‖φ_I‖` (module
/// docs) for the bra's variance `x`; `bra.k > 0`.
fn lowered<const D: usize>(bra: &GvrFunction<D>, go: &GvrOps<D>, x: f64) -> (GvrFunction<D>, f64) {
    let (n, k) = (go.n_ang as f64, bra.k as f64);
    let lower = GvrFunction::new(bra.a, bra.u, bra.k - 1, bra.c_a, go, 0).expect("K − 1 of a checked function");
    (lower, (n / ((2.0 * n + 1.0) * x * (2.0 * k + n - 0.5))).sqrt())
}

/// `(L+1) <φ̂'_J| (w^T r)_+ φ_I> / ‖φ_I‖` of the bra `φ_I` of N = L (of variance `x`) and the ket of
/// N = L + 1, the context's: `∂_t` of the overlap with `χ_t` less `2K` times the quadratic form
/// against `ψ_I`, each with its norm relative to `φ_I`'s (module docs); for a bra of N = K = 0
/// the overlap with the function of global vector `w`.
fn raised<const D: usize, T: Damping>(bra: &GvrFunction<D>, ket: &GvrFunction<D, T>, go: &GvrOps<D>, w: &Vector<D>, x: f64) -> T {
    let (n, k) = (go.n_ang as f64, bra.k as f64);
    if bra.k == 0 && go.n_ang == 1 {
        let x_w = variance(&bra.a, w);
        if x_w == 0.0 {
            return T::zero(); // w = 0 (a system of no dipole)
        }
        let g = GvrFunction::new(bra.a, *w, 0, bra.c_a, go, 0).expect("a checked exponent and w ≠ 0");
        return <EcgGvr as Family<D>>::overlap(&g.cast(), ket, go) * (2.0 * x_w).sqrt();
    }
    let t = T::alpha();
    let mut moved = lift(&bra.cast::<T>());
    moved.u += w.map(|c| t * c);
    moved.c_u = moved.u.sum();
    let ratio = (4.0 * x * (2.0 * k + n + 0.5) * n / (2.0 * n + 1.0)).sqrt();
    let mut e = T::slope(&<EcgGvr as Family<D>>::overlap(&moved, &lift(ket), go)) * ratio;
    if bra.k > 0 {
        let (lower, ratio) = lowered(bra, go, x);
        e -= quadratic(&lower.cast(), ket, go, &outer(&bra.u, w).map(re)) * (2.0 * k * ratio);
    }
    e
}

/// `<L+1‖d‖L>_IJ`, `v = [w]` (module docs); `bra` of N = L, `ket` of N = L + 1, the context's N
/// (of dual numbers for the derivatives along its parameters, `between_gradient`).
pub fn dipole<const D: usize, T: Damping>(bra: &GvrFunction<D>, ket: &GvrFunction<D, T>, go: &GvrOps<D>, v: &[Vector<D>]) -> T {
    let n = go.n_ang as f64;
    raised(bra, ket, go, &v[0], variance(&bra.a, &bra.u)) * (((2.0 * n + 1.0) / 2.0).sqrt() / n)
}

/// `<L+1‖∇_w'‖L>_IJ`, `v = [w']` (module docs); `bra` and `ket` as for `dipole`.
pub fn velocity<const D: usize, T: Damping>(bra: &GvrFunction<D>, ket: &GvrFunction<D, T>, go: &GvrOps<D>, v: &[Vector<D>]) -> T {
    let (w, n, x) = (&v[0], go.n_ang as f64, variance(&bra.a, &bra.u));
    let mut e = raised(bra, ket, go, &(bra.a * w), x) * (-2.0 / n);
    if bra.k > 0 {
        let (lower, ratio) = lowered(bra, go, x);
        e += <EcgGvr as Family<D>>::overlap(&lower.cast(), ket, go) * (2.0 * bra.k as f64 * w.dot(&bra.u) * ratio);
    }
    e * ((2.0 * n + 1.0) / 2.0).sqrt()
}

/// `<p̂_J| v_J² |p̂_J>^{1/2}` of the ket's partner of N = 0.
fn norm<const D: usize>(ket: &GvrFunction<D>, go: &GvrOps<D>) -> f64 {
    quadratic(ket, ket, go, &outer(&ket.u, &ket.u)).sqrt()
}

/// The bra's function of power `K_I − 1` and the ratio of its norm to the bra's, both of N = 0,
/// `1/(x_I √((4K_I+1)(4K_I−1)))` (module docs); `bra.k > 0`.
fn lowered_partner<const D: usize>(bra: &GvrFunction<D>, go: &GvrOps<D>) -> (GvrFunction<D>, f64) {
    let k = bra.k as f64;
    let lower = GvrFunction::new(bra.a, bra.u, bra.k - 1, bra.c_a, go, 0).expect("K − 1 of a checked function");
    let x = variance(&bra.a, &bra.u);
    (lower, 1.0 / (x * ((4.0 * k + 1.0) * (4.0 * k - 1.0)).sqrt()))
}

/// `<1‖∇_w' V‖0>_IJ`, `v = [w']`, `V` the context's Coulomb potential (module docs); `bra` of
/// N = 0, `ket` the partner of N = 1's function.
pub fn acceleration<const D: usize>(bra: &GvrFunction<D>, ket: &GvrFunction<D>, go: &GvrOps<D>, v: &[Vector<D>]) -> f64 {
    let (w, u) = (&v[0], &ket.u);
    let plain = <EcgGvr as Family<D>>::element(bra, ket, go).v;
    let (_, coupled) = damped(bra, ket, go, &outer(u, &((bra.a + ket.a) * w)));
    let mut e = 2.0 * coupled - plain * ((3 + 2 * ket.k) as f64 * w.dot(u));
    if bra.k > 0 {
        let (lower, ratio) = lowered_partner(bra, go);
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
    //! Against Gauss–Hermite quadrature of the Cartesian elements of `O_z` with the ket's M = L
    //! component `v_z v_+^L |v|^{2K} exp(−r^T A_J r)`, not the stretched one the elements are
    //! derived from (`<L+1‖O‖L> = ((2L+3)(L+1))^{1/2} <L+1 L|O_z|L L>`, Edmonds), for two and three
    //! coordinates, L up to 2 and K up to 1: the length form exactly (a polynomial under the
    //! Gaussian weight), the velocity form by a central difference of the bra along `w'` inside the
    //! quadrature.
    use nalgebra::Complex;

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
        // the M^D nodes of one component with their weights, shared by the three
        let nodes: Vec<(Vector<D>, f64)> = (0..M.pow(D as u32))
            .map(|i| {
                let index: [usize; D] = std::array::from_fn(|d| i / M.pow(d as u32) % M);
                (back * Vector::<D>::from_fn(|d, _| rule[index[d]].0), index.iter().map(|&k| rule[k].1).product())
            })
            .collect();
        let mut total = 0.0;
        for (x, wx) in &nodes {
            for (y, wy) in &nodes {
                for (z, wz) in &nodes {
                    total += wx * wy * wz * g(&[*x, *y, *z]);
                }
            }
        }
        total * det.powf(-1.5)
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

        /// The bra and the ket read at N = `n` (the dipole's, the ket's N; the quadrupole's, 0).
        fn functions(&self, n: u32) -> (GvrFunction<D>, GvrFunction<D>, GvrOps<D>) {
            let go = GvrOps::new(Operators { lambda: Mat::<D>::identity() * 0.5, pairs: vec![], cm_mass: None }, n, 2).unwrap();
            let f = |(a, u, k): (Mat<D>, Vector<D>, u32), i| GvrFunction::new(a, u, k, 1.0, &go, i).unwrap();
            (f(self.bra, 0), f(self.ket, 1), go)
        }

        /// The bra `φ_I = |v_I|^{2K_I} v_{I+}^L exp(−r^T A_I r)` of N = L without its Gaussian.
        fn phi(&self, l: u32) -> impl Fn(&[Vector<D>; 3]) -> Complex<f64> {
            let (_, u, k) = self.bra;
            move |r: &[Vector<D>; 3]| Complex::new(u.dot(&r[0]), u.dot(&r[1])).powu(l) * power(&u, k, r)
        }

        /// The ket's M = L component `f = v_{Jz} v_{J+}^L |v_J|^{2K_J} exp(−r^T A_J r)` without its
        /// Gaussian (`−f̂` is `L_−` of the stretched ket, normalised).
        fn f(&self, l: u32) -> impl Fn(&[Vector<D>; 3]) -> Complex<f64> {
            let (_, u, k) = self.ket;
            move |r: &[Vector<D>; 3]| Complex::new(u.dot(&r[0]), u.dot(&r[1])).powu(l) * (u.dot(&r[2]) * power(&u, k, r))
        }

        /// `∫ f^* O_z φ_I(r + s) dr` (`f`, `phi`), `O_z` = `o(r)`, `s = h w' ẑ`.
        fn moment<const M: usize>(&self, l: u32, o: impl Fn(&[Vector<D>; 3]) -> f64, h: f64, w: &Vector<D>) -> f64 {
            let ((ai, ..), (aj, ..)) = (self.bra, self.ket);
            let (phi, f) = (self.phi(l), self.f(l));
            integrate::<D, M>(&(ai + aj), |r| {
                let decay = (-2.0 * h * (ai * w).dot(&r[2]) - h * h * w.dot(&(ai * w))).exp();
                (f(r).conj() * phi(&[r[0], r[1], r[2] + w * h])).re * o(r) * decay
            })
        }

        /// `‖f‖ ‖φ_I‖ / ((2L+3)(L+1))^{1/2}`: `<L+1‖O‖L> = moment / scale`, Edmonds' theorem with
        /// `(L+1 1 L; −L 0 L) = −((2L+3)(L+1))^{−1/2}`.
        fn scale<const M: usize>(&self, l: u32) -> f64 {
            let ((ai, ..), (aj, ..)) = (self.bra, self.ket);
            let (phi, f) = (self.phi(l), self.f(l));
            let norms = integrate::<D, M>(&(aj * 2.0), |r| f(r).norm_sqr()) * integrate::<D, M>(&(ai * 2.0), |r| phi(r).norm_sqr());
            (norms / ((2 * l + 3) * (l + 1)) as f64).sqrt()
        }

        /// The length form's `<L+1‖O‖L>` of `O_z` = `o(r)`.
        fn cartesian<const M: usize>(&self, l: u32, o: impl Fn(&[Vector<D>; 3]) -> f64, w: &Vector<D>) -> f64 {
            self.moment::<M>(l, o, 0.0, w) / self.scale::<M>(l)
        }
    }

    /// `<L+1‖d‖L>` of a pair against `cartesian` with `M` nodes (exact for degree < 2M).
    fn length<const D: usize, const M: usize>(l: u32, seeds: (f64, f64), ks: (u32, u32)) {
        let pair = Pair::<D>::new(seeds, ks);
        let (bra, ket, go) = pair.functions(l + 1);
        let w = Vector::<D>::from_fn(|i, _| [1.0, -2.0, 0.5][i % 3]);
        let got = dipole(&bra, &ket, &go, &[w]);
        let want = pair.cartesian::<M>(l, |r| w.dot(&r[2]), &w);
        assert!((got - want).abs() <= 1e-11 * want.abs(), "D={D} L={l} K={ks:?}: {got} vs {want}");
    }

    #[test]
    fn the_length_form_matches_quadrature_for_two_and_three_coordinates() {
        for ks in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            length::<2, 4>(0, (0.3, 1.7), ks);
            length::<2, 5>(1, (0.3, 1.7), ks);
            length::<2, 6>(2, (0.3, 1.7), ks);
        }
        length::<3, 4>(0, (0.9, 2.4), (1, 1));
        length::<3, 4>(1, (0.9, 2.4), (1, 0));
        length::<3, 4>(2, (0.9, 2.4), (0, 0));
    }

    /// `P_12`: the first two coordinates swapped.
    fn swap<const D: usize>() -> Mat<D> {
        Mat::<D>::from_fn(|i, j| f64::from(match i { 0 => j == 1, 1 => j == 0, _ => i == j }))
    }

    /// Engines of `D` coordinates (no Coulomb pairs): the bra's of family `bra` and N = `ns.0`, the
    /// ket's of ECG-GVR and N = `ns.1` with two images, `(1 − P_12)/2`.
    fn engines<const D: usize>(bra: Kind, ns: (u32, u32)) -> (Engine, Engine) {
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
        let bra = Engine::new(bra, rep(vec![(Mat::<D>::identity(), 1.0)]), ns.0).unwrap();
        let ket = Engine::new(Kind::EcgGvr, rep(vec![(Mat::<D>::identity(), 0.5), (swap, -0.5)]), ns.1).unwrap();
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

    /// `between_gradient` of a one-function ket of N = L + 1 against a bra basis of three functions
    /// of N = L (K_I = `ks.0`, the ket's K_J = `ks.1`) along `p` random directions: row 0 has
    /// `between`'s bits, rows 1.. its derivatives by a fourth-order central difference of
    /// `between` (step 1e-3).
    fn derivatives<const D: usize>(bra_kind: Kind, l: u32, ks: (u32, u32), p: usize, seed: u64) {
        let mut rng = Rng(seed);
        let u = |rng: &mut Rng| Vector::<D>::from_fn(|_, _| rng.signed());
        let bras: Vec<_> = (0..3).map(|i| (exponent::<D>(0.4 + 0.9 * i as f64), u(&mut rng), ks.0)).collect();
        let (a, uj) = (exponent::<D>(2.3) * 0.7, u(&mut rng));
        let da: Vec<Mat<D>> = (0..p).map(|_| Mat::<D>::from_fn(|_, _| rng.signed() * 0.3)).map(|m| m + m.transpose()).collect();
        let du: Vec<Vector<D>> = (0..p).map(|_| u(&mut rng)).collect();
        let (bra_engine, ket_engine) = engines::<D>(bra_kind, (l, l + 1));
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
                    assert!((d - want).abs() <= 1e-8 * want.abs().max(1e-2), "{name} D={D} L={l} K={ks:?} direction {k}, bra {i}: {d} vs {want}");
                }
            }
        }
    }

    #[test]
    fn the_ket_derivatives_match_a_difference_of_the_elements() {
        for bra in [Kind::Pecg, Kind::EcgGvr] {
            for kj in [0, 1] {
                let ki = if bra == Kind::Pecg { 0 } else { 1 };
                derivatives::<2>(bra, 0, (ki, kj), 4, 7 + kj as u64);
                derivatives::<3>(bra, 0, (ki, kj), 5, 11 + kj as u64);
            }
        }
        derivatives::<3>(Kind::EcgGvr, 0, (0, 1), 18, 5); // two chunks of directions
        derivatives::<2>(Kind::EcgGvr, 1, (0, 1), 4, 13);
        derivatives::<3>(Kind::EcgGvr, 1, (1, 0), 5, 17);
        derivatives::<2>(Kind::EcgGvr, 2, (1, 1), 4, 19);
    }

    #[test]
    fn the_velocity_form_matches_a_central_difference_of_the_bra() {
        for (l, ks) in [(0, (0, 0)), (0, (1, 0)), (0, (2, 1)), (1, (0, 1)), (1, (1, 0)), (2, (1, 1))] {
            let pair = Pair::<2>::new((0.6, 1.9), ks);
            let (bra, ket, go) = pair.functions(l + 1);
            let w = Vector::<2>::new(0.7, -1.1);
            let got = velocity(&bra, &ket, &go, &[w]);
            let h = 1e-2;
            let at = |s: f64| pair.moment::<7>(l, |_| 1.0, s * h, &w);
            let want = (8.0 * (at(1.0) - at(-1.0)) - (at(2.0) - at(-2.0))) / (12.0 * h) / pair.scale::<7>(l);
            assert!((got - want).abs() <= 1e-7 * want.abs(), "L={l} K={ks:?}: {got} vs {want}");
        }
    }

    /// `Engine::between`'s dipole between a bra basis of N = L (family `kind`, K_I = `ks.0`, two
    /// functions) and a ket of N = L + 1, against the quadrature (`G` nodes) of each bra with the
    /// ket and its image under `P_12`, `(1 − P_12)/2`.
    fn symmetrised_dipole<const D: usize, const G: usize>(kind: Kind, l: u32, ks: (u32, u32)) {
        let pairs = [Pair::<D>::new((0.6, 1.9), ks), Pair::<D>::new((1.4, 1.9), ks)];
        let (bra_engine, ket_engine) = engines::<D>(kind, (l, l + 1));
        let bra = columns(kind, &pairs.iter().map(|p| p.bra).collect::<Vec<_>>());
        let ket = columns(Kind::EcgGvr, &[pairs[0].ket]);
        let w = Vector::<D>::from_fn(|i, _| [0.8, -1.5, 0.3][i % 3]);
        let got = bra_engine.between(DIPOLE, &bra, &ket_engine, &ket, w.as_slice()).unwrap();
        let p = swap::<D>();
        for (i, pair) in pairs.iter().enumerate() {
            let (aj, uj, kj) = pair.ket;
            let image = Pair { bra: pair.bra, ket: (p.transpose() * aj * p, p.transpose() * uj, kj) };
            let z = |r: &[Vector<D>; 3]| w.dot(&r[2]);
            let want = 0.5 * (pair.cartesian::<G>(l, z, &w) - image.cartesian::<G>(l, z, &w));
            assert!((got[i] - want).abs() <= 1e-11 * want.abs(), "D={D} {kind:?} L={l} {ks:?} bra {i}: {} vs {want}", got[i]);
        }
    }

    #[test]
    fn the_symmetrised_dipole_joins_n_to_n_plus_one() {
        symmetrised_dipole::<2, 4>(Kind::Pecg, 0, (0, 1));
        symmetrised_dipole::<2, 4>(Kind::EcgGvr, 1, (1, 0));
        symmetrised_dipole::<3, 3>(Kind::EcgGvr, 1, (0, 0));
        let one = columns(Kind::EcgGvr, &[Pair::<2>::new((0.6, 1.9), (0, 0)).bra]);
        for (ns, name) in [((1, 1), DIPOLE), ((0, 2), VELOCITY), ((2, 1), DIPOLE)] {
            let (bra, ket) = engines::<2>(Kind::EcgGvr, ns);
            let err = bra.between(name, &one, &ket, &one, &[0.0; 2]).unwrap_err().to_string();
            assert!(err.contains(&format!("N = {} and a ket of N = {}", ns.0, ns.1)) && err.contains("join N = L to N = L + 1"), "{err}");
        }
        let (bra, ket) = engines::<2>(Kind::EcgGvr, (1, 2));
        let err = bra.between(ACCELERATION, &one, &ket, &one, &[0.0; 2]).unwrap_err().to_string();
        assert!(err.contains("N = 1 and a ket of N = 2") && err.contains("join N = 0 to N = 1; derived there alone"), "{err}");
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
        let (bra, ket, go) = pair.functions(0);
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
        let (bra, ket, go) = pair.functions(0);
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
        let (bra_engine, ket_engine) = engines::<D>(kind, (0, 2));
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
        let (bra_engine, ket_engine) = engines::<2>(Kind::EcgGvr, (0, 1));
        let one = columns(Kind::EcgGvr, &[Pair::<2>::new((0.6, 1.9), (0, 0)).bra]);
        let err = bra_engine.between(QUADRUPOLE, &one, &ket_engine, &one, &[0.0; 4]).unwrap_err().to_string();
        assert!(err.contains("N = 0 and a ket of N = 1") && err.contains("N = 0 to N = 2"), "{err}");
    }
}
