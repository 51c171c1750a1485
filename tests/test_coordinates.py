"""Coordinate sets: defining conditions (paper eqs. Uconstraint1-2), closure (eq. 1recasted),
the mass-matrix block structure (eq. 2genconstr) and parameter transformations."""
import numpy as np
import pytest

import prebo
from prebo.coordinates import all_sets, by_name, cm_centred, heavy_particle_centred, jacobi
from prebo.errors import InputError, SeparabilityError

MASSES = {3: np.array([1836.15, 1.0, 1.0]), 4: np.array([1836.15, 1836.15, 1.0, 1.0]),
          5: np.array([7294.3, 1.0, 1.0, 1.0, 206.77])}


@pytest.mark.parametrize("n", sorted(MASSES))
def test_every_set_satisfies_the_defining_conditions(n):
    m = MASSES[n]
    sets = all_sets(m)
    from math import factorial
    assert len(sets) == factorial(n) // 2 + n + 1
    for x in sets:
        x.check(m)
        assert np.allclose(x.U[:-1].sum(axis=1), 0, atol=1e-14)
        assert np.allclose(x.U[-1], m / m.sum(), atol=1e-15)
        assert by_name(m, x.name).name == x.name


@pytest.mark.parametrize("n", sorted(MASSES))
def test_closure_and_mass_matrix_blocks(n):
    """U_y U_x^-1 = blockdiag(𝒰, 1) and U_y M U_x^T = blockdiag(., 1/(2 m_tot))."""
    m = MASSES[n]
    M = np.diag(1 / (2 * m))
    sets = all_sets(m)
    for x, y in zip(sets, sets[::-1]):
        W = y.U @ x.U_inv
        assert np.allclose(W[-1, :-1], 0, atol=1e-12) and np.allclose(W[:-1, -1], 0, atol=1e-12)
        assert W[-1, -1] == pytest.approx(1.0)
        K = y.U @ M @ x.U.T
        assert np.allclose(K[-1, :-1], 0, atol=1e-15) and np.allclose(K[:-1, -1], 0, atol=1e-15)
        assert K[-1, -1] == pytest.approx(1 / (2 * m.sum()), rel=1e-13)


def test_two_particle_mu_is_the_reduced_mass():
    m = np.array([1836.15267343, 1.0])
    mu = jacobi(m).mu(np.diag(1 / (2 * m)))
    assert mu[0, 0] == pytest.approx(0.5 / (m[0] / (1 + m[0])), rel=1e-14)


def test_jacobi_definition():
    """x_i = Σ_{j<=i} m_j r_j / m_{1..i} - r_{i+1} (paper eq. Jac-TICC) for order (2, 0, 1)."""
    m = np.array([2.0, 3.0, 5.0])
    r = np.random.default_rng(0).normal(size=3)
    x = jacobi(m, (2, 0, 1)).U @ r
    assert x[0] == pytest.approx(r[2] - r[0])
    assert x[1] == pytest.approx((m[2] * r[2] + m[0] * r[0]) / (m[2] + m[0]) - r[1])
    assert x[2] == pytest.approx(m @ r / m.sum())


def test_parameters_transform_both_ways():
    m = MASSES[4]
    rng = np.random.default_rng(1)
    for x in all_sets(m):
        L = np.tril(rng.normal(size=(3, 3)))
        A_int = L @ L.T + np.eye(3)
        A_r = x.to_lab(A_int, 0.8)
        assert np.allclose(A_r.sum(axis=1), 0.8 * m / m.sum())  # A 1 = c_A m/m_tot
        back, c = x.from_lab(A_r)
        assert np.allclose(back, A_int, rtol=1e-10) and c == pytest.approx(0.8)
        y = hpc = heavy_particle_centred(m, 0)
        other, c2 = y.from_lab(A_r)  # same function seen in another set: same c_A
        assert c2 == pytest.approx(0.8) and np.all(np.linalg.eigvalsh(other) > 0)
        u_r = rng.normal(size=4)
        u_x = x.transform_vectors_to_x(u_r)
        assert np.allclose(x.U.T @ u_x, u_r)  # u^(r) = U^T u^(x)
    del hpc


def test_non_separable_exponent_is_detected():
    m = MASSES[3]
    x = cm_centred(m)
    A = x.to_lab(np.eye(2), 1.0)
    A[0, 0] += 0.1
    with pytest.raises(SeparabilityError):
        x.from_lab(A)


def test_bad_sets_are_refused():
    m = MASSES[3]
    with pytest.raises(InputError):
        jacobi(m, (0, 0, 1))
    with pytest.raises(InputError):
        by_name(m, "polar:1")
    bad = prebo.CoordinateSet("bad", np.eye(3))
    with pytest.raises(InputError, match="does not sum to zero"):
        bad.check(m)


