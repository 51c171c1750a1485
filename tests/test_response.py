"""The response objective (optimise/response.py): Hylleraas' functional of a first-order function,
its updates against a direct solve, and a run of the one driver on it (TOML [response], resume,
bad input)."""
import json
import math
import signal
import subprocess
import sys

import numpy as np
import pytest

from prebo import System, State, evaluate
from prebo.eigen import solve
from prebo.matrices import Matrices
from prebo.optimise import Optimiser, optimise
from prebo.cli.run import response as run_response
from prebo.optimise.response import Hylleraas, Source

from conftest import cli_error, functions, hydrogen_1s, mid_schedule

E0 = -0.5


def pencil(rng, n: int):
    """A random pencil (H, S) whose every level lies above E0, and sources b."""
    X = rng.normal(size=(n, n))
    S = X @ X.T + n * np.eye(n)
    d = 1.0 / np.sqrt(np.diag(S))
    S = S * np.outer(d, d)
    Y = rng.normal(size=(n, n))
    H = (E0 + 0.3) * S + 0.1 * (Y @ Y.T)
    return H, S, rng.normal(size=n)


def direct(H, S, b, shift=E0):
    """J = −bᵀ(H − shift S)⁻¹b by a dense solve."""
    return float(-b @ np.linalg.solve(H - shift * S, b))


@pytest.fixture
def problem():
    return pencil(np.random.default_rng(7), 9)


def test_value_is_the_minimum_of_the_functional(problem):
    H, S, b = problem
    J = Hylleraas(E0).value(solve(H, S, 1e-14), b)
    assert J == pytest.approx(direct(H, S, b), rel=1e-12)
    z = -np.linalg.solve(H - E0 * S, b)
    for trial in (z, z + 1e-3 * np.random.default_rng(1).normal(size=len(z))):  # a minimum: any other ψ₁ is above
        assert trial @ (H - E0 * S) @ trial + 2 * trial @ b >= J - 1e-12


def test_updates_against_a_direct_solve(problem):
    H, S, b = problem
    obj, n = Hylleraas(E0, 0.05), len(b)
    shift = E0 + 0.05
    rest = solve(H[:-3, :-3], S[:-3, :-3], 1e-14)
    E, C = rest.energies, rest.vectors
    # one function (the 7th) added
    k = n - 3
    one = obj.with_added(E, C, H[k, :k], S[k, :k], H[k, k], S[k, k], 1e-10, (b[:k], b[k]))
    assert one == pytest.approx(direct(H[:k + 1, :k + 1], S[:k + 1, :k + 1], b[:k + 1], shift), rel=1e-11)
    # each of the last three added alone
    many = obj.with_added_many(E, C, H[k:, :k], S[k:, :k], np.diag(H)[k:], np.diag(S)[k:], 1e-10, (b[:k], b[k:]))
    for m, j in enumerate(range(k, n)):
        idx = list(range(k)) + [j]
        assert many[m] == pytest.approx(direct(H[np.ix_(idx, idx)], S[np.ix_(idx, idx)], b[idx], shift), rel=1e-11)
    # all three at once
    J, (level,) = obj.with_block(E, C, H[k:, :k], S[k:, :k], H[k:, k:], S[k:, k:], 1e-10, b=(b[:k], b[k:]))
    assert J == pytest.approx(direct(H, S, b, shift), rel=1e-11)
    z = -np.linalg.solve(H - shift * S, b)
    assert np.allclose(np.concatenate([C @ level.a, level.beta]), z, rtol=1e-9, atol=1e-12)
    # each removed from the whole basis
    whole = solve(H, S, 1e-14)
    without = obj.without_each(whole.energies, whole.vectors, b)
    for i in range(n):
        keep = np.arange(n) != i
        assert without[i] == pytest.approx(direct(H[np.ix_(keep, keep)], S[np.ix_(keep, keep)], b[keep], shift),
                                           rel=1e-10)


