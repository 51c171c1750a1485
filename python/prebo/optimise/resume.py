"""A run read back from its checkpoint (checkpoint.py), for `prebo run --resume`, which continues
it (bit for bit in a fixed schedule): every part is checked as a claim (`resumed`, `check_rng`,
history.check_history, the schedule's and the momentum's own checks), and a malformed part is
refused in one line naming the file and the key.
"""
from __future__ import annotations

import reprlib
from collections.abc import Callable
from pathlib import Path

import numpy as np

from ..basis import Basis
from ..errors import BasisFileError, PreboError
from ..integrals import laboratory
from ..io import basis_json
from ..system import System
from ..validation import number
from .checkpoint import CHECKPOINT
from .convergence import STOPPED
from .expansion import Expansion
from .history import Step, check_history
from .momentum import Momentum
from .objective import Followed, Levels
from .schedule import kind_of, schedule_of
from .settings import Optimiser


def resumed(d: dict, opts: Optimiser, rng: np.random.Generator, where: str) -> tuple:
    """The basis, cursor, history (history.Step), elapsed seconds, schedule (schedule.schedule_of)
    and stop reason of checkpoint content `d` (`rng` takes its state); BasisFileError naming
    `where` for anything that does not fit."""
    basis = Basis.from_dict(d, where, empty=True)
    if basis.kind != opts.kind:
        raise BasisFileError(f"{where}: a {basis.kind} basis, but the optimiser's kind is {opts.kind}")
    try:
        schedule, stopped = schedule_of(opts, d.get("schedule")), d.get("stopped")
        cursor = schedule.cursor(d["progress"], len(basis))
        rng.bit_generator.state = check_rng(d["rng"])
        history, elapsed = [Step(*row) for row in check_history(d["history"])], number(d.get("elapsed", 0.0), "elapsed")
        if elapsed < 0:
            raise ValueError(f"elapsed = {elapsed!r}: must be the seconds of the run so far (≥ 0)")
        if stopped not in STOPPED:
            raise ValueError(f"stopped = {reprlib.repr(stopped)}: must be one of {tuple(STOPPED)}")
    except (KeyError, TypeError, ValueError) as exc:
        raise BasisFileError(f"{where}: malformed run state ({exc})") from exc
    nb = len(basis)
    if (cursor.phase != "grow" and nb == 0) or (cursor.phase in ("sweep", "refine") and cursor.index >= nb):
        raise BasisFileError(f"{where}: progress {cursor.to_dict()} does not fit a basis of {nb} functions")
    beyond = kind_of(opts).beyond(opts)
    if nb > opts.size + beyond:
        pruning = f" (and {beyond} more while pruning)" if beyond else ""
        raise BasisFileError(f"{where}: {nb} functions, more than the run's size = {opts.size}{pruning} allows")
    return basis, cursor, history, elapsed, schedule, stopped


def followed_roots(d: dict, targets: tuple, where: str,
                   recorded: Callable[[tuple], bool] | None = None) -> tuple[tuple, list[Followed]]:
    """The root indices at which a run with several or higher targeted levels (`targets`, the
    state's) stood, and the record of its re-assignments (objective.Followed), from checkpoint
    content `d` (the state's own indices where it has none); BasisFileError naming `where`, the key
    and its value for `levels` that are not distinct root indices, `followed` rows that are not
    [seconds, roots before, roots after], and levels that do not stand one per targeted level at or
    above it. A run's levels start at its targets and move only as `followed` records, so there the
    edited key is the state's `roots` if they are not where the levels started — the first row's
    roots before, or, for levels that never moved, the roots at which the checkpoint's objective is
    Σ w_k E_k (`recorded(roots)`: whether it is at `roots`; without it, `levels` is named)."""
    levels, rows = d.get("levels", list(targets)), d.get("followed", [])
    followed = [followed_row(f) for f in rows] if isinstance(rows, list) else [None]
    if not indices(levels):
        raise BasisFileError(f"{where}: levels = {reprlib.repr(levels)}: must be distinct root indices, one per "
                             "targeted level")
    if None in followed:
        raise BasisFileError(f"{where}: followed = {reprlib.repr(rows)}: must be [seconds, roots before, "
                             "roots after] rows")
    if len(levels) == len(targets) and all(r >= t for r, t in zip(levels, targets)):
        return tuple(levels), followed
    state = d["system"]["state"]
    if followed[0].before != tuple(targets) if followed else recorded is not None and not recorded(targets):
        read = f"roots = {reprlib.repr(state['roots'])}" if "roots" in state else "no roots (the lowest alone)"
        how = f"where its levels started, followed[0]: {list(followed[0].before)}" if followed else \
            f"its objective is not Σ w_k E_k there; its levels = {levels} never moved"
        raise BasisFileError(f"{where}: system.state: {read}: not the roots the run targeted ({how}): a resumed run "
                             "goes on for its own; start a new run for other roots")
    raise BasisFileError(f"{where}: levels = {reprlib.repr(levels)}: must be {len(targets)} root indices, one per "
                         f"targeted level, each at or above its target {list(targets)}")


