//! The closed form against the Gauss–Legendre quadrature of `element` (the oracle), hand values,
//! and (ignored) the timing of both per pair.
use super::*;
use crate::ecg::{Mat, Operators};
use crate::families::ecg_gvr::build::coulomb_partials;
use crate::quadrature::even_rule;
use crate::test_support::Rng;

const D: usize = 3;

fn context(n_ang: u32, k_max: u32) -> GvrOps<D> {
    GvrOps::new(Operators { lambda: Mat::<D>::identity(), pairs: vec![], cm_mass: None }, n_ang, k_max).unwrap()
}

/// Inputs of a valid covariance structure: `x = |p|²`, `y = |q|²`, `z = p·q`, `γ_I = p·e`,
/// `γ_J = q·e` for a unit vector `e` (then `x', y' ≥ 0` and `x'y' ≥ z'²`).
fn inputs(rng: &mut Rng) -> [f64; 5] {
    let dot = |a: &[f64; 3], b: &[f64; 3]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let mut vector = || [rng.signed(), rng.signed(), rng.signed()];
    let (p, q, e) = (vector(), vector(), vector());
    let e = e.map(|c| c / dot(&e, &e).sqrt());
    [dot(&p, &p), dot(&q, &q), dot(&p, &q), dot(&p, &e), dot(&q, &e)]
}

/// The value of `coulomb_partials` (the quadrature) for each input.
fn quadrature(go: &GvrOps<D>, ki: u32, kj: u32, inputs: &[[f64; 5]]) -> Vec<f64> {
    let mut out = vec![(0.0, [0.0; 5]); inputs.len()];
    coulomb_partials(go, ki, kj, inputs, &mut out);
    out.into_iter().map(|(f, _)| f).collect()
}

#[test]
fn closed_form_matches_the_quadrature_up_to_k_40() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for n in 0..=2 {
        let go = context(n, 40);
        let mut worst: f64 = 0.0;
        for ki in 0..=40 {
            for kj in 0..=40 {
                let xs: Vec<_> = (0..4).map(|_| inputs(&mut rng)).collect();
                let mut got = vec![0.0; xs.len()];
                coulomb_values(&go, ki, kj, &xs, &mut got);
                for (g, q) in got.iter().zip(quadrature(&go, ki, kj, &xs)) {
                    worst = worst.max((g - q).abs() / q.abs());
                }
            }
        }
        println!("N = {n}: max |closed − quadrature| / |quadrature| = {worst:.2e} (K_I, K_J <= 40)");
        assert!(worst < 5e-14, "N = {n}: {worst:.2e}");
    }
}

#[test]
fn closed_form_matches_the_quadrature_beyond_the_stack_buffer() {
    let mut rng = Rng(11);
    for n in 0..=2 {
        let go = context(n, 100);
        for (ki, kj) in [(60, 60), (100, 0), (0, 100), (47, 55), (60, 40)] {
            assert!((ki + kj + n) as usize + 3 > STACK);
            let xs: Vec<_> = (0..4).map(|_| inputs(&mut rng)).collect();
            let mut got = vec![0.0; xs.len()];
            coulomb_values(&go, ki, kj, &xs, &mut got);
            for (g, q) in got.iter().zip(quadrature(&go, ki, kj, &xs)) {
                assert!((g - q).abs() < 5e-14 * q.abs(), "K = ({ki}, {kj}), N = {n}: {g} vs {q}");
            }
        }
    }
}

#[test]
fn closed_form_matches_hand_values() {
    let go = context(0, 2);
    let x = [2.0, 3.0, 0.5, 0.8, -0.6];
    // K = N = 0: Ω = 1
    assert_eq!(ClosedForm::new(&go, 0, 0).integral(x), 1.0);
    // (1, 0, 0): ∫ (x − τ²γ_I²)/x dτ = 1 − γ_I²/(3x)
    let want = 1.0 - 0.64 / 6.0;
    assert!((ClosedForm::new(&go, 1, 0).integral(x) - want).abs() < 1e-15);
    // (1, 1, 0): Ω = xy + (2/3) z², divided by xy; ∫ over τ of the three quadratics in τ²
    let [xx, yy, zz, gi, gj] = x;
    let (a, b, c) = (gi * gi, gj * gj, gi * gj);
    let integral = xx * yy - (xx * b + yy * a) / 3.0 + a * b / 5.0 + (zz * zz - 2.0 * zz * c / 3.0 + c * c / 5.0) * 2.0 / 3.0;
    assert!((ClosedForm::new(&go, 1, 1).integral(x) - integral / (xx * yy)).abs() < 1e-15);
    // z < 0 with odd N: Ω(x, y, −z) = −Ω(x, y, z) (the sign flip)
    let go1 = context(1, 2);
    let flipped = [2.0, 3.0, -0.5, 0.8, 0.6];
    let (f, g) = (ClosedForm::new(&go1, 2, 1).integral(x), ClosedForm::new(&go1, 2, 1).integral(flipped));
    assert!((f + g).abs() < 1e-15 * f.abs(), "{f} {g}");
}