def test_gradient_of_an_added_function_against_differences(problem):
    """Rows, diagonal and source of the added function moving linearly along two directions:
    the gradient against central differences."""
    H, S, b = problem
    obj, k = Hylleraas(E0), len(b) - 1
    rest = solve(H[:k, :k], S[:k, :k], 1e-14)
    rng = np.random.default_rng(3)
    dh, ds = rng.normal(size=(2, k)) * 0.05, rng.normal(size=(2, k)) * 0.01
    dh_nn, ds_nn, db = rng.normal(size=2) * 0.05, np.array([0.0, 0.0]), rng.normal(size=2)

    def at(t):
        return (H[k, :k] + t @ dh, S[k, :k] + t @ ds, H[k, k] + t @ dh_nn, S[k, k] + t @ ds_nn, b[k] + t @ db)

    h, s, h_nn, s_nn, b_n = at(np.zeros(2))
    J, g = obj.with_added_gradient(rest.energies, rest.vectors, h, s, h_nn, s_nn, dh, ds, dh_nn, ds_nn, 1e-10,
                                   (b[:k], np.concatenate([[b_n], db])))
    assert J == pytest.approx(direct(H, S, b), rel=1e-11)
    for p in range(2):
        e = np.eye(2)[p] * 1e-5
        up, down = (obj.with_added(rest.energies, rest.vectors, *x[:4], 1e-10, (b[:k], x[4])) for x in (at(e), at(-e)))
        assert g[p] == pytest.approx((up - down) / 2e-5, rel=1e-6)


def test_no_minimum_at_or_above_a_pole(problem):
    H, S, b = problem
    eig = solve(H, S, 1e-14)
    above = Hylleraas(float(eig.energies[0]) + 1e-3)
    assert not above.holds(eig) and above.value(eig, b) == math.inf
    assert above.uncertainty(eig, Matrices(S, H, H, 0 * H), b) == math.inf


@pytest.fixture(scope="module")
def hydrogen_ground():
    return hydrogen_1s()


def exact_alpha(system) -> float:
    """9/(2μ³), hydrogen's static polarisability with the reduced mass μ."""
    m = system.masses
    return 4.5 / (m[0] * m[1] / (m[0] + m[1])) ** 3


def test_the_driver_lowers_the_functional_to_the_polarisability(hydrogen_ground):
    """Hydrogen's 1s: a run on J[ψ₁] (growth, sweeps, refinement) gives α = −2J, equal to what the
    fixed-basis polarisability gives on the run's basis, below the exact 9/2 of the ground basis's
    ψ₀ only by what the ground state misses."""
    from prebo.level.response import polarisability

    src = Source.of(hydrogen_ground)
    mu = hydrogen_ground.system.masses[0] / (hydrogen_ground.system.masses[0] + 1)
    assert src.E0 == pytest.approx(-mu / 2, abs=1e-10)
    opts = Optimiser(kind="ecg-gvr", size=10, trials=30, sweeps=1, refine=1, refine_method="powell", seed=3,
                     schedule="fixed")
    basis = optimise(System(["p", "e"], State(N=1, parity=-1)), opts, progress=False, response=src)
    J = basis.convergence["objective"]
    alpha = polarisability(hydrogen_ground, basis)
    assert -2 * J == pytest.approx(alpha["alpha"][0], rel=1e-9)  # two solves of an overlap of condition ~1e8
    assert abs(-2 * J / exact_alpha(hydrogen_ground.system) - 1) < 1e-3


