//! The hand-derived row gradient against the dual-number path (`path::row_gradient`, the
//! oracle) and against central differences of the row.
//!
//! Scales: a value of output X is compared to `1e-12 · Σ_P|c_P| · √(|X_II X_JJ|)` (unsymmetrised
//! diagonals); a derivative along `(dA, du)` to the same scale times the direction's size
//! `‖A_I⁻¹‖‖dA‖ + (2K_I + N + 1)‖du‖/‖u_I‖` (the relative change of φ_I per unit step).
use super::*;
use crate::ecg::Operators;
use crate::families::ecg_gvr::element::element;
use crate::families::ecg_gvr::EcgGvr;
use crate::families::Family;
use crate::params::Exponents;
use crate::path;
use crate::test_support::Rng;

fn spd<const D: usize>(rng: &mut Rng, scale: f64) -> Mat<D> {
    let l = Mat::<D>::from_fn(|i, j| if j <= i { rng.signed() * scale } else { 0.0 });
    l * l.transpose() + Mat::<D>::identity() * 0.05
}

/// Symmetric Λ, every pair `e_i − e_j` and one dense `w`, positive charges; `cm_mass` or none.
fn operators<const D: usize>(rng: &mut Rng, cm: bool) -> Operators<D> {
    let b = Mat::<D>::from_fn(|_, _| rng.signed());
    let mut pairs = Vec::new();
    for i in 0..D {
        for j in i + 1..D {
            let w = Vector::<D>::from_fn(|k, _| f64::from(k == i) - f64::from(k == j));
            pairs.push((w, 0.5 + 1.5 * rng.next()));
        }
    }
    pairs.push((Vector::<D>::from_fn(|_, _| rng.signed()), 0.5 + rng.next()));
    Operators { lambda: b * b.transpose() * 0.1 + Mat::<D>::identity() * 0.01, pairs, cm_mass: cm.then_some(3.5) }
}

/// Flat parameters of `ks.len()` random functions (c_U = 1ᵀu ≠ 0).
struct Flat {
    a: Vec<f64>,
    c_a: Vec<f64>,
    v: Vec<f64>,
    k: Vec<u32>,
}

impl Flat {
    fn random<const D: usize>(rng: &mut Rng, ks: &[u32]) -> Self {
        let mut f = Flat { a: vec![], c_a: vec![], v: vec![], k: ks.to_vec() };
        for _ in ks {
            let spread = 0.3 + rng.next();
            let a = spd::<D>(rng, spread);
            f.a.extend(a.transpose().iter());
            f.c_a.push(0.2 + rng.next());
            f.v.extend((0..D).map(|_| rng.signed()));
        }
        f
    }

    fn params(&self) -> GvrParams<'_> {
        GvrParams { e: Exponents { a: &self.a, c_a: &self.c_a }, u: &self.v, k: &self.k }
    }

    /// This (one) function moved by `h (dA, du)`.
    fn moved<const D: usize>(&self, h: f64, da: &Mat<D>, du: &Vector<D>) -> Self {
        let a = Mat::<D>::from_row_slice(&self.a) + da * h;
        let u = Vector::<D>::from_row_slice(&self.v) + du * h;
        Flat { a: a.transpose().iter().copied().collect(), c_a: self.c_a.clone(), v: u.iter().copied().collect(), k: self.k.clone() }
    }
}

/// Identity, a coordinate swap and four random invertible maps, with random c_P: a group of
/// `MAX_LANES` images in lanes and two one by one.
fn symmetry<const D: usize>(rng: &mut Rng) -> Vec<(Mat<D>, f64)> {
    let swap = Mat::<D>::from_fn(|i, j| {
        let p = |k: usize| if k < 2 { 1 - k } else { k };
        f64::from(p(i) == j)
    });
    let mut near = || (Mat::<D>::identity() + Mat::<D>::from_fn(|_, _| 0.3 * rng.signed()), 0.5 * rng.signed());
    let maps = [near(), near(), near(), near()];
    let c = rng.signed();
    [(Mat::identity(), 1.0), (swap, c)].into_iter().chain(maps).collect()
}

