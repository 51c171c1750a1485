"""A run's history: a `Step` for every unit of work that lowered the energy, kept in the
checkpoint's "history" as the list of its fields and summarised by convergence.py."""
from __future__ import annotations

import math
import reprlib

from .cursor import PHASES


class Step(tuple):
    """One step of the history: the basis `size` after it, its `energy` (Eh), the `phase` that
    took it and the `seconds` of the run at its end — None in the rows of checkpoints written
    before wall times were recorded, which stay three long. A tuple of the fields the checkpoint
    stores, so it is written as they are."""

    __slots__ = ()

    def __new__(cls, size: int, energy: float, phase: str, seconds: float | None = None):
        return super().__new__(cls, (size, energy, phase) if seconds is None else (size, energy, phase, seconds))

    @property
    def size(self) -> int:
        return self[0]

    @property
    def energy(self) -> float:
        return self[1]

    @property
    def phase(self) -> str:
        return self[2]

    @property
    def seconds(self) -> float | None:
        return self[3] if len(self) > 3 else None


def check_history(history) -> list:
    """A checkpoint's "history": rows [size, energy (Eh), phase, seconds] (no seconds in
    checkpoints written before wall times were recorded), each a Step's fields; ValueError naming
    the first malformed row."""
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