/// Thread CPU time in nanoseconds (`clock_gettime(CLOCK_THREAD_CPUTIME_ID)`, Linux).
fn cpu_ns() -> f64 {
    #[repr(C)]
    struct Timespec {
        sec: i64,
        nsec: i64,
    }
    extern "C" {
        fn clock_gettime(clock: i32, tp: *mut Timespec) -> i32;
    }
    let mut t = Timespec { sec: 0, nsec: 0 };
    // SAFETY: a valid clock id (3 = CLOCK_THREAD_CPUTIME_ID) and a valid out-pointer
    assert_eq!(unsafe { clock_gettime(3, &mut t) }, 0);
    t.sec as f64 * 1e9 + t.nsec as f64
}

/// Today's `element::quadrature` in `f64` (the element's value path), line for line.
fn quadrature_value(inputs: [f64; 5], rule: &[(f64, f64)], c: &[f64], ki: i32, kj: i32, n: i32) -> f64 {
    let [x, y, z, gam_i, gam_j] = inputs;
    let rt = (x * y).sqrt();
    let mut integral = 0.0;
    for &(tau, weight) in rule {
        let t2 = tau * tau;
        let xt = (x - gam_i * t2 * gam_i).max(0.0);
        let yt = (y - gam_j * t2 * gam_j).max(0.0);
        let zt = z - gam_i * t2 * gam_j;
        let r2 = if xt * yt > 0.0 { (zt * zt / (xt * yt)).min(1.0) } else { 1.0 };
        let g = c.iter().rev().fold(0.0, |acc, ck| acc * r2 + ck);
        integral += (xt / x).powi(ki) * weight * (yt / y).powi(kj) * (zt / rt).powi(n) * g;
    }
    integral
}

/// CPU ns per call of (closed form, value quadrature, `coulomb_partials`) for one pair of K,
/// the minimum over interleaved repeats.
fn time_pair(go: &GvrOps<D>, ki: u32, kj: u32, xs: &[[f64; 5]]) -> [f64; 3] {
    use std::hint::black_box;
    let form = ClosedForm::new(go, ki, kj);
    let rule = even_rule(((ki + kj + go.n_ang) / 2 + 1) as usize);
    let c = series_coefficients(go, ki, kj);
    let mut partials = vec![(0.0, [0.0; 5]); xs.len()];
    let mut best = [f64::INFINITY; 3];
    let per = xs.len() as f64;
    for _ in 0..7 {
        let t0 = cpu_ns();
        for x in xs {
            black_box(form.integral(black_box(*x)));
        }
        let t1 = cpu_ns();
        for x in xs {
            black_box(quadrature_value(black_box(*x), &rule, &c, ki as i32, kj as i32, go.n_ang as i32));
        }
        let t2 = cpu_ns();
        coulomb_partials(go, ki, kj, black_box(xs), &mut partials);
        black_box(&partials);
        let t3 = cpu_ns();
        for (b, t) in best.iter_mut().zip([t1 - t0, t2 - t1, t3 - t2]) {
            *b = b.min(t / per);
        }
    }
    best
}

/// `cargo test --release -p prebo-core coulomb::tests::timing -- --ignored --nocapture`
/// (one thread): ns per call, closed form vs today's quadrature, over the pairs of the H2
/// checkpoint's row of function 100 (K = 19, N = 0) and over K_I = K_J = 0..=40.
#[test]
#[ignore]
fn timing() {
    let mut rng = Rng(7);
    let xs: Vec<_> = (0..256).map(|_| inputs(&mut rng)).collect();
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../benchmarks/checkpoints/h2-cycles/basis.json");
    let text = std::fs::read_to_string(path).unwrap();
    let ks: Vec<u32> =
        text.split("\"K\":").skip(1).map(|s| s.trim_start().split(|c: char| !c.is_ascii_digit()).next().unwrap().parse().unwrap()).collect();
    assert_eq!((ks.len(), ks[100]), (500, 19));
    let go = context(0, 40);
    let mut total = [0.0; 3];
    println!("H2 checkpoint row of function 100: (K_I, K_J) = (19, K), N = 0, ns per call");
    println!("{:>3} {:>5} {:>9} {:>9} {:>9} {:>7}", "K", "count", "closed", "quad", "partials", "q/c");
    let mut kjs = ks.clone();
    kjs.sort_unstable();
    kjs.dedup();
    for kj in kjs {
        let count = ks.iter().enumerate().filter(|&(i, &k)| i != 100 && k == kj).count() as f64;
        let t = time_pair(&go, 19, kj, &xs);
        println!("{kj:>3} {count:>5} {:>9.1} {:>9.1} {:>9.1} {:>7.2}", t[0], t[1], t[2], t[1] / t[0]);
        for (s, ti) in total.iter_mut().zip(t) {
            *s += count * ti;
        }
    }
    println!(
        "row total (499 pairs, one w): closed {:.1} µs, quadrature {:.1} µs, partials {:.1} µs; quadrature/closed = {:.2}",
        total[0] / 1e3,
        total[1] / 1e3,
        total[2] / 1e3,
        total[1] / total[0]
    );
    println!("K_I = K_J = K, N = 0, ns per call");
    for k in 0..=40 {
        let t = time_pair(&go, k, k, &xs);
        println!("{k:>3} {:>9.1} {:>9.1} {:>9.1} {:>7.2}", t[0], t[1], t[2], t[1] / t[0]);
    }
}

