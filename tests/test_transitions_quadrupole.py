"""Electric-quadrupole lines between a basis of N = 0 and one of N = 2 (level/transitions.py, the
core's "quadrupole"): hydrogen 1s–3d with the proton's finite mass against the closed forms, the
elements' coordinate independence, the selection rules and bad input."""
import json

import numpy as np
import pytest

import prebo
from prebo.errors import UnsupportedError
from prebo.integrals import laboratory, translationally_invariant
from prebo.level.transitions import ALPHA, AU_TIME, forbidden, quadrupole_matrix, transitions
from test_transitions import EXPONENTS, hydrogen


@pytest.fixture(scope="module")
def lines():
    return transitions(hydrogen(0), hydrogen(2), roots=1)


def test_hydrogen_1s_3d_matches_the_closed_forms_with_the_reduced_mass(lines):
    # ⟨R_32|r²|R_10⟩ = ∫ R_32 R_10 r⁴ dr = 1215/(128√30) a_0² at infinite mass (R_10 = 2e^{−r},
    # R_32 = 4r²e^{−r/3}/(81√30)), lengths scale as 1/μ, energies as μ; ⟨2‖C_2‖0⟩ = 1 (Edmonds);
    # Q about the CM of p e is (q_e m_p² + q_p m_e²)/m_tot² r² C_2(r̂), r = r_e − r_p
    system = prebo.System(["p", "e"])
    (m_p, m_e), m = system.masses, system.m_total
    mu = m_p * m_e / m
    R = 1215 / (128 * 30 ** 0.5) / mu ** 2 * (m_p ** 2 - m_e ** 2) / m ** 2
    de = 4 * mu / 9
    (line,) = lines["lines"]
    assert abs(line["Eh"] - de) < 1e-10
    assert abs(abs(line["quadrupole"]) - R) < 1e-8 * R
    assert abs(line["line_strength"] - R * R) < 2e-8 * R * R
    want_A = ALPHA ** 5 * de ** 5 * R * R / 15 / 5 / AU_TIME
    assert abs(line["einstein_A"] - want_A) < 2e-8 * want_A
    assert "length" not in line and "oscillator_strength" not in line
    assert lines["lifetimes"] == [{"level": line["upper"], "lifetime": 1 / line["einstein_A"], "lines": 1}]
    assert [lv["N"] for lv in lines["levels"]] == [0, 2]


def test_the_rate_at_infinite_mass_is_nists():
    # A = 1.1199e18 S/(g λ⁵[Å]) s⁻¹ (Wiese & Fuhr 2009) for 3d → 1s, S = (1215/(128√30))², g = 5,
    # λ = 2π α a_0/ΔE with ΔE = 4/9 Eh and a_0 = 0.529177210903 Å (CODATA 2018): 594.09 s⁻¹
    S, de = (1215 / (128 * 30 ** 0.5)) ** 2, 4 / 9
    ours = ALPHA ** 5 * de ** 5 * S / 15 / 5 / AU_TIME
    nist = 1.1199e18 * S / (5 * (2 * np.pi * 0.529177210903 / (ALPHA * de)) ** 5)
    assert ours == pytest.approx(594.0856, rel=1e-6) and ours == pytest.approx(nist, rel=1e-4)


def test_laboratory_and_translationally_invariant_elements_agree(lines):
    lower, upper = hydrogen(0, EXPONENTS[:6]), hydrogen(2, EXPONENTS[2:9])
    M = quadrupole_matrix(lower.system)
    lab = laboratory(lower.system).between("quadrupole", lower, upper, M)[0]
    ti = translationally_invariant(lower.system).between("quadrupole", lower, upper, M)[0]
    assert np.max(np.abs(lab - ti)) < 1e-11 * np.max(np.abs(lab))
    # the line: the two frames' level vectors of the 40 functions differ by ~1e-10 (the dipole's alike)
    (ti_line,) = transitions(hydrogen(0), hydrogen(2), roots=1, coordinates="ti")["lines"]
    assert ti_line["quadrupole"] == pytest.approx(lines["lines"][0]["quadrupole"], rel=1e-8)


