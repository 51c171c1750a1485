"""The properties of one level of a basis (issue 40): its energy, uncertainty, virial coefficient
and whether it is bound, with the expectation value of every registered pair operator
(`expectation.OPERATORS`: ⟨r_ij⟩, ⟨r_ij²⟩, ⟨1/r_ij⟩, ⟨1/r_ij²⟩, ⟨δ³(r_ij)⟩) per class of equivalent
pairs — what `prebo properties BASIS --root k` prints and `prebo.properties(basis, root=k)`
returns. ⟨δ³(r_ij)⟩ is the direct expectation value, which Gaussians, lacking the cusp, reach
slowly (hydrogen 1s in 80 even-tempered Gaussians: 1.8e-4 low, against 2e-11 for ⟨r⟩).
"""
from __future__ import annotations

from . import eigen
from .basis import Basis
from .errors import InputError
from .expectation import OPERATORS
from .results import evaluate
from .validation import Integer, checked


def properties(basis, root: int = 0, coordinates: str = "lab", threshold: float = eigen.THRESHOLD) -> dict:
    """The properties of level `root` (0: the lowest of the basis's symmetry) of `basis`.

    Returns {"root", "energy", "energy_uncertainty" (Eh), "virial", "bound", "expectation":
    {operator: {pair class "a-b": value}}, "units": {operator: unit}} (and "n2", ⟨N²⟩_TI in ħ²,
    for floating ECGs). InputError for a root that is not a non-negative integer below the basis
    size; the errors of `results.evaluate` otherwise."""
    if not isinstance(basis, Basis) or len(basis) == 0:
        raise InputError(f"properties: basis = {basis!r}: must be a prebo.Basis with at least one function")
    root = checked(Integer(0, len(basis) - 1), root, "properties: root", f"roots of a basis of {len(basis)} functions")
    r = evaluate(basis, coordinates=coordinates, threshold=threshold, operators=tuple(OPERATORS), roots=root + 1)
    level = r["levels"][root] if "levels" in r else r
    keys = ("root", "energy", "energy_uncertainty", "virial", "bound", "n2", "expectation")
    return {k: level[k] for k in keys if k in level} | {"root": root, "units": {k: op.unit for k, op in OPERATORS.items()}}
