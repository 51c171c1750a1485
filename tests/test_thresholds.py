"""Bound or not (issue 17): the lowest dissociation threshold of a system (`prebo.system.thresholds`), the
user's threshold, and the result's verdict and warning — shown on an H⁻ basis that describes a
hydrogen atom plus a distant electron, whose virial coefficient is as small as a bound state's."""
import json
import math

import numpy as np
import pytest

import prebo
from conftest import ROOT, cli_error, prebo_process, toml_text
from prebo.cli import main
from prebo.errors import InputError
from prebo.io import toml
from prebo.system.particles import KNOWN
from prebo.system.thresholds import hydrogen_like, lowest

M = {name: mass for name, (mass, _, _) in KNOWN.items()}
LI = {"name": "li", "mass": 12786.3933, "charge": 3, "spin": 1.5}  # a 7Li nucleus by hand


def mu(a, b):
    """The reduced mass m_a m_b / (m_a + m_b) (m_e)."""
    return a * b / (a + b)


#: particles -> (exact threshold −Σ μ_ij (q_i q_j)² / 2 of the lowest fragments, their label)
CASES = [
    (["p", "e", "e"], -mu(M["p"], 1) / 2, "p-e + e"),                                # H⁻ → H + e
    (["alpha", "e", "e"], -mu(M["alpha"], 1) * 4 / 2, "alpha-e + e"),              # He → He⁺ + e
    (["p", "p", "e", "e"], -2 * mu(M["p"], 1) / 2, "p-e + p-e"),                   # H₂ → H + H
    (["e+", "e", "e"], -1 / 4, "e+-e + e"),                                        # Ps⁻ → Ps + e
    (["e+", "e+", "e", "e"], -1 / 2, "e+-e + e+-e"),                               # Ps₂ → Ps + Ps
    (["p", "mu", "e"], -mu(M["p"], M["mu"]) / 2, "p-mu + e"),                      # pμe → pμ + e
    (["d", "t", "mu"], -mu(M["t"], M["mu"]) / 2, "t-mu + d"),                      # dtμ → tμ + d, below dμ + t
    (["alpha", "p", "mu", "e"], -mu(M["alpha"], M["mu"]) * 2 - mu(M["p"], 1) / 2, "alpha-mu + p-e"),  # two pairs
    ([LI, "e", "e", "e"], -mu(LI["mass"], 1) * 9 / 2, "li-e + e + e"),             # Li → Li²⁺ + e + e
    (["p", "e"], 0.0, "p + e"),                                                    # two particles: no fragments
    (["e+", "e"], 0.0, "e+ + e"),
    (["e", "e", "e"], 0.0, "e + e + e"),                                           # no pair attracts
]


@pytest.mark.parametrize("particles, energy, fragments", CASES, ids=lambda v: v if isinstance(v, str) else None)
def test_threshold_is_that_of_the_lowest_hydrogen_like_fragments(particles, energy, fragments):
    t = hydrogen_like(prebo.System(particles))
    assert t.energy == pytest.approx(energy, rel=1e-14, abs=0) and t.fragments == fragments


# --- the user's threshold: API, TOML, basis.json ------------------------------------------
def test_a_given_threshold_lower_than_the_fragments_is_the_effective_one():
    """Li: Li⁺ + e (−7.28 Eh) lies far below Li²⁺ + e + e, which the hydrogen-like search finds."""
    li = prebo.System([LI, "e", "e", "e"], threshold=-7.28)
    assert lowest(li).energy == -7.28 and lowest(li).fragments == "given"
    high = prebo.System([LI, "e", "e", "e"], threshold=-1)  # above Li²⁺ + e + e: the fragments stay
    assert lowest(high) == hydrogen_like(high)


def test_given_threshold_survives_basis_json_and_is_absent_when_not_given():
    given = prebo.System(["p", "e", "e"], state=prebo.State(spin={"e": 0}, threshold=-0.6))
    assert given.to_dict()["state"]["threshold"] == -0.6
    assert prebo.System.from_dict(given.to_dict()).state.threshold == -0.6
    assert "threshold" not in prebo.System(["p", "e", "e"]).to_dict()["state"]  # existing files stay as they are
    assert prebo.Basis.load(ROOT / "examples" / "bases" / "h-" / "basis.json").system.state.threshold is None


