"""The files of a run's folder: out/basis.json, the checkpoint (the basis, the settings, the run
state; written by driver.optimise after every step, read back by resume.py), and out/lowest.json,
the lowest state while the run stands above it (lowest.py).
"""
from __future__ import annotations

from pathlib import Path

from ..basis import Basis

CHECKPOINT = "basis.json"
LOWEST = "lowest.json"


def checkpoint_in(folder) -> Path | None:
    """The checkpoint (basis.json, else lowest.json) in `folder` that a new run there would
    overwrite, or None."""
    return next((p for p in (Path(folder) / CHECKPOINT, Path(folder) / LOWEST) if p.exists()), None)


def of_this_run(other: Basis, basis: Basis) -> bool:
    """Whether the basis `other` belongs to the run of `basis`: the same particles, state and
    basis type (a lowest state or a momentum reference read back with a checkpoint)."""
    return (other.kind, other.system.particles, other.system.state) == (
        basis.kind, basis.system.particles, basis.system.state)
