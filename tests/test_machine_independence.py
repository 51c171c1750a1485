"""Energies of the stored bases do not depend on the machine (issue 13, item 8).

Every examples/bases/*/basis.json and benchmarks/checkpoints/*/basis.json is evaluated in
subprocesses with numpy's OpenBLAS on its own kernel (OPENBLAS_CORETYPE unset) and on another
core type (its DYNAMIC_ARCH build runs any), with 1 and 2 threads (BLAS and rayon); the energies
agree to 1e-10 relative. Before the extended-precision refinement (eigen.solve) the H2+ plain-ECG
basis moved by 7e-9 relative between kernels. The variable is set in the subprocesses only.
"""
import json
import os
import subprocess
import sys

import pytest

from conftest import ROOT

BASES = sorted(ROOT.glob("examples/bases/*/basis.json")) + sorted(ROOT.glob("benchmarks/checkpoints/*/basis.json"))

#: evaluates the bases given as arguments; prints the OpenBLAS core in use and their energies
SCRIPT = """
import ctypes, glob, json, os, sys
import numpy
from prebo.basis import Basis
from prebo.level.evaluate import evaluate

core = "unknown"
for lib in glob.glob(os.path.join(os.path.dirname(numpy.__file__), "..", "numpy.libs", "*openblas*")):
    name = getattr(ctypes.CDLL(lib), "scipy_openblas_get_corename64_", None)
    if name is not None:
        name.restype = ctypes.c_char_p
        core = name().decode()
energies = {p: [evaluate(Basis.load(p))[k] for k in ("energy", "energy_lab")] for p in sys.argv[1:]}
print(json.dumps({"core": core, "energies": energies}))
"""


def run(paths, core: str | None, threads: int) -> dict:
    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_CORETYPE"}
    env |= {"OPENBLAS_NUM_THREADS": str(threads), "RAYON_NUM_THREADS": str(threads), "OMP_NUM_THREADS": str(threads)}
    if core is not None:
        env["OPENBLAS_CORETYPE"] = core
    r = subprocess.run([sys.executable, "-c", SCRIPT, *map(str, paths)], capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout)


@pytest.fixture(scope="module")
def snapshots(tmp_path_factory):
    """Copies of the stored bases (a running optimisation may rewrite a checkpoint meanwhile)."""
    folder = tmp_path_factory.mktemp("bases")
    copies = []
    for f in BASES:
        copy = folder / f"{f.parent.parent.name}-{f.parent.name}.json"
        copy.write_bytes(f.read_bytes())
        copies.append(copy)
    return copies


def test_stored_energies_agree_across_blas_kernels_and_threads(snapshots):
    assert len(snapshots) >= 10
    native = run(snapshots, None, 1)
    if native["core"] == "unknown":
        pytest.skip("numpy's BLAS is not OpenBLAS with DYNAMIC_ARCH: OPENBLAS_CORETYPE has no meaning")
    other = "Sandybridge" if native["core"] == "Haswell" else "Haswell"
    runs = {(None, 1): native} | {(core, t): run(snapshots, core, t) for core, t in [(None, 2), (other, 1), (other, 2)]}
    assert runs[(other, 1)]["core"] == other != native["core"]
    for path in map(str, snapshots):
        for k, key in enumerate(("energy", "energy_lab")):
            values = {config: r["energies"][path][k] for config, r in runs.items()}
            ref = values[(None, 1)]
            for config, value in values.items():
                assert value == pytest.approx(ref, rel=1e-10, abs=0), f"{path} {key}: {config} {value!r} vs {ref!r}"
