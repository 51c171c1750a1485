"""The fixed schedule of the settings (resolved by defaults.resolved): growth to `size` by
competitive selection, then `cycles` times growth to `size` + `prune` and removal back to `size`,
`sweeps` replacement sweeps, `refine` refinement sweeps and `polish` joint steps (methods.py).
It makes the same decisions on every run, so a run repeats, and resumes, bit for bit.
"""
from __future__ import annotations

from .cursor import OLD, Cursor
from .settings import FIXED, Optimiser

#: the fixed schedule's settings where the input leaves them out: no pruning, sweeps or joint steps, one cycle
SETTINGS = dict(zip(FIXED, (0, 0, 0, 0, 1)))
#: the "schedule" block of checkpoints written before the fixed schedule had one of its own: an empty
#: adaptive schedule's (adaptive.Adaptive.to_dict), with "restarts": 0 in the later ones
IDLE = {"passes": [], "start": [None, 0.0], "next": {"refine": 0, "sweep": 0}, "stalled": None}


class Fixed:
    """The fixed schedule of `opts` (module docstring; the interface of schedule.Schedule).
    Growth that stalls ends it: the run stops with StalledError (`stall`)."""

    #: the schedule's name, its [optimiser] schedule value
    name = "fixed"
    #: a pruning is a unit of work per function grown or removed (methods.PruneStep)
    whole_pruning = False
    #: the basis does not move on along its displacement (momentum.py)
    moves = False
    stalled = None

    def __init__(self, opts: Optimiser):
        self.opts, self.stopped = opts, None

    @staticmethod
    def defaults(opts: Optimiser, molecule: bool) -> dict:
        """The settings the schedule chooses where the input leaves them out (defaults.py): 20
        trials per step (30 for a `molecule`), 200 energies per refinement, one function at a time,
        no trials near the basis (the runs of the fixed schedule are reproduced as they were
        measured), and SETTINGS."""
        return {"trials": 30 if molecule else 20, "refine_evaluations": 200, "refine_group": 1, "near": 0.0} | SETTINGS

    @staticmethod
    def refines_newcomers(opts: Optimiser) -> bool:
        """Grown and replacing functions are refined first with refinement sweeps (methods.methods)."""
        return bool(opts.refine)

    @staticmethod
    def beyond(opts: Optimiser) -> int:
        """The functions a checkpoint may hold past the size: `prune`, grown a step at a time with a
        checkpoint after each (resume.py)."""
        return opts.prune or 0

    @staticmethod
    def report(advantage: float | None) -> dict:
        """The convergence report's schedule entries (convergence.py): no rates are measured."""
        return {"adaptive": False, "advantage": None}

    def first(self) -> Cursor:
        """The cursor of a new run: growth from no function."""
        return Cursor("grow", target=self.opts.size)

    def cursor(self, progress, nb: int) -> Cursor:
        """The cursor of a checkpoint's "progress" block (Cursor.to_dict), also of one written before
        each field had one meaning (cursor.OLD: a pruning's growth at `index` 0, its removals at 1);
        TypeError or InputError for one that is malformed."""
        if not (isinstance(progress, dict) and set(progress) <= OLD):
            return Cursor(**progress)
        old, opts = Cursor(**progress), self.opts
        if old.phase == "grow":
            return self.first()
        if old.phase == "prune":
            return Cursor("prune", target=opts.size + (opts.prune if old.index == 0 else 0), cycle=old.cycle)
        return Cursor(old.phase, index=old.index, sweep=old.sweep, cycle=old.cycle)

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
        basis of `nb` functions (module docstring): a pruning grows to `size` + `prune`, then
        removes back to `size`."""
        opts = self.opts
        if cursor.phase == "grow":
            if nb < opts.size:
                return cursor
            return self.settle(Cursor("prune"))
        if cursor.phase == "prune":
            if nb < cursor.target:
                return cursor
            if nb > opts.size:
                return Cursor("prune", target=opts.size, cycle=cursor.cycle)
            return self.settle(Cursor("sweep", cycle=cursor.cycle))
        nxt = Cursor(cursor.phase, index=cursor.index + functions, sweep=cursor.sweep, cycle=cursor.cycle)
        if nxt.index >= nb or cursor.phase == "polish":
            nxt = Cursor(cursor.phase, sweep=cursor.sweep + 1, cycle=cursor.cycle)
        return self.settle(nxt)

    def settle(self, cursor: Cursor) -> Cursor:
        """`cursor`, its phases whose sweeps are used up skipped; after the last polish step, the
        next cycle, which starts with a pruning's growth to `size` + `prune`."""
        opts = self.opts
        if cursor.phase == "prune":
            if not opts.prune:
                return self.settle(Cursor("sweep", cycle=cursor.cycle))
            return Cursor("prune", target=opts.size + opts.prune, cycle=cursor.cycle)
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
        """The checkpoint's "schedule" block: the schedule's name (its state is the cursor's)."""
        return {"schedule": self.name}

    @classmethod
    def check(cls, opts: Optimiser, block) -> Fixed:
        """The schedule of a checkpoint's "schedule" block (`to_dict`; IDLE in checkpoints written
        before it, none in older ones); ValueError for another."""
        idle = (isinstance(block, dict) and block.get("restarts", 0) == 0
                and block.keys() - {"restarts"} == IDLE.keys() and all(block[k] == v for k, v in IDLE.items()))
        if not (block is None or idle or block == {"schedule": cls.name}):
            raise ValueError(f"schedule = {block!r}: must be {{schedule: {cls.name}}} for a fixed schedule")
        return cls(opts)