/// Directions: symmetric dA (as the parametrisation's `dA = dL Lᵀ + L dLᵀ`; the dual path reads
/// `A` through its Cholesky factor, i.e. its lower triangle), du alone, and both.
fn directions<const D: usize>(rng: &mut Rng) -> (Vec<f64>, Vec<f64>) {
    let sym = |rng: &mut Rng| {
        let m = Mat::<D>::from_fn(|_, _| rng.signed());
        (m + m.transpose()) * 0.5
    };
    let vec = |rng: &mut Rng| Vector::<D>::from_fn(|_, _| rng.signed());
    let dirs = [
        (sym(rng), Vector::<D>::zeros()),
        (Mat::<D>::zeros(), vec(rng)),
        (sym(rng), vec(rng)),
        (sym(rng) * 3.0, vec(rng) * 0.1),
    ];
    let a = dirs.iter().flat_map(|(a, _)| a.transpose().iter().copied().collect::<Vec<_>>()).collect();
    let u = dirs.iter().flat_map(|(_, u)| u.iter().copied().collect::<Vec<_>>()).collect();
    (a, u)
}

fn outputs(e: &Element) -> [f64; 4] {
    [e.s, e.t, e.t_ti, e.v]
}

fn get(m: &Matrices, i: usize, j: usize) -> [f64; 4] {
    let k = i * m.cols + j;
    [m.s[k], m.t[k], m.t_ti[k], m.v[k]]
}

/// `√(|X_II X_JJ|) Σ|c_P|` for every output, and the directions' sizes.
fn scales<const D: usize>(go: &GvrOps<D>, sym: &[(Mat<D>, f64)], trial: &Flat, basis: &Flat, dir: &(Vec<f64>, Vec<f64>)) -> (Vec<[f64; 4]>, Vec<f64>) {
    let bra = <EcgGvr as Family<D>>::functions(&trial.params(), go).unwrap().remove(0);
    let kets = <EcgGvr as Family<D>>::functions(&basis.params(), go).unwrap();
    let c_sum: f64 = sym.iter().map(|(_, c)| c.abs()).sum();
    let ii = outputs(&element(&bra, &bra, go));
    let per_ket = kets
        .iter()
        .map(|f| {
            let jj = outputs(&element(f, f, go));
            std::array::from_fn(|o| (ii[o] * jj[o]).abs().sqrt() * c_sum)
        })
        .collect();
    let ainv = bra.a.try_inverse().unwrap().norm();
    let kn = (2 * bra.k + go.n_ang + 1) as f64;
    let size = dir
        .0
        .chunks(D * D)
        .zip(dir.1.chunks(D))
        .map(|(a, u)| ainv * Mat::<D>::from_row_slice(a).norm() + kn * Vector::<D>::from_row_slice(u).norm() / bra.u.norm())
        .collect();
    (per_ket, size)
}

