//! Properties of the plain-ECG kernel that need no Python: normalisation, hermiticity,
//! and the CM elimination equal to the internal mass matrix M - 1 1^T / (2 m_tot).
use prebo_core::engine::{Engine, Kind, Representation};
use prebo_core::params::Column;
use prebo_core::matrices::Matrices;

const N: usize = 3;
const MASSES: [f64; N] = [1836.15267343, 1.0, 1.0];

/// A = Σ α_ij (e_i - e_j)(e_i - e_j)^T + c_A (m/m_tot)(m/m_tot)^T, row-major.
fn exponent(alpha: [f64; 3], c_a: f64) -> Vec<f64> {
    let mt: f64 = MASSES.iter().sum();
    let mut a = vec![0.0; N * N];
    for (k, (i, j)) in [(0, 1), (0, 2), (1, 2)].into_iter().enumerate() {
        a[i * N + i] += alpha[k];
        a[j * N + j] += alpha[k];
        a[i * N + j] -= alpha[k];
        a[j * N + i] -= alpha[k];
    }
    for i in 0..N {
        for j in 0..N {
            a[i * N + j] += c_a * MASSES[i] * MASSES[j] / (mt * mt);
        }
    }
    a
}

fn basis() -> (Vec<f64>, Vec<f64>) {
    let params = [
        ([1.0, 0.3, 0.1], 0.5),
        ([0.2, 2.0, 0.05], 1.5),
        ([4.0, 0.7, 0.9], 3.0),
    ];
    let a = params
        .iter()
        .flat_map(|(al, c)| exponent(*al, *c))
        .collect();
    (a, params.iter().map(|p| p.1).collect())
}

fn run(lambda: &[f64], cm_mass: Option<f64>) -> Matrices {
    let identity: Vec<f64> = (0..N * N)
        .map(|k| if k % (N + 1) == 0 { 1.0 } else { 0.0 })
        .collect();
    // electrons singlet: 1 + P23
    let p23 = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 0.0];
    let sym_t: Vec<f64> = identity.iter().chain(p23.iter()).copied().collect();
    let pair_w = [1.0, -1.0, 0.0, 1.0, 0.0, -1.0, 0.0, 1.0, -1.0];
    let rep = Representation {
        n: N,
        lambda: lambda.to_vec(),
        pair_w: pair_w.to_vec(),
        pair_q: vec![-1.0, -1.0, 1.0],
        sym_t,
        sym_c: vec![1.0, 1.0],
        cm_mass,
    };
    let (a, c_a) = basis();
    let engine = Engine::new(Kind::Pecg, rep, 0).unwrap();
    engine.matrices(&[Column::Floats(a), Column::Floats(c_a)]).unwrap()
}

fn mass_matrix(internal: bool) -> Vec<f64> {
    let mt: f64 = MASSES.iter().sum();
    let mut l = vec![0.0; N * N];
    for i in 0..N {
        l[i * N + i] = 0.5 / MASSES[i];
        if internal {
            for j in 0..N {
                l[i * N + j] -= 0.5 / mt;
            }
        }
    }
    l
}

#[test]
fn symmetric_and_normalised() {
    let m = run(&mass_matrix(false), Some(MASSES.iter().sum()));
    for i in 0..N {
        for j in 0..N {
            for v in [&m.s, &m.t, &m.t_ti, &m.v] {
                assert!(
                    (v[i * N + j] - v[j * N + i]).abs() <= 1e-14 * v[i * N + j].abs().max(1e-300)
                );
            }
        }
    }
    // un-symmetrised self-overlap is 1, so the symmetrised one is 1 + <phi|P23 phi> in (1, 2]
    for i in 0..N {
        assert!(m.s[i * N + i] > 1.0 && m.s[i * N + i] <= 2.0 + 1e-14);
    }
}

#[test]
fn elimination_equals_internal_mass_matrix() {
    let lab = run(&mass_matrix(false), Some(MASSES.iter().sum()));
    let internal = run(&mass_matrix(true), None);
    for k in 0..N * N {
        assert!((lab.t_ti[k] - internal.t[k]).abs() <= 1e-12 * internal.t[k].abs());
        assert!((lab.t[k] - lab.t_ti[k]).abs() > 1e-8 * lab.t[k].abs());
    }
}

#[test]
fn not_positive_definite_is_an_error() {
    let mut a = exponent([1.0, 0.3, 0.1], 0.5);
    a[0] = -1.0;
    let l = mass_matrix(false);
    let rep = Representation {
        n: N,
        lambda: l,
        pair_w: vec![],
        pair_q: vec![],
        sym_t: vec![1., 0., 0., 0., 1., 0., 0., 0., 1.],
        sym_c: vec![1.0],
        cm_mass: None,
    };
    let engine = Engine::new(Kind::Pecg, rep, 0).unwrap();
    let err = engine.matrices(&[Column::Floats(a), Column::Floats(vec![0.5])]).unwrap_err();
    assert_eq!(
        err,
        prebo_core::CoreError::NotPositiveDefinite { function: 0 }
    );
}
