"""Fuzzing (issue 13): random corruptions of basis.json files, run checkpoints, TOML inputs and API
arguments. Whatever the corruption, prebo either takes the input (a finite result, strict JSON)
or refuses it with one line and exit 2 (CLI) or a PreboError (API) — never a traceback, a NaN
or a hang. Derandomised, so CI sees the same examples; the CLI runs in-process. The last tests
run real processes: a closed output pipe, and a kill during a checkpoint write."""
import contextlib
import json
import math
import os
import shutil
import signal
import stat
import subprocess
import sys
import warnings
from pathlib import Path
from unittest import mock

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import prebo
import prebo.io.ecgpack
from prebo.basis import FAMILIES
from prebo.cli import main
from prebo.errors import PreboError
from prebo.optimise import SETTINGS

from conftest import POSIX_FILES, h_input, prebo_process, toml_text

ROOT = Path(__file__).resolve().parents[1]
BASES = ROOT / "examples" / "bases"

#: where the optimisation is looked up: the package (by cli) and its driver (by resume_from);
#: sys.modules, because prebo.optimise is the function
OPTIMISING = [sys.modules["prebo.optimise"], sys.modules["prebo.optimise.driver"]]

FUZZ = settings(max_examples=100, deadline=None, derandomize=True, database=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])

#: values at the edges of what prebo takes: empty, zero, negative, huge, non-finite, of the wrong type
EDGES = st.sampled_from([[], {}, "", 0, 1, -1, 2, 9, 10**9, 0.0, -1.0, 0.5, 1e300, 1e-300, float("nan"), float("inf"),
                         "1", "x", True, [1.0], [0.1, float("inf")], ["hpc:9"], "pecg", "ecg-gvr", "all", "e"])
SCALARS = (st.none() | st.booleans() | st.integers(-10, 10) | st.integers(-2**70, 2**70)
           | st.floats(allow_nan=True, allow_infinity=True) | st.text(max_size=4))
JSON = EDGES | EDGES | st.recursive(SCALARS, lambda inner: st.lists(inner, max_size=3)
                                    | st.dictionaries(st.text(max_size=3), inner, max_size=3), max_leaves=6)
TOML = EDGES | EDGES | st.recursive(SCALARS.filter(lambda v: v is not None),
                                    lambda inner: st.lists(inner, max_size=3)
                                    | st.dictionaries(st.text("abcNe", min_size=1, max_size=3), inner, max_size=2),
                                    max_leaves=4)


#: positions a corruption most often matters at (the state, the particles, the functions, the symmetry)
SENSITIVE = [("system", "state", "N"), ("system", "state", "parity"), ("system", "state", "spin"),
             ("system", "state", "threshold"),
             ("system", "particles"), ("system", "particles", 0, "charge"), ("system", "particles", 1, "mass"),
             ("system", "particles", 0, "spin"), ("functions",), ("functions", 0), ("functions", 0, "A"),
             ("functions", 0, "c_A"), ("functions", 0, "K"), ("functions", 0, "u"), ("basis_type",),
             ("symmetry", "permutations", 0), ("symmetry", "coefficients"), ("coefficients",)]


def mutate(doc, data):
    """Replace, delete or grow one position of `doc` (a deep copy) with values drawn from `data`:
    a `SENSITIVE` one, or one found by descending from the root into random children."""
    doc = json.loads(json.dumps(doc))
    parent, key = {"doc": doc}, "doc"
    target = data.draw(st.sampled_from(SENSITIVE) | st.none())
    try:
        for k in target or ():
            parent, key = parent[key], k
            parent[key]
    except (KeyError, IndexError, TypeError):
        parent, key = {"doc": doc}, "doc"
    while isinstance(parent[key], (dict, list)) and parent[key] and (key == "doc" or not target and
                                                                      data.draw(st.booleans())):
        node = parent[key]
        parent, key = node, data.draw(st.sampled_from(sorted(node) if isinstance(node, dict) else range(len(node))))
    action = data.draw(st.sampled_from(["replace"] * 4 + ["delete", "append"]))
    if action == "delete":
        del parent[key]
    elif action == "append" and isinstance(parent[key], list):
        parent[key].append(data.draw(JSON))
    else:
        parent[key] = data.draw(JSON)
    return doc


