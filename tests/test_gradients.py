"""Exact parameter derivatives (forward-mode dual numbers in the Rust core) against finite
differences, for every basis type; gradient refinement keeps the state exact."""
import numpy as np
import pytest

from prebo import eigen
from prebo.errors import IllConditionedError, InputError
from prebo.integrals import laboratory
from prebo.optimise import Expansion, Optimiser, Sampler
from prebo.optimise.parametrisation import Parametrisation
from prebo.optimise.polish import Joint, polish
from prebo.optimise.refine import FunctionEnergy, GroupEnergy, partners, refine_function, refine_group, regenerate_function
from prebo.system import State, System

P = {"name": "p", "mass": 1836.15267}
CASES = {
    # name: particles, state, basis type, K_max
    "pecg-H2+": ([P, P, "e"], State(N=0, spin={"p": 0}), "pecg", 0),
    "pecg-H2": ([P, P, "e", "e"], State(N=0, spin={"p": 0, "e": 0}), "pecg", 0),
    "gvr-H2+": ([P, P, "e"], State(N=0, spin={"p": 0}), "ecg-gvr", 4),
    "gvr-H2+-N1": ([P, P, "e"], State(N=1, parity=-1, spin={"p": 1}), "ecg-gvr", 3),
    "gvr-H2": ([P, P, "e", "e"], State(N=0, spin={"p": 0, "e": 0}), "ecg-gvr", 3),
    "fecg-H2+": ([P, P, "e"], State(N=0, spin={"p": 0}), "fecg", 0),
    "fecg-Ps-": (["e+", "e", "e"], State(N=0, spin={"e": 0}), "fecg", 0),
}


def setup(case: str, nb: int = 8, seed: int = 3):
    """A random basis of `nb` functions and one more function with general parameters
    (the sampler's diagonal 𝒜 and unit u' perturbed)."""
    particles, state, kind, k_max = CASES[case]
    system = System(particles, state)
    opts = Optimiser(kind=kind, K_max=k_max, channels="all", length_range=(0.2, 4.0), seed=seed)
    sampler = Sampler(system, opts, np.random.default_rng(seed))
    fs = [sampler.fresh() for _ in range(nb + 1)]
    basis = fs[0].subset([0])
    for f in fs[1:-1]:
        basis.append(f)
    p = Parametrisation.of(fs[-1])
    theta = p.theta() + 0.2 * np.random.default_rng(seed).standard_normal(len(p.theta()))
    return system, basis, p, theta


def richardson(f, theta, k, h):
    """Fourth-order central difference of f along θ_k."""
    e = np.zeros_like(theta)
    e[k] = h
    return (8 * (f(theta + e) - f(theta - e)) - (f(theta + 2 * e) - f(theta - 2 * e))) / (12 * h)


@pytest.mark.parametrize("case", CASES)
def test_row_derivatives_match_finite_differences(case):
    system, basis, p, theta = setup(case)
    rep = laboratory(system)
    rows, diag = rep.row_gradient(p.function(theta), *p.directions(theta), basis)

    def values(t):
        r, d = rep.rows(p.function(t), basis)
        return np.concatenate([np.concatenate([r[k][0] for k in ("S", "T", "T_ti", "V")]), d[0]])

    exact = np.concatenate([np.concatenate([rows[k] for k in ("S", "T", "T_ti", "V")], axis=1), diag], axis=1)
    assert np.allclose(exact[0], values(theta), rtol=1e-12, atol=1e-14)
    for k in range(len(theta)):
        fd = richardson(values, theta, k, 1e-4)
        scale = np.max(np.abs(exact[1 + k])) + 1e-3 * np.max(np.abs(exact[0]))
        assert np.max(np.abs(exact[1 + k] - fd)) < 2e-9 * scale, (case, k)


@pytest.mark.parametrize("case", ["gvr-H2", "fecg-Ps-", "pecg-H2"])
def test_energy_gradient_matches_finite_differences(case):
    system, basis, p, theta = setup(case, nb=4)  # few functions: the energy depends strongly on each
    f = p.function(theta)
    basis.append(f)
    st = Expansion(basis, laboratory(system), 1e-13)
    obj = FunctionEnergy(st, len(basis) - 1)
    e, g = obj.energy_and_gradient(theta)
    assert e == pytest.approx(obj.energy(theta), abs=1e-12)
    fd = np.array([richardson(obj.energy, theta, k, 1e-3) for k in range(len(theta))])
    assert np.max(np.abs(g - fd)) < 1e-7 * np.max(np.abs(g)), (g, fd)


