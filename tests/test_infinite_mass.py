"""Issue 57, item 4: a particle of infinite mass (`mass = inf`), a clamped nucleus with no kinetic
term and the centre of mass on it, through the whole pipeline: coordinates, the laboratory-frame
and translationally invariant matrices, the optimiser, the properties, basis.json and result.json;
and the bad inputs around it (one line, exit 2)."""
import json
import math
import warnings

import numpy as np
import pytest
import mpmath

import prebo
from prebo.coordinates import all_sets, by_name, cm_centred, jacobi
from prebo.cli import main
from prebo.errors import InputError
from prebo.integrals import laboratory, translationally_invariant
from prebo.system import reduced_mass

from conftest import cli_error, pair_A, toml_text

INF = math.inf
HE = [{"name": "He", "mass": INF, "charge": 2, "spin": 0}, "e", "e"]
H = [{"name": "p", "mass": INF}, "e"]
#: even-tempered s exponents (bohr⁻²) for hydrogen's 1s: 24 of them, 0.01 to 3e4
EXPONENTS = np.geomspace(0.01, 3e4, 24)


def hydrogen(mass: float, exponents=EXPONENTS) -> prebo.Basis:
    """H (proton of `mass`) in s Gaussians exp(−a r²) of r = r_e − r_p times a CM Gaussian, c_A = 1."""
    system = prebo.System([{"name": "p", "mass": mass}, "e"])
    A = [pair_A(system, {(0, 1): a}, 1.0) for a in exponents]
    return prebo.Basis(system, np.array(A), np.ones(len(A)), ["pairs"] * len(A))


def clamped_hydrogen(exponents=EXPONENTS) -> float:
    """The lowest eigenvalue of the clamped-nucleus H in s Gaussians, from the closed forms
    S = (π/(a+b))^{3/2}, T = 3ab/(a+b) S, V = −2π/(a+b) (Eh, bohr), in 40-digit arithmetic (the
    basis's overlap condition is 1.7e5)."""
    mpmath.mp.dps = 40
    e = [mpmath.mpf(float(a)) for a in exponents]
    S = mpmath.matrix([[(mpmath.pi / (a + b)) ** 1.5 for b in e] for a in e])
    H = mpmath.matrix([[3 * a * b / (a + b) * S[i, j] - 2 * mpmath.pi / (a + b) for j, b in enumerate(e)]
                       for i, a in enumerate(e)])
    L = mpmath.cholesky(S) ** -1
    return float(min(mpmath.eigsy(L * H * L.T)[0]))


def test_the_infinite_mass_is_the_centre_of_mass():
    system = prebo.System(HE)
    assert system.m_total == INF and system.cm_vector.tolist() == [1.0, 0.0, 0.0]
    assert np.diag(system.M).tolist() == [0.0, 0.5, 0.5] and np.array_equal(system.M_internal, system.M)
    for x in all_sets(system.masses, [p.name for p in system.particles]):
        x.check(system.masses)
        assert np.isfinite(x.U).all() and x.U[-1].tolist() == [1.0, 0.0, 0.0]
        assert np.allclose(x.mu(system.M), x.U[:-1] @ system.M @ x.U[:-1].T)
    assert "cmc:2" not in [x.name for x in all_sets(system.masses)]  # it would be hpc:0
    assert np.array_equal(cm_centred(system.masses).U, by_name(system.masses, "cmc:0").U)
    assert np.array_equal(jacobi(system.masses, [1, 2, 0]).U[1], [-1.0, 0.5, 0.5])


def test_reduced_masses_of_an_infinite_mass_are_the_finite_ones():
    assert reduced_mass(INF, 1.0) == 1.0 and reduced_mass(3.0, INF) == 3.0 and reduced_mass(1.0, 1.0) == 0.5
    m = prebo.System(HE).masses
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        mu = reduced_mass(m[:, None], m[None, :])
    assert mu.tolist() == [[INF, 1.0, 1.0], [1.0, 0.5, 0.5], [1.0, 0.5, 0.5]]


def test_hydrogen_with_a_clamped_proton_is_the_clamped_nucleus_hydrogen():
    """Against the closed forms of the same functions with the nucleus fixed; and −1/2."""
    basis = hydrogen(INF)
    r = prebo.evaluate(basis)
    assert r["energy"] == pytest.approx(clamped_hydrogen(), rel=1e-14, abs=0)
    assert r["energy"] == pytest.approx(-0.5, rel=1e-8, abs=0) and r["energy"] > -0.5  # 24 functions: 7.6e-9
    assert r["energy_lab"] == r["energy"]  # no CM kinetic energy
    assert prebo.evaluate(basis, "ti")["energy"] == pytest.approx(r["energy"], rel=1e-14, abs=0)


def test_nothing_is_eliminated_from_the_kinetic_energy():
    """The core is given no CM mass (integrals.laboratory): T_ti = T, to the bit."""
    basis = hydrogen(INF)
    rep = laboratory(basis.system)
    assert rep.cm_mass is None
    m = rep.matrices(basis)
    assert np.array_equal(m["T_ti"], m["T"])
    internal = laboratory(basis.system, "internal").matrices(basis)
    assert np.array_equal(internal["T"], m["T"])


@pytest.mark.parametrize("basis", ["hydrogen", "he"])
def test_a_mass_of_1e12_agrees_with_an_infinite_one(basis, he_run):
    """The same functions with the nucleus at 1e12 m_e: within 1e-11 relative (m_e/M = 1e-12)."""
    if basis == "hydrogen":
        inf, big = hydrogen(INF), hydrogen(1e12)
    else:
        inf = prebo.Basis.load(he_run / "basis.json")
        d = inf.to_dict()
        d["system"]["particles"][0]["mass"] = 1e12
        big = prebo.Basis.from_dict(d)
    e_inf, e_big = prebo.evaluate(inf)["energy"], prebo.evaluate(big)["energy"]
    assert e_big != e_inf and abs(e_big - e_inf) / abs(e_inf) < 1e-11


