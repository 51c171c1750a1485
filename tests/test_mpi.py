"""MPI ranks sharing a run (parallel.py), on this machine's loopback with `mpiexec -n 2`: integrals
equal one process's bit for bit, a 2-rank run equals a 1-rank one refining the same batches, a
killed 2-rank run resumes to the same basis on 2 ranks or 1, a failing rank stops every rank in
bounded time, and an error every rank meets is reported once. Needs prebo's MPI extra (pip install
".[mpi]"), which the README's test command installs."""
import json
import os
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import INPUT, functions, hydrogen_1s, mid_schedule

pytest.importorskip("mpi4py")
MPIEXEC = shutil.which("mpiexec") or pytest.skip("no mpiexec on the PATH", allow_module_level=True)
WORKER = Path(__file__).parent / "mpi_worker.py"
#: one core per rank: 2 ranks x 1 thread on the 2-core machine
ENV = os.environ | {"RAYON_NUM_THREADS": "1"}


def mpi(ranks: int, *args, **kw) -> subprocess.Popen:
    return subprocess.Popen([MPIEXEC, "-n", str(ranks), *map(str, args)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=ENV, **kw)


def prebo_run(ranks: int, *args, **kw) -> subprocess.Popen:
    return mpi(ranks, sys.executable, "-m", "prebo", "run", *args, "--quiet", **kw)


def finished(p: subprocess.Popen, timeout: float) -> str:
    out, err = p.communicate(timeout=timeout)
    assert p.returncode == 0, err
    return out


def test_two_ranks_evaluate_the_integrals_of_one_process_bit_for_bit():
    out = finished(mpi(2, sys.executable, WORKER, "integrals"), 300)
    assert "2 ranks equal one process bit for bit" in out


def test_a_failing_rank_stops_every_rank_with_an_error():
    p = mpi(2, sys.executable, WORKER, "raise")
    try:
        _, err = p.communicate(timeout=60)  # bounded: never a hang
    except subprocess.TimeoutExpired:
        p.kill()
        pytest.fail("the ranks still ran 60 s after one failed")
    assert p.returncode != 0 and "a deliberate failure on the last rank" in err


def test_a_bad_input_under_two_ranks_is_reported_once_with_exit_status_2(tmp_path):
    """Every rank meets a bad input: rank 0 reports it and stops both (parallel.stop_all)."""
    (tmp_path / "bad.toml").write_text('[system]\nparticles = ["p", "zz"]\n')
    p = prebo_run(2, tmp_path / "bad.toml", "--out", tmp_path / "out")
    _, err = p.communicate(timeout=60)
    assert p.returncode == 2 and err.count("prebo: error:") == 1 and "unknown particle 'zz'" in err
    assert err.count("\n") == 1, err  # not followed by MPICH's "Abort(2) on node 0 ..." (issue 55, item 3)


def test_ranks_whose_copies_differ_stop_with_an_error_naming_it():
    """Replicated state: ranks that make different calls (a run's copies that drifted apart) are
    caught at the next gathering, never joined into wrong matrices."""
    p = mpi(2, sys.executable, WORKER, "diverge")
    _, err = p.communicate(timeout=60)
    assert p.returncode != 0 and "MPI ranks diverged" in err


def test_a_two_rank_run_equals_a_one_rank_run_of_its_batch_and_resumes_after_a_kill_on_any_rank_count(tmp_path):
    """Two ranks work on two functions of a sweep at once (batch defaults to the rank count): one
    process with batch = 2 gives the same basis bit for bit, and so does the 2-rank run whose one
    rank is killed mid-way (the launcher stops the other), resumed on 2 ranks or on 1 (the batch
    is kept in the checkpoint)."""
    (tmp_path / "in.toml").write_text(INPUT)
    (tmp_path / "batch.toml").write_text(INPUT + "batch = 2\n")
    finished(prebo_run(1, tmp_path / "batch.toml", "--out", tmp_path / "one"), 300)
    finished(prebo_run(2, tmp_path / "in.toml", "--out", tmp_path / "two"), 300)
    assert functions(tmp_path / "two") == functions(tmp_path / "one")
    assert json.loads((tmp_path / "two" / "basis.json").read_text())["optimiser"]["batch"] == 2

    killed = prebo_run(2, tmp_path / "in.toml", "--out", tmp_path / "killed", start_new_session=True)
    mid_schedule(tmp_path / "killed")
    ranks = subprocess.run(["pgrep", "-f", f"^{sys.executable} -m prebo run .*killed"], capture_output=True,
                           text=True).stdout.split()
    assert len(ranks) == 2, f"not two ranks running: {ranks}"
    os.kill(int(ranks[-1]), signal.SIGKILL)  # one rank: the launcher stops the other
    try:
        killed.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        os.killpg(killed.pid, signal.SIGKILL)
        pytest.fail("the other rank still ran 60 s after one was killed")
    assert killed.returncode != 0
    cut = json.loads((tmp_path / "killed" / "basis.json").read_text())["progress"]
    assert cut["phase"] != "done", "the run ended before it was killed: nothing tested"
    shutil.copytree(tmp_path / "killed", tmp_path / "on-one")
    finished(prebo_run(2, "--resume", tmp_path / "killed"), 300)
    finished(prebo_run(1, "--resume", tmp_path / "on-one"), 300)
    for folder in ("killed", "on-one"):
        assert functions(tmp_path / folder) == functions(tmp_path / "one")
    energies = [json.loads((tmp_path / k / "result.json").read_text())["energy"] for k in ("one", "two", "killed", "on-one")]
    assert len(set(energies)) == 1


def test_a_response_run_on_two_ranks_equals_one_rank_of_its_batch(tmp_path):
    """A first-order function's run (TOML [response], optimise/response.py) shares its rows as a
    level's does; the source terms each rank evaluates alike: two ranks give the basis and the
    polarisability of one process with batch = 2, bit for bit."""
    hydrogen_1s().save(tmp_path / "ground.json")
    text = '[response]\nground = "ground.json"\n[basis]\nsize = 6\n[optimiser]\nschedule = "fixed"\nsweeps = 1\n'
    (tmp_path / "in.toml").write_text(text)
    (tmp_path / "batch.toml").write_text(text + "batch = 2\n")
    finished(prebo_run(1, tmp_path / "batch.toml", "--out", tmp_path / "one"), 300)
    finished(prebo_run(2, tmp_path / "in.toml", "--out", tmp_path / "two"), 300)
    assert functions(tmp_path / "two") == functions(tmp_path / "one")
    one, two = (json.loads((tmp_path / d / "result.json").read_text())["response"] for d in ("one", "two"))
    assert one == two