fn against_dual_path<const D: usize>() {
    let mut rng = Rng(0x5eed_0f_9a3d ^ D as u64);
    for n_ang in 0..=2 {
        for cm in [false, true] {
            let ops = operators::<D>(&mut rng, cm);
            let go = GvrOps::new(ops, n_ang, 40).unwrap();
            let sym = symmetry::<D>(&mut rng);
            let k_trial = [0, 40, rng.natural(40)][n_ang as usize];
            let trial = Flat::random::<D>(&mut rng, &[k_trial]);
            let ks: Vec<u32> = [0, 1, 40].into_iter().chain((0..4).map(|_| rng.natural(40))).collect();
            let basis = Flat::random::<D>(&mut rng, &ks);
            let dir = directions::<D>(&mut rng);
            let d = Directions { a: &dir.0, v: &dir.1 };
            let (got, got_diag) = <EcgGvr as Family<D>>::row_gradient(&go, &sym, &trial.params(), &d, &basis.params(), &Cache::default()).unwrap();
            let (want, want_diag) = path::row_gradient::<D, EcgGvr>(&go, &sym, &trial.params(), &d, &basis.params(), &Cache::default()).unwrap();
            assert_eq!(got_diag, want_diag);
            assert_eq!((got.rows, got.cols), (want.rows, want.cols));
            let (scale, size) = scales(&go, &sym, &trial, &basis, &dir);
            for j in 0..ks.len() {
                for i in 0..got.rows {
                    let (g, w) = (get(&got, i, j), get(&want, i, j));
                    for o in 0..4 {
                        let tol = 1e-12 * scale[j][o] * if i == 0 { 1.0 } else { size[i - 1] };
                        assert!(
                            (g[o] - w[o]).abs() <= tol,
                            "D={D} N={n_ang} cm={cm} K=({},{}) row {i} output {o}: {} vs {} (tol {tol:e})",
                            trial.k[0], ks[j], g[o], w[o]
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn matches_the_dual_path_d2() {
    against_dual_path::<2>();
}

#[test]
fn matches_the_dual_path_d3() {
    against_dual_path::<3>();
}

#[test]
fn matches_the_dual_path_d4() {
    against_dual_path::<4>();
}

/// Central differences of the row (`rows`, the trial as bra: placed before the basis) along each direction: error `O(h²)` from the third
/// derivative plus `O(ε/h)` rounding, about 1e-9 of the scale at `h = 1e-5`; tolerance 1e-7.
#[test]
fn matches_central_differences() {
    const D: usize = 3;
    let mut rng = Rng(0xfd_c0de);
    let go = GvrOps::new(operators::<D>(&mut rng, true), 1, 12).unwrap();
    let sym = symmetry::<D>(&mut rng);
    let trial = Flat::random::<D>(&mut rng, &[5]);
    let basis = Flat::random::<D>(&mut rng, &[0, 3, 12]);
    let dir = directions::<D>(&mut rng);
    let d = Directions { a: &dir.0, v: &dir.1 };
    let (got, _) = <EcgGvr as Family<D>>::row_gradient(&go, &sym, &trial.params(), &d, &basis.params(), &Cache::default()).unwrap();
    let (scale, size) = scales(&go, &sym, &trial, &basis, &dir);
    let h = 1e-5;
    for p in 0..size.len() {
        let da = Mat::<D>::from_row_slice(&dir.0[p * D * D..(p + 1) * D * D]);
        let du = Vector::<D>::from_row_slice(&dir.1[p * D..(p + 1) * D]);
        let row = |s: f64| <EcgGvr as Family<D>>::rows(&go, &sym, &trial.moved(s * h, &da, &du).params(), &basis.params(), Some(0), &Cache::default()).unwrap().0;
        let (plus, minus) = (row(1.0), row(-1.0));
        for j in 0..3 {
            let (fp, fm, g) = (get(&plus, 0, j), get(&minus, 0, j), get(&got, 1 + p, j));
            for o in 0..4 {
                let fd = (fp[o] - fm[o]) / (2.0 * h);
                let tol = 1e-7 * scale[j][o] * size[p];
                assert!((fd - g[o]).abs() <= tol, "direction {p} ket {j} output {o}: {} vs {fd}", g[o]);
            }
        }
    }
}

/// The lanes of `symmetrised` (`MAX_LANES` images at once) have the bits of the images one by
/// one, also where one image's `A_I + A_J` is not positive definite (NaN for that image alone).
#[test]
fn images_in_lanes_have_the_bits_of_one_by_one() {
    const D: usize = 3;
    let mut rng = Rng(17);
    let go = GvrOps::new(operators::<D>(&mut rng, true), 1, 40).unwrap();
    let sym = symmetry::<D>(&mut rng);
    let k = rng.natural(40);
    let trial = Flat::random::<D>(&mut rng, &[k]);
    let basis = Flat::random::<D>(&mut rng, &[0, 7, 40]);
    let bra = &Side::new(&go, &sym, &trial.params()).unwrap().functions[0];
    let side = Side::new(&go, &sym, &basis.params()).unwrap();
    let lambda = matrix(|i, j| go.ops.lambda[(i, j)]);
    let bits = |(o, g): &([f64; 4], [Grad<D>; 4])| -> Vec<u64> {
        o.iter().chain(g.iter().flat_map(|g| g.a.iter().chain(g.u.iter()))).map(|v| v.to_bits()).collect()
    };
    let check = |kets: &[Prepared<D>], ser: &Series| {
        let lanes = symmetrised::<D, 4>(bra, kets, &side.coef, ser, &lambda, &go);
        let (mut o, mut g) = ([0.0; 4], [Grad::<D>::zero(); 4]);
        for (ket, c) in kets.iter().zip(&side.coef) {
            let (ok, gk) = symmetrised::<D, 4>(bra, std::slice::from_ref(ket), &[*c], ser, &lambda, &go);
            for t in 0..4 {
                o[t] += ok[t];
                g[t].a += gk[t].a;
                g[t].u += gk[t].u;
            }
        }
        assert_eq!(bits(&lanes), bits(&(o, g)));
        lanes
    };
    for (f, kets) in side.functions.iter().zip(&side.images) {
        let lanes = check(kets, &Series::new(&go, bra.k, f.k));
        assert!(bits(&lanes).into_iter().all(|b| f64::from_bits(b).is_finite()));
    }
    let mut kets = side.images[1].clone();
    kets[2].a = std::array::from_fn(|i| std::array::from_fn(|j| -2.0 * bra.a[i][j]));
    let ser = Series::new(&go, bra.k, side.functions[1].k);
    let each: Vec<_> = kets.iter().map(|k| symmetrised::<D, 4>(bra, std::slice::from_ref(k), &[1.0], &ser, &lambda, &go).0[0]).collect();
    assert!(each[2].is_nan() && each.iter().enumerate().all(|(i, s)| i == 2 || s.is_finite()));
    check(&kets, &ser);
}
