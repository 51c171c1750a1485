"""A run's history: a `Step` for every unit of work that lowered the energy, kept in the
checkpoint's "history" as the list of its fields (`Step.row`) and summarised by convergence.py."""
from __future__ import annotations

import math
import reprlib
from dataclasses import dataclass

from .cursor import PHASES


@dataclass(frozen=True, slots=True)
class Step:
    """One step of the history: the basis `size` after it, its `energy` (Eh), the `phase` that
    took it and the `seconds` of the run at its end — None in the rows of checkpoints written
    before wall times were recorded, which stay three long (`row`)."""

    size: int
    energy: float
    phase: str
    seconds: float | None = None

    def row(self) -> list:
        """The checkpoint's row of the step: [size, energy, phase, seconds] (no seconds where None)."""
        return [self.size, self.energy, self.phase] + ([] if self.seconds is None else [self.seconds])


def check_history(history) -> list:
    """A checkpoint's "history": rows [size, energy (Eh), phase, seconds] (no seconds in
    checkpoints written before wall times were recorded), each a Step's fields; ValueError naming
    the first malformed row."""
    def finite(x):
        return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)

    if not isinstance(history, list):
        raise ValueError(f"history = {reprlib.repr(history)}: must be a list of [size, energy, phase, seconds] rows")
    def step(size, energy, phase, *seconds):
        return (type(size) is int and size > 0 and finite(energy) and phase in PHASES
                and all(finite(t) and t >= 0 for t in seconds))

    for k, row in enumerate(history):
        if not (isinstance(row, list) and len(row) in (3, 4) and step(*row)):
            raise ValueError(f"history row {k} = {reprlib.repr(row)}: must be [size, energy, phase, seconds] "
                             f"(a positive integer, a number, one of {', '.join(PHASES)}, seconds ≥ 0)")
    return history
