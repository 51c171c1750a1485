"""Excited states optimised (issue 39): `[state] root = k` or `roots = K` (with `weights`) makes the
objective the weighted sum of those eigenvalues, each an upper bound to its exact level
(Hylleraas–Undheim–MacDonald); the levels are followed by overlap (optimise/objective.py)."""
import json

import numpy as np
import pytest

import prebo
from prebo.cli import main
from prebo.errors import InputError
from prebo.integrals import laboratory
from prebo.optimise import optimise, resume_from
from prebo.optimise.expansion import Expansion
from prebo.optimise.objective import Levels
from prebo.optimise.settings import Optimiser

from conftest import hydrogen_s


def test_hydrogen_1s_2s_3s_optimised_as_roots_0_to_2_within_1e8():
    """H (finite proton mass), plain ECGs, roots = 3: the three levels of one basis within 1e-8
    relative of −μ/(2n²), each above it; the stored basis re-evaluates to the same three energies."""
    system = prebo.System(["p", "e"], prebo.State(roots=3))
    basis = optimise(system, Optimiser(size=30, seed=1, refine=6, polish=20), progress=False)
    m = system.masses
    mu = m[0] * m[1] / (m[0] + m[1])
    r = prebo.evaluate(basis)
    exact = np.array([-mu / (2 * n**2) for n in (1, 2, 3)])
    energies = np.array([v["energy"] for v in r["levels"]])
    assert r["targets"] == [0, 1, 2] and len(energies) == 3
    assert np.all(energies > exact) and np.all((energies - exact) / -exact < 1e-8), (energies - exact) / -exact
    again = prebo.Basis.from_dict(json.loads(json.dumps(prebo.io.basis_json.to_dict(basis))), "stored")
    assert [v["energy"] for v in prebo.evaluate(again)["levels"]] == list(energies)


def test_one_excited_root_alone_is_optimised_and_reported():
    """root = 1 optimises the 2s level alone: within 1e-7 relative, above −μ/8; the result reports
    roots 0..1 and the target."""
    system = prebo.System(["p", "e"], prebo.State(root=1))
    basis = optimise(system, Optimiser(size=16, seed=2, refine=4, polish=10), progress=False)
    m = system.masses
    mu = m[0] * m[1] / (m[0] + m[1])
    r = prebo.evaluate(basis)
    assert r["targets"] == [1] and [v["root"] for v in r["levels"]] == [0, 1]
    assert 0 < (r["levels"][1]["energy"] + mu / 8) / (mu / 8) < 1e-7


def test_a_crossing_in_a_group_refinement_keeps_the_target():
    """A basis of 1s functions and one diffuse Gaussian targets root 1, the diffuse state (bound:
    below H's threshold of 0); two idle tight functions are replaced at once by one in the 2s
    region and a more diffuse one. A 2s-like root comes in below the target: root 1 of the new
    basis lies 0.09 Eh lower, a gain the target never made; followed by overlap, the target is
    root 2, said so, and its energy is its own (it gained 1.6e-3 Eh)."""
    tight, idle = [0.2, 0.6, 1.8, 5.4, 16.0, 4e-4], [1000.0, 3000.0]
    basis, _ = hydrogen_s(tight + idle)
    rep = laboratory(basis.system)
    ex = Expansion(basis, rep, 4 * 2.0**-53, objective=Levels((1,), threshold=0.0))
    before = ex.energy
    c_before = ex.eig.vectors[:, 1]
    moved = [hydrogen_s([a])[0] for a in (0.03, 2e-4)]
    assert ex.put_group([6, 7], moved)
    assert (ex.followed.before, ex.followed.after) == ((1,), (2,)) and ex.objective.roots == (2,)
    assert ex.energy == ex.eig.energies[2] and before - 2e-3 < ex.energy < before - 1e-3
    naive = Expansion(ex.basis, rep, 4 * 2.0**-53, objective=Levels((1,)))
    assert naive.energy < before - 0.08  # what the index alone would have taken for a gain
    S = ex.m.S
    overlap = (np.concatenate([c_before[:6], [0, 0]]) @ S @ ex.eig.vectors[:, :3]) ** 2
    assert np.argmax(overlap) == 2 and overlap[2] > 0.5
    basis, _ = hydrogen_s(tight + idle)  # put_group changed the first in place
    unbound = Expansion(basis, rep, 4 * 2.0**-53, objective=Levels((1,), threshold=-1.0))  # not followed
    assert unbound.put_group([6, 7], moved) and unbound.followed is None and unbound.objective.roots == (1,)


