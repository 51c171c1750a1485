"""Issue 37: outputs never replace inputs, and replace earlier outputs only with --force
(atomically); a run owns its folder while it runs (an advisory lock, released on any exit) and a
refused run leaves no trace; a closed or full standard output or error ends the command with
exit 2 and at most one line, after its files are written; `prebo plot` refuses a malformed history
in one line. Locks and streams need real processes; the rest runs in-process."""
import fcntl
import json
import math
import os
import shutil
import signal
import stat
import subprocess
import sys
import tempfile
from pathlib import Path
from unittest import mock

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import prebo
from prebo.cli import main
from prebo.errors import InputError, OutputError
from prebo.optimise.cursor import PHASES

from conftest import POSIX_FILES

ROOT = Path(__file__).resolve().parents[1]
LI = ROOT / "tests" / "data" / "ecgpack" / "ecgpack-Li7-100.inout.txt"
H_RUN = ROOT / "examples" / "bases" / "auto-h"  # a run of 20 functions: its checkpoint and result
PREBO = [sys.executable, "-m", "prebo"]
H_TOML = '[system]\nparticles = ["p", "e"]\n[basis]\nsize = 3\n[optimiser]\ntrials = 4\nseed = 3\n'


def cli(capsys, *args):
    """The exit status, stdout and stderr of `prebo ARGS` run in-process."""
    status = main(list(map(str, args)))
    return status, *capsys.readouterr()


def refused(capsys, *args) -> str:
    """The one line of `prebo ARGS` (in-process) refusing its arguments with exit 2."""
    status, _, err = cli(capsys, *args)
    assert status == 2 and err.startswith("prebo: error: ") and err.count("\n") == 1, (status, err)
    return err


def process(*args, **kw):
    """`python -m prebo ARGS` in a process of its own (stdout and stderr captured unless given)."""
    kw = {"stdout": subprocess.PIPE, "stderr": subprocess.PIPE} | kw
    return subprocess.run([*PREBO, *map(str, args)], text=True, timeout=120, **kw)


# --- case 6: an output never replaces an input; an existing one only with --force --------------
def same_file_as(source: Path, how: str, tmp_path: Path) -> Path:
    """A path naming the file `source`: itself, spelled otherwise, or a symbolic or hard link."""
    if how == "itself":
        return source
    if how == "spelled otherwise":
        return source.parent / ".." / source.parent.name / source.name
    link = tmp_path / ("link" + "".join(source.suffixes))
    (link.symlink_to if how == "symbolic link" else link.hardlink_to)(source)
    return link


@pytest.mark.parametrize("force", [[], ["--force"]])
@pytest.mark.parametrize("how", ["itself", "spelled otherwise", "symbolic link", "hard link"])
def test_an_output_never_replaces_its_input(tmp_path, capsys, how, force):
    """`prebo import X.inout.txt --out X.inout.txt` replaced the ecgpack file with JSON and `prebo
    export B.json --format ecgpack --out B.json` the basis with ecgpack text, exit 0."""
    inout = tmp_path / "li.inout.txt"
    shutil.copy(LI, inout)
    basis = tmp_path / "li.json"
    assert main(["import", str(inout), "--out", str(basis)]) == 0
    for command, source in (["import"], inout), (["export"], basis):
        before = source.read_bytes()
        out = same_file_as(source, how, tmp_path)
        args = [*command, source] + (["--format", "ecgpack"] if command == ["export"] else []) + ["--out", out]
        err = refused(capsys, *args, *force)
        assert f"the input file {source} itself" in err and str(out) in err
        assert source.read_bytes() == before and not list(tmp_path.glob("*.tmp"))