def test_a_response_input_runs_and_a_killed_run_resumes_to_the_same_basis(hydrogen_ground, tmp_path):
    """`prebo run` of a [response] input of four lines and a schedule: result.json's response
    block (α = −2J = the sum over states); the run killed mid-schedule resumes to the functions and
    bits of the whole run."""
    hydrogen_ground.save(tmp_path / "ground.json")
    (tmp_path / "h.toml").write_text('[response]\nground = "ground.json"\n[basis]\nsize = 8\n'
                                     '[optimiser]\nschedule = "fixed"\nrefine_method = "powell"\n')

    def run(*args):
        return subprocess.Popen([sys.executable, "-m", "prebo", "run", *map(str, args), "--quiet"],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)

    whole = run(tmp_path / "h.toml", "--out", tmp_path / "whole")
    assert whole.wait(timeout=300) == 0, whole.stderr.read()
    r = json.loads((tmp_path / "whole" / "result.json").read_text())["response"]
    assert r["alpha"][0] == pytest.approx(-2 * r["objective"], rel=1e-10)
    assert r["alpha"][0] == pytest.approx(r["sum_over_states"][0], rel=1e-8)
    assert abs(r["alpha"][0] / exact_alpha(hydrogen_ground.system) - 1) < 1e-2
    killed = run(tmp_path / "h.toml", "--out", tmp_path / "killed")
    mid_schedule(tmp_path / "killed")
    killed.send_signal(signal.SIGKILL)
    killed.wait()
    assert json.loads((tmp_path / "killed" / "basis.json").read_text())["progress"]["phase"] != "done"
    resumed = run("--resume", tmp_path / "killed")
    assert resumed.wait(timeout=300) == 0, resumed.stderr.read()
    assert functions(tmp_path / "killed") == functions(tmp_path / "whole")
    assert json.loads((tmp_path / "killed" / "result.json").read_text())["response"] == r


@pytest.mark.parametrize("bad, what", [('ground = "missing.json"', "missing.json"),
                                       ('ground = "ground.json"\nroot = -1', "root"),
                                       ('ground = "ground.json"\noperator = "quadrupole"', "operator"),
                                       ('ground = "ground.json"\nomega = "x"', "omega"),
                                       ('operator = "dipole"', "ground"),
                                       ('ground = "ground.json"\n[state]\nN = 1\nparity = 1', "parity"),
                                       ('ground = "ground.json"\n[state]\nN = 2\nparity = 1', "N = 2")])
def test_bad_response_settings_get_one_line(hydrogen_ground, tmp_path, capsys, bad, what):
    hydrogen_ground.save(tmp_path / "ground.json")
    (tmp_path / "bad.toml").write_text(f"[response]\n{bad}\n[basis]\nsize = 4\n")
    err = cli_error(capsys, "run", tmp_path / "bad.toml", "--out", tmp_path / "out", "--quiet")
    assert what in err


@pytest.fixture(scope="module")
def response_expansion(hydrogen_ground):
    """An expansion of six hydrogen p functions (ECG-GVR, N = 1) on J[ψ₁] of the 1s level, driven
    by its source terms."""
    from prebo.integrals import laboratory
    from prebo.optimise.expansion import Expansion
    from prebo.optimise.response import driven

    src = Source.of(hydrogen_ground)
    opts = Optimiser(kind="ecg-gvr", size=6, trials=20, sweeps=0, refine=0, seed=5, schedule="fixed", c_A=1.3)
    basis = optimise(System(["p", "e"], State(N=1, parity=-1)), opts, progress=False, response=src)
    rep = driven(laboratory(basis.system), src)
    return Expansion(basis, rep, opts.threshold, opts.min_norm, opts.max_overlap, Hylleraas(src.E0))


def differences(f, theta, h=1e-5):
    """Central differences of f along each coordinate of θ."""
    return np.array([(f(theta + h * e) - f(theta - h * e)) / (2 * h) for e in np.eye(len(theta))])


