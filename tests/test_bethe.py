"""The Bethe logarithm (level/bethe.py): the integral representation against the pseudostate sum on
small bases, hydrogen's 1s and 2s with the proton's finite mass against Drake & Swainson, the
sum rules and the large-k expansion against hydrogen's closed forms, and bad input."""
import math

import numpy as np
import pytest

import prebo
from prebo.errors import InputError, UnsupportedError
from prebo.level.bethe import bethe_logarithm, reduced_rydberg

from test_transitions import hydrogen

#: ln k₀ of hydrogen in the reduced Rydberg μ/2 (G. W. F. Drake and R. A. Swainson, Phys. Rev. A 41,
#: 1243 (1990), the digits as tabulated by its users, e.g. 2.984128555765498 and 2.811769893120563)
DRAKE_SWAINSON = {0: 2.984128556, 1: 2.811769893}


def even(lo: float, hi: float, ratio: float) -> np.ndarray:
    """Even-tempered exponents lo·ratio^k up to hi (bohr⁻², of the relative coordinate)."""
    return lo * ratio ** np.arange(int(math.log(hi / lo) / math.log(ratio)) + 1)


#: 1s and 2s to ~1e-12 Eh with the cusp resolved to 1e10 bohr⁻² (56 functions); their first-order
#: functions to 1e9 bohr⁻² (67)
GROUND, RESPONSE = even(0.002, 1e10, 1.7), even(0.002, 1e9, 1.5)

MU = float(np.prod(prebo.System(["p", "e"]).masses) / prebo.System(["p", "e"]).m_total)


@pytest.fixture(scope="module")
def wide():
    """The even-tempered bases: ln k₀ of 1s and 2s, with f, g and the expansion tabulated for 1s."""
    ground, response = hydrogen(0, GROUND), hydrogen(1, RESPONSE)
    R = reduced_rydberg(ground.system)
    k = np.geomspace(1e3, 1e6, 7)
    return {root: bethe_logarithm(ground, response, root=root, rydberg=R, K=1e5, k=k if root == 0 else None)
            for root in (0, 1)}


@pytest.mark.parametrize("root", [0, 1])
def test_the_integral_representation_is_the_pseudostate_sum_on_a_small_basis(root):
    # integrated to ∞ with the basis's own asymptotics the two are one number; 2s in a ground basis
    # too tight for it, whose 2p pseudostate lies 2e-3 Eh below it: the sum counts it with ln|ΔE|,
    # the integral adds its term (6e-6 of ln k₀) and keeps its pole off the path
    ground, response = hydrogen(0, even(0.03, 300.0, 2.5)), hydrogen(1, even(0.01, 500.0, 2.2))
    r = bethe_logarithm(ground, response, root=root, k=[0.1, 1.0, 10.0], K=100.0)
    assert abs(r["own"] - r["pseudostate"]) < 1e-8
    if root == 0:  # f(k), minus Hylleraas' minimum in the basis's matrices, against g: k f(k) = A − g(k)
        for x in r["spectrum"]:
            assert x["k"] * x["f"] == pytest.approx(r["J2_response"] - x["g"], rel=1e-10)
    if root == 1:
        (below,) = r["lower"]
        share = below["s"] * below["de"] * math.log(-below["de"] / r["rydberg"]) / r["D_response"]
        assert below["de"] < -1e-3 and abs(share) > 1e-6
    else:
        assert r["lower"] == []


@pytest.mark.parametrize("root", [0, 1])
def test_hydrogen_1s_and_2s_match_drake_and_swainson(wide, root):
    # the reduced Rydberg makes ln k₀ mass-independent; the basis's own sum misses the high-k tail
    r = wide[root]
    assert abs(r["ln_k0"] - DRAKE_SWAINSON[root]) < 1e-6
    assert abs(r["pseudostate"] - DRAKE_SWAINSON[root]) > 1e-4
    assert abs(r["own"] - r["pseudostate"]) < 1e-8
    assert r["integral"]["quadrature"] + r["integral"]["tail"] == pytest.approx(r["ln_k0"], abs=1e-12)
    assert abs(r["integral"]["fit"]["share"]) < 1e-4 < r["integral"]["tail"]


@pytest.mark.parametrize("root", [0, 1])
def test_the_sum_rules_are_hydrogens(wide, root):
    # D = −2π Σ q_a q_b (w'_a − w'_b)² ⟨δ³⟩ = 2μ/n³ with Drachmann's ⟨δ³⟩ = μ³/(πn³); ⟨J'²⟩ = 1/n²
    n, r = root + 1, wide[root]
    assert r["regularised"]
    assert r["D"] == pytest.approx(2 * MU / n**3, rel=1e-8)
    assert r["delta"]["e-p"] == pytest.approx(MU**3 / math.pi / n**3, rel=1e-8)
    # ⟨J'²⟩ = 2T/μ errs as the level's kinetic energy: by the virial theorem, with E exact to 1e-12,
    # δT/T = 2η (the basis's virial coefficient; 2s: 7e-10 or less, as the machine's rounding leaves it)
    eta = prebo.evaluate(hydrogen(0, GROUND), roots=2)["levels"][root]["virial"]
    assert r["J2"] == pytest.approx(1 / n**2, rel=3 * eta + 1e-12)
    assert r["J2_response"] == pytest.approx(r["J2"], rel=1e-7)  # the N = 1 basis holds J'ψ₀
    assert r["C"] == pytest.approx(4 * math.sqrt(2) * MU**1.5 / n**3, rel=1e-8)
    assert r["log"]["e-p"] == pytest.approx(4 * MU**2 / n**3, rel=1e-8)