@pytest.mark.parametrize("case, size", [("gvr-H2", 2), ("fecg-Ps-", 2), ("pecg-H2", 3), ("gvr-H2+", 3)])
def test_group_energy_and_gradient_match_a_full_solve_and_finite_differences(case, size):
    """A group of functions moved together (refine_group): the block update's energy at the
    group's own θ is the expansion's, and its gradient over every member's θ matches finite
    differences."""
    system, basis, p, theta = setup(case, nb=8)
    basis.append(p.function(theta))
    st = Expansion(basis, laboratory(system), 1e-13)
    idx = [len(basis) - 1] + partners(st, len(basis) - 1, size - 1)
    obj = GroupEnergy(st, idx)
    t0 = obj.theta()
    e, g = obj.energy_and_gradient(t0)
    assert e == pytest.approx(st.energy, rel=1e-12)
    fd = np.array([richardson(lambda t: obj.energy_and_gradient(t)[0], t0, k, 1e-4) for k in range(len(t0))])
    assert np.max(np.abs(g - fd)) < 1e-7 * np.max(np.abs(g)), (g, fd)


def test_independence_from_the_eigen_solution_matches_the_schur_complement_of_the_rest(monkeypatch):
    """Expansion.independence (no solve) equals the smallest eigenvalue of the scaled overlap of
    a group's part orthogonal to the rest, S_ff - S_fB S_BB^-1 S_Bf; a near-duplicate pair below
    min_norm, which the block update's guard refuses, is not refined and costs no solve."""
    system, basis, _, _ = setup("pecg-H2", nb=8)
    p = Parametrisation.of(basis.subset([0]))
    basis.append(p.function(p.theta() + 1e-5 * np.random.default_rng(1).standard_normal(len(p.theta()))))
    st = Expansion(basis, laboratory(system), 1e-14)
    S = st.m.S
    for idx in ([3, 5], [0, len(basis) - 1], [2]):
        rest = np.setdiff1d(np.arange(len(basis)), idx)
        O = S[np.ix_(idx, idx)] - S[np.ix_(idx, rest)] @ np.linalg.solve(S[np.ix_(rest, rest)], S[np.ix_(rest, idx)])
        scale = 1 / np.sqrt(np.diag(S)[idx])
        assert st.independence(idx) == pytest.approx(np.linalg.eigvalsh(O * np.outer(scale, scale))[0], rel=1e-6)
    assert st.independence([0, len(basis) - 1]) < st.min_norm
    solves = []
    monkeypatch.setattr(eigen, "solve", lambda *a, **k: solves.append(1))
    before = st.basis.subset(slice(None))
    assert not refine_group(st, len(basis) - 1, 2, 40) and not solves
    assert all(np.array_equal(a, b) for a, b in zip(before.parameters.values(), st.basis.parameters.values()))


def test_partners_are_the_functions_of_largest_normalised_overlap():
    system, basis, _, _ = setup("gvr-H2+", nb=15)
    st = Expansion(basis, laboratory(system), 1e-13)
    S = st.m.S
    assert partners(st, 3, 2) == [int(j) for j in np.argsort(-np.abs(S[3]) / np.sqrt(S[3, 3] * np.diag(S)))[1:3]]


def test_a_group_as_large_as_the_basis_is_refined_whole():
    """refine_group larger than the basis: every function moves at once against an empty rest."""
    system, basis, _, _ = setup("pecg-H2+", nb=3)
    st = Expansion(basis, laboratory(system), 1e-13)
    before = st.energy
    assert refine_group(st, 0, 6, 40) and st.energy < before
    assert_matrices_exact(st)


@pytest.mark.parametrize("count", [5, 7, 11, 20])
def test_any_number_of_directions_gives_the_same_derivatives(count):
    """count directions — lane widths 5, 8 and 12, and 20 = two passes (16 + 4) — equal the linear
    combinations of the θ derivatives computed at the function's own width (9)."""
    system, basis, p, theta = setup("gvr-H2")
    rep = laboratory(system)
    dA, du = p.directions(theta)
    R = np.random.default_rng(count).standard_normal((count, len(theta)))
    f = p.function(theta)
    rows, diag = rep.row_gradient(f, dA, du, basis)
    rows_r, diag_r = rep.row_gradient(f, np.einsum("rp,pij->rij", R, dA), R @ du, basis)
    for k in rows:
        assert np.allclose(rows_r[k][1:], R @ rows[k][1:], rtol=1e-10, atol=1e-13 * np.abs(rows[k]).max())
        assert np.array_equal(rows_r[k][0], rows[k][0])
    assert np.allclose(diag_r[1:], R @ diag[1:], rtol=1e-10, atol=1e-13)


def assert_matrices_exact(st):
    """The expansion's matrices have the bits of a rebuild and its energy is their eigenvalue."""
    fresh = st.rep.matrices(st.basis)
    for k in fresh:
        assert np.array_equal(fresh[k], getattr(st.m, k)), k
    assert st.energy == eigen.solve(fresh["T_ti"] + fresh["V"], fresh["S"], 1e-13).energies[0]


@pytest.mark.parametrize("refine", [lambda st, i: refine_function(st, i, 40, "gradient"),
                                    lambda st, i: refine_group(st, i, 2, 40)], ids=["one", "pairs"])
