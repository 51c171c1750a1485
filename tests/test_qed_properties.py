"""`prebo properties --qed` (cli/properties.py) and the current's first-order bases the optimiser builds
on a grid of photon energies (optimise/current.py): hydrogen's ln k₀ and E⁽³⁾ from stored bases and
from bases the driver optimises against Drake & Swainson, their reuse, and bad input."""
import json
import math

import numpy as np
import pytest

import prebo
from prebo.cli import main
from prebo.errors import InputError
from prebo.level.qed import of_level
from prebo.level.relativistic import ALPHA
from prebo.integrals import laboratory
from prebo.level.bethe import coulomb_scale
from prebo.optimise.current import current_bases, folder_of, grid, union

from conftest import cli_error, edited
from test_bethe import DRAKE_SWAINSON, GROUND, RESPONSE, even
from test_qed import clamped
from test_transitions import hydrogen

MU = float(np.prod(prebo.System(["p", "e"]).masses) / prebo.System(["p", "e"]).m_total)

#: hydrogen 1s's ln k₀ in R_∞ = ½ Eh: Drake & Swainson's, in the reduced Rydberg μ/2, plus ln μ (bethe.py)
LN_K0 = DRAKE_SWAINSON[0] + math.log(MU)


def saved(folder, basis, name: str):
    path = folder / name
    basis.save(path)
    return path


