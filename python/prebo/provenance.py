"""Where an output came from: the "provenance" block of every result.json, basis.json and run
checkpoint (docs/basis-format.md) — the prebo version, the git commit of its source where known,
the Python, numpy and BLAS in use, the thread and rank counts and the command line. Informational:
a file is read the same with it, without it (files of earlier versions) or with another's.
"""
from __future__ import annotations

import functools
import platform
import subprocess
import sys
from importlib import metadata
from pathlib import Path

import numpy as np

#: prebo's version: the package's metadata, whose one source is the Cargo workspace's version
#: (maturin; pyproject.toml declares it dynamic)
VERSION = metadata.version("prebo")


@functools.cache
def commit() -> str | None:
    """The git commit of the code that runs: the checkout this package is imported from (a
    development install; "+modified" when its tracked files differ from the commit), else the one
    the core was built from (`_core.GIT_COMMIT`: a wheel or `pip install .` of a checkout), else None."""
    here = Path(__file__).resolve().parent
    try:
        top = subprocess.run(["git", "-C", str(here), "rev-parse", "--show-toplevel", "HEAD"],
                             capture_output=True, text=True, timeout=10)
        root, head = top.stdout.split() if top.returncode == 0 else ("", "")
        if root and Path(root).resolve() / "python" / "prebo" == here:
            status = subprocess.run(["git", "-C", root, "status", "--porcelain", "--untracked-files=no"],
                                    capture_output=True, text=True, timeout=10)
            return head + ("+modified" if status.returncode != 0 or status.stdout.strip() else "")
    except (OSError, ValueError, subprocess.SubprocessError):
        pass  # no git, or not a checkout: the build's commit
    from . import _core
    return _core.GIT_COMMIT or None


def blas() -> list[dict]:
    """The BLAS libraries loaded (threadpoolctl): library, version, CPU architecture, threads."""
    from threadpoolctl import threadpool_info

    return [{"library": i.get("internal_api"), "version": i.get("version"), "architecture": i.get("architecture"),
             "threads": i.get("num_threads")} for i in threadpool_info() if i.get("user_api") == "blas"]


def provenance() -> dict:
    """The provenance block of an output written now (module docstring)."""
    from . import _core
    from .parallel import world

    return {"prebo": VERSION, "commit": commit(), "python": platform.python_version(), "numpy": np.__version__,
            "blas": blas(), "threads": _core.num_threads(), "ranks": world().size,
            "command": list(sys.argv)}