def test_gradient_refinement_lowers_the_energy_and_keeps_the_matrices_exact(refine):
    system, basis, p, theta = setup("gvr-H2+", nb=15)
    st = Expansion(basis, laboratory(system), 1e-13)
    before = st.energy
    improved = [refine(st, i) for i in range(4)]
    assert any(improved) and st.energy < before
    assert_matrices_exact(st)


def test_regeneration_keeps_the_better_of_refined_newcomer_and_incumbent():
    """A replacement that refinement cannot bring below the incumbent is undone, and the step is
    then exactly a refinement of the incumbent; a good one is kept. Energies never rise and the
    patched matrices equal a rebuild."""
    system, basis, _, _ = setup("gvr-H2+", nb=15)
    rep = laboratory(system)
    i = 4
    hopeless = basis.subset([i])
    hopeless.A *= 1e-4  # a function ~100 times too diffuse
    regenerated, refined = (Expansion(basis.subset(range(15)), rep, 1e-13) for _ in range(2))
    before = regenerated.energy
    regenerate_function(regenerated, i, hopeless, 5)
    refine_function(refined, i, 5)
    assert regenerated.energy == refined.energy <= before
    assert np.array_equal(regenerated.basis.A, refined.basis.A) and np.array_equal(regenerated.basis.u, refined.basis.u)

    good = basis.subset([i])  # the other way round: the incumbent is hopeless, the newcomer good
    worse = basis.subset(range(15))
    worse.replace(i, hopeless)
    regenerated, refined = (Expansion(worse.subset(range(15)), rep, 1e-13) for _ in range(2))
    regenerate_function(regenerated, i, good, 5)
    refine_function(refined, i, 5)
    assert regenerated.energy < refined.energy
    assert regenerated.basis.K[i] == good.K[0]
    assert_matrices_exact(regenerated)


def test_unknown_refine_method_is_refused():
    with pytest.raises(InputError, match="refine_method"):
        Optimiser(refine_method="newton")


def test_extreme_parameters_are_refused_not_collapsed():
    """An exponent with condition number ~1e16 (reached once by unguarded L-BFGS restarts, where
    lost digits gave E = -8e9 Eh) is refused; implausible elements are caught by their bounds."""
    system, basis, p, theta = setup("gvr-H2+", nb=6)
    extreme = theta.copy()
    extreme[:2] = -13.0
    extreme[2] = 115.0
    with pytest.raises(IllConditionedError):
        p.function(extreme)
    basis.append(p.function(theta))
    st = Expansion(basis, laboratory(system), 1e-13)
    obj = FunctionEnergy(st, len(basis) - 1)
    assert obj.energy(extreme) == obj.worse and obj.energy_and_gradient(extreme)[0] == obj.worse
    rows, diag = st.rep.rows(p.function(theta), basis.subset(range(6)))
    S_b = np.diag(st.m.S)[:6]
    assert st.rep.plausible(rows, diag, S_b)[0]
    for k, bad in [(0, 3.0), (1, -1.0), (2, -1e-3)]:  # S_nn above Σ|c_P| = 2, negative kinetic energies
        d = diag.copy()
        d[0, k] = bad
        assert not st.rep.plausible(rows, d, S_b)[0]
    r = {"S": rows["S"].copy()}
    r["S"][0, 2] = 1.01 * np.sqrt(diag[0, 0] * S_b[2])  # Cauchy–Schwarz
    assert not st.rep.plausible(r, diag, S_b)[0]


def test_the_length_of_the_global_vector_is_irrelevant():
    """u is kept at unit length in its channel (it would otherwise drift along the flat direction)."""
    system, basis, p, theta = setup("gvr-H2", nb=4)
    rep = laboratory(system)
    d = len(theta) - 3
    scaled = theta.copy()
    scaled[d:] *= 1e6
    assert np.allclose(p.function(scaled).u, p.function(theta).u, rtol=1e-14)
    a, b = rep.rows(p.function(theta), basis), rep.rows(p.function(scaled), basis)
    for k in a[0]:
        assert np.allclose(a[0][k], b[0][k], rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("case", ["gvr-H2+", "fecg-H2+", "pecg-H2"])
def test_joint_gradient_matches_finite_differences(case):
    system, basis, p, theta = setup(case, nb=5)
    basis.append(p.function(theta))
    st = Expansion(basis, laboratory(system), 1e-13)
    joint = Joint(st)
    x = joint.theta0 + 0.05 * np.random.default_rng(1).standard_normal(len(joint.theta0))
    e, g = joint(x)
    assert e < joint.worse
    fd = np.array([richardson(lambda t: joint(t)[0], x, k, 1e-4) for k in range(len(x))])
    assert np.max(np.abs(g - fd)) < 1e-7 * np.max(np.abs(g)), (g, fd)


def test_polish_lowers_the_energy_and_leaves_a_consistent_state():
    system, basis, p, theta = setup("gvr-H2+", nb=12)
    st = Expansion(basis, laboratory(system), 1e-13)
    before = st.energy
    assert polish(st, 15) and st.energy < before
    assert_matrices_exact(st)
