"""Lines between two bases (prebo.transitions, level/transitions.py): hydrogen with the proton's
finite mass against the closed forms, the elements' coordinate and family independence, the
velocity form against the length form through [H, d], and bad input."""
import numpy as np
import pytest

import prebo
from prebo.coordinates import jacobi
from prebo.errors import InputError, UnsupportedError
from prebo.integrals import laboratory, translationally_invariant
from prebo.level.transitions import ALPHA, AU_TIME, dipole_vectors, transitions

#: even-tempered exponents (bohr⁻²) of the relative coordinate: 1s and 2p to ~1e-11 Eh
EXPONENTS = 0.002 * 1.7 ** np.arange(40)


def hydrogen(N: int, exponents=EXPONENTS, kind=None, c_A=0.7) -> prebo.Basis:
    """p e of N = 0 (plain ECGs) or N = 1 (ECG-GVR, K = 0, u = r_e − r_p), the Gaussians exp(−a r²)
    of the relative coordinate with one CM exponent c_A."""
    system = prebo.System(["p", "e"], N=N, parity=(-1) ** N)
    coords = jacobi(system.masses)
    A = np.array([coords.to_lab(np.array([[a]]), c_A) for a in exponents])
    kind = kind or ("pecg" if N == 0 else "ecg-gvr")
    if kind == "pecg":
        return prebo.Basis(system, A, np.full(len(A), c_A))
    u = np.tile([-1.0, 1.0], (len(A), 1))
    return prebo.Basis(system, A, np.full(len(A), c_A), kind="ecg-gvr", u=u, K=np.zeros(len(A), int))


@pytest.fixture(scope="module")
def lines():
    return transitions(hydrogen(0), hydrogen(1), roots=1)


def test_hydrogen_1s_2p_matches_the_closed_forms_with_the_reduced_mass(lines):
    # R_{10,21} = ∫ R_10 R_21 r³ dr = 2^7 √6 / 3^5 a_0 at infinite mass, lengths scale as 1/μ and
    # energies as μ; d = −(r_e − r_p) about the CM; S = R² (Σ over M and q of the 3j symbols)
    mu = prebo.System(["p", "e"]).masses.prod() / prebo.System(["p", "e"]).m_total
    R = 2 ** 7 * 6 ** 0.5 / 3 ** 5 / mu
    de = 3 * mu / 8
    (line,) = lines["lines"]
    assert abs(line["Eh"] - de) < 1e-10
    assert abs(abs(line["length"]) - R) < 1e-9 * R
    assert abs(line["velocity"] - line["length"]) < 1e-9 * R
    assert abs(line["line_strength"] - R * R) < 2e-9 * R * R
    assert abs(line["oscillator_strength"] - 2 / 3 * de * R * R) < 2e-9
    want_A = 4 / 3 * ALPHA ** 3 * de ** 3 * R * R / 3 / AU_TIME
    assert abs(line["einstein_A"] - want_A) < 1e-8 * want_A
    assert lines["lifetimes"] == [{"level": line["upper"], "lifetime": 1 / line["einstein_A"], "lines": 1}]
    assert [lv["N"] for lv in lines["levels"]] == [0, 1]


def test_the_thomas_reiche_kuhn_sum_over_pseudostates_is_one_over_mu():
    # Σ_n f_0n = Σ_k q_k²/m_k − Q²/m_tot = 1/m_e + 1/m_p: the N = 1 basis holds d ψ_0 exactly
    lower, upper = hydrogen(0), hydrogen(1)
    r = transitions(lower, upper, roots=(1, len(EXPONENTS)))
    assert all(r["levels"][line["lower"]]["N"] == 0 for line in r["lines"])
    f = sum(line["oscillator_strength"] for line in r["lines"])
    mu = 1 / (1 + 1 / 1836.15267343)
    assert abs(f - 1 / mu) < 1e-6