def test_a_level_is_never_followed_below_its_target():
    """Following moves a level only to roots at or above the one it targets: root 0 of a basis is
    no bound to the exact level 1 (the variational principle)."""
    basis, _ = hydrogen_s([0.2, 0.6, 1.8, 5.4, 16.0, 4e-4, 0.03])
    ex = Expansion(basis, laboratory(basis.system), 4 * 2.0**-53, objective=Levels((1,), threshold=0.0))
    vectors = ex.eig.vectors[:, [0]]  # a level that looks like root 0 in every respect
    assert ex.objective.follow((vectors, ex.eig.energies[[0]]), ex.m.S, ex.eig) == (1,)


@pytest.mark.parametrize("state, message", [
    ({"root": -1}, "state: root = -1: must be an integer in 0.."),
    ({"roots": [1, 1]}, "state: roots = [1, 1]: must be distinct eigenvalue indices"),
    ({"roots": 0}, "state: roots = 0: must be an integer in 1.."),
    ({"roots": [0, 2], "weights": [1.0]}, "state: weights = [1.0]: 1 number for 2 roots"),
    ({"weights": [1.0, 0.5]}, "state: weights = [1.0, 0.5] without roots: weights weigh the levels roots names"),
    ({"roots": 2, "weights": [1.0, 0.0]}, "state: weights = 0.0: must be a finite number"),
    ({"root": 1, "roots": 2}, "state: root = 1 and roots = 2: give one of them"),
    ({"root": True}, "state: root = True: must be an integer"),
    ({"root": 30}, "state: root 30 asked for, but a basis of size = 30 holds roots 0..29 only"),
])
def test_bad_roots_are_refused_in_one_line(tmp_path, capsys, state, message):
    keys = "".join(f"{k} = {json.dumps(v).lower()}\n" for k, v in state.items())
    path = tmp_path / "in.toml"
    path.write_text(f'[system]\nparticles = ["p", "e"]\n[state]\n{keys}[basis]\nsize = 30\n[optimiser]\nsweeps = 0\n')
    assert main(["run", str(path), "--out", str(tmp_path / "run"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.splitlines()) == 1, err
    assert err.startswith(f"prebo: error: {path}: "), err


def test_the_state_keeps_its_levels_through_a_basis_file_and_the_api():
    a, b = prebo.State(roots=[2, 0], weights=[0.5, 1.0]), prebo.State(roots=[0, 2], weights=[1.0, 0.5])
    assert a == b and a.levels == ((0, 2), (1.0, 0.5)) and prebo.State(root=0) == prebo.State()
    system = prebo.System(["p", "e"], a)
    assert system.to_dict()["state"] | {} == {"N": 0, "parity": 1, "spin": {}, "roots": [0, 2], "weights": [1.0, 0.5]}
    assert prebo.System.from_dict(system.to_dict()).state == a
    with pytest.raises(InputError, match="state: unknown keys"):
        prebo.System.from_dict({"particles": ["p", "e"], "state": {"root": 1}})


def test_a_run_for_several_roots_resumes_bit_for_bit(tmp_path):
    """A fixed-schedule run for roots = 2 stopped by its budget and resumed ends with the basis of an
    uninterrupted run, bit for bit; the checkpoint keeps where the levels stand."""
    system = prebo.System(["p", "e"], prebo.State(roots=2, weights=[1.0, 2.0]))
    opts = Optimiser(size=10, seed=4, refine=2, polish=4)
    whole = optimise(system, opts, out=tmp_path / "whole", progress=False)
    from dataclasses import replace
    optimise(system, replace(opts, budget=0.5), out=tmp_path / "part", progress=False)
    resumed, _ = resume_from(tmp_path / "part", progress=False, budget=1e9)
    assert np.array_equal(resumed.A, whole.A)
    d = json.loads((tmp_path / "whole" / "basis.json").read_text())
    assert d["levels"] == [0, 1] and d["followed"] == [] and d["system"]["state"]["roots"] == [0, 1]
    # the file's energy is the lowest root's, the objective Σ w_k E_k what the history records
    levels = [v["energy"] for v in prebo.evaluate(prebo.Basis.load(tmp_path / "whole" / "basis.json"), roots=2)["levels"]]
    assert d["energy"] == pytest.approx(levels[0], rel=1e-13)
    assert d["objective"] == pytest.approx(levels[0] + 2 * levels[1], rel=1e-13) == d["history"][-1][1]



@pytest.fixture(scope="module")
def roots_2(tmp_path_factory):
    """The checkpoint of a short fixed-schedule run of H for roots = 2 (levels [0, 1], never moved)."""
    folder = tmp_path_factory.mktemp("roots_2")
    optimise(prebo.System(["p", "e"], prebo.State(roots=2, weights=[1.0, 2.0])),
             Optimiser(size=6, seed=4, refine=1, polish=1), out=folder, progress=False)
    return json.loads((folder / "basis.json").read_text())


@pytest.mark.parametrize("edit, message", [
    ({"levels": [0, 0]}, "levels = [0, 0]: must be distinct root indices, one per targeted level"),
    ({"levels": [1, 0]}, "levels = [1, 0]: must be 2 root indices, one per targeted level, each at or above its "
                         "target [0, 1]"),
    ({"levels": [0]}, "levels = [0]: must be 2 root indices, one per targeted level, each at or above its target "
                      "[0, 1]"),
    ({"roots": [0, 2]}, "system.state: roots = [0, 2]: not the roots the run targeted (its objective is not Σ w_k "
                        "E_k there; its levels = [0, 1] never moved)"),
    ({"roots": [0, 1, 2], "weights": [1.0, 1.0, 1.0]}, "system.state: roots = [0, 1, 2]: not the roots the run "
                                                       "targeted (its objective is not Σ w_k E_k there;"),
    ({"followed": [[1.0, [0, 1], [0, 2]]], "levels": [0, 2], "roots": [0, 3]},
     "system.state: roots = [0, 3]: not the roots the run targeted (where its levels started, followed[0]: [0, 1])"),
], ids=["levels-repeated", "levels-swapped", "levels-short", "roots", "roots-and-weights", "roots-followed"])
def test_an_edited_checkpoints_levels_or_roots_are_named_with_the_file(roots_2, tmp_path, capsys, edit, message):
    """A checkpoint whose levels or state's roots were edited was refused as "checkpoint: levels =
    …" — no file, and an edit of the roots reported as the levels (the old ones, which fit no
    longer); now the file, the key edited and its value as read: the roots where the levels do not
    start there (the record of where they moved, or the objective the checkpoint records)."""
    d = json.loads(json.dumps(roots_2))
    for key, value in edit.items():
        (d["system"]["state"] if key in ("roots", "weights") else d)[key] = value
    (tmp_path / "basis.json").write_text(json.dumps(d))
    assert main(["run", "--resume", str(tmp_path), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"prebo: error: {tmp_path / 'basis.json'}: {message}") and err.count("\n") == 1, err


@pytest.mark.parametrize("particles", [["p", "e", "e"], ["e+", "e", "e"]], ids=["H-", "Ps-"])
def test_root_1_of_h_minus_and_ps_minus_is_optimised_and_reported_not_bound(tmp_path, capsys, particles):
    """H⁻ and Ps⁻ have one bound S state: optimised for roots = 2, root 0 is bound and root 1 lies
    above the lowest threshold (H + e, Ps + e), said so in the result and in one warning line —
    never claimed as a level (a root 1 below the threshold would break the variational principle)."""
    path = tmp_path / "in.toml"
    names = ", ".join(f'"{p}"' for p in particles)
    path.write_text(f"[system]\nparticles = [{names}]\n[state]\nspin = {{ e = 0 }}\nroots = 2\n[basis]\nsize = 14\n"
                    "[optimiser]\nrefine = 2\npolish = 5\nseed = 1\n")
    assert main(["run", str(path), "--out", str(tmp_path / "run"), "--quiet"]) == 0
    r = json.loads((tmp_path / "run" / "result.json").read_text())
    assert r["targets"] == [0, 1] and r["bound"] and r["levels"][0]["bound"]
    assert not r["levels"][1]["bound"] and r["levels"][1]["energy"] > r["threshold"]
    err = capsys.readouterr().err
    assert "level 1 not below the dissociation threshold" in err and len(err.splitlines()) == 1
    # the head of the text output is root 0's, and says so where other levels were optimised
    assert main(["energy", str(tmp_path / "run" / "basis.json")]) == 0
    out = capsys.readouterr().out
    assert "energy of root 0 (translation-free)" in out and "binding energy of root 0" in out


def test_a_root_1_run_writes_root_1_at_the_top_of_its_result(tmp_path):
    """`prebo run` of a root = 1 input (H's 2s level): result.json's top-level energy, uncertainty
    and virial coefficient are root 1's (`root`), the level it optimised, not root 0's (issue 56)."""
    path = tmp_path / "in.toml"
    path.write_text('[system]\nparticles = ["p", "e"]\n[state]\nroot = 1\n[basis]\nsize = 8\n'
                    "[optimiser]\nrefine = 2\npolish = 5\nseed = 2\n")
    assert main(["run", str(path), "--out", str(tmp_path / "run"), "--quiet"]) == 0
    r = json.loads((tmp_path / "run" / "result.json").read_text())
    assert r["targets"] == [1] and r["root"] == 1 and [v["root"] for v in r["levels"]] == [0, 1]
    assert r["energy"] > r["levels"][0]["energy"] + 0.3  # 2s, not 1s (−μ/8 against −μ/2)
    assert {k: r[k] for k in ("energy", "energy_uncertainty", "virial")} == \
        {k: r["levels"][1][k] for k in ("energy", "energy_uncertainty", "virial")}