def test_three_particles_laboratory_and_translationally_invariant_elements_agree():
    # p p e, random ECG-GVR functions (K ∈ {0, 1}) of N = 0 and N = 2 at one c_A and c_U = 0, the kets
    # symmetrised over the protons' images
    from test_operators import family_basis

    rng = np.random.default_rng(5)
    s = family_basis("ecg-gvr", prebo.System(["p", "p", "e"]), rng, nb=4, shared_c_A=0.9, cm_free=True)
    d = family_basis("ecg-gvr", prebo.System(["p", "p", "e"], N=2, parity=1), rng, nb=3, shared_c_A=0.9, cm_free=True)
    M = quadrupole_matrix(s.system)
    lab = laboratory(s.system).between("quadrupole", s, d, M)[0]
    ti = translationally_invariant(s.system).between("quadrupole", s, d, M)[0]
    assert np.max(np.abs(lab - ti)) < 1e-11 * np.max(np.abs(lab)) and np.min(np.abs(lab)) > 0


def test_the_quadrupole_matrix_is_the_charges_tensor_about_the_centre_of_mass():
    # Σ_k q_k ρ_k ρ_kᵀ for random particle positions against Σ_ij M_ij r_i r_jᵀ
    system = prebo.System(["p", "e", "e"])
    r = np.random.default_rng(1).normal(size=(3, 3))
    rho = r - system.cm_vector @ r
    want = sum(q * np.outer(x, x) for q, x in zip(system.charges, rho))
    M = quadrupole_matrix(system)
    assert np.allclose(np.einsum("ij,ia,jb->ab", M, r, r), want, atol=1e-13)
    assert np.allclose(M @ np.ones(3), 0.0, atol=1e-15)


def test_selection_rules():
    few = EXPONENTS[::8]
    s, p, d, f, g = (hydrogen(n, few) for n in range(5))
    assert [forbidden(a, b) for a, b in [(s, p), (s, d), (p, f)]] == [None] * 3
    assert forbidden(s, f) == "forbidden for an electric dipole (N = 0 and 3) and quadrupole (the parities differ)"
    assert forbidden(s, g) == "forbidden for an electric dipole (both levels of parity +1) and quadrupole (N = 0 and 4)"
    (line,) = transitions(s, g)["lines"]
    assert line["forbidden"] == forbidden(s, g) and "quadrupole" not in line and "einstein_A" not in line
    with pytest.raises(UnsupportedError, match=r"quadrupole elements between N = 1 and N = 3: derived for N = 0 ↔ 2 only"):
        transitions(p, f)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("quadrupole")
    few = EXPONENTS[::5]
    for n, name in enumerate("spdf"):
        hydrogen(n, few).save(d / f"{name}.json")
    return d


def test_the_command_prints_the_quadrupole_lines_and_their_json(files, capsys):
    from prebo.cli import main

    assert main(["transitions", str(files / "d.json"), str(files / "s.json"), "--json"]) == 0
    r = json.loads(capsys.readouterr().out)
    assert r == transitions(prebo.Basis.load(files / "d.json"), prebo.Basis.load(files / "s.json"))
    assert "quadrupole" in r["lines"][0]
    assert main(["transitions", str(files / "s.json"), str(files / "d.json"), "--roots", "2", "3"]) == 0
    out = capsys.readouterr().out
    assert "electric-quadrupole lines" in out and out.count("(N=0+) →") + out.count("(N=2+) →") == 6
    assert "radiative lifetimes" in out


def test_a_pair_not_derived_is_one_line(files, capsys):
    from conftest import cli_error

    err = cli_error(capsys, "transitions", files / "p.json", files / "f.json")
    assert "derived for N = 0 ↔ 2 only" in err, err
