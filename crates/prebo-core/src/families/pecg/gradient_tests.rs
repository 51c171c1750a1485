//! The hand-derived row gradient against the dual-number path (the oracle), finite differences,
//! and the same bits on every instruction set.
use super::*;
use crate::cache::Cache;
use crate::families::pecg::kernel::tests::{gaussian, operators};
use crate::test_support::Rng;
use crate::families::pecg::{diagonal, Pecg};
use crate::families::Family;
use crate::params::{Directions, Exponents};
use crate::isa::best_isa;
use crate::path;

/// Identity, (D > 1) a swap of coordinates 0 and 1, and (D > 2) a cyclic shift, with Young-like coefficients.
fn symmetry<const D: usize>() -> Vec<(Mat<D>, f64)> {
    let perm = |p: &dyn Fn(usize) -> usize| Mat::<D>::from_fn(|i, j| if p(i) == j { 1.0 } else { 0.0 });
    let mut sym = vec![(Mat::<D>::identity(), 1.0)];
    if D > 1 {
        sym.push((perm(&|i| [1, 0].get(i).copied().unwrap_or(i)), -0.5));
    }
    if D > 2 {
        sym.push((perm(&|i| (i + 1) % D), 0.25));
    }
    sym
}

/// A random symmetric direction.
fn direction<const D: usize>(rng: &mut Rng) -> Mat<D> {
    let x = Mat::<D>::from_fn(|_, _| rng.signed());
    x + x.transpose()
}

struct Case<const D: usize> {
    ops: Operators<D>,
    sym: Vec<(Mat<D>, f64)>,
    trial: Gaussian<D>,
    basis: Vec<Gaussian<D>>,
    da: Vec<Mat<D>>,
}

impl<const D: usize> Case<D> {
    fn new(seed: u64, lab: bool, nb: usize, n_dir: usize) -> Self {
        let mut rng = Rng(seed);
        let ops = operators::<D>(&mut rng, lab);
        Self {
            sym: symmetry::<D>(),
            trial: gaussian::<D>(&mut rng, 1.0),
            basis: (0..nb).map(|k| gaussian::<D>(&mut rng, 0.5 + k as f64 * 0.3)).collect(),
            da: (0..n_dir).map(|_| direction::<D>(&mut rng)).collect(),
            ops,
        }
    }

    fn images(&self) -> Images<Gaussian<D>> {
        Images::new(self.basis.clone(), &self.sym, &()).unwrap()
    }

    /// `(1 + P) x nb` rows and the diagonal from the family (this kernel) and from the dual path.
    fn both(&self) -> ((Matrices, Vec<Element>), (Matrices, Vec<Element>)) {
        let flat = |g: &[&Gaussian<D>]| {
            g.iter()
                .flat_map(|g| g.a.transpose().iter().copied().collect::<Vec<_>>())
                .collect::<Vec<_>>()
        };
        let (ta, tc) = (flat(&[&self.trial]), vec![self.trial.c_a]);
        let (ba, bc) = (
            flat(&self.basis.iter().collect::<Vec<_>>()),
            self.basis.iter().map(|g| g.c_a).collect::<Vec<_>>(),
        );
        let da: Vec<f64> = self
            .da
            .iter()
            .flat_map(|d| d.transpose().iter().copied().collect::<Vec<_>>())
            .collect();
        let trial = Exponents { a: &ta, c_a: &tc };
        let basis = Exponents { a: &ba, c_a: &bc };
        let dir = Directions { a: &da, v: &[] };
        let ctx = <Pecg as Family<D>>::context(self.ops.clone(), 0, &[]).unwrap();
        (
            <Pecg as Family<D>>::row_gradient(&ctx, &self.sym, &trial, &dir, &basis, &Cache::default()).unwrap(),
            path::row_gradient::<D, Pecg>(&ctx, &self.sym, &trial, &dir, &basis, &Cache::default()).unwrap(),
        )
    }

    /// Per basis function `j`, the scales `Σ_P |c_P| sqrt(|X_II X_JJ|)` of S, T, T_TI and V
    /// (V with every charge positive, so that no cancellation hides an error).
    fn scales(&self) -> Vec<[f64; 4]> {
        let ti = self.diagonal_scale();
        self.basis
            .iter()
            .map(|g| {
                let tj = self.diagonal_scale_of(g);
                std::array::from_fn(|x| (ti[x] * tj[x]).sqrt())
            })
            .collect()
    }