def test_laboratory_and_translationally_invariant_agree(he_run):
    basis = prebo.Basis.load(he_run / "basis.json")
    for x in all_sets(basis.system.masses):
        ti = translationally_invariant(basis.system, x).matrices(basis)
        lab = laboratory(basis.system).matrices(basis)
        for k in ("S", "T_ti", "V"):
            assert np.allclose(ti[k], lab[k], rtol=1e-11, atol=1e-13), (x.name, k)


@pytest.fixture(scope="module")
def he_run(tmp_path_factory):
    """`prebo run` of He with a clamped nucleus: 30 plain ECGs."""
    d = tmp_path_factory.mktemp("he")
    doc = {"system": {"particles": HE}, "state": {"spin": {"e": 0}}, "basis": {"type": "pecg", "size": 30},
           "optimiser": {"trials": 20, "sweeps": 1, "seed": 1}}
    (d / "he.toml").write_text(toml_text(doc))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no inf/inf, no NaN anywhere
        assert main(["run", str(d / "he.toml"), "--out", str(d / "out"), "--quiet"]) == 0
    return d / "out"


def test_he_with_a_clamped_nucleus_optimises_towards_its_energy(he_run):
    """30 functions: above and within 2e-3 of Drake's −2.903 724 377 (infinite mass)."""
    r = json.loads((he_run / "result.json").read_text())
    assert -2.903724377 < r["energy"] < -2.9015 and r["energy_lab"] == r["energy"]
    assert r["particles"][0]["mass"] == "inf" and r["threshold"] == -2.0


def test_an_infinite_mass_round_trips_through_basis_json(he_run, tmp_path):
    text = (he_run / "basis.json").read_text()
    stored = json.loads(text)["system"]["particles"][0]
    assert stored == {"name": "He", "mass": "inf", "charge": 2.0, "spin": 0.0}
    basis = prebo.Basis.load(he_run / "basis.json")
    assert basis.system.particles[0].mass == INF
    basis.save(tmp_path / "again.json")
    again = prebo.Basis.load(tmp_path / "again.json")
    assert np.array_equal(again.A, basis.A) and again.system.masses.tolist() == [INF, 1.0, 1.0]
    assert prebo.evaluate(again)["energy"] == prebo.evaluate(basis)["energy"]


def test_properties_of_a_clamped_nucleus_are_finite(he_run):
    """Terms with 1/m of the nucleus are 0, not NaN (relativistic.py, drachmann.py)."""
    basis = prebo.Basis.load(he_run / "basis.json")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        p = prebo.properties(basis)
    flat = json.dumps(p, default=float)
    assert "NaN" not in flat and "Infinity" not in flat
    assert p["breit_pauli"]["classes"]["mass_velocity"]["He"] == 0.0


# --- bad input: one line, exit 2 --------------------------------------------------------------
def test_two_infinite_masses_are_refused(capsys, tmp_path):
    with pytest.raises(InputError, match="'x', 'y' have infinite masses: at most one"):
        prebo.System([{"name": "x", "mass": INF, "charge": 1, "spin": 0},
                      {"name": "y", "mass": INF, "charge": 1, "spin": 0}, "e"])
    doc = {"system": {"particles": [{"name": "p", "mass": INF}, {"name": "p", "mass": INF}, "e"]},
           "basis": {"size": 3}}
    (tmp_path / "in.toml").write_text(toml_text(doc))
    err = cli_error(capsys, "run", tmp_path / "in.toml", "--out", tmp_path / "out")
    assert "in.toml" in err and "'p', 'p' have infinite masses" in err


@pytest.mark.parametrize("particle, words", [
    ({"name": "p", "mass": -INF}, "particle 'p': mass = -inf: must be a finite positive number x with "
                                  "1e-06 ≤ x ≤ 1e+12, or inf"),
    ({"name": "p", "charge": INF}, "particle 'p': charge = inf: must be 0, or a finite number"),
    ({"name": "p", "mass": float("nan")}, "particle 'p': mass = nan: must be"),
    ({"name": "p", "spin": INF}, "particle 'p': spin"),
])
def test_inf_where_it_makes_no_sense_is_refused(capsys, tmp_path, particle, words):
    (tmp_path / "in.toml").write_text(toml_text({"system": {"particles": [particle, "e"]}, "basis": {"size": 3}}))
    err = cli_error(capsys, "run", tmp_path / "in.toml", "--out", tmp_path / "out")
    assert words in err, err


def test_a_cm_centred_set_that_keeps_the_clamped_particle_is_refused():
    with pytest.raises(InputError, match=r"cmc:2: particle 0 has an infinite mass .* drops it \(cmc:0\)"):
        by_name(prebo.System(HE).masses, "cmc:2")
    with pytest.raises(InputError, match="finite but for at most one"):
        jacobi([INF, INF, 1.0])


def test_a_stored_infinite_mass_is_only_the_string_inf(he_run, tmp_path, capsys):
    d = json.loads((he_run / "basis.json").read_text())
    d["system"]["particles"][0]["mass"] = "Infinity"
    (tmp_path / "b.json").write_text(json.dumps(d))
    err = cli_error(capsys, "energy", tmp_path / "b.json")
    assert "b.json" in err and "mass = 'Infinity': must be" in err, err