def assert_clean(rc, out, err):
    """Exit 0 with strict JSON, a finite energy and a state the basis type can describe, or exit 2
    with one `prebo: error:` line."""
    if rc == 0:
        r = json.loads(out, parse_constant=lambda c: pytest.fail(f"{c} in the JSON output"))
        assert np.isfinite(r["energy"]) and np.isfinite(r["threshold"]) and isinstance(r["bound"], bool)
        N, parity = r["state"]["N"], r["state"]["parity"]
        assert {"pecg": (N, parity) == (0, 1), "ecg-gvr": parity == (-1) ** N}.get(r["basis_type"], True), r["state"]
    else:
        assert rc == 2 and out == "", (rc, out, err)
        assert err.startswith("prebo: error: ") and err.count("\n") == 1 and "Traceback" not in err, err


@pytest.fixture(scope="module")
def checkpoints(tmp_path_factory):
    """Run checkpoints (basis.json with optimiser state) of three basis types."""
    d = tmp_path_factory.mktemp("checkpoints")
    runs = {
        "pecg": (prebo.System(["p", "e", "e"], spin={"e": 0}, threshold=-0.6),
                 prebo.Optimiser(size=3, trials=3, seed=2, sweeps=1)),
        "gvr": (prebo.System(["p", "e"], N=1, parity=-1),
                prebo.Optimiser(size=3, trials=3, seed=2, kind="ecg-gvr", K_max=2, channels=["jacobi:0-1"])),
        "fecg": (prebo.System(["p", "e"]), prebo.Optimiser(size=2, trials=3, seed=2, kind="fecg")),
    }
    for name, (system, opts) in runs.items():
        prebo.optimise(system, opts, out=d / name, progress=False)
    return {name: json.loads((d / name / "basis.json").read_text()) for name in runs}


BASIS_KEYS = ("format", "version", "system", "symmetry", "basis_type", "functions", "coefficients")


@FUZZ
@given(data=st.data())
def test_corrupted_basis_files(checkpoints, tmp_path, capsys, data):
    doc = checkpoints[data.draw(st.sampled_from(sorted(checkpoints)))]
    doc = mutate({k: doc[k] for k in BASIS_KEYS}, data)
    f = tmp_path / "basis.json"
    f.write_text(json.dumps(doc))
    assert_clean(main(["energy", str(f), "--json"]), *capsys.readouterr())


@FUZZ
@given(name=st.sampled_from(["pecg", "gvr", "fecg"]), kind=st.sampled_from(["pecg", "ecg-gvr", "fecg"]),
       N=st.integers(0, 3), parity=st.sampled_from([1, -1]))
def test_basis_files_relabelled_to_another_state_or_type(checkpoints, tmp_path, capsys, name, kind, N, parity):
    """Never a number for a state the basis type cannot describe (plain ECGs: N = 0, parity +1;
    ECG-GVR: parity (-1)^N), whatever a file says."""
    doc = json.loads(json.dumps(checkpoints[name]))
    doc["system"]["state"].update(N=N, parity=parity)
    doc["basis_type"] = kind
    f = tmp_path / "basis.json"
    f.write_text(json.dumps(doc))
    assert_clean(main(["energy", str(f), "--json"]), *capsys.readouterr())


#: small stored bases whose states have one-dimensional symmetry (every operator of such a state is
#: its own up to a factor): an edited one that is taken must give exactly the energy of its label
LABELLED = ["he", "h2plus-gvr", "h2plus-fecg", "h2-pecg"]


#: numbers at and beyond the edges of double precision, as a file may hold them
EDGE_NUMBERS = st.sampled_from(["1e300", "1.0E+301", "-1e308", "1.7976931348623157e308", "1e154", "-1e154", "1e-300",
                                "1e-320", "1e400", "-2.5e308"])
PLACE = '"@number@"'


