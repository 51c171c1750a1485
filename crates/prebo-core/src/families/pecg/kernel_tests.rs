//! The lane kernel against the former implementation, the unrolled copies against the
//! generic loops (bit for bit), and the logarithmic fallback of S.
use super::*;
use crate::ecg::{Mat, Vector};
use crate::test_support::Rng;

/// The former implementation (Cholesky factor and inverse from nalgebra, `exp`/`ln` for `S`).
fn element_reference<const D: usize>(bra: &Gaussian<D>, ket: &Gaussian<D>, ops: &Operators<D>) -> Element {
    let a_ij = bra.a + ket.a;
    let chol = Cholesky::new(a_ij).expect("A_I + A_J of positive-definite A_I, A_J");
    let l = chol.l_dirty();
    let mut log_det_ij = 0.0;
    for k in 0..D {
        log_det_ij += 2.0 * l[(k, k)].ln();
    }
    let s = (1.5 * (D as f64 * LN_2 + 0.5 * (bra.log_det + ket.log_det) - log_det_ij)).exp();
    let b = chol.inverse();
    let x = bra.a * ops.lambda * ket.a;
    let r = b.component_mul(&x.transpose()).sum(); // Tr(B X)
    let t = 6.0 * r * s;
    let t_ti = match ops.cm_mass {
        Some(m_tot) => t - 3.0 * bra.c_a * ket.c_a / ((bra.c_a + ket.c_a) * m_tot) * s,
        None => t,
    };
    let mut v = 0.0;
    for (w, q) in &ops.pairs {
        let c = (w.transpose() * b * w)[(0, 0)];
        v += q * 2.0 / (PI * c).sqrt();
    }
    Element { s, t, t_ti, v: v * s }
}

/// A positive-definite exponent: L L^T + 0.05 I with scaled random L, and c_A.
pub(crate) fn gaussian<const D: usize>(rng: &mut Rng, scale: f64) -> Gaussian<D> {
    let mut l = Mat::<D>::zeros();
    for i in 0..D {
        for j in 0..=i {
            l[(i, j)] = rng.signed() * scale;
        }
    }
    let a = l * l.transpose() + Mat::<D>::identity() * 0.05;
    Gaussian::new(a, 0.3 + 2.0 * rng.next(), 0).unwrap()
}

/// Λ = diag(1/(2 m)) (laboratory) or a symmetric positive matrix (internal coordinates),
/// LFCC-style pairs e_i - e_j with charges, or dense vectors.
pub(crate) fn operators<const D: usize>(rng: &mut Rng, lab: bool) -> Operators<D> {
    let mut lambda = Mat::<D>::zeros();
    let mut pairs = Vec::new();
    if lab {
        for i in 0..D {
            lambda[(i, i)] = 0.5 / (1.0 + 3000.0 * rng.next());
            for j in (i + 1)..D {
                let mut w = Vector::<D>::zeros();
                w[i] = 1.0;
                w[j] = -1.0;
                pairs.push((w, if rng.next() < 0.5 { -1.0 } else { 2.0 }));
            }
        }
    } else {
        let mut b = Mat::<D>::zeros();
        for i in 0..D {
            for j in 0..D {
                b[(i, j)] = rng.signed();
            }
        }
        lambda = b * b.transpose() * 0.1 + Mat::<D>::identity() * 0.01;
        for _ in 0..3 {
            let w = Vector::<D>::from_fn(|_, _| rng.signed());
            pairs.push((w, rng.signed()));
        }
    }
    Operators {
        lambda,
        pairs,
        cm_mass: if lab { Some(5000.0) } else { None },
    }
}

fn close(a: f64, b: f64, scale: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * scale.max(1e-300)
}

fn against_reference<const D: usize>() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15 ^ D as u64);
    for lab in [true, false] {
        let ops = operators::<D>(&mut rng, lab);
        for _ in 0..200 {
            let (x, y) = (gaussian::<D>(&mut rng, 1.0), gaussian::<D>(&mut rng, 2.0));
            let new = element(&x, &y, &ops);
            let old = element_reference(&x, &y, &ops);
            // T and V are compared on the scale of their parts (they can cancel)
            let tscale = (new.t.abs()).max(6.0 * new.s * ops.lambda.norm() * x.a.norm() * y.a.norm());
            let vscale: f64 = new.s * ops.pairs.iter().map(|(_, q)| q.abs()).sum::<f64>() * 10.0;
            assert!(close(new.s, old.s, old.s, 1e-13), "S {new:?} {old:?}");
            assert!(close(new.t, old.t, tscale, 1e-13), "T {new:?} {old:?}");
            assert!(close(new.t_ti, old.t_ti, tscale, 1e-13), "T_TI {new:?} {old:?}");
            assert!(close(new.v, old.v, vscale.max(old.v.abs()), 1e-13), "V {new:?} {old:?}");
        }
    }
}