    /// The scale of the trial's diagonal, `Σ_P |c_P| |X_II|`.
    fn diagonal_scale(&self) -> [f64; 4] {
        self.diagonal_scale_of(&self.trial)
    }

    /// `Σ_P |c_P| |X_gg|` of S, T, T_TI and V (V with every charge positive).
    fn diagonal_scale_of(&self, g: &Gaussian<D>) -> [f64; 4] {
        let mut positive = self.ops.clone();
        positive.pairs.iter_mut().for_each(|(_, q)| *q = q.abs());
        let (e, v) = (kernel::element(g, g, &self.ops), kernel::element(g, g, &positive));
        let c = self.sym.iter().map(|(_, c)| c.abs()).sum::<f64>();
        [e.s, e.t, e.t_ti, v.v].map(|x| c * x.abs())
    }

    /// The diagonals `d` and `r` agree: the value to 1e-13 and direction `p` to 1e-12 × `step(p)`
    /// of `diagonal_scale`.
    fn same_diagonal(&self, d: &[Element], r: &[Element]) {
        assert_eq!(d.len(), r.len());
        let scale = self.diagonal_scale();
        for (row, (x, y)) in d.iter().zip(r).enumerate() {
            let tol = if row == 0 { 1e-13 } else { 1e-12 * self.step(row - 1) };
            for (k, (a, b)) in [(x.s, y.s), (x.t, y.t), (x.t_ti, y.t_ti), (x.v, y.v)].into_iter().enumerate() {
                assert!((a - b).abs() <= tol * scale[k], "D {D} diagonal row {row} part {k}: {a} vs {b}");
            }
        }
    }

    /// `‖A_I^{-1} dA_p‖_F`: the relative size of the step along direction `p`.
    fn step(&self, p: usize) -> f64 {
        (self.trial.a.try_inverse().unwrap() * self.da[p]).norm()
    }
}

fn parts(m: &Matrices, r: usize, j: usize) -> [f64; 4] {
    let k = r * m.cols + j;
    [m.s[k], m.t[k], m.t_ti[k], m.v[k]]
}

/// Every value within `1e-13` and every derivative within `1e-12 ‖A_I^{-1} dA_p‖_F` of the
/// scale `Σ_P |c_P| sqrt(|X_II X_JJ|)` of the dual path; the diagonal the dual path's own.
fn against_dual<const D: usize>() {
    for (seed, lab) in [(11, true), (12, false), (13, true), (14, false)] {
        let case = Case::<D>::new(seed ^ (D as u64) << 8, lab, 11, 7);
        let ((m, diag), (r, diag_r)) = case.both();
        case.same_diagonal(&diag, &diag_r);
        assert_eq!((m.rows, m.cols), (r.rows, r.cols));
        let scales = case.scales();
        for (j, scale) in scales.iter().enumerate() {
            for row in 0..m.rows {
                let tol = if row == 0 { 1e-13 } else { 1e-12 * case.step(row - 1) };
                let (x, y) = (parts(&m, row, j), parts(&r, row, j));
                for k in 0..4 {
                    assert!(
                        (x[k] - y[k]).abs() <= tol * scale[k],
                        "D {D} lab {lab} row {row} j {j} part {k}: {} vs {} (scale {})",
                        x[k],
                        y[k],
                        scale[k]
                    );
                }
            }
        }
    }
}

#[test]
fn row_gradient_matches_the_dual_path() {
    against_dual::<1>();
    against_dual::<2>();
    against_dual::<3>();
    against_dual::<4>();
    against_dual::<5>();
}

/// Central differences of the row along each direction agree with the derivatives.
fn against_finite_differences<const D: usize>() {
    for lab in [true, false] {
        let case = Case::<D>::new(21 ^ D as u64, lab, 6, 3);
        let basis = Kets::new(&case.images(), best_isa());
        let m = row_gradient(&case.trial, &case.da, &basis, &case.ops);
        let scales = case.scales();
        for (p, d) in case.da.iter().enumerate() {
            let h = 1e-5 / d.norm();
            let moved = |x: f64| {
                let g = Gaussian::new(case.trial.a + d * x, case.trial.c_a, 0).unwrap();
                row_gradient(&g, &[], &basis, &case.ops)
            };
            let (up, down) = (moved(h), moved(-h));
            for (j, scale) in scales.iter().enumerate() {
                let (u, w, g) = (parts(&up, 0, j), parts(&down, 0, j), parts(&m, 1 + p, j));
                for k in 0..4 {
                    let fd = (u[k] - w[k]) / (2.0 * h);
                    assert!(
                        (fd - g[k]).abs() <= 1e-6 * case.step(p) * scale[k],
                        "D {D} lab {lab} p {p} j {j} part {k}: {fd} vs {}",
                        g[k]
                    );
                }
            }
        }
    }
}

