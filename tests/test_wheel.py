"""Installed without a compiler: the wheel built from this tree (maturin, through pip), installed
into a fresh virtual environment whose PATH has no `cargo` or `rustc`, runs a small job and
`prebo energy` on a stored basis.

The README's test command installs the package first, so the wheel's build finds the core
compiled in target/ and only packs it (seconds); after a change to the Rust code it compiles
again. The release workflow's test job skips this file: installing each platform's wheel into a
fresh environment is what that job itself does.
"""
import json
import os
import shutil
import subprocess
import sys
import textwrap
import venv
from pathlib import Path

import pytest

import prebo

from conftest import ROOT

pytestmark = pytest.mark.wheel

INPUT = """\
title = "Hydrogen atom 1s in eight plain ECGs (exact: -mu/2)"

[system]
particles = ["p", "e"]

[basis]
type = "pecg"
size = 8

[optimiser]
trials = 10
sweeps = 1
seed = 3
"""
STORED = ROOT / "examples" / "bases" / "h2plus-gvr" / "basis.json"


def without_compiler() -> str:
    """This PATH less every folder that holds `cargo` or `rustc`."""
    keep = [d for d in os.environ.get("PATH", "").split(os.pathsep)
            if d and not any(shutil.which(tool, path=d) for tool in ("cargo", "rustc"))]
    return os.pathsep.join(keep)


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """(the fresh environment's bin folder, its environment variables), prebo's wheel installed."""
    tmp = tmp_path_factory.mktemp("wheel")
    built = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", str(ROOT),
                            "-w", str(tmp / "dist")], capture_output=True, text=True)
    assert built.returncode == 0, built.stderr[-3000:]
    (wheel,) = (tmp / "dist").glob("prebo-*.whl")
    venv.create(tmp / "venv", with_pip=True)
    bin_ = tmp / "venv" / "bin"
    env = {k: v for k, v in os.environ.items()
           if k not in ("PYTHONPATH", "VIRTUAL_ENV", "CARGO", "RUSTC", "CARGO_HOME", "RUSTUP_HOME")}
    env["PATH"] = os.pathsep.join([str(bin_), without_compiler()])
    assert shutil.which("cargo", path=env["PATH"]) is None and shutil.which("rustc", path=env["PATH"]) is None
    # every package from a wheel: nothing is compiled to install prebo
    done = subprocess.run([bin_ / "python", "-m", "pip", "install", "-q", "--only-binary", ":all:", str(wheel)],
                          capture_output=True, text=True, env=env, cwd=tmp)
    assert done.returncode == 0, done.stderr[-3000:]
    return bin_, env, tmp


def run(installed, *args):
    bin_, env, tmp = installed
    return subprocess.run([str(bin_ / "prebo"), *map(str, args)], capture_output=True, text=True,
                          env=env, cwd=tmp, timeout=600)


def test_the_wheel_installs_the_package_not_the_tree(installed):
    bin_, env, tmp = installed
    where = subprocess.run([bin_ / "python", "-c", "import prebo, prebo._core; print(prebo._core.__file__)"],
                           capture_output=True, text=True, env=env, cwd=tmp)
    assert where.returncode == 0, where.stderr
    assert Path(where.stdout.strip()).is_relative_to(tmp / "venv")
    version = run(installed, "--version")
    assert version.returncode == 0 and version.stdout.split()[:2] == ["prebo", prebo.__version__]


def test_the_installed_wheel_runs_a_small_job(installed):
    tmp = installed[2]
    (tmp / "h.toml").write_text(textwrap.dedent(INPUT))
    done = run(installed, "run", tmp / "h.toml", "--out", tmp / "h")
    assert done.returncode == 0, done.stderr
    result = json.loads((tmp / "h" / "result.json").read_text())
    m_p, m_e = (p["mass"] for p in result["particles"])
    exact = -m_p * m_e / (m_p + m_e) / 2
    assert exact < result["energy"] < exact + 1e-2  # variational, and a hydrogen atom


def test_the_installed_wheel_gives_the_stored_basis_its_energy(installed):
    done = run(installed, "energy", STORED, "--json")
    assert done.returncode == 0, done.stderr
    here = prebo.evaluate(prebo.Basis.load(STORED))
    assert json.loads(done.stdout)["energy"] == here["energy"]  # the same core: the same bits