def test_an_existing_output_is_replaced_only_with_force_and_atomically(tmp_path, capsys):
    """`prebo import --out existing.json` (and `export --out existing`, `plot --out existing.png`)
    overwrote the file without a word; with --force the file is replaced by a new one (a new
    inode: written beside it and renamed, never truncated and rewritten in place)."""
    json_, inout, png = tmp_path / "li.json", tmp_path / "li.inout.txt", tmp_path / "conv.png"
    commands = [(json_, ["import", LI, "--out", json_]),
                (inout, ["export", ROOT / "examples" / "bases" / "he" / "basis.json", "--format", "ecgpack",
                         "--out", inout]),
                (png, ["plot", H_RUN, "--out", png])]
    for out, args in commands:
        out.write_text("mine")
        assert f"{out}: the file exists: give --force to replace it" in refused(capsys, *args)
        assert out.read_text() == "mine"
        inode = out.stat().st_ino
        assert cli(capsys, *args, "--force")[0] == 0
        assert out.read_bytes() != b"mine" and out.stat().st_ino != inode
        assert not list(tmp_path.glob("*.tmp"))
    assert len(json.loads(json_.read_text())["functions"]) == 100
    assert inout.read_text().startswith(" BASIS_TYPE") and png.read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize("args", [["run", "in.toml", "--out", ""], ["import", "li.inout.txt", "--out", ""],
                                  ["export", "run/basis.json", "--format", "ecgpack", "--out", ""],
                                  ["plot", "run", "--out", ""], ["run", "--resume", ""]])
def test_an_empty_output_path_is_refused(tmp_path, capsys, monkeypatch, args):
    """`--out ""` wrote to the default output (`plot`: ./.png) as if no --out were given."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "in.toml").write_text(H_TOML)
    shutil.copy(LI, tmp_path / "li.inout.txt")
    shutil.copytree(H_RUN, tmp_path / "run")
    before = sorted(tmp_path.rglob("*"))
    assert "= '': empty" in refused(capsys, *args)
    assert sorted(tmp_path.rglob("*")) == before


def test_plot_into_a_folder_writes_its_convergence_png(tmp_path, capsys):
    """`prebo plot RUN --out DIR` wrote DIR.png beside the folder DIR."""
    for folder, out in (tmp_path / "plots", tmp_path / "plots"), (tmp_path / "figs", f"{tmp_path / 'figs'}{os.sep}"):
        folder.mkdir()
        status, printed, _ = cli(capsys, "plot", H_RUN, "--out", out)
        assert status == 0 and printed == f"wrote {folder / 'convergence.png'}\n"
        assert (folder / "convergence.png").read_bytes()[:4] == b"\x89PNG"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["figs", "plots"]


# --- issue 55 case 1: only a regular file is ever replaced ------------------------------------------
def special(tmp_path: Path, kind: str) -> Path:
    """A FIFO, a character device (a copy of /dev/null's numbers, made in `tmp_path`: the machine's
    own /dev is never a test's target) or a socket in `tmp_path`."""
    path = tmp_path / f"{kind}.out"
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "device":
        try:
            os.mknod(path, 0o666 | stat.S_IFCHR, os.makedev(1, 3))
        except PermissionError:
            pytest.skip("mknod needs privileges this machine does not give")
    else:
        import socket
        with socket.socket(socket.AF_UNIX) as s:
            s.bind(str(path))
    return path


def commands(tmp_path: Path, out: Path) -> dict[str, list]:
    """Every writer's command line with `out` as the file it writes."""
    return {"export": ["export", ROOT / "examples" / "bases" / "he" / "basis.json", "--format", "ecgpack", "--out", out],
            "import": ["import", LI, "--out", out],
            "plot": ["plot", H_RUN, "--out", out.with_suffix(".png") if out.suffix != ".png" else out],
            "densities": ["plot", "--densities", H_RUN / "basis.json", "--points", 20, "--out",
                          out.with_suffix(".png") if out.suffix != ".png" else out]}


@POSIX_FILES
@pytest.mark.parametrize("force", [[], ["--force"]])
@pytest.mark.parametrize("kind", ["fifo", "device", "socket"])
@pytest.mark.parametrize("command", ["export", "import", "plot", "densities"])
def test_a_device_or_fifo_is_never_replaced(tmp_path, capsys, command, kind, force):
    """`prebo export B --format ecgpack --out /dev/full --force` said "wrote /dev/full", exit 0,
    and left a regular file where the device was (a FIFO too): every writer refuses, with
    --force or without, and leaves the node as it was."""
    node = special(tmp_path, kind)
    if command in ("plot", "densities"):
        node.rename(node := node.with_suffix(".png"))
    mode = os.lstat(node).st_mode
    err = refused(capsys, *commands(tmp_path, node)[command], *force)
    assert f"{node}: a " in err and "not a regular file" in err, err
    assert os.lstat(node).st_mode == mode and not list(tmp_path.glob("*.tmp"))


@POSIX_FILES
def test_the_densities_table_beside_the_picture_is_not_replaced_if_a_fifo(tmp_path, capsys):
    """The CSV beside `prebo plot --densities`' picture is an output too."""
    table = tmp_path / "d.csv"
    os.mkfifo(table)
    err = refused(capsys, "plot", "--densities", H_RUN / "basis.json", "--points", 20, "--out", tmp_path / "d.png")
    assert f"{table}: a FIFO" in err and stat.S_ISFIFO(os.lstat(table).st_mode)
    assert not (tmp_path / "d.png").exists()


@POSIX_FILES
@pytest.mark.parametrize("name", ["basis.json", "result.json", "lowest.json", "folder"])
def test_a_run_never_replaces_a_fifo_in_or_as_its_folder(tmp_path, capsys, name):
    """A run's folder, and its checkpoint, lowest state and result, replace only regular files
    (with --force too, which removes an earlier run's files)."""
    out = tmp_path / "run"
    fifo = out if name == "folder" else out / name
    out.mkdir(exist_ok=name != "folder") if name != "folder" else None
    os.mkfifo(fifo)
    (tmp_path / "h.toml").write_text(H_TOML)
    err = refused(capsys, "run", tmp_path / "h.toml", "--out", out, "--quiet", "--force")
    assert f"{fifo}: a FIFO" in err and stat.S_ISFIFO(os.lstat(fifo).st_mode)


def test_an_output_through_a_symbolic_link_is_written_into_its_file(tmp_path, capsys):
    """A link to a regular file is kept: the output replaces the file it names, atomically."""
    real, link = tmp_path / "real.inout.txt", tmp_path / "link.inout.txt"
    real.write_text("old\n")
    link.symlink_to(real.name)
    assert cli(capsys, *commands(tmp_path, link)["export"], "--force")[0] == 0
    assert link.is_symlink() and real.read_text().split()[:2] == ["BASIS_TYPE", "RG_0S"]


@POSIX_FILES
def test_the_api_writer_refuses_a_fifo(tmp_path):
    """Basis.save, the API's writer, goes through the same check."""
    fifo = tmp_path / "b.json"
    os.mkfifo(fifo)
    basis = prebo.Basis.load(H_RUN / "basis.json")
    with pytest.raises(OutputError, match="a FIFO"):
        basis.save(fifo)
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)