#[test]
fn row_gradient_matches_finite_differences() {
    against_finite_differences::<2>();
    against_finite_differences::<3>();
    against_finite_differences::<4>();
}

/// AVX-512, AVX2 and plain code (where the CPU has them) give the same bits.
fn same_bits<const D: usize>() {
    let case = Case::<D>::new(31 ^ D as u64, true, 13, 5);
    let basis = case.images();
    let run = |isa| row_gradient(&case.trial, &case.da, &Kets::new(&basis, isa), &case.ops);
    let plain = run(Isa::Plain);
    for isa in [Isa::Avx2, Isa::Avx512] {
        let m = run(isa);
        for (x, y) in [
            (&m.s, &plain.s),
            (&m.t, &plain.t),
            (&m.t_ti, &plain.t_ti),
            (&m.v, &plain.v),
        ] {
            assert!(
                x.iter().zip(y).all(|(a, b)| a.to_bits() == b.to_bits()),
                "D {D} {isa:?}"
            );
        }
    }
}

#[test]
fn every_instruction_set_gives_the_same_bits() {
    same_bits::<2>();
    same_bits::<3>();
    same_bits::<4>();
    same_bits::<5>();
}

/// The trial's diagonal from the bra-side kernel (`kernel::diagonal`) against the dual path, for
/// operators that commute with the operations: H2-like (two pairs of identical particles, the
/// four operations of (1 − P₀₁)(1 + P₂₃)) and three identical particles with the cyclic
/// shifts (P⁻¹ ≠ P, unequal coefficients); and none for operators that do not commute.
#[test]
fn the_diagonal_from_the_kernel_matches_the_dual_path() {
    fn check<const D: usize>(sym: Vec<(Mat<D>, f64)>, masses: [f64; D], charges: [f64; D], seed: u64) {
        let mut rng = Rng(seed);
        let lambda = Mat::<D>::from_fn(|i, j| if i == j { 0.5 / masses[i] } else { 0.0 });
        let mut pairs = Vec::new();
        for i in 0..D {
            for j in (i + 1)..D {
                let mut w = crate::ecg::Vector::<D>::zeros();
                w[i] = 1.0;
                w[j] = -1.0;
                pairs.push((w, charges[i] * charges[j]));
            }
        }
        let ops = Operators { lambda, pairs, cm_mass: Some(masses.iter().sum()) };
        let mut case = Case::<D>::new(seed, true, 1, 5);
        case.ops = ops.clone();
        case.sym = sym;
        case.trial = gaussian::<D>(&mut rng, 1.0);
        let diag = diagonal(&case.trial, &case.da, &case.sym, &ops).unwrap().expect("commuting operations");
        let ((_, _), (_, dual)) = case.both();
        case.same_diagonal(&diag, &dual);
        let mut other = ops.clone();
        other.lambda[(0, 0)] *= 1.5; // particle 0 no longer identical to the one it is exchanged with
        assert!(diagonal(&case.trial, &case.da, &case.sym, &other).unwrap().is_none());
    }
    let perm = |p: [usize; 4]| Mat::<4>::from_fn(|i, j| if p[i] == j { 1.0 } else { 0.0 });
    let h2 = vec![(perm([0, 1, 2, 3]), 1.0), (perm([1, 0, 2, 3]), -1.0), (perm([0, 1, 3, 2]), 1.0), (perm([1, 0, 3, 2]), -1.0)];
    check::<4>(h2, [1836.15, 1836.15, 1.0, 1.0], [1.0, 1.0, -1.0, -1.0], 41);
    let perm = |p: [usize; 3]| Mat::<3>::from_fn(|i, j| if p[i] == j { 1.0 } else { 0.0 });
    let cyclic = vec![(perm([0, 1, 2]), 1.0), (perm([1, 2, 0]), -0.5), (perm([2, 0, 1]), 0.25)];
    check::<3>(cyclic, [1.0, 1.0, 1.0], [-1.0, -1.0, -1.0], 42);
}