#[test]
fn kernel_matches_the_former_implementation() {
    against_reference::<1>();
    against_reference::<2>();
    against_reference::<3>();
    against_reference::<4>();
    against_reference::<5>();
    against_reference::<6>();
}

fn unrolled_equals_generic<const D: usize, const W: usize>() {
    let mut rng = Rng(0x1234_5678 + D as u64 * 7 + W as u64);
    for lab in [true, false] {
        let ops = operators::<D>(&mut rng, lab);
        let pre = Prepared::new(&ops);
        for _ in 0..50 {
            let bra = Bra::new(&gaussian::<D>(&mut rng, 1.5), &pre);
            let kets: Vec<Gaussian<D>> = (0..W).map(|_| gaussian::<D>(&mut rng, 1.0)).collect();
            let refs: Vec<&Gaussian<D>> = kets.iter().collect();
            let k = KetLanes::<D, W>::from_gaussians(&refs);
            let cm = cm_terms(&bra, &k, &pre);
            let (mut a, mut b) = (Accumulator::<W>::default(), Accumulator::<W>::default());
            lanes::<D, W>(&bra, &k, &pre, &cm, 0.7, &mut a);
            lanes_generic::<D, W>(&bra, &k, &pre, &cm, 0.7, &mut b);
            for l in 0..W {
                assert_eq!(a.s[l].to_bits(), b.s[l].to_bits());
                assert_eq!(a.t[l].to_bits(), b.t[l].to_bits());
                assert_eq!(a.t_ti[l].to_bits(), b.t_ti[l].to_bits());
                assert_eq!(a.v[l].to_bits(), b.v[l].to_bits());
            }
            // and every lane equals the one-lane kernel (`element`), bit for bit
            let bra_g = Gaussian {
                a: bra_matrix(&bra),
                log_det: bra.log_det,
                c_a: bra.c_a,
            };
            for (l, g) in kets.iter().enumerate() {
                let one = element(&bra_g, g, &ops);
                assert_eq!((0.7 * one.s).to_bits(), a.s[l].to_bits());
                assert_eq!((0.7 * one.t).to_bits(), a.t[l].to_bits());
                assert_eq!((0.7 * one.t_ti).to_bits(), a.t_ti[l].to_bits());
                assert_eq!((0.7 * one.v).to_bits(), a.v[l].to_bits());
            }
        }
    }
}

fn bra_matrix<const D: usize>(b: &Bra<D>) -> Mat<D> {
    Mat::<D>::from_fn(|i, j| b.a[i][j])
}

#[test]
fn unrolled_kernels_equal_the_loops_bit_for_bit() {
    unrolled_equals_generic::<2, 1>();
    unrolled_equals_generic::<2, 8>();
    unrolled_equals_generic::<3, 1>();
    unrolled_equals_generic::<3, 4>();
    unrolled_equals_generic::<3, 8>();
    unrolled_equals_generic::<4, 1>();
    unrolled_equals_generic::<4, 4>();
    unrolled_equals_generic::<4, 8>();
}

#[test]
fn overlap_falls_back_to_logarithms_outside_the_normal_range() {
    // |A_IJ| overflows for D = 8 with entries ~1e50: S still from ln|A|
    let mut rng = Rng(99);
    let ops = operators::<8>(&mut rng, true);
    let x = gaussian::<8>(&mut rng, 1.0);
    let big = Gaussian::new(x.a * 1e50, 1.0, 0).unwrap();
    let e = element(&big, &big, &ops);
    let r = element_reference(&big, &big, &ops);
    assert!(
        close(e.s, 1.0, 1.0, 1e-12) && close(r.s, 1.0, 1.0, 1e-12),
        "{e:?} {r:?}"
    );
    // a tiny overlap (far apart widths) stays finite and matches
    let small = Gaussian::new(x.a * 1e-30, 1.0, 0).unwrap();
    let e = element(&big, &small, &ops);
    let r = element_reference(&big, &small, &ops);
    assert!(close(e.s, r.s, r.s, 1e-10), "{e:?} {r:?}");
}