# --- case 7 and 13: a run owns its folder; a refused run leaves no trace --------------------------
def hold(folder: Path) -> int:
    """Lock `folder` as a run does (fcntl.flock of folder/.lock), from this test's process."""
    fd = os.open(folder / ".lock", os.O_RDWR | os.O_CREAT)
    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    os.write(fd, f"{os.getpid()}\n".encode())
    return fd


def test_a_run_folder_is_owned_by_one_run(tmp_path):
    """Two new runs into one folder both ran in 1 of 9 tries, two --resume of one folder in 3 of 3:
    with the folder's lock held (here by this process), a new run, a resumed one and the API are
    refused in one line naming the owner, and the folder is untouched; once released, a run goes."""
    (tmp_path / "in.toml").write_text(H_TOML)
    new, old = tmp_path / "new", tmp_path / "old"
    new.mkdir()
    shutil.copytree(H_RUN, old)
    (old / "result.json").unlink()
    before = (old / "basis.json").read_bytes()
    fds = [hold(new), hold(old)]
    try:
        for args, folder in ((["run", tmp_path / "in.toml", "--out", new], new), (["run", "--resume", old], old)):
            r = process(*args, "--quiet")
            assert r.returncode == 2 and r.stderr == f"prebo: error: {folder}: another prebo run (pid {os.getpid()}) " \
                                                     "owns this folder\n", r.stderr
        assert os.listdir(new) == [".lock"] and sorted(os.listdir(old)) == [".lock", "basis.json"]
        assert (old / "basis.json").read_bytes() == before
        system, opts = prebo.System(["p", "e"]), prebo.Optimiser(size=2, trials=2, seed=1)
        with pytest.raises(OutputError, match=f"{new}: another prebo run"):
            prebo.optimise(system, opts, out=new, progress=False)
        from prebo.optimise import resume_from
        with pytest.raises(OutputError, match=f"{old}: another prebo run"):
            resume_from(old, progress=False)
    finally:
        for fd in fds:
            os.close(fd)
    assert process("run", tmp_path / "in.toml", "--out", new, "--quiet").returncode == 0
    assert sorted(os.listdir(new)) == ["basis.json", "result.json"]  # the lock file goes with its run