def followed_row(row) -> Followed | None:
    """The re-assignment of a checkpoint's `followed` row [seconds, roots before, roots after]
    (objective.Followed), or None for a malformed one."""
    if not (isinstance(row, list) and len(row) == 3):
        return None
    _, before, after = row
    return Followed.of(row) if indices(before) and indices(after) else None


def indices(roots) -> bool:
    """Whether `roots` is a list of distinct root indices (integers ≥ 0)."""
    return isinstance(roots, list) and all(type(r) is int and r >= 0 for r in roots) and len(set(roots)) == len(roots)


def check_rng(block) -> dict:
    """A checkpoint's "rng" block: the state of numpy's PCG64 generator, {bit_generator: "PCG64",
    state: {state, inc}, has_uint32, uinteger} with integers in their ranges (numpy itself takes
    booleans and truncates floats); ValueError otherwise."""
    def count(k, bits):
        return type(k) is int and 0 <= k < 1 << bits

    ok = isinstance(block, dict) and set(block) == {"bit_generator", "state", "has_uint32", "uinteger"}
    state = block.get("state") if ok else None
    if not (ok and block["bit_generator"] == "PCG64" and isinstance(state, dict) and set(state) == {"state", "inc"}
            and count(state["state"], 128) and count(state["inc"], 128) and count(block["has_uint32"], 1)
            and count(block["uinteger"], 32)):
        raise ValueError(f"rng = {reprlib.repr(block)}: must be the state of numpy's PCG64 generator")
    return block


def load_checkpoint(folder) -> tuple[dict, System, Optimiser]:
    """The content of folder/basis.json with its system and settings, checked as a whole: the
    basis, the settings, the run state, the levels and the momentum block (BasisFileError naming
    the file)."""
    path = Path(folder) / CHECKPOINT
    if not path.exists():
        raise BasisFileError(f"{path}: no checkpoint to resume")
    d = basis_json.read(path)
    if not (isinstance(d, dict) and {"optimiser", "progress", "rng", "history"} <= set(d)):
        raise BasisFileError(f"{path}: not a run checkpoint (no optimiser state)")
    try:
        opts = Optimiser.from_dict(d["optimiser"])
    except PreboError as exc:
        raise BasisFileError(f"{path}: {exc}") from exc
    basis, *_ = resumed(d, opts, np.random.default_rng(), str(path))
    targets, _ = basis.system.state.levels
    followed_roots(d, targets, str(path), lambda roots: objective_at(d, basis, opts, roots))
    Momentum.from_dict(d.get("momentum"), basis, str(path))
    return d, basis.system, opts


def objective_at(d: dict, basis: Basis, opts: Optimiser, roots: tuple) -> bool:
    """Whether checkpoint content `d`'s objective is Σ w_k E_k of `basis` at `roots` (the state's
    weights; the run's representation and linear-dependence settings), to 1e-10 relative."""
    recorded, (_, weights) = d.get("objective"), basis.system.state.levels
    try:
        value = Expansion(basis, laboratory(basis.system), opts.threshold, opts.min_norm, opts.max_overlap,
                          Levels(roots, weights)).energy
    except PreboError:
        return False
    return type(recorded) is float and abs(value - recorded) <= 1e-10 * abs(recorded)