def number_in_basis_json(doc: dict, data) -> str:
    """The text of basis file `doc` with one edge number put where a file holds numbers: a
    function's A and c_A scaled by it (as a whole: still symmetric and separable), or one of its
    u or s, or one coefficient."""
    doc = json.loads(json.dumps(doc))
    f = data.draw(st.sampled_from(doc["functions"]))
    where = data.draw(st.sampled_from(["scale"] + [k for k in ("u", "s") if k in f]
                                      + (["coefficients"] if doc.get("coefficients") else [])))
    x = data.draw(EDGE_NUMBERS)
    if where == "scale":  # a product beyond the largest double (or 1e400 itself) written as the number's text
        def scaled(a):
            return a * float(x) if math.isfinite(a * float(x)) else PLACE
        f["A"], f["c_A"] = [[scaled(a) for a in row] for row in f["A"]], scaled(f["c_A"])
    elif where == "coefficients":
        doc["coefficients"][data.draw(st.integers(0, len(doc["coefficients"]) - 1))] = PLACE
    else:
        row = f[where] if not isinstance(f[where][0], list) else data.draw(st.sampled_from(f[where]))
        row[data.draw(st.integers(0, len(row) - 1))] = PLACE
    return json.dumps(doc, allow_nan=False).replace(json.dumps(PLACE), x)


@pytest.fixture(scope="module")
def inout(tmp_path_factory, checkpoints):
    """The pecg checkpoint as an ecgpack file's lines."""
    path = tmp_path_factory.mktemp("inout") / "pecg.inout.txt"
    prebo.io.ecgpack.write_inout(prebo.Basis.from_dict(checkpoints["pecg"]), path)
    return path.read_text().splitlines()


