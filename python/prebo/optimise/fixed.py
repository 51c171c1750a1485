"""The fixed schedule of the settings (resolved by defaults.resolved): growth to `size` by
competitive selection, then `cycles` times growth to `size` + `prune` and removal back to `size`,
`sweeps` replacement sweeps, `refine` refinement sweeps and `polish` joint steps (methods.py).
It makes the same decisions on every run, so a run repeats, and resumes, bit for bit.
"""
from __future__ import annotations

from .cursor import Cursor
from .settings import Optimiser

#: a fixed schedule's "schedule" block in the checkpoint: that of an adaptive schedule before its
#: first pass (adaptive.Adaptive.to_dict), one format for both
IDLE = {"passes": [], "start": [None, 0.0], "next": {"refine": 0, "sweep": 0}, "stalled": None, "restarts": 0}


class Fixed:
    """The fixed schedule of `opts` (module docstring; the interface of schedule.Schedule).
    Growth that stalls ends it: the run stops with StalledError (`stall`)."""

    stalled = None

    def __init__(self, opts: Optimiser):
        self.opts, self.stopped = opts, None

    def first(self) -> Cursor:
        """The cursor of a new run: growth from no function."""
        return self.next(Cursor(), 0)

    def advance(self, cursor: Cursor, nb: int, energy: float, now: float, functions: int = 1) -> Cursor:
        """The unit of work after the one at `cursor`, which visited `functions` functions of a
        sweep and left `nb` functions (the energy and the seconds do not change a fixed schedule);
        at the end, "done", `stopped` "schedule"."""
        cursor = self.next(cursor, nb, functions)
        if cursor.phase == "done":
            self.stopped = "schedule"
        return cursor

    def next(self, cursor: Cursor, nb: int, functions: int = 1) -> Cursor:
        """The unit of work after `cursor`, which visited `functions` functions of a sweep, for a
        basis of `nb` functions (module docstring)."""
        opts = self.opts
        if cursor.phase == "grow":
            if nb < opts.size:
                return cursor
            return self.settle(Cursor("prune"))
        if cursor.phase == "prune":
            if cursor.index == 0 and nb < opts.size + opts.prune:
                return cursor
            if nb > opts.size:
                return Cursor("prune", index=1, cycle=cursor.cycle)
            return self.settle(Cursor("sweep", cycle=cursor.cycle))
        nxt = Cursor(cursor.phase, cursor.sweep, cursor.index + functions, cursor.cycle)
        if nxt.index >= nb or cursor.phase == "polish":
            nxt = Cursor(cursor.phase, cursor.sweep + 1, 0, cursor.cycle)
        return self.settle(nxt)

    def settle(self, cursor: Cursor) -> Cursor:
        """`cursor`, its phases whose sweeps are used up skipped; after the last polish step, the
        next cycle."""
        opts = self.opts
        if cursor.phase == "prune" and not opts.prune:
            return self.settle(Cursor("sweep", cycle=cursor.cycle))
        if cursor.phase == "sweep" and cursor.sweep >= opts.sweeps:
            return self.settle(Cursor("refine", cycle=cursor.cycle))
        if cursor.phase == "refine" and cursor.sweep >= opts.refine:
            return self.settle(Cursor("polish", cycle=cursor.cycle))
        if cursor.phase == "polish" and cursor.sweep >= opts.polish:
            if cursor.cycle + 1 < opts.cycles:
                return self.settle(Cursor("prune", cycle=cursor.cycle + 1))
            return Cursor("done")
        return cursor

    def resume(self, cursor: Cursor, stopped: str | None, nb: int, energy: float,
               now: float) -> tuple[Cursor, str | None]:
        """A resumed run goes on at its cursor."""
        return cursor, stopped

    def stall(self, nb: int) -> bool:
        """Growth stalled at `nb` functions: the schedule cannot go on (False)."""
        return False

    def restart(self, phase: str, nb: int, energy: float, threshold: float) -> None:
        """A fixed schedule never starts afresh."""
        return None

    def advantage(self, nb: int) -> None:
        """No rates are measured."""
        return None

    def progress(self, cursor: Cursor, nb: int) -> tuple[str, int, int]:
        """(description, done, total) of the progress line: functions grown, pruned again past the
        size, joint steps, or functions visited in a sweep."""
        opts, cycle = self.opts, cursor.cycle + 1
        if cursor.phase == "grow":
            return "growing", nb, opts.size
        if cursor.phase == "prune":  # growth past the size: the functions to be pruned again
            return f"prune (cycle {cycle})", nb - opts.size, opts.prune
        if cursor.phase == "polish":
            return f"polish (cycle {cycle})", cursor.sweep + 1, opts.polish
        return f"{cursor.phase} {cursor.sweep + 1} (cycle {cycle})", cursor.index + 1, nb

    def to_dict(self) -> dict:
        """The checkpoint's "schedule" block (IDLE)."""
        return IDLE
