"""Several roots of one basis (issue 39): `prebo.evaluate(basis, roots=K)` and `prebo energy --roots K`
report the lowest K levels of the symmetry, each an upper bound to its exact level
(Hylleraas–Undheim–MacDonald), their uncertainties, whether each is bound, and the transitions."""
import json
from dataclasses import replace

import numpy as np
import pytest

import prebo
from prebo.cli import main
from prebo.errors import InputError, LinearDependenceError
from prebo.integrals import laboratory
from prebo.level.evaluate import HARTREE_CM

from conftest import ROOT, hydrogen_s

BASES = ROOT / "examples" / "bases"


def hydrogen(size: int = 50, ratio: float = 1.45, widest: float = 3e-4):
    """H (finite proton mass) in `size` even-tempered s Gaussians, a = widest × ratio^k
    (conftest.hydrogen_s). Returns (basis, μ)."""
    return hydrogen_s(widest * ratio ** np.arange(size))


def test_hydrogen_s_levels_are_upper_bounds_within_1e8_of_the_exact_ones():
    """1s-4s of H with μ = m_p/(1 + m_p): E_n = −μ/(2n²) exactly; every root lies above its level
    (HUM) and, in 50 even-tempered s Gaussians, within 1e-8 relative; the 1s → 2s transition is
    3μ/8 Eh, in cm⁻¹ by the CODATA 2018 hartree."""
    basis, mu = hydrogen()
    r = prebo.evaluate(basis, roots=4)
    exact = np.array([-mu / (2 * n**2) for n in range(1, 5)])
    energies = np.array([v["energy"] for v in r["levels"]])
    assert np.all(energies > exact) and np.all((energies - exact) / -exact < 1e-8), (energies - exact) / -exact
    assert [v["root"] for v in r["levels"]] == [0, 1, 2, 3] and all(v["bound"] for v in r["levels"])
    assert [(t["lower"], t["upper"]) for t in r["transitions"]] == [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
    first = r["transitions"][0]
    assert first["Eh"] == energies[1] - energies[0] and first["cm-1"] == first["Eh"] * HARTREE_CM
    assert abs(first["Eh"] - 3 * mu / 8) < 1e-8 * mu
    assert HARTREE_CM == pytest.approx(2.1947463136320e5, rel=1e-13)


def test_the_ground_state_keys_are_those_of_one_root():
    """Asking for several roots leaves root 0's result as it was, bit for bit (the main job and every
    stored basis keep their energies)."""
    basis = prebo.Basis.load(BASES / "he" / "basis.json")
    one, three = prebo.evaluate(basis, operators=["r2"]), prebo.evaluate(basis, operators=["r2"], roots=3)
    assert "levels" not in one and "transitions" not in one
    for key in ("energy", "energy_uncertainty", "energy_lab", "virial", "kinetic", "potential", "bound",
                "binding_energy", "overlap_condition", "kept", "expectation"):
        assert three[key] == one[key], key
    assert np.array_equal(three["coefficients"], one["coefficients"])
    assert three["levels"][0] == {k: one[k] for k in three["levels"][0] if k != "root"} | {"root": 0}
    assert three["levels"][1]["energy"] < three["levels"][2]["energy"]
    assert three["levels"][1]["expectation"]["r2"]["e-e"] > one["expectation"]["r2"]["e-e"]  # 1s2s is larger


def test_a_level_above_the_threshold_is_reported_not_bound(capsys):
    """H⁻ has one bound state: root 1 of its singlet S symmetry lies above H(1s) + e, and is said so
    (JSON `bound` false, the table's 'no' and one warning line), never claimed as a level."""
    path = BASES / "h-" / "basis.json"
    assert main(["energy", str(path), "--roots", "2", "--json"]) == 0
    out, err = capsys.readouterr()
    r = json.loads(out)
    assert r["bound"] and not r["levels"][1]["bound"] and r["levels"][1]["energy"] > r["threshold"]
    assert "level 1 not below the dissociation threshold" in err and len(err.splitlines()) == 1
    assert main(["energy", str(path), "--roots", "2"]) == 0
    out, _ = capsys.readouterr()
    assert "levels" in out and "0 → 1" in out


@pytest.mark.parametrize("roots, message", [("0", "'0' is not an integer ≥ 1"), ("-1", "'-1' is not an integer ≥ 1"),
                                            ("1.5", "'1.5' is not an integer ≥ 1"),
                                            ("151", "roots = 151: must be an integer in 1..150")])
def test_roots_outside_the_basis_are_refused_in_one_line(capsys, roots, message):
    try:
        status = main(["energy", str(BASES / "he" / "basis.json"), "--roots", roots])
    except SystemExit as exc:  # argparse's refusals
        status = exc.code
    assert status == 2
    err = capsys.readouterr().err
    assert message in err and len(err.splitlines()) == 1


def test_roots_beyond_the_resolved_directions_and_bad_types_are_refused():
    basis, _ = hydrogen(size=12, ratio=1.0005)  # nearly duplicate functions: most directions dropped
    with pytest.raises(LinearDependenceError, match="12 roots asked for, but the basis resolves"):
        prebo.evaluate(basis, roots=12)
    for bad in (True, 2.0, "2"):
        with pytest.raises(InputError, match="evaluate: roots"):
            prebo.evaluate(basis, roots=bad)


def test_a_root_k_result_is_that_roots_at_the_top(tmp_path, capsys):
    """A basis optimised for root = 1 (H's 2s level): the top of its result — energy, uncertainty,
    virial coefficient, expectation values, `coefficients`, the laboratory-frame energy — is root
    1's, named by `root`, not root 0's; every targeted root's vector is kept (`vectors`), and
    `prebo energy` heads its table with root 1 (issue 56)."""
    basis, mu = hydrogen(20)
    excited = replace(basis, system=prebo.System(basis.system.particles, prebo.State(root=1)))
    r, both = prebo.evaluate(excited, operators=["r2"]), prebo.evaluate(basis, operators=["r2"], roots=2)
    for key in ("energy", "energy_uncertainty", "virial", "kinetic", "potential", "bound", "binding_energy",
                "expectation"):
        assert r[key] == both["levels"][1][key], key
    assert r["root"] == 1 and r["targets"] == [1] and r["levels"] == both["levels"]
    assert r["energy"] > -mu / 8 and r["energy_lab"] - r["energy"] == pytest.approx(both["energy_lab"] - both["energy"])
    m = laboratory(basis.system).matrices(basis)
    c = r["coefficients"]
    assert r["vectors"].shape == (len(basis), 1) and np.array_equal(r["vectors"][:, 0], c)
    residual = (m["T_ti"] + m["V"]) @ c - r["energy"] * m["S"] @ c
    assert c @ m["S"] @ c == pytest.approx(1.0) and np.max(np.abs(residual)) < 1e-8
    pair = prebo.evaluate(replace(basis, system=prebo.System(basis.system.particles, prebo.State(roots=[0, 2]))))
    assert pair["root"] == 0 and pair["energy"] == both["energy"] and pair["vectors"].shape == (len(basis), 2)
    assert np.array_equal(pair["vectors"][:, 0], pair["coefficients"])
    for bad in ([1, 1], [], [len(basis)], 1):
        with pytest.raises(InputError, match="evaluate: targets"):
            prebo.evaluate(basis, targets=bad)
    f = tmp_path / "basis.json"
    excited.save(f)
    assert main(["energy", str(f)]) == 0
    out = capsys.readouterr().out
    assert "energy of root 1 (translation-free)" in out and f"{r['energy']:.12f} Eh" in out