def test_refinement_gradients_of_the_functional_against_differences(response_expansion):
    """One function (FunctionEnergy), a group (GroupEnergy) and every function (polish.Joint): the
    exact gradients of J, the source terms' derivatives from the core included, against central
    differences of J over θ."""
    from prebo.optimise.polish import Joint
    from prebo.optimise.refine import FunctionEnergy, GroupEnergy

    ex = response_expansion
    one = FunctionEnergy(ex, 2)
    theta = one.p.theta()
    J, g = one.energy_and_gradient(theta)
    assert J == pytest.approx(ex.energy, rel=1e-10)
    assert np.allclose(g, differences(one.energy, theta), rtol=1e-5, atol=1e-9 * np.abs(g).max())
    group = GroupEnergy(ex, [1, 4])
    theta = group.theta()
    J, g = group.energy_and_gradient(theta)
    assert J == pytest.approx(ex.energy, rel=1e-10)
    assert np.allclose(g, differences(lambda t: group.energy_and_gradient(t)[0], theta), rtol=1e-5,
                       atol=1e-9 * np.abs(g).max())
    joint = Joint(ex)  # a whole rebuild and solve per θ: J carries ~1e-11 of rounding, so a wider step
    J, g = joint(joint.theta0)
    assert J == pytest.approx(ex.energy, rel=1e-10)
    assert np.abs(g - differences(lambda t: joint(t)[0], joint.theta0, 1e-4)).max() < 1e-6 * np.abs(g).max()


def test_a_default_schedule_runs_on_the_functional(hydrogen_ground):
    """The adaptive schedule (growth, sweeps, group refinement and joint steps on exact gradients,
    pruning) lowers J of hydrogen's 1s to α within 1e-6 of 9/(2μ³) in eight functions."""
    src = Source.of(hydrogen_ground)
    basis = optimise(System(["p", "e"], State(N=1, parity=-1)), Optimiser(size=8, budget=60, seed=2),
                     progress=False, response=src)
    assert abs(-2 * basis.convergence["objective"] / exact_alpha(hydrogen_ground.system) - 1) < 1e-6


def test_the_current_drives_the_functional_of_the_bethe_logarithm(hydrogen_ground):
    """operator = "velocity" at ω = −k: the first-order function of the current J' = −i∇_w', whose
    f(k) = ⟨J'(H − E₀ + k)⁻¹J'⟩ = −3J is the Bethe logarithm's integrand (level/bethe.py). Hydrogen's
    1s at k = 0.5 Eh: six optimised functions reach the value of 52 fixed even-tempered ones
    (exponents 7e-4 to 3e8) within 2e-5 (1.4e-5 measured) from below, and result.json's block is
    what the fixed-basis resolvent gives on the run's basis; the refinement's gradients of J with the
    current's source terms match differences."""
    from prebo.level.response import first_order
    from prebo.optimise.refine import FunctionEnergy
    from test_transitions import hydrogen

    k = 0.5
    src = Source.of(hydrogen_ground, "velocity", omega=-k)
    wide = hydrogen(1, 0.002 * 1.7 ** np.arange(-2, 50), c_A=float(hydrogen_ground.c_A[0]))
    want = first_order(hydrogen_ground, wide, operator="velocity").resolvent(-k)["f"][0]
    basis = optimise(System(["p", "e"], State(N=1, parity=-1)), Optimiser(size=6, budget=60, seed=2),
                     progress=False, response=src)
    f = -3 * basis.convergence["objective"]
    assert 0 < 1 - f / want < 2e-5
    block = run_response(basis, src)
    assert block["operator"] == "velocity" and block["f"][0] == pytest.approx(f, rel=1e-12)
    assert block["sum_over_states"][0] == pytest.approx(f, rel=1e-9)

    from prebo.integrals import laboratory
    from prebo.optimise.expansion import Expansion
    from prebo.optimise.response import driven

    opts = Optimiser()
    ex = Expansion(basis, driven(laboratory(basis.system), src), opts.threshold, opts.min_norm, opts.max_overlap,
                   Hylleraas(src.E0, src.omega))
    one = FunctionEnergy(ex, 3)
    assert one.energy(one.p.theta()) == pytest.approx(ex.energy, rel=1e-10)
    theta = one.p.theta() + 0.1 * np.random.default_rng(1).standard_normal(len(one.p.theta()))  # off the minimum
    _, g = one.energy_and_gradient(theta)
    assert np.abs(g).max() > 1e-4
    assert np.allclose(g, differences(one.energy, theta), rtol=1e-5, atol=1e-9 * np.abs(g).max())
