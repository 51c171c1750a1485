"""The lowest state a run has passed through.

A fixed schedule's pruning raises the energy before refinement lowers it again, so the state a
run stands in need not be the lowest it passed through. `Lowest` keeps that one — the lowest
state of at most `size` functions — and writes it to out/lowest.json while the run stands
elsewhere (the file is removed once the run is back at or below it); the run returns it.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..basis import Basis
from ..errors import BasisFileError, InputError
from ..io import basis_json
from ..validation import number
from .checkpoint import LOWEST, of_this_run


class Lowest:
    """The lowest state of at most `size` functions a run has passed through (module docstring):
    its `energy` (hartree; the objective, objective.py) and `basis` (with the state's coefficients;
    None before the first function); `basis` is the run's (its system and kind). With a folder
    `out`, out/lowest.json holds it whenever the run stands elsewhere, written as a basis file with
    `extra` (the settings) when the run leaves it — its `energy` the lowest root's, and for a run
    for excited levels or a response the `objective` too; a `resumed` run reads it back (BasisFileError if it is
    not of this run; a new run never starts in a folder holding one, driver.optimise)."""

    def __init__(self, basis: Basis, size: int, out: Path | None, extra: dict, resumed: bool):
        self.size, self.extra = size, extra
        self.path = None if out is None else Path(out) / LOWEST
        self.energy, self.basis, self.written, self.record = np.inf, None, False, {}
        if resumed and self.path is not None and self.path.exists():  # the run stood above it when it stopped
            d = basis_json.read(self.path)
            self.basis = Basis.from_dict(d, str(self.path))
            key = "objective" if "objective" in d else "energy"
            try:
                self.energy = number(d.get(key), key)
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
            self.basis.coefficients = expansion.coefficients
            self.record = {"energy": expansion.lowest_root} | ({"objective": self.energy}
                                                               if expansion.objective.recorded else {})
            if self.path is not None and self.written:
                self.path.unlink(missing_ok=True)
            self.written = False
        elif self.path is not None and self.basis is not None and not self.written and (
                nb > self.size or expansion.energy > self.energy):
            self.basis.save(self.path, self.record | self.extra)
            self.written = True
