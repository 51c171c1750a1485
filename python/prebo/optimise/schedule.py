"""A schedule answers "what next" from the run's state and learns from what each unit of work
left: the fixed one of the settings (fixed.py) or the adaptive one that chooses by the energy each
kind of pass gains per second (adaptive.py). The driver (driver.optimise) runs either through
`Schedule` alone, made by `schedule_of`; what else depends on the kind — the defaults
(defaults.resolved), the methods (methods.methods), a checkpoint's margin past the size
(resume.py), the convergence report — asks the kind, `kind_of`.

The kind is the [optimiser] setting `schedule`. Inputs written before it have none: there the
kind is fixed if any of the fixed schedule's settings (settings.FIXED) is given, adaptive
otherwise, as it was.
"""
from __future__ import annotations

from typing import Protocol

from .adaptive import RATIO, Adaptive
from .cursor import Cursor
from .fixed import Fixed
from .settings import FIXED, Optimiser

#: the kinds of schedule by their [optimiser] schedule names
KINDS = {kind.name: kind for kind in (Adaptive, Fixed)}
#: a convergence report's "advantage" above which growth gains faster than the last passes did
GROWTH_FASTER = 1 / RATIO


class Schedule(Protocol):
    """What the driver asks a schedule. `stopped`: why it ended, a key of convergence.STOPPED
    (None while it goes on); `stalled`: the size at which growth stalled and the basis stays
    (None: it did not)."""

    stopped: str | None
    stalled: int | None

    def first(self) -> Cursor:
        """The cursor of a new run."""

    def advance(self, cursor: Cursor, nb: int, energy: float, now: float, functions: int = 1) -> Cursor:
        """The unit of work after the one at `cursor`, which visited `functions` functions of a
        sweep from `cursor.index` on (a batch of refinements, methods.Refine) and left `nb`
        functions at `energy` (Eh) after `now` seconds of the run; Cursor("done") when the
        schedule ends (`stopped` says why)."""

    def resume(self, cursor: Cursor, stopped: str | None, nb: int, energy: float,
               now: float) -> tuple[Cursor, str | None]:
        """The cursor and stop reason a resumed run goes on with, from those of its checkpoint."""

    def stall(self, nb: int) -> bool:
        """Growth stalled at `nb` functions (StalledError): whether the schedule goes on."""

    def restart(self, phase: str, nb: int, energy: float, threshold: float) -> Schedule | None:
        """The schedule of a fresh start from no function, if the unit of work of `phase` left a
        basis of `nb` functions at `energy` that should start afresh (`threshold`: the lowest
        dissociation threshold less the energy's uncertainty, Eh); else None."""

    def advantage(self, nb: int) -> float | None:
        """The convergence report's "advantage" (convergence.py) at `nb` functions."""

    def progress(self, cursor: Cursor, nb: int) -> tuple[str, int, int]:
        """The progress line's (description, done, total) of the unit of work at `cursor` on a basis
        of `nb` functions (report.Reporter)."""

    def cursor(self, progress, nb: int) -> Cursor:
        """The cursor of a checkpoint's "progress" block on a basis of `nb` functions."""

    def to_dict(self) -> dict:
        """The checkpoint's "schedule" block."""


def kind_of(opts: Optimiser) -> type[Adaptive] | type[Fixed]:
    """The kind of schedule of `opts`: its `schedule`, or where that is not given, fixed if any of
    the fixed schedule's settings is (module docstring)."""
    if opts.schedule is not None:
        return KINDS[opts.schedule]
    return Fixed if any(getattr(opts, k) is not None for k in FIXED) else Adaptive


def schedule_of(opts: Optimiser, block: dict | None = None) -> Schedule:
    """The schedule of `opts` (`kind_of`), with the state of a checkpoint's "schedule" block (its
    kind's `check`: ValueError for one that is malformed)."""
    return kind_of(opts).check(opts, block)