@pytest.mark.parametrize("value", ["x", True, float("nan"), float("inf"), [1.0], {}])
def test_bad_thresholds_are_refused(value, tmp_path, capsys):
    with pytest.raises(InputError, match="state: threshold = .*must be a finite number"):
        prebo.State(threshold=value)
    doc = {"system": {"particles": ["p", "e", "e"]}, "state": {"threshold": value}, "basis": {"size": 2}}
    f = tmp_path / "in.toml"
    f.write_text(toml_text(doc))
    err = cli_error(capsys, "run", f, "--out", tmp_path / "out", "--quiet")
    assert f"{f}: state: threshold = " in err and "must be a finite number" in err
    d = json.loads((ROOT / "examples" / "bases" / "h-" / "basis.json").read_text())
    d["system"]["state"]["threshold"] = value
    g = tmp_path / "basis.json"
    g.write_text(json.dumps(d, allow_nan=True))
    finite = not (isinstance(value, float) and not math.isfinite(value))  # NaN, Infinity: refused as they are read
    assert ("state: threshold = " if finite else f"{g}:1: {json.dumps(value)}: not a finite number") in \
        cli_error(capsys, "energy", g)


def test_toml_threshold_reaches_the_run_and_its_result(tmp_path, capsys):
    """`[state] threshold` → State → the checkpoint's basis.json → result.json, and `prebo run` warns
    (exit 0) when the energy is not below it."""
    doc = {"system": {"particles": ["p", "e", "e"]}, "state": {"spin": {"e": 0}, "threshold": -0.6},
           "basis": {"size": 2}, "optimiser": {"trials": 2, "seed": 1}}
    f = tmp_path / "in.toml"
    f.write_text(toml_text(doc))
    assert toml.load(f).system.state.threshold == -0.6
    assert main(["run", str(f), "--out", str(tmp_path / "out"), "--quiet"]) == 0
    out, err = capsys.readouterr()
    r = json.loads((tmp_path / "out" / "result.json").read_text())
    assert r["state"]["threshold"] == -0.6 and r["threshold"] == -0.6 and r["threshold_fragments"] == "given"
    assert r["thresholds"] == {"p-e + e": pytest.approx(-mu(M["p"], 1) / 2, rel=1e-14), "given": -0.6}
    assert r["bound"] is False and r["binding_energy"] == pytest.approx(-0.6 - r["energy"], rel=1e-14)
    assert err.startswith("prebo: warning: E = ") and "(given)" in err and err.count("\n") == 1, err
    assert prebo.Basis.load(tmp_path / "out" / "basis.json").system.state.threshold == -0.6


# --- bound or not: an atom plus a distant particle ------------------------------------------
HMINUS = [{"name": "p", "mass": 1836.15267}, "e", "e"]  # the mass of the H⁻ reference (tests/data)


def hydrogen_plus_distant_electron(widths=(1e-8, 4e-8)) -> prebo.Basis:
    """H⁻ (electrons singlet) as H(1s) plus a distant electron: products exp(−a_k r_1p² − b_l r_2p²)
    of the 40 Gaussians a_k of the optimised hydrogen basis (examples/bases/h: 1e-13 relative
    above −μ/2) and very diffuse Gaussians b_l (bohr⁻², extent b^−½ ~ 10⁴ bohr), built as A matrices in
    proton-centred coordinates and made singlet by the system's symmetriser."""
    h = prebo.Basis.load(ROOT / "examples" / "bases" / "h" / "basis.json")
    a = [prebo.heavy_particle_centred(h.system.masses, 0).from_lab(A)[0][0, 0] for A in h.A]
    system = prebo.System(HMINUS, spin={"e": 0})
    x = prebo.heavy_particle_centred(system.masses, 0)
    A = np.array([x.to_lab(np.diag([ak, bl]), 1.0) for ak in a for bl in widths])
    return prebo.Basis(system, A, np.ones(len(A)), [x.name] * len(A))


@pytest.fixture(scope="module")
def optimised():
    """The optimised, bound H⁻ basis of examples/bases/h- re-evaluated."""
    return prebo.evaluate(prebo.Basis.load(ROOT / "examples" / "bases" / "h-" / "basis.json"))


def test_an_atom_plus_a_distant_electron_is_not_bound(optimised):
    """Not bound: the energy is not below H + e. Its virial coefficient is even smaller than the
    optimised bound H⁻'s: the fragment, H(1s), satisfies the virial theorem 2⟨T⟩ + ⟨V⟩ = 0 by
    itself, and the distant electron adds only its kinetic energy ΔT = E − E_threshold, so
    η = |1 + ⟨V⟩/(2⟨T⟩)| = ΔT/⟨T⟩, which vanishes as the electron moves away (here within 1 %: the
    hydrogen basis's own η is 2e-11)."""
    r = prebo.evaluate(hydrogen_plus_distant_electron())
    assert r["threshold"] == pytest.approx(-mu(1836.15267, 1) / 2, rel=1e-14) and r["threshold_fragments"] == "p-e + e"
    assert r["bound"] is False
    assert r["binding_energy"] <= r["energy_uncertainty"]
    assert r["virial"] < optimised["virial"]
    assert r["virial"] == pytest.approx(-r["binding_energy"] / r["kinetic"], rel=1e-2)


