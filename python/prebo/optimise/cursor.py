"""Where a run stands: the `Cursor`, the next unit of work of its schedule (schedule.py), kept in
the checkpoint's "progress" block."""
from __future__ import annotations

from dataclasses import asdict, dataclass, fields

from ..errors import InputError

#: the phases of a run, as its checkpoint and history name them
PHASES = ("grow", "prune", "sweep", "refine", "polish", "momentum", "done")


@dataclass(frozen=True, slots=True)
class Cursor:
    """The next unit of work: its `phase` — one competitive step ("grow"), one step of a pruning
    ("prune"), one step of a replacement or refinement sweep ("sweep", "refine"), a joint step
    ("polish"), a move along the basis's displacement ("momentum", adaptive schedule only), or
    "done" — and, each with one meaning, what the schedules keep of it:

    - `target`: the size the basis heads for: growth adds functions up to it; a pruning grows
      up to it and removes functions while the basis is larger (fixed.py), or grows by
      `target` − N_b steps and removes as many again (methods.PrunePass);
    - `index`: the function a sweep's step starts at;
    - `sweep`: the sweep of its phase, or the joint step, within the cycle (fixed schedule);
    - `cycle`: the prune-sweep-refine-polish block (fixed schedule);
    - `number`: the pass of the adaptive schedule (adaptive.py);
    - `visited`: the functions of the pass visited so far (adaptive schedule's sweeps)."""

    phase: str = "grow"
    target: int = 0
    index: int = 0
    sweep: int = 0
    cycle: int = 0
    number: int = 0
    visited: int = 0

    def __post_init__(self):
        counts = [getattr(self, f.name) for f in fields(self)][1:]
        if self.phase not in PHASES or not all(type(k) is int and k >= 0 for k in counts):
            raise InputError(f"progress {self.to_dict()}: phase must be one of {', '.join(PHASES)}, "
                             f"{', '.join(f.name for f in fields(self)[1:])} non-negative integers")

    def to_dict(self) -> dict:
        """The checkpoint's "progress" block."""
        return asdict(self)


#: the fields of a "progress" block written before each had one meaning (read by the schedules' `cursor`)
OLD = {"phase", "sweep", "index", "cycle"}