OWN_AND_DIE = """
import os, signal, sys
from prebo.io.lock import owned
with owned(sys.argv[1]):
    os.kill(os.getpid(), signal.SIGKILL)
"""


def test_the_lock_is_released_however_its_run_ends(tmp_path, capsys):
    """A run killed while it owns its folder leaves a .lock that owns nothing; a refused or failed
    run (in-process) releases the folder at once."""
    out = tmp_path / "out"
    r = subprocess.run([sys.executable, "-c", OWN_AND_DIE, out], timeout=60)
    assert r.returncode == -signal.SIGKILL and (out / ".lock").exists()
    (tmp_path / "in.toml").write_text(H_TOML)
    with mock.patch("prebo.optimise.driver.resolved", side_effect=InputError("refused")):
        assert "refused" in refused(capsys, "run", tmp_path / "in.toml", "--out", out, "--quiet")
    assert cli(capsys, "run", tmp_path / "in.toml", "--out", out, "--quiet")[0] == 0
    assert sorted(os.listdir(out)) == ["basis.json", "result.json"]


def test_a_refused_run_leaves_no_folder(tmp_path, capsys):
    """A run refused once it had begun left its (empty) output folder behind; the folders it
    creates are removed again, a folder that was there stays."""
    (tmp_path / "in.toml").write_text(H_TOML)
    (tmp_path / "there").mkdir()
    with mock.patch("prebo.optimise.driver.resolved", side_effect=InputError("refused")):
        for out in (tmp_path / "a" / "b" / "c", tmp_path / "there" / "d", tmp_path / "there"):
            assert "refused" in refused(capsys, "run", tmp_path / "in.toml", "--out", out, "--quiet")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in.toml", "there"]
    assert not list((tmp_path / "there").iterdir())


# --- case 9: closed and full standard streams -------------------------------------------------
def closed_stdout(*args):
    """`prebo ARGS >&-`: the process starts with its standard output closed."""
    return subprocess.run(["sh", "-c", 'exec "$@" >&-', "sh", *PREBO, *map(str, args)], stderr=subprocess.PIPE,
                          text=True, timeout=120)


def full_stdout(*args):
    """`prebo ARGS > /dev/full`: every write to its standard output fails (ENOSPC)."""
    with open("/dev/full", "w") as full:
        return process(*args, stdout=full)


def pipe_closed_early(*args):
    """`prebo ARGS | true`: the reading end of its standard output is closed before it writes."""
    read, write = os.pipe()
    os.close(read)
    try:
        return process(*args, stdout=write)
    finally:
        os.close(write)


STDOUT = {closed_stdout: "standard output was closed",
          full_stdout: "standard output cannot be written (No space left on device)",
          pipe_closed_early: "standard output was closed by the command reading it"}


@pytest.mark.parametrize("stdout", STDOUT)
def test_energy_into_a_closed_or_full_stdout(stdout):
    """`prebo energy X >&-` raised AttributeError, `> /dev/full` an OSError traceback, and the
    table into `| true` exited 1 without a word: exit 2, one line."""
    r = stdout("energy", H_RUN / "basis.json")
    assert r.returncode == 2 and r.stderr == f"prebo: error: {STDOUT[stdout]}\n", r.stderr


@pytest.mark.parametrize("stdout", [closed_stdout, full_stdout])
def test_a_run_into_a_closed_or_full_stdout_keeps_its_result(tmp_path, stdout):
    """`prebo run X > /dev/full` aborted without result.json (the progress display failed as the run
    ended); the run's result is written first, then the failure reported (exit 2, one line)."""
    (tmp_path / "in.toml").write_text(H_TOML)
    r = stdout("run", tmp_path / "in.toml", "--out", tmp_path / "out")
    assert r.returncode == 2 and r.stderr == f"prebo: error: {STDOUT[stdout]}\n", r.stderr
    result = json.loads((tmp_path / "out" / "result.json").read_text())
    assert result["n_basis"] == 3 and math.isfinite(result["energy"])


