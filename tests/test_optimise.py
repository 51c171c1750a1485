"""Optimiser runs: checkpoints, exact resumption after a kill, the files of a run (basis.json,
lowest.json), the refusals of optimise and resume_from."""
import json
import signal
import subprocess
import sys

import numpy as np
import pytest

import prebo
from prebo.optimise import Optimiser
from prebo.optimise.defaults import resolved
from conftest import INPUT, ROOT, functions, mid_schedule


def run(*args):
    return subprocess.Popen([sys.executable, "-m", "prebo", "run", *map(str, args), "--quiet"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def test_a_killed_run_resumes_to_the_same_basis(tmp_path):
    (tmp_path / "in.toml").write_text(INPUT)
    whole = run(tmp_path / "in.toml", "--out", tmp_path / "whole")
    assert whole.wait(timeout=300) == 0, whole.stderr.read()

    killed = run(tmp_path / "in.toml", "--out", tmp_path / "killed")
    mid_schedule(tmp_path / "killed")
    killed.send_signal(signal.SIGKILL)
    killed.wait()
    cut = json.loads((tmp_path / "killed" / "basis.json").read_text())["progress"]
    assert cut["phase"] != "done", "the run ended before it was killed: nothing tested"
    resumed = subprocess.run([sys.executable, "-m", "prebo", "run", "--resume", tmp_path / "killed", "--quiet"],
                             capture_output=True, text=True)
    assert resumed.returncode == 0, resumed.stderr
    assert functions(tmp_path / "killed") == functions(tmp_path / "whole")
    a = json.loads((tmp_path / "whole" / "result.json").read_text())["energy"]
    b = json.loads((tmp_path / "killed" / "result.json").read_text())["energy"]
    assert a == b


def test_resume_without_checkpoint_is_a_clear_error(tmp_path):
    r = subprocess.run([sys.executable, "-m", "prebo", "run", "--resume", tmp_path], capture_output=True, text=True)
    assert r.returncode == 2 and "no checkpoint" in r.stderr and "Traceback" not in r.stderr


def test_a_checkpoint_holding_more_functions_than_its_size_allows_is_refused(tmp_path, capsys):
    """An edited checkpoint (size 6 → 3, six functions, still growing) resumed grew past its size;
    now it is a one-line error naming the file."""
    from prebo.cli import main
    prebo.optimise(prebo.System(["p", "e"]), Optimiser(size=6, seed=1, refine=1, polish=1), out=tmp_path / "run",
                   progress=False)
    f = tmp_path / "run" / "basis.json"
    d = json.loads(f.read_text())
    d["optimiser"]["size"], d["progress"] = 3, {"phase": "grow", "sweep": 0, "index": 0, "cycle": 0}
    f.write_text(json.dumps(d))
    assert main(["run", "--resume", str(tmp_path / "run"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert f"{f}: 6 functions, more than the run's size = 3" in err and err.count("\n") == 1, err


@pytest.fixture(scope="module")
def six(tmp_path_factory):
    """Checkpoints of six functions of H: of a fixed schedule that does not prune and of an adaptive
    one run to its end."""
    d = tmp_path_factory.mktemp("six")
    system = prebo.System(["p", "e"])
    prebo.optimise(system, Optimiser(size=6, trials=2, seed=1, refine=0, polish=0), out=d / "fixed", progress=False)
    prebo.optimise(system, Optimiser(size=6, trials=2, seed=1), out=d / "adaptive", progress=False)
    return {name: json.loads((d / name / "basis.json").read_text()) for name in ("fixed", "adaptive")}


@pytest.mark.parametrize("name", ["fixed", "adaptive"])
def test_a_checkpoint_one_function_above_its_size_is_refused_where_the_schedule_does_not_prune_past_it(
        six, tmp_path, capsys, name):
    """A checkpoint of six functions whose size is edited to 5 resumed and ended with six (so did
    one of 40 edited to 37 or 39): the margin of a pruning pass (adaptive.pruned) was granted to a
    fixed schedule that does not prune and to an adaptive one, which prunes in one step and so
    never leaves a checkpoint above its size. A fixed schedule's pruning keeps its margin: that
    checkpoint with size 5 and prune = 1, between its growth and its removal, resumes to five."""
    from prebo.cli import main
    d = json.loads(json.dumps(six[name]))
    assert len(d["functions"]) == 6
    d["optimiser"]["size"] = 5
    f = tmp_path / "basis.json"
    f.write_text(json.dumps(d))
    assert main(["run", "--resume", str(tmp_path), "--quiet", "--budget", "1e9"]) == 2
    err = capsys.readouterr().err
    assert err == f"prebo: error: {f}: 6 functions, more than the run's size = 5 allows\n"
    if name == "fixed":
        d["optimiser"]["prune"], d["progress"] = 1, {"phase": "prune", "sweep": 0, "index": 1, "cycle": 0}
        f.write_text(json.dumps(d))
        assert main(["run", "--resume", str(tmp_path), "--quiet"]) == 0
        assert len(functions(tmp_path)) == 5 and json.loads((tmp_path / "result.json").read_text())["n_basis"] == 5


def test_a_checkpoint_has_a_line_per_key_and_per_function():
    """basis.json as write_json_atomic lays it out: strict JSON, a line per top-level key and per
    element of the function list (compact lines keep json's C encoder: indent would not)."""
    import tempfile
    from pathlib import Path
    basis = prebo.Basis.load(ROOT / "examples" / "bases" / "h2plus-gvr" / "basis.json")
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "basis.json"
        basis.save(path)
        text = path.read_text()
    d = json.loads(text)
    assert d["functions"] == json.loads((ROOT / "examples" / "bases" / "h2plus-gvr" / "basis.json").read_text())["functions"]
    lines = text.splitlines()
    assert len(lines) == 2 + len(d) + 1 + len(d["functions"])  # braces, keys, the list's closing bracket


def test_history_rows_are_named_in_memory_and_stored_as_they_were(tmp_path):
    """history.Step names a row's fields; written back, a checkpoint's rows are the lists it held,
    a row per line, the three-long rows of checkpoints before wall times included."""
    from prebo.io.files import write_json_atomic
    from prebo.optimise.history import Step, check_history
    rows = [[1, -0.4, "grow"], [2, -0.45, "grow", 1.5], [2, -0.47, "refine", 3.0]]
    steps = [Step(*row) for row in check_history(json.loads(json.dumps(rows)))]
    assert [(h.size, h.energy, h.phase, h.seconds) for h in steps] == [(1, -0.4, "grow", None), (2, -0.45, "grow", 1.5),
                                                                        (2, -0.47, "refine", 3.0)]
    assert steps[1] == Step(2, -0.45, "grow", 1.5) and Step(1, -0.4, "grow").row() == [1, -0.4, "grow"]
    write_json_atomic(tmp_path / "h.json", {"history": [step.row() for step in steps]})
    written = (tmp_path / "h.json").read_text()
    write_json_atomic(tmp_path / "h.json", {"history": rows})
    assert written == (tmp_path / "h.json").read_text() and len(written.splitlines()) == 4 + len(rows)  # a row per line


def test_a_run_that_stops_above_its_lowest_state_returns_that_state_and_keeps_it_in_lowest_json(tmp_path, monkeypatch):
    """A fixed-schedule pruning that raises the energy (made to remove the dearest functions)
    leaves the run above the state it pruned: the run returns that state, out/lowest.json holds
    it beside the checkpoint, and a resumed run returns it too."""
    from prebo import eigen
    from prebo.optimise import optimise, resume_from

    without = eigen.root_without_each
    monkeypatch.setattr(eigen, "root_without_each", lambda E, C, root=0: -without(E, C, root))
    system = prebo.System(["p", "e"])
    basis = optimise(system, Optimiser(size=3, prune=2, cycles=1, trials=5, seed=3), out=tmp_path, progress=False)
    checkpoint = json.loads((tmp_path / "basis.json").read_text())
    lowest = json.loads((tmp_path / "lowest.json").read_text())
    grown = [h for h in checkpoint["history"] if h[2] == "grow"][-1]  # the state the pruning started from
    assert grown[0] == 3 and lowest["energy"] == grown[1] < checkpoint["energy"]
    assert len(basis) == 3 and prebo.evaluate(basis)["energy"] == pytest.approx(lowest["energy"], rel=1e-14)
    assert prebo.evaluate(prebo.Basis.load(tmp_path / "lowest.json"))["energy"] == pytest.approx(lowest["energy"],
                                                                                                 rel=1e-14)
    again, _ = resume_from(tmp_path, progress=False)
    assert prebo.evaluate(again)["energy"] == pytest.approx(lowest["energy"], rel=1e-14)


def test_optimise_refuses_an_out_of_the_wrong_type_and_one_holding_a_checkpoint(tmp_path):
    """optimise(..., out=5) raised TypeError, and a new run into a folder holding a checkpoint
    overwrote that run; resuming it is still possible."""
    from prebo.errors import InputError, OutputError
    from prebo.optimise import optimise, resume_from

    h, opts = prebo.System(["p", "e"]), Optimiser(size=2, trials=2, seed=1)
    for bad in (5, 2.5, ["runs"]):
        with pytest.raises(InputError, match=r"optimise: out = .*: must be a folder \(a str or path\), or None"):
            optimise(h, opts, out=bad, progress=False)
    optimise(h, opts, out=tmp_path, progress=False)
    before = (tmp_path / "basis.json").read_bytes()
    with pytest.raises(OutputError, match=r"out = '.*' holds a run's checkpoint \(basis.json\): continue that run "
                                          r"with resume_from\(out\)"):
        optimise(h, opts, out=str(tmp_path), progress=False)
    assert (tmp_path / "basis.json").read_bytes() == before
    assert len(resume_from(tmp_path, progress=False)[0]) == 2


def test_optimise_refuses_an_empty_out_and_resume_from_a_folder_that_is_not_a_path(tmp_path, monkeypatch):
    """optimise(..., out="") wrote its checkpoint into the current folder; resume_from(5) raised TypeError."""
    from prebo.errors import InputError
    from prebo.optimise import optimise, resume_from

    monkeypatch.chdir(tmp_path)
    with pytest.raises(InputError, match=r"optimise: out = '': empty; must be a folder \(a str or path\), or None"):
        optimise(prebo.System(["p", "e"]), Optimiser(size=2, trials=2, seed=1), out="", progress=False)
    assert not list(tmp_path.iterdir())
    for bad in (5, None, ["runs"], ""):
        with pytest.raises(InputError, match=r"resume_from: folder = .*must be a folder \(a str or path\)"):
            resume_from(bad, progress=False)


def test_lowest_json_is_written_when_the_run_leaves_its_lowest_state_and_removed_when_it_is_back(tmp_path):
    """lowest.Lowest: a state above the lowest, or of more than `size` functions, writes the
    lowest to lowest.json; a state as low at the size removes it; a fresh run's tracker removes a
    file an earlier run left, a resumed run's reads it back and refuses one of another system."""
    from types import SimpleNamespace
    from prebo.optimise.lowest import Lowest

    basis = prebo.Basis.load(ROOT / "examples/bases/h/basis.json")

    def state(n, energy):
        return SimpleNamespace(basis=basis.subset(slice(0, n)), energy=energy, coefficients=np.eye(n)[:, 0],
                               lowest_root=energy, objective=SimpleNamespace(lowest=True, recorded=False))

    lowest, path = Lowest(basis, 3, tmp_path, {"optimiser": {}}, resumed=False), tmp_path / "lowest.json"
    lowest.see(state(3, -0.4))
    assert not path.exists() and lowest.energy == -0.4
    lowest.see(state(4, -0.45))  # beyond the size: not a candidate, the lowest is written
    assert json.loads(path.read_text())["energy"] == -0.4 and len(lowest.basis) == 3
    assert Lowest(basis, 3, tmp_path, {}, resumed=True).energy == -0.4
    with pytest.raises(prebo.errors.BasisFileError, match="lowest.json: not a state of this run"):
        Lowest(prebo.Basis.empty(prebo.System(["alpha", "e", "e"], spin={"e": 0})), 3, tmp_path, {}, resumed=True)
    lowest.see(state(3, -0.3))
    assert lowest.energy == -0.4 and path.exists()
    lowest.see(state(2, -0.4))  # back as low: the run stands at its lowest, the file goes
    assert not path.exists() and len(lowest.basis) == 2
    lowest.see(state(3, -0.2))
    assert path.exists()
    assert Lowest(basis, 3, tmp_path, {}, resumed=False).energy == np.inf and path.exists()  # a new run's own


def test_a_whole_basis_with_a_function_the_symmetriser_annihilates_is_not_taken():
    """Expansion.replace_basis (joint steps, momentum moves) refuses a basis in which a function lost
    its digits to the symmetriser (what prebo.evaluate would refuse at the end of the run): a triplet's
    function symmetric in the two electrons to 1e-9 is annihilated to 1e-9 of its norm."""
    from conftest import pair_A
    from prebo.basis import Basis
    from prebo.integrals import laboratory
    from prebo.optimise.expansion import Expansion

    system = prebo.System(["alpha", "e", "e"], spin={"e": 1})
    A = [pair_A(system, {(0, 1): a1, (0, 2): a2, (1, 2): 0.1}, 1.0) for a1, a2 in ((1.0, 0.3), (2.0, 0.5), (0.8, 0.2))]
    basis = Basis(system, np.array(A), np.ones(3), ["pairs"] * 3)
    ex = Expansion(basis, laboratory(system), 4 * 2.0**-53)
    energy = ex.energy
    symmetric = pair_A(system, {(0, 1): 0.7, (0, 2): 0.7 * (1 + 1e-9), (1, 2): 0.1}, 1.0)
    moved = Basis(system, np.array(A[:2] + [symmetric]), np.ones(3), ["pairs"] * 3)
    assert not ex.replace_basis(moved)
    assert ex.energy == energy and np.array_equal(ex.basis.A, basis.A) and ex.resolved()