@FUZZ
@given(data=st.data())
def test_numbers_at_the_edge_of_double_precision_in_files(checkpoints, inout, tmp_path, capsys, data):
    """Issue 55, item 2: a number at or beyond the largest double in a basis.json's exponents,
    coefficients, u or s, or in an ecgpack basis line: a finite result or one line naming the file,
    and no numpy warning ahead of either (warnings are errors here)."""
    if data.draw(st.booleans()):
        f = tmp_path / "basis.json"
        f.write_text(number_in_basis_json(checkpoints[data.draw(st.sampled_from(sorted(checkpoints)))], data))
    else:
        f = tmp_path / "edge.inout.txt"
        lines = list(inout)
        k = data.draw(st.integers(len(lines) - 3, len(lines) - 1))
        values = lines[k].split()
        values[data.draw(st.integers(1, len(values) - 1))] = data.draw(EDGE_NUMBERS)
        lines[k] = " ".join(values)
        f.write_text("\n".join(lines) + "\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        rc = main(["energy", str(f), "--json"])
    out, err = capsys.readouterr()
    assert_clean(rc, out, err)
    assert rc == 0 or err.startswith(f"prebo: error: {f}"), err


@pytest.fixture(scope="module")
def labelled():
    """The first 20 functions of each LABELLED basis, with its system, symmetry and basis type."""
    bases = Path(__file__).resolve().parents[1] / "examples" / "bases"
    docs = {name: json.loads((bases / name / "basis.json").read_text()) for name in LABELLED}
    return {name: {k: d[k] for k in BASIS_KEYS if k != "coefficients"} | {"functions": d["functions"][:20]}
            for name, d in docs.items()}


def edit_label(doc, data) -> None:
    """One edit of what basis file `doc` says it is: a group's spin relabelled, a permutation of the
    symmetry dropped, replaced or added, a coefficient edited (within rounding too), the basis type
    relabelled (with the functions' keys rewritten to the new family's, or not), the symmetry
    replaced by that of the label, or dropped."""
    sym, n = doc.get("symmetry"), len(doc["system"]["particles"])
    what = data.draw(st.sampled_from(["spin", "permutations", "coefficients", "kind", "label's symmetry",
                                      "no symmetry"]))
    if what == "spin":
        spins = doc["system"]["state"]["spin"]
        spins[data.draw(st.sampled_from(sorted(spins)))] = data.draw(st.sampled_from([0, 0.5, 1, 1.5, 2]))
    elif what == "permutations" and sym:
        perms, coefs = sym["permutations"], sym["coefficients"]
        k, other = data.draw(st.integers(0, len(perms) - 1)), data.draw(st.permutations(range(n)))
        action = data.draw(st.sampled_from(["drop", "replace", "add"]))
        if action == "drop":
            del perms[k], coefs[k]
        elif action == "replace":
            perms[k] = other
        else:
            perms.append(other)
            coefs.append(data.draw(st.sampled_from([1.0, -1.0, 0.5])))
    elif what == "coefficients" and sym:
        coefs = sym["coefficients"]
        k = data.draw(st.integers(0, len(coefs) - 1))
        coefs[k] = data.draw(st.sampled_from([-coefs[k], 0.0, 0.5, 2.0, coefs[k] * (1 + 1e-6), coefs[k] * (1 + 1e-13)]))
    elif what == "kind":
        kind = doc["basis_type"] = data.draw(st.sampled_from(sorted(FAMILIES)))
        if data.draw(st.booleans()):
            new = {"u": [1.0, -1.0] + [0.0] * (n - 2), "K": 0, "s": [[0.0] * 3] * n}
            doc["functions"] = [{k: v for k, v in f.items() if k in ("A", "c_A", "channel")}
                                | {k: new[k] for k in FAMILIES[kind].shapes} for f in doc["functions"]]
    elif what == "label's symmetry":
        with contextlib.suppress(PreboError):
            doc["symmetry"] = prebo.System.from_dict(doc["system"]).symmetriser.as_dict()
    else:
        doc.pop("symmetry", None)


@FUZZ
@given(name=st.sampled_from(LABELLED), data=st.data())
def test_edited_labels_are_evaluated_as_they_say_or_refused(labelled, tmp_path, capsys, name, data):
    """Relabelled spin, edited permutations and coefficients, relabelled basis type: taken only as
    what the label says (every key of the functions read, the energy of the state's own
    operator), else refused in one line (issue 37)."""
    doc = json.loads(json.dumps(labelled[name]))
    for _ in range(data.draw(st.integers(1, 3))):
        edit_label(doc, data)
    f = tmp_path / "edited.json"
    f.write_text(json.dumps(doc))
    rc = main(["energy", str(f), "--json"])
    out, err = capsys.readouterr()
    assert_clean(rc, out, err)
    if rc == 0:
        fields = {"A", "c_A", "channel", *FAMILIES[doc["basis_type"]].shapes}
        assert all(set(fn) <= fields for fn in doc["functions"]), doc["basis_type"]
        label = tmp_path / "label.json"
        label.write_text(json.dumps({k: v for k, v in doc.items() if k != "symmetry"}))
        assert main(["energy", str(label), "--json"]) == 0
        assert json.loads(out)["energy"] == json.loads(capsys.readouterr().out)["energy"]


@FUZZ
@given(data=st.data())
def test_truncated_or_garbled_basis_files(checkpoints, tmp_path, capsys, data):
    text = json.dumps(checkpoints[data.draw(st.sampled_from(sorted(checkpoints)))])
    cut = data.draw(st.integers(0, len(text)))
    junk = data.draw(st.text(max_size=3) | st.binary(max_size=3).map(lambda b: b.decode("latin-1")))
    f = tmp_path / "basis.json"
    f.write_bytes((text[:cut] + junk + text[cut + len(junk):]).encode("utf-8", "surrogateescape"))
    assert_clean(main(["energy", str(f), "--json"]), *capsys.readouterr())


class Accepted(Exception):
    """Raised in place of the optimisation once an input has passed every check."""


@contextlib.contextmanager
def accepting():
    """The optimisation replaced by `accept` wherever it is looked up."""
    with contextlib.ExitStack() as stack:
        for module in OPTIMISING:
            stack.enter_context(mock.patch.object(module, "optimise", accept))
        yield


def accept(system, opts, *args, **kwargs):
    assert isinstance(system, prebo.System) and isinstance(opts, prebo.Optimiser)
    for name, s in SETTINGS.items():  # what was accepted is within the table
        assert s.rule(getattr(opts, name)) == getattr(opts, name)
    raise Accepted


@FUZZ
@given(data=st.data())
def test_corrupted_checkpoints_on_resume(checkpoints, tmp_path, capsys, data):
    doc = checkpoints[data.draw(st.sampled_from(sorted(checkpoints)))]
    part = data.draw(st.sampled_from(["optimiser", "progress", "rng", "history", "elapsed", "functions"]))
    doc = mutate(doc, data) if part == "functions" else doc | {
        part: mutate({"x": doc[part]}, data).get("x") if data.draw(st.booleans()) else data.draw(JSON)}
    run = tmp_path / "run"
    run.mkdir(exist_ok=True)
    (run / "basis.json").write_text(json.dumps(doc))
    with accepting():
        try:
            rc = main(["run", "--resume", str(run), "--quiet"])
        except Accepted:
            return
    out, err = capsys.readouterr()
    assert rc == 2 and str(run / "basis.json") in err
    assert_clean(rc, out, err)



@pytest.fixture(scope="module")
def sized(tmp_path_factory):
    """Checkpoints of six functions of H, of each schedule kind: a fixed one that does not prune,
    and an adaptive one (which prunes in one step)."""
    d = tmp_path_factory.mktemp("sized")
    system = prebo.System(["p", "e"])
    prebo.optimise(system, prebo.Optimiser(size=6, trials=2, seed=1, refine=0, polish=0), out=d / "fixed",
                   progress=False)
    prebo.optimise(system, prebo.Optimiser(size=6, trials=2, seed=1), out=d / "adaptive", progress=False)
    return {name: json.loads((d / name / "basis.json").read_text()) for name in ("fixed", "adaptive")}


@FUZZ
@given(name=st.sampled_from(["fixed", "adaptive"]), change=st.integers(-4, 3), prune=st.sampled_from([None, 0, 1, 2]))
def test_checkpoints_whose_size_is_edited_around_their_functions(sized, tmp_path, capsys, name, change, prune):
    """A checkpoint's size edited to values around its count of functions (a fixed one's `prune`
    too, and its place between growth and pruning): refused in one line naming the file, or resumed
    to a basis no larger than the size (a fixed schedule to its end, an adaptive one with the
    budget it had spent)."""
    doc = json.loads(json.dumps(sized[name]))
    nb = len(doc["functions"])
    doc["optimiser"]["size"] = max(1, nb + change)
    if name == "fixed" and prune is not None:
        doc["optimiser"]["prune"], doc["progress"] = prune, {"phase": "prune", "sweep": 0, "index": 1, "cycle": 0}
    run = tmp_path / "run"
    run.mkdir(exist_ok=True)
    (run / "result.json").unlink(missing_ok=True)
    (run / "basis.json").write_text(json.dumps(doc))
    spent = ["--budget", str(max(doc["elapsed"], 0.1))] if name == "adaptive" else []  # not grown on to a new size
    rc = main(["run", "--resume", str(run), "--quiet", *spent])
    out, err = capsys.readouterr()
    if rc == 0:
        assert json.loads((run / "result.json").read_text())["n_basis"] <= doc["optimiser"]["size"]
    else:
        assert rc == 2 and err.startswith(f"prebo: error: {run / 'basis.json'}: ") and err.count("\n") == 1, err

TOML_KEYS = {"system": ["particles"], "state": ["N", "parity", "spin", "threshold", "root", "roots", "weights"],
             "basis": ["type", "size", "c_A", "K_max"],
             "optimiser": sorted(s.key.partition(" ")[2] for s in SETTINGS.values() if s.key.startswith("[optimiser]"))}


@FUZZ
@given(data=st.data())
def test_corrupted_toml_inputs(tmp_path, capsys, data):
    doc = h_input() | {"state": {"N": 0}}
    action = data.draw(st.sampled_from(["set"] * 6 + ["unknown key", "delete", "replace table"]))
    table = data.draw(st.sampled_from(sorted(TOML_KEYS) + ["title", "extra"] * (action == "replace table")))
    if action == "set":
        doc[table][data.draw(st.sampled_from(TOML_KEYS[table]))] = data.draw(TOML)
    elif action == "unknown key":
        doc[table][data.draw(st.text("abcNe_", min_size=1, max_size=4))] = data.draw(TOML)
    elif action == "delete":
        doc[table].pop(data.draw(st.sampled_from(sorted(doc[table]) or ["x"])), None)
    else:
        doc[table] = data.draw(TOML)
    f = tmp_path / "in.toml"
    f.write_text(toml_text(doc))
    with accepting():
        try:
            rc = main(["run", str(f), "--out", str(tmp_path / "out"), "--quiet"])
        except Accepted:
            return
    out, err = capsys.readouterr()
    assert_clean(rc, out, err)
    assert rc == 2 and str(f) in err


@FUZZ
@given(name=st.sampled_from(sorted(SETTINGS)), value=TOML | st.just(None))
def test_optimiser_arguments(name, value):
    try:
        opts = prebo.Optimiser(**{name: value})
    except PreboError as exc:
        assert f"{name} = {value!r}" in str(exc)
    else:
        assert SETTINGS[name].rule(getattr(opts, name)) == getattr(opts, name)


@FUZZ
@given(particles=st.lists(st.sampled_from(["p", "e", "e+", "alpha", "mu"]) | st.dictionaries(
    st.sampled_from(["name", "mass", "charge", "spin", "x"]), SCALARS, max_size=4), max_size=4),
    state=st.dictionaries(st.sampled_from(["N", "parity", "spin", "threshold", "root", "roots", "weights", "L"]), JSON,
                          max_size=3))
def test_system_arguments(particles, state):
    try:
        system = prebo.System(particles, **state)
    except PreboError:
        return
    assert all(np.isfinite([p.mass, p.charge]).all() and p.mass > 0 for p in system.particles)
    assert system.state.threshold is None or np.isfinite(system.state.threshold)
    roots, weights = system.state.levels
    assert list(roots) == sorted(set(roots)) and roots[0] >= 0 and len(weights) == len(roots)
    assert all(np.isfinite(w) and w > 0 for w in weights)


# --- real processes ---------------------------------------------------------------------
def test_closed_output_pipe(tmp_path, checkpoints):
    """`prebo energy --json | true`: one line and exit 2, no BrokenPipeError traceback."""
    f = tmp_path / "basis.json"
    f.write_text(json.dumps(checkpoints["pecg"]))
    read, write = os.pipe()
    os.close(read)
    try:
        r = subprocess.run([sys.executable, "-m", "prebo", "energy", str(f), "--json"], stdout=write,
                           stderr=subprocess.PIPE, text=True, timeout=120)
    finally:
        os.close(write)
    assert r.returncode == 2 and "Traceback" not in r.stderr and r.stderr.count("\n") == 1, r.stderr
    assert r.stderr.startswith("prebo: error: standard output was closed")


KILL_IN_SECOND_WRITE = """
import os, signal, sys
from prebo.cli import main
writes = 0
fsync = os.fsync
def killing_fsync(fd):
    global writes
    writes += 1
    if writes == 2:  # the second checkpoint: its temporary file is written but not yet renamed
        os.kill(os.getpid(), signal.SIGKILL)
    fsync(fd)
os.fsync = killing_fsync
main(sys.argv[1:])
"""


def test_a_kill_during_a_checkpoint_write_leaves_nothing_behind_after_resume(tmp_path):
    (tmp_path / "h.toml").write_text(toml_text(h_input()))
    out = tmp_path / "out"
    r = subprocess.run([sys.executable, "-c", KILL_IN_SECOND_WRITE, "run", tmp_path / "h.toml", "--out", out, "--quiet"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == -signal.SIGKILL, r.stderr
    assert list(out.glob("basis.json.*.tmp")), "the kill left no temporary file: nothing tested"
    resumed = prebo_process("run", "--resume", out, "--quiet")
    assert resumed.returncode == 0, resumed.stderr
    assert not list(out.glob("*.tmp")) and (out / "result.json").exists()
    assert len(json.loads((out / "basis.json").read_text())["functions"]) == 3


def test_killed_run_started_anew_leaves_nothing_behind(tmp_path):
    (tmp_path / "h.toml").write_text(toml_text(h_input()))
    out = tmp_path / "out"
    args = ["run", tmp_path / "h.toml", "--out", out, "--quiet"]
    r = subprocess.run([sys.executable, "-c", KILL_IN_SECOND_WRITE, *map(str, args)], capture_output=True, timeout=120)
    assert r.returncode == -signal.SIGKILL and list(out.glob("basis.json.*.tmp"))
    assert main(list(map(str, args))) == 2  # the folder holds the killed run's checkpoint
    (out / "basis.json").unlink()  # given up: start anew
    assert main(list(map(str, args))) == 0
    assert not list(out.glob("*.tmp"))


# --- writers onto what is not a regular file -------------------------------------------------------
def node(path: Path, kind: str) -> None:
    """Make a FIFO, a character device (/dev/null's numbers, inside the test's folder), a socket or a
    folder at `path`."""
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "device":
        os.mknod(path, 0o666 | stat.S_IFCHR, os.makedev(1, 3))
    elif kind == "socket":
        import socket
        socket.socket(socket.AF_UNIX).bind(str(path))
    else:
        path.mkdir()


WRITERS = {"export": lambda out: ["export", BASES / "he" / "basis.json", "--format", "ecgpack", "--out", out],
           "import": lambda out: ["import", ROOT / "tests" / "data" / "ecgpack" / "ecgpack-Li7-100.inout.txt",
                                  "--out", out],
           "plot": lambda out: ["plot", BASES / "auto-h", "--out", out],
           "densities": lambda out: ["plot", "--densities", BASES / "h" / "basis.json", "--points", 10, "--out", out],
           "run": lambda out: ["run", BASES.parent / "h.toml", "--out", out, "--quiet"]}


@POSIX_FILES
@FUZZ
@given(writer=st.sampled_from(sorted(WRITERS)), kind=st.sampled_from(["fifo", "device", "socket", "folder"]),
       where=st.sampled_from(["itself", "link", "link to a link", "inside"]), force=st.booleans(),
       name=st.sampled_from(["basis.json", "result.json", "lowest.json"]))
def test_writers_onto_devices_and_fifos(tmp_path_factory, capsys, writer, kind, where, force, name):
    """Whatever writer, whatever is at its output's path (a FIFO, a device node, a socket, a folder;
    reached through links or not) or at a file it writes beside it (a run's checkpoint or result,
    the densities' table), with --force or without: one line, exit 2, and the node left as it was —
    never replaced by a regular file (`prebo export --out /dev/full --force` did that). A run into
    a folder, and a plot into one (its convergence.png), are what they are documented to be."""
    assume(not (kind == "folder" and writer == "run" and where != "inside"))  # a run's folder: its normal case
    d = tmp_path_factory.mktemp("writer")
    out = d / ("out.png" if writer in ("plot", "densities") else "out")
    if where == "inside" and writer == "run":
        out.mkdir()
        target = out / name
    elif where == "inside" and writer == "densities":
        target = out.with_suffix(".csv")
    else:
        target = out if where in ("itself", "inside") else d / "node"
    try:
        node(target, kind)
    except PermissionError:
        pytest.skip("mknod needs privileges this machine does not give")
    if where.startswith("link"):
        (d / "link").symlink_to(target)
        out.symlink_to(d / "link" if where == "link to a link" else target)
    mode = os.lstat(target).st_mode
    status = main(list(map(str, WRITERS[writer](out) + ["--force"] * force)))
    err = capsys.readouterr().err
    if writer == "plot" and kind == "folder":
        assert status == 0 and (target / "convergence.png").is_file()
    else:
        assert status == 2 and err.startswith("prebo: error: ") and err.count("\n") == 1, (status, err)
    assert os.lstat(target).st_mode == mode and not list(d.rglob("*.tmp"))


@pytest.mark.parametrize("text,words", [
    ('[system]\nparticles = ["p", "zz"]\n', "unknown particle 'zz'"),
    ('[system]\nparticles = ["p", "e"]\n[state]\nweights = [1, 2]\n', "weights = [1, 2] without roots"),
    ('[system]\nparticles = ["p", "e"]\n[basis]\nsize = 0\n', "size"),
    ('[system\nparticles = ["p", "e"]\n', "line 1"),
])
def test_a_bad_input_under_two_ranks_prints_one_line(tmp_path, text, words):
    """Issue 55, item 3: under `mpiexec -n 2` a bad input's line was followed by MPICH's `Abort(2) on
    node 0 ...`; now exactly the one line, exit status 2."""
    pytest.importorskip("mpi4py")
    mpiexec = shutil.which("mpiexec") or pytest.skip("no mpiexec on the PATH")
    (tmp_path / "bad.toml").write_text(text)
    r = subprocess.run([mpiexec, "-n", "2", sys.executable, "-m", "prebo", "run", tmp_path / "bad.toml", "--out",
                        tmp_path / "out", "--quiet"], capture_output=True, text=True, timeout=120,
                       env=os.environ | {"RAYON_NUM_THREADS": "1"})
    assert r.returncode == 2 and r.stdout == "", r
    assert r.stderr.startswith(f"prebo: error: {tmp_path / 'bad.toml'}") and r.stderr.count("\n") == 1, r.stderr
    assert words in r.stderr, r.stderr
