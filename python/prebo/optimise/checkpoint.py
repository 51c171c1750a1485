"""Where a run stands, and its checkpoint: out/basis.json holds the basis, the settings, the
`Cursor` (the next unit of work), the random-number state, the history, the seconds spent, the
adaptive schedule's passes and why the run stopped, written atomically after every step;
`load_checkpoint` reads it back for `prebo run --resume`, which continues the run (bit for bit
in a fixed schedule), and checks every part of it as a claim (`resumed`, `check_history`,
`check_rng`): a malformed part is refused in one line naming the file and the key.

A fixed schedule's pruning raises the energy before refinement lowers it again, so the state a
run stands in need not be the lowest it passed through. `Lowest` keeps that one — the lowest
state of at most `size` functions — and writes it to out/lowest.json while the run stands
elsewhere (the file is removed once the run is back at or below it); the run returns it.
"""
from __future__ import annotations

import math
import reprlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..basis import Basis
from ..errors import BasisFileError, InputError, PreboError
from ..system import System
from ..validation import number
from .settings import Optimiser

CHECKPOINT = "basis.json"
LOWEST = "lowest.json"

PHASES = ("grow", "prune", "sweep", "refine", "polish", "momentum", "done")


@dataclass
class Cursor:
    """The next unit of work: one competitive step ("grow"); one step of growth past the size
    (`index` 0) or one removal (1) ("prune"), function `index` of replacement sweep / refinement
    sweep `sweep` ("sweep", "refine"), joint-refinement step `sweep` ("polish") of the
    prune-sweep-refine-polish block `cycle`, a move along the basis's displacement ("momentum",
    adaptive schedule only), or "done"."""

    phase: str = "grow"
    sweep: int = 0
    index: int = 0
    cycle: int = 0

    def __post_init__(self):
        counts = (self.sweep, self.index, self.cycle)
        if self.phase not in PHASES or not all(type(k) is int and k >= 0 for k in counts):
            raise InputError(f"progress {vars(self)}: phase must be one of {', '.join(PHASES)}, "
                             "sweep, index and cycle non-negative integers")

    def advance(self, nb: int, opts: Optimiser) -> "Cursor":
        """The unit of work after this one, for a basis of `nb` functions and the fixed schedule of
        `opts` (settings resolved by defaults.resolved: grow to `size`; per cycle growth to
        `size` + `prune` and removal back to `size`, `sweeps` replacement sweeps, `refine`
        refinement sweeps, `polish` joint steps; `cycles` cycles)."""
        if self.phase == "grow":
            if nb < opts.size:
                return self
            return Cursor("prune").settle(opts)
        if self.phase == "prune":
            if self.index == 0 and nb < opts.size + opts.prune:
                return self
            if nb > opts.size:
                return Cursor("prune", index=1, cycle=self.cycle)
            return Cursor("sweep", cycle=self.cycle).settle(opts)
        nxt = Cursor(self.phase, self.sweep, self.index + 1, self.cycle)
        if nxt.index >= nb or self.phase == "polish":
            nxt = Cursor(self.phase, self.sweep + 1, 0, self.cycle)
        return nxt.settle(opts)

    def settle(self, opts: Optimiser) -> "Cursor":
        """Skip phases whose sweeps are used up; after the last polish step, the next cycle."""
        if self.phase == "prune" and not opts.prune:
            return Cursor("sweep", cycle=self.cycle).settle(opts)
        if self.phase == "sweep" and self.sweep >= opts.sweeps:
            return Cursor("refine", cycle=self.cycle).settle(opts)
        if self.phase == "refine" and self.sweep >= opts.refine:
            return Cursor("polish", cycle=self.cycle).settle(opts)
        if self.phase == "polish" and self.sweep >= opts.polish:
            if self.cycle + 1 < opts.cycles:
                return Cursor("prune", cycle=self.cycle + 1).settle(opts)
            return Cursor("done")
        return self



