"""Expectation values of the pair operators beyond ⟨r_ij²⟩ (issue 40): ⟨r_ij⟩, ⟨1/r_ij⟩,
⟨1/r_ij²⟩ and ⟨δ³(r_ij)⟩, from the damped overlap's profile for every family
(crates/prebo-core/src/operators/profile.rs; element checks there), here on wave functions
against closed forms."""
import json

import numpy as np
import pytest

import prebo
from prebo.cli import main
from prebo.expectation import OPERATORS

from conftest import ROOT, hydrogen_s


def hydrogen_exact(n: int, mu: float) -> dict:
    """⟨r⟩, ⟨r²⟩, ⟨1/r⟩, ⟨1/r²⟩, ⟨δ³(r)⟩ of hydrogen's ns level with reduced mass μ (l = 0;
    e.g. H. A. Bethe, E. E. Salpeter, Quantum Mechanics of One- and Two-Electron Atoms (1957),
    eqs. 3.24–3.26, scaled r → r/μ)."""
    return {"r": 3 * n**2 / (2 * mu), "r2": n**2 * (5 * n**2 + 1) / (2 * mu**2), "inv_r": mu / n**2,
            "inv_r2": 2 * mu**2 / n**3, "delta": mu**3 / (np.pi * n**3)}


#: relative error allowed per operator in 80 even-tempered s Gaussians (measured for 1s and 2s:
#: r, r2, inv_r ≤ 3.6e-12, inv_r2 2.0e-8, δ 1.8e-4 — Gaussians, without the cusp, reach the
#: contact density slowly)
TOLERANCE = {"r": 2e-11, "r2": 2e-11, "inv_r": 2e-11, "inv_r2": 1e-7, "delta": 5e-4}


def test_hydrogen_1s_and_2s_expectation_values_match_the_closed_forms():
    """H (finite proton mass) 1s and 2s as roots 0 and 1 of 80 even-tempered s Gaussians: every
    operator's value within its tolerance of the closed form, from plain ECGs (one pair, p-e); the
    contact density approaches μ³/π from below as the tightest Gaussian sharpens (3.0e-3, 4.7e-4,
    1.8e-4 for 50, 60, 80 functions)."""
    errors = []
    for size, ratio in ((50, 1.45), (60, 1.45), (80, 1.35)):
        basis, mu = hydrogen_s(3e-4 * ratio ** np.arange(size))
        r = prebo.evaluate(basis, roots=2, operators=sorted(TOLERANCE))
        for n, level in zip((1, 2), r["levels"]):
            exact = hydrogen_exact(n, mu)
            errors.append(level["expectation"]["delta"]["e-p"] / exact["delta"] - 1)
            for name, tol in TOLERANCE.items():
                (label, value), = level["expectation"][name].items()
                assert label == "e-p"
                assert size < 80 or abs(value / exact[name] - 1) < tol, (n, name, value, exact[name])
    assert all(e < 0 for e in errors) and errors[0] < errors[2] < errors[4], errors


def test_properties_of_a_ladder_level_are_its_evaluated_expectation_values():
    """`prebo.properties(basis, root=k)` is level k of `evaluate` with every registered operator:
    in the first 80 functions of the H2⁺ ladder's basis, v = 1 has its energy, and the protons
    further apart than in v = 0 (⟨r_pp⟩, ⟨r_pp²⟩ up, ⟨1/r_pp⟩ down) with no contact density
    (⟨δ³(r_pp)⟩ ≈ 0 beside e-p's)."""
    basis = prebo.Basis.load(ROOT / "examples" / "bases" / "h2plus-ladder" / "basis.json").subset(range(80))
    v1 = prebo.properties(basis, root=1)
    r = prebo.evaluate(basis, roots=2, operators=sorted(OPERATORS))
    v0 = r["levels"][0]
    assert v1["energy"] == r["levels"][1]["energy"] and v1["expectation"] == r["levels"][1]["expectation"]
    assert set(v1["expectation"]) == set(OPERATORS) and v1["units"]["delta"] == "bohr⁻³"
    pp0, pp1 = ({k: v["p-p"] for k, v in p["expectation"].items()} for p in (v0, v1))
    assert pp1["r"] > pp0["r"] and pp1["r2"] > pp0["r2"] and pp1["inv_r"] < pp0["inv_r"]
    assert abs(pp0["delta"]) < 1e-9 * v0["expectation"]["delta"]["e-p"]


def test_prebo_properties_prints_a_table_and_json_and_refuses_a_root_the_basis_does_not_hold(capsys):
    """`prebo properties BASIS --root K [--json]`: one line and exit 2 for a root not below the
    basis size or not an integer ≥ 0."""
    he = str(ROOT / "examples" / "bases" / "he" / "basis.json")
    assert main(["properties", he, "--json"]) == 0
    p = json.loads(capsys.readouterr().out)
    assert p["root"] == 0 and set(p["expectation"]["delta"]) == {"alpha-e", "e-e"}
    assert main(["properties", he]) == 0 and "expectation values" in capsys.readouterr().out
    for bad in (["--root", "150"], ["--root", "-1"], ["--root", "x"]):
        try:
            code = main(["properties", he, *bad])
        except SystemExit as exc:  # argparse's refusals
            code = exc.code
        assert code == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith("prebo: error:"), err