def properties(capsys, *argv) -> dict:
    """`prebo properties ARGV --json` in-process: its JSON."""
    assert main(["properties", *map(str, argv), "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_given_bases_give_hydrogens_bethe_logarithm_and_the_api_numbers(tmp_path, capsys):
    ground, response = hydrogen(0, GROUND), hydrogen(1, RESPONSE)
    g, r = saved(tmp_path, ground, "g.json"), saved(tmp_path, response, "r.json")
    q = properties(capsys, g, "--qed", r)["qed"]
    assert abs(q["ln_k0"] - LN_K0) < 1e-6, q["ln_k0"] - LN_K0
    assert q["Eh"] == of_level(ground, response)["Eh"]
    assert [row["n_basis"] for row in q["bethe"]["convergence"]] == [len(RESPONSE)]
    assert main(["properties", str(g), "--qed", str(r)]) == 0
    text = capsys.readouterr().out
    assert "leading QED correction" in text and "electron–nucleus" in text and "Bethe logarithm" in text


def test_the_driver_builds_the_bases_on_a_k_grid_and_reuses_them(tmp_path, capsys):
    # three photon energies, eight functions each: their union's ln k₀ by the integral (split at a
    # third of the grid's top, 100 Eh) within 5e-3 of the exact value (−2.3e-3 measured), ten times
    # closer than the union's own pseudostate sum (0.32 low); a second call reads the runs back (the
    # same numbers to the bit, no run changed)
    g = saved(tmp_path, hydrogen(0, even(0.01, 1e7, 2.0)), "g.json")
    ks = ["0.3", "10", "300"]
    argv = (g, "--qed", "--qed-k", *ks, "--qed-size", "8", "--qed-out", tmp_path / "qed")
    q = properties(capsys, *argv)["qed"]
    assert 10 * abs(q["ln_k0"] - LN_K0) < abs(q["bethe"]["pseudostate"] - LN_K0) and abs(q["ln_k0"] - LN_K0) < 5e-3
    # each union keeps what its overlap resolves (current.union): a function near the cut goes or
    # stays with the machine's rounding (Haswell's OpenBLAS kernels kept 23 of the 24)
    ns = [row["n_basis"] for row in q["bethe"]["convergence"]]
    assert ns[0] == 8 and 8 < ns[1] <= 16 < ns[2] <= 24, ns
    runs = [folder_of(tmp_path / "qed" / "root0", float(k)) / "basis.json" for k in ks]
    stamps = [p.stat().st_mtime_ns for p in runs]
    assert properties(capsys, *argv)["qed"] == q
    assert [p.stat().st_mtime_ns for p in runs] == stamps


def test_the_default_grid_reaches_the_split_point():
    ground = hydrogen(0, GROUND)
    ks = grid(ground)
    assert ks[0] == pytest.approx(0.3 * MU) and ks == sorted(ks) and ks[-1] >= 3 * 1e4 * MU
    assert np.allclose(np.diff(np.log10(ks)), np.diff(np.log10(ks))[0])
    # the unit of the lowest k: (Z μ)² of the attracting pairs, the infinite mass's limit μ = m_e included
    assert coulomb_scale(clamped("alpha", 2)) == 4.0 and coulomb_scale(prebo.System(["e+", "e", "e"])) == 0.5
    with pytest.raises(InputError, match="non-empty list of finite photon energies"):
        grid(ground, [])
    with pytest.raises(InputError, match="non-empty list of finite photon energies"):
        current_bases(ground, k=[1.0, float("nan")])


def test_a_folder_of_another_level_is_refused(tmp_path):
    ground = hydrogen(0, even(0.01, 1e5, 2.5))
    current_bases(ground, k=[1.0], size=3, out=tmp_path)
    with pytest.raises(InputError, match=r"k=1: holds a run that is not the current's first-order function"):
        current_bases(hydrogen(0, even(0.01, 1e5, 2.6)), k=[1.0], size=3, out=tmp_path)


def test_bad_input_gets_one_line(tmp_path, capsys):
    g = saved(tmp_path, hydrogen(0, even(0.03, 300.0, 2.5)), "g.json")
    r = saved(tmp_path, hydrogen(1, even(0.01, 500.0, 2.2)), "r.json")
    # a level that is not bound: root 7 of the ground basis lies in its discretised continuum
    assert "not a bound level" in cli_error(capsys, "properties", g, "--root", "7", "--qed", r)
    # a response basis stored as of unnatural parity (N = 1, parity +1): the current cannot reach it
    unnatural = edited(tmp_path, r, lambda d: d["system"]["state"].update(parity=1), "u.json")
    assert "parity" in cli_error(capsys, "properties", g, "--qed", unnatural)
    assert "--qed-k" in cli_error(capsys, "properties", g, "--qed", "--qed-k", "nan")
    assert "--qed-k" in cli_error(capsys, "properties", g, "--qed", "--qed-k")
    assert "--qed-k" in cli_error(capsys, "properties", g, "--qed", "--qed-k", "-1")
    assert "only with --qed and no RESPONSE" in cli_error(capsys, "properties", g, "--qed", r, "--qed-size", "4")
    assert "only with --qed and no RESPONSE" in cli_error(capsys, "properties", g, "--qed-k", "1")
    assert "--qed-budget" in cli_error(capsys, "properties", g, "--qed", "--qed-budget", "0")
    assert "the response basis is of N = 0" in cli_error(capsys, "properties", g, "--qed", g)
    # the bases' folder where a file stands
    (tmp_path / "file").write_text("")
    assert "cannot make the folder" in cli_error(capsys, "properties", g, "--qed", "--qed-k", "1",
                                                 "--qed-out", tmp_path / "file")


def test_energy_gives_each_level_and_line_by_order_in_alpha(tmp_path, capsys):
    # 1s and 2s from the even-tempered bases: α³ of each against the reduced-mass Lamb-shift form
    # with Drake & Swainson's ln k₀ and the exact ⟨δ³⟩, within the uncertainty the budget reports;
    # α² and α³ as `prebo properties` gives them; each line the difference of its levels' parts
    g = saved(tmp_path, hydrogen(0, GROUND), "g.json")
    r = saved(tmp_path, hydrogen(1, RESPONSE), "r.json")
    assert main(["energy", str(g), "--roots", "2", "--qed", str(r), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    for level in out["levels"]:
        n, parts = level["root"] + 1, level["budget"]
        exact = MU**3 * 4 * ALPHA**3 / (3 * math.pi * n**3) * (math.log(1 / (MU * ALPHA**2))
                                                              - DRAKE_SWAINSON[level["root"]] + 19 / 30)
        a3 = parts["alpha3"]
        assert abs(a3["Eh"] - exact) <= max(a3["uncertainty"], 1e-15) < 1e-3 * exact, (a3, exact)
        p = properties(capsys, g, "--root", level["root"], "--qed", r)
        assert a3["Eh"] == p["qed"]["Eh"]["total"]
        assert parts["alpha2"]["Eh"] == pytest.approx(p["breit_pauli"]["Eh"]["total"], rel=1e-12)
        assert parts["alpha0"]["Eh"] == level["energy"]
        assert parts["total"]["Eh"] == pytest.approx(sum(parts[k]["Eh"] for k in ("alpha0", "alpha2", "alpha3")),
                                                     rel=1e-15)
    (line,) = out["transitions"]
    lower, upper = (v["budget"] for v in out["levels"])
    for k in ("alpha0", "alpha2", "alpha3"):
        assert line["budget"][k]["Eh"] == upper[k]["Eh"] - lower[k]["Eh"]
    assert main(["energy", str(g), "--roots", "2", "--corrections"]) == 0
    text = capsys.readouterr().out
    assert "energy by order in α" in text and "lines from the lowest level" in text and "α³" not in text


def test_transitions_give_each_line_by_order_in_alpha(tmp_path, capsys):
    # hydrogen 1s, 2s → 2p, 3p: each line's α⁰ its frequency, its α² the difference of its levels'
    # Breit–Pauli corrections as `prebo properties` gives them, uncertainties in quadrature
    g = saved(tmp_path, hydrogen(0, GROUND), "g.json")
    r = saved(tmp_path, hydrogen(1, RESPONSE), "r.json")
    assert main(["transitions", str(g), str(r), "--roots", "2", "--corrections", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    bp = {(v["basis"], v["root"]): properties(capsys, (g, r)[v["basis"]], "--root", v["root"])["breit_pauli"]
          for v in out["levels"]}
    for line in out["lines"]:
        lower, upper = (out["levels"][line[k]] for k in ("lower", "upper"))
        b = line["budget"]
        assert b["alpha0"]["Eh"] == pytest.approx(line["Eh"], abs=1e-14)
        a2 = bp[upper["basis"], upper["root"]]["Eh"]["total"] - bp[lower["basis"], lower["root"]]["Eh"]["total"]
        assert b["alpha2"]["Eh"] == pytest.approx(a2, rel=1e-10, abs=1e-16)
        assert b["alpha2"]["uncertainty"] == pytest.approx(math.hypot(lower["budget"]["alpha2"]["uncertainty"],
                                                                      upper["budget"]["alpha2"]["uncertainty"]))
        assert "alpha3" not in b
    assert main(["transitions", str(g), str(r), "--roots", "2", "--corrections"]) == 0
    assert "line frequencies by order in α" in capsys.readouterr().out


def test_the_union_drops_what_its_overlap_cannot_resolve():
    # a basis joined with itself, and with its functions moved by 1e-9 relative, is itself; a
    # function 1e-3 off its neighbour's exponent stays; in hydrogen's driver-optimised k-bases the
    # union's scaled overlap had eigenvalues at −1e-12, and the Bethe logarithm failed on it
    b = hydrogen(1, even(0.01, 1e4, 3.0))
    moved = prebo.Basis(b.system, b.A * (1 + 1e-9), b.c_A, kind=b.kind, u=b.u, K=b.K)
    for other in (b, moved):
        u = union([b, other])
        assert len(u) == len(b) and not len(u.differs(b))
    apart = prebo.Basis(b.system, b.A[:1] * 1.001, b.c_A[:1], kind=b.kind, u=b.u[:1], K=b.K[:1])
    assert len(union([b, apart])) == len(b) + 1
    u = union([b, moved, apart], min_norm=1e-5)
    S = laboratory(u.system).matrices(u)["S"]
    d = 1 / np.sqrt(np.diag(S))
    assert np.linalg.eigvalsh(S * np.outer(d, d))[0] > 1e-12