class Lowest:
    """The lowest state of at most `size` functions a run has passed through (module docstring):
    its `energy` (hartree) and `basis` (with the state's coefficients; None before the first
    function); `basis` is the run's (its system and kind). With a folder `out`, out/lowest.json
    holds it whenever the run stands elsewhere, written as a basis file with `extra` (the
    settings) when the run leaves it; a `resumed` run reads it back (BasisFileError if it is not
    of this run; a new run never starts in a folder holding one, driver.optimise)."""

    def __init__(self, basis: Basis, size: int, out: Path | None, extra: dict, resumed: bool):
        self.size, self.extra = size, extra
        self.path = None if out is None else Path(out) / LOWEST
        self.energy, self.basis, self.written = np.inf, None, False
        if resumed and self.path is not None and self.path.exists():  # the run stood above it when it stopped
            from ..io import basis_json

            d = basis_json.read(self.path)
            self.basis = Basis.from_dict(d, str(self.path))
            try:
                self.energy = number(d.get("energy"), "energy")
            except InputError as exc:
                raise BasisFileError(f"{self.path}: {exc}") from exc
            if not of_this_run(self.basis, basis):
                raise BasisFileError(f"{self.path}: not a state of this run (another system, state or basis type "
                                     "than its checkpoint's)")
            self.written = True

    def see(self, expansion) -> None:
        """Take the expansion's state if it is as low as the lowest yet (or back at it) at `size`
        or fewer functions; otherwise write the lowest, if the run has just left it."""
        nb = len(expansion.basis)
        if 0 < nb <= self.size and expansion.energy <= self.energy:
            self.energy, self.basis = expansion.energy, expansion.basis.subset(slice(None))
            self.basis.coefficients = expansion.eig.vectors[:, 0]
            if self.path is not None and self.written:
                self.path.unlink(missing_ok=True)
            self.written = False
        elif self.path is not None and self.basis is not None and not self.written and (
                nb > self.size or expansion.energy > self.energy):
            self.basis.save(self.path, {"energy": self.energy} | self.extra)
            self.written = True


def of_this_run(other: Basis, basis: Basis) -> bool:
    """Whether the basis `other` belongs to the run of `basis`: the same particles, state and
    basis type (a lowest state or a momentum reference read back with a checkpoint)."""
    return (other.kind, other.system.particles, other.system.state) == (
        basis.kind, basis.system.particles, basis.system.state)


def resumed(d: dict, opts: Optimiser, rng: np.random.Generator, where: str) -> tuple:
    """The basis, cursor, history, elapsed seconds, adaptive schedule (schedule.Adaptive) and
    stop reason of checkpoint content `d` (`rng` takes its state); BasisFileError naming `where`
    for anything that does not fit."""
    from .convergence import STOPPED
    from .schedule import Adaptive

    basis = Basis.from_dict(d, where, empty=True)
    if basis.kind != opts.kind:
        raise BasisFileError(f"{where}: a {basis.kind} basis, but the optimiser's kind is {opts.kind}")
    try:
        cursor = Cursor(**d["progress"])
        rng.bit_generator.state = check_rng(d["rng"])
        history, elapsed = check_history(d["history"]), number(d.get("elapsed", 0.0), "elapsed")
        if elapsed < 0:
            raise ValueError(f"elapsed = {elapsed!r}: must be the seconds of the run so far (≥ 0)")
        schedule, stopped = Adaptive.check(opts, d.get("schedule")), d.get("stopped")
        if stopped not in STOPPED:
            raise ValueError(f"stopped = {reprlib.repr(stopped)}: must be one of {tuple(STOPPED)}")
    except (KeyError, TypeError, ValueError) as exc:
        raise BasisFileError(f"{where}: malformed run state ({exc})") from exc
    nb = len(basis)
    if (cursor.phase != "grow" and nb == 0) or (cursor.phase in ("sweep", "refine") and cursor.index >= nb):
        raise BasisFileError(f"{where}: progress {vars(cursor)} does not fit a basis of {nb} functions")
    return basis, cursor, history, elapsed, schedule, stopped


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


def check_history(history) -> list:
    """A run's history: rows [size, energy (Eh), phase, seconds] (no seconds in checkpoints written
    before wall times were recorded); ValueError naming the first malformed row."""
    def finite(x):
        return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)

    if not isinstance(history, list):
        raise ValueError(f"history = {reprlib.repr(history)}: must be a list of [size, energy, phase, seconds] rows")
    for k, row in enumerate(history):
        if not (isinstance(row, list) and len(row) in (3, 4) and type(row[0]) is int and row[0] > 0
                and finite(row[1]) and row[2] in PHASES and (len(row) == 3 or finite(row[3]) and row[3] >= 0)):
            raise ValueError(f"history row {k} = {reprlib.repr(row)}: must be [size, energy, phase, seconds] "
                             f"(a positive integer, a number, one of {', '.join(PHASES)}, seconds ≥ 0)")
    return history


def load_checkpoint(folder) -> tuple[dict, System, Optimiser]:
    """The content of folder/basis.json with its system and settings, checked as a whole: the
    basis, the settings, the run state and the momentum block (BasisFileError naming the file)."""
    from ..io import basis_json
    from .momentum import Momentum

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
    Momentum.from_dict(d.get("momentum"), basis, str(path))
    return d, basis.system, opts


def checkpoint_in(folder) -> Path | None:
    """The checkpoint (basis.json, else lowest.json) in `folder` that a new run there would
    overwrite, or None."""
    return next((p for p in (Path(folder) / CHECKPOINT, Path(folder) / LOWEST) if p.exists()), None)