def test_the_large_k_expansion_is_what_the_basis_computes(wide):
    # k^(3/2) (D/k − g) → C once the ln k/k² term is added; the slope of k²[g − D/k + C k^(−3/2)]
    # against ln k → λ = 4μ²: both derived pair by pair, here measured against hydrogen
    r = wide[0]
    rows = r["spectrum"]
    k = np.array([x["k"] for x in rows])
    g = np.array([x["g"] for x in rows])
    D, C, lam = r["D"], r["C"], r["log"]["e-p"]
    c = k**1.5 * (D / k - g) + lam * np.log(k / MU) / k**0.5
    assert abs(c[-1] / C - 1) < 1e-3 and abs(c[-1] - C) < abs(c[0] - C)
    y = k**2 * (g - D / k + C * k**-1.5)
    slope = np.diff(y) / np.diff(np.log(k))
    assert abs(slope[4] / lam - 1) < 1e-2  # between k = 1e5 and 3e5: −7e-3, the k^(−5/2) term's
    assert np.all(np.abs(np.array([x["asymptotic"] for x in rows[-3:]]) / g[-3:] - 1) < 1e-4)


def test_a_convergence_table_follows_the_response_bases():
    ground = hydrogen(0, even(0.002, 1e8, 1.7))
    responses = [hydrogen(1, even(0.002, hi, 1.7)) for hi in (1e4, 1e6, 1e8)]
    r = bethe_logarithm(ground, responses, rydberg=reduced_rydberg(ground.system))
    rows = r["convergence"]
    assert [row["n_basis"] for row in rows] == [len(b) for b in responses]
    assert rows[0]["pseudostate"] < rows[1]["pseudostate"] < rows[2]["pseudostate"] < DRAKE_SWAINSON[0]
    assert r["ln_k0"] == rows[-1]["ln_k0"] and r["pseudostate"] == rows[-1]["pseudostate"]
    errors = [abs(row["ln_k0"] - DRAKE_SWAINSON[0]) for row in rows]
    assert errors[2] < errors[1] < errors[0]


def test_the_unit_converts_by_its_logarithm():
    ground, response = hydrogen(0, even(0.01, 300.0, 2.5)), hydrogen(1, even(0.02, 500.0, 2.2))
    a = bethe_logarithm(ground, response, K=100.0)
    b = bethe_logarithm(ground, response, rydberg=reduced_rydberg(ground.system), K=100.0)
    assert a["rydberg"] == 0.5
    assert b["pseudostate"] == pytest.approx(a["pseudostate"] - math.log(MU), abs=1e-12)
    assert b["ln_k0"] - a["ln_k0"] == pytest.approx(-math.log(MU), abs=1e-9)


def helium(state, count: int = 3) -> prebo.Basis:
    """A few sampled functions of He in `state` (plain ECGs for N = 0, ECG-GVR for N = 1)."""
    from prebo.optimise import Optimiser, Sampler

    system = prebo.System(["alpha", "e", "e"], state)
    kind = "pecg" if state.N == 0 else "ecg-gvr"
    opts = Optimiser(kind=kind, K_max=state.N, channels="all", length_range=(0.3, 3.0), seed=5)
    sampler = Sampler(system, opts, np.random.default_rng(5))
    fs = [sampler.fresh() for _ in range(count)]
    for f in fs[1:]:
        fs[0].append(f)
    return fs[0]


def test_bad_input_is_refused_in_one_line():
    ground, response = hydrogen(0, even(0.01, 300.0, 2.5)), hydrogen(1, even(0.02, 500.0, 2.2))
    with pytest.raises(InputError, match="not a bound level"):
        bethe_logarithm(hydrogen(0, [1e4]), response)
    with pytest.raises(InputError, match="N = 0"):
        bethe_logarithm(ground, ground)
    singlet, triplet = helium(prebo.State(N=0, spin={"e": 0})), helium(prebo.State(N=1, parity=-1, spin={"e": 1}))
    with pytest.raises(InputError, match="cannot hold.*spin"):
        bethe_logarithm(singlet, triplet)
    with pytest.raises(InputError, match="different particles"):
        bethe_logarithm(ground, hydrogen(1, even(0.02, 500.0, 2.2), nucleus="d"))
    with pytest.raises(UnsupportedError, match="N = 1"):
        bethe_logarithm(response, response)
    for k in ([], [float("nan")], [0.0], [[1.0]]):
        with pytest.raises(InputError, match="photon energies"):
            bethe_logarithm(ground, response, k=k)
    for K in (float("inf"), 0.0, -1.0):
        with pytest.raises(InputError, match="K ="):
            bethe_logarithm(ground, response, K=K)
    with pytest.raises(InputError, match="at least one"):
        bethe_logarithm(ground, [])