def unbound(tmp_path) -> Path:
    """H⁻ in one function: not bound, so `prebo energy` warns on stderr."""
    d = json.loads((ROOT / "examples" / "bases" / "h-" / "basis.json").read_text())
    d["functions"], d["coefficients"] = d["functions"][:1], [1.0]
    (tmp_path / "h-.json").write_text(json.dumps(d))
    return tmp_path / "h-.json"


def test_a_closed_or_full_stderr(tmp_path):
    """A warning into a full or closed standard error (a traceback that could not be shown, exit 1):
    exit 2, the result on stdout all the same; both streams gone: exit 2."""
    f = unbound(tmp_path)
    with open("/dev/full", "w") as full:
        r = process("energy", f, "--json", stderr=full)
    assert r.returncode == 2 and json.loads(r.stdout)["bound"] is False
    r = subprocess.run(["sh", "-c", 'exec "$@" 2>&-', "sh", *PREBO, "energy", f, "--json"], stdout=subprocess.PIPE,
                       text=True, timeout=120)
    assert r.returncode == 2 and json.loads(r.stdout)["bound"] is False
    r = subprocess.run(["sh", "-c", 'exec "$@" >&- 2>&-', "sh", *PREBO, "energy", f], timeout=120)
    assert r.returncode == 2


# --- case 11: a malformed history; case 13: a stored threshold that is no threshold --------------
def is_row(row) -> bool:
    """A history row as `prebo run` writes it: [basis size, energy (Eh), phase, wall time (s)]
    (older runs: without the time); a size of at least one function, finite numbers, seconds ≥ 0."""
    def real(v):
        return type(v) in (int, float) and math.isfinite(v)
    return (isinstance(row, list) and len(row) in (3, 4) and type(row[0]) is int and row[0] >= 1
            and real(row[1]) and row[2] in PHASES and all(real(v) and v >= 0 for v in row[3:]))


VALUES = st.sampled_from([None, True, 0, -1, 3, 1.5, -0.5, float("nan"), float("inf"), "3", "grow", [], {}, [1]])


@settings(max_examples=40, deadline=None, derandomize=True, database=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(k=st.integers(0, 89), position=st.integers(-1, 4), value=VALUES, action=st.sampled_from(["set", "row", "cut"]))
def test_plot_refuses_a_malformed_history_row(tmp_path, capsys, k, position, value, action):
    """`prebo plot` on a checkpoint with malformed history rows raised TypeError: one line naming the
    file and the row (or draws the row, if it is one)."""
    d = json.loads((H_RUN / "basis.json").read_text())
    row = d["history"][k]
    if action == "row":
        d["history"][k] = value
    elif action == "cut":
        del row[max(position, 0):]
    elif position in range(len(row)):
        row[position] = value
    else:
        row.append(value)
    run = Path(tempfile.mkdtemp(dir=tmp_path))
    (run / "basis.json").write_text(json.dumps(d))
    status, _, err = cli(capsys, "plot", run)
    if action != "cut" and isinstance(value, float) and not math.isfinite(value):
        # not JSON's: refused as it is read, with its line
        assert status == 2 and err.startswith(f"prebo: error: {run / 'basis.json'}:1: ") and "not a finite number" in err
    elif is_row(d["history"][k]):
        assert status == 0, err
    else:
        assert status == 2 and err.startswith(f"prebo: error: {run / 'basis.json'}: history row {k} = ")
        assert err.count("\n") == 1 and "must be" in err


@pytest.mark.parametrize("threshold", [float("nan"), float("inf"), "1e-13", None, True, 0.0, 1.5, -1e-13, 1])
def test_a_stored_threshold_that_is_no_threshold_is_refused(tmp_path, capsys, threshold):
    """A NaN (or any other non-threshold) stored as the run's optimiser threshold fell back to
    1e-13 without a word (io.load.load_basis): one line naming the file, the key and the value."""
    d = json.loads((H_RUN / "basis.json").read_text())
    d["optimiser"]["threshold"] = threshold
    f = tmp_path / "basis.json"
    f.write_text(json.dumps(d))
    err = refused(capsys, "energy", f)
    if isinstance(threshold, float) and not math.isfinite(threshold):  # not JSON's: refused as it is read
        assert f"{f}:1: {json.dumps(threshold)}: not a finite number" in err
    else:
        assert f"{f}: optimiser threshold = {threshold!r}: must be" in err
