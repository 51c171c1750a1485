"""Where a run stands: the `Cursor`, the next unit of work of its schedule (schedule.py), kept in
the checkpoint's "progress" block."""
from __future__ import annotations

from dataclasses import dataclass

from ..errors import InputError

#: the phases of a run, as its checkpoint and history name them
PHASES = ("grow", "prune", "sweep", "refine", "polish", "momentum", "done")


@dataclass
class Cursor:
    """The next unit of work: one competitive step ("grow"); one step of growth past the size
    (`index` 0) or one removal (1) ("prune"), function `index` of replacement sweep / refinement
    sweep `sweep` ("sweep", "refine"), joint-refinement step `sweep` ("polish") of the
    prune-sweep-refine-polish block `cycle`, a move along the basis's displacement ("momentum",
    adaptive schedule only), or "done". The adaptive schedule keeps a growth pass's target size
    in `sweep` and its pass number in `cycle` (adaptive.py)."""

    phase: str = "grow"
    sweep: int = 0
    index: int = 0
    cycle: int = 0

    def __post_init__(self):
        counts = (self.sweep, self.index, self.cycle)
        if self.phase not in PHASES or not all(type(k) is int and k >= 0 for k in counts):
            raise InputError(f"progress {vars(self)}: phase must be one of {', '.join(PHASES)}, "
                             "sweep, index and cycle non-negative integers")