def test_laboratory_and_translationally_invariant_elements_agree():
    lower, upper = hydrogen(0, EXPONENTS[:6]), hydrogen(1, EXPONENTS[2:9])
    w, w_v = dipole_vectors(lower.system)
    for name, v, momentum in [("dipole", w, False), ("velocity", w_v, True)]:
        lab = laboratory(lower.system).between(name, lower, upper, v[None], momentum)[0]
        ti = translationally_invariant(lower.system).between(name, lower, upper, v[None], momentum)[0]
        assert np.max(np.abs(lab - ti)) < 1e-11 * np.max(np.abs(lab))


def test_a_plain_bra_equals_the_ecg_gvr_bra_at_k_0():
    upper = hydrogen(1, EXPONENTS[3:10])
    w, w_v = dipole_vectors(upper.system)
    rep = laboratory(upper.system)
    for name, v, momentum in [("dipole", w, False), ("velocity", w_v, True)]:
        plain = rep.between(name, hydrogen(0, EXPONENTS[:8]), upper, v[None], momentum)[0]
        gvr = rep.between(name, hydrogen(0, EXPONENTS[:8], kind="ecg-gvr"), upper, v[None], momentum)[0]
        assert np.array_equal(plain, gvr)


def test_bad_pairs_are_refused_in_one_line():
    with pytest.raises(InputError, match="one symmetry"):
        transitions(hydrogen(0), hydrogen(0))
    d = prebo.Basis(prebo.System(["d", "e"], N=1, parity=-1), hydrogen(1).A, hydrogen(1).c_A, kind="ecg-gvr",
                    u=hydrogen(1).u, K=hydrogen(1).K)
    with pytest.raises(InputError, match="different particles"):
        transitions(hydrogen(0), d)


def test_the_static_polarisability_of_hydrogen_is_nine_halves_over_mu_cubed():
    from prebo.level.response import polarisability

    mu = 1 / (1 + 1 / 1836.15267343)
    r = polarisability(hydrogen(0), hydrogen(1))
    want = 4.5 / mu ** 3
    assert abs(r["alpha"][0] - want) < 1e-8 * want
    assert r["alpha"][0] < want * (1 + 1e-12)  # Hylleraas: from below
    assert abs(r["sum_over_states"][0] - r["alpha"][0]) < 1e-10 * want
    assert r["hylleraas"] == -r["alpha"][0] / 2


def test_the_dynamic_polarisability_grows_towards_the_first_pole_and_stops_there():
    from prebo.level.response import polarisability

    r = polarisability(hydrogen(0), hydrogen(1), omega=[0.0, 0.1, 0.3])
    assert r["alpha"][0] < r["alpha"][1] < r["alpha"][2]
    assert np.allclose(r["alpha"], r["sum_over_states"], rtol=1e-9)
    with pytest.raises(InputError, match="first pole"):
        polarisability(hydrogen(0), hydrogen(1), omega=r["pole"])



def test_ecgpack_he_samples_give_the_elements_its_readme_prints():
    # ecgpack's RG_0S-1P He sample (tests/data/ecgpack/README.md): its README prints, digits cut off,
    # dE = 0.779 287 387, <S|z|P> = 0.395 665 167 for the M = 0 component (<1‖d‖0> = √3 <1 0|d_z|0 0>)
    # and <S|P_z|P> = i 0.314 193 144 with P_z the electrons' momentum (|velocity form| × ΔE / √3)
    from prebo.cli.files import load_basis

    data = __import__("pathlib").Path(__file__).parent / "data" / "ecgpack"
    lower, upper = (load_basis(data / f"ecgpack-He-inf-{s}-10.inout.txt")[0] for s in ("1S", "2P"))
    (line,) = transitions(lower, upper)["lines"]
    assert 0.779287387 <= line["Eh"] < 0.779287388
    assert 0.395665167 <= abs(line["length"]) / 3 ** 0.5 < 0.395665168
    assert 0.314193144 <= abs(line["velocity"]) * line["Eh"] / 3 ** 0.5 < 0.314193145