def test_the_optimised_h_minus_basis_is_bound(optimised, references):
    """The positive control: bound, by less than the exact binding energy (variational principle;
    H⁻ energy of A. M. Frolov, tests/data/reference_energies.toml)."""
    assert optimised["bound"] is True and optimised["threshold_fragments"] == "p-e + e"
    assert 0 < optimised["binding_energy"] < optimised["threshold"] - references["H-"]["energy"]


def test_prebo_energy_warns_when_not_bound(tmp_path, capsys):
    f = tmp_path / "basis.json"
    hydrogen_plus_distant_electron().save(f)
    r = prebo_process("energy", f)
    assert r.returncode == 0 and "dissociation threshold" in r.stdout and "not bound" in r.stdout, r.stderr
    assert r.stderr.count("\n") == 1 and r.stderr.startswith("prebo: warning: E = -0.4997"), r.stderr
    for words in ("is not below the dissociation threshold -0.4997", "Eh (p-e + e): the state is not bound in this",
                  "basis (a small virial coefficient is no evidence of binding)"):
        assert words in r.stderr, r.stderr
    assert main(["energy", str(f), "--json"]) == 0
    out, err = capsys.readouterr()
    assert json.loads(out)["bound"] is False and err.startswith("prebo: warning:")
    assert main(["energy", str(ROOT / "examples" / "bases" / "h-" / "basis.json")]) == 0
    out, err = capsys.readouterr()
    assert err == "" and "(bound)" in out


# --- break-ups the hydrogen-like search does not count ----------------------------------------
@pytest.mark.parametrize("particles, unchecked", [
    (["alpha", "e", "e", "e"], "alpha-e-e + e"),   # He⁻: He + e lies below He⁺ + e + e
    (["p", "p", "e", "e"], "p-p-e + e"),           # H₂: H₂⁺ + e (above H + H, but not computed)
    (["alpha", "p", "e", "e"], "alpha-p-e + e"),   # HeH⁺: He + p lies below He⁺ + H
    (["p", "e", "e"], None),                       # three particles: every fragment is counted
    (["e+", "e", "e"], None),
    (["e", "e", "e", "e"], None),                  # no fragment can bind
])
def test_a_fragment_of_three_or_more_particles_is_named_where_it_could_bind(particles, unchecked):
    assert hydrogen_like(prebo.System(particles)).unchecked == unchecked
    given = prebo.System(particles, threshold=-100.0)
    assert lowest(given).fragments == "given" and lowest(given).unchecked is None


def test_bound_is_qualified_where_a_break_up_was_not_computed(capsys):
    """H₂ (4 particles): 'bound' below H + H, with H₂⁺ + e named as not computed; H₂⁺ (3): plainly."""
    h2 = ROOT / "examples" / "bases" / "h2-pecg" / "basis.json"
    assert main(["energy", str(h2), "--json"]) == 0
    r = json.loads(capsys.readouterr().out)
    assert r["bound"] is True and r["threshold_unchecked"] == "p-p-e + e"
    assert main(["energy", str(h2)]) == 0
    out = " ".join(capsys.readouterr().out.split())
    assert "bound below the thresholds computed" in out and "give [state] threshold" in out
    assert main(["energy", str(ROOT / "examples" / "bases" / "h2plus-gvr" / "basis.json"), "--json"]) == 0
    r = json.loads(capsys.readouterr().out)
    assert r["bound"] is True and r["threshold_unchecked"] is None


def test_prebo_properties_warns_when_the_level_is_not_bound(capsys):
    """H⁻'s root 1 lies above H + e: its properties are printed, and one warning line says so."""
    h_minus = ROOT / "examples" / "bases" / "h-" / "basis.json"
    for extra in ([], ["--json"]):
        assert main(["properties", str(h_minus), "--root", "1", *extra]) == 0
        err = capsys.readouterr().err
        assert err.startswith("prebo: warning: root 1 is not below") and err.count("\n") == 1, err
    assert main(["properties", str(h_minus)]) == 0 and capsys.readouterr().err == ""