@pytest.mark.parametrize("call, message", [
    (lambda: jacobi(None), "jacobi: masses = None: must be the masses of two or more particles, positive "
                           "numbers in m_e, finite but for at most one (System.masses)"),
    (lambda: jacobi([float("inf"), 1.0, float("inf")]), "jacobi: masses = [inf, 1.0, inf]: must be"),
    (lambda: jacobi([-float("inf"), 1.0]), "jacobi: masses = [-inf, 1.0]: must be"),
    (lambda: jacobi(prebo.System(["p", "e"])), "jacobi: masses = System("),
    (lambda: jacobi([1.0]), "jacobi: masses = [1.0]: must be the masses of two or more particles"),
    (lambda: jacobi([float("nan"), 1.0]), "jacobi: masses = [nan, 1.0]: must be"),
    (lambda: heavy_particle_centred([1.0, -1.0], 0), "heavy_particle_centred: masses = [1.0, -1.0]: must be"),
    (lambda: cm_centred("pe"), "cm_centred: masses = 'pe': must be"),
    (lambda: all_sets(None), "all_sets: masses = None: must be"),
    (lambda: jacobi(MASSES[3], 5), "Jacobi order 5 is not a permutation of the particles 0..2"),
    (lambda: jacobi(MASSES[3], [0, "1", 2]), "Jacobi order [0, '1', 2] is not a permutation of the particles 0..2"),
    (lambda: jacobi(MASSES[3], [0, 1.0, 2]), "Jacobi order [0, 1.0, 2] is not a permutation"),
    (lambda: heavy_particle_centred(MASSES[3], "a"), "coordinate set hpc:a: centre particle 'a' is not one of 0..2"),
    (lambda: heavy_particle_centred(MASSES[3], 1.0), "coordinate set hpc:1.0: centre particle 1.0 is not one of"),
    (lambda: heavy_particle_centred(MASSES[3], True), "coordinate set hpc:True: centre particle True is not one of"),
    (lambda: cm_centred(MASSES[3], "0"), "coordinate set cmc:0: dropped particle '0' is not one of 0..2"),
    (lambda: all_sets(MASSES[3], ["p", "e"]), "all_sets: labels must be one label per particle (3), or None"),
    (lambda: all_sets(MASSES[3], 5), "all_sets: labels must be one label per particle (3), or None"),
    (lambda: prebo.CoordinateSet("mine", None), "CoordinateSet mine: U = None: must be a square matrix of finite real"),
    (lambda: prebo.CoordinateSet("mine", np.ones(3)), "CoordinateSet mine: U = [1.0, 1.0, 1.0]: must be a square"),
    (lambda: prebo.CoordinateSet(3, np.eye(3)), "CoordinateSet: name = 3: must be a str"),
])
def test_wrong_arguments_name_the_argument(call, message):
    """A new user's calls raised TypeError, IndexError or AttributeError, or built a set of a
    negative or NaN mass or of particle True."""
    with pytest.raises(InputError) as exc:
        call()
    assert message in str(exc.value)


def test_masses_may_be_a_list():
    m = [1.0, 2.0, 3.0]
    assert [x.name for x in all_sets(m)] == [x.name for x in all_sets(np.array(m))]
    assert np.array_equal(jacobi(m, (2, 0, 1)).U, jacobi(np.array(m), (2, 0, 1)).U)


@pytest.mark.parametrize("names, jacobi_orders, centres", [
    (["p", "p", "e"], {(0, 1, 2), (0, 2, 1)}, {0, 2}),
    (["p", "e", "e"], {(0, 1, 2), (1, 2, 0)}, {0, 1}),
    (["a", "b", "c"], {(0, 1, 2), (0, 2, 1), (1, 2, 0)}, {0, 1, 2}),
    (["p", "p", "e", "e"], {(0, 1, 2, 3), (0, 2, 1, 3), (0, 2, 3, 1), (2, 3, 0, 1)}, {0, 2}),
    (["alpha", "e", "e", "e"], {(0, 1, 2, 3), (1, 2, 0, 3), (1, 2, 3, 0)}, {0, 1}),
])
def test_channels_up_to_identical_particles(names, jacobi_orders, centres):
    """One channel per class of sets related by relabelling identical particles (3 and 4 particles)."""
    m = np.arange(1.0, len(names) + 1)
    sets = all_sets(m, names)
    orders = {tuple(int(k) for k in x.name.split(":")[1].split("-")) for x in sets if x.name.startswith("jacobi")}
    hpc = {int(x.name.split(":")[1]) for x in sets if x.name.startswith("hpc")}
    assert orders == jacobi_orders and hpc == centres
    assert [x.name for x in sets if x.name.startswith("cmc")] == [f"cmc:{len(names) - 1}"]
