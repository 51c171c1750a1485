"""Expectation values ⟨Ψ|O|Ψ⟩ of the registered operators: the Python end of the operator axis.

An operator registered here is evaluated for every basis family by the core's generic path
(`prebo._core.Engine.operator`, crates/prebo-core/src/operators/), in the laboratory frame or in
translationally invariant coordinates; `results.evaluate(basis, operators=...)` and
`prebo energy --operator NAME` report it for the state they solve. A new operator is one core
module plus one registration line per layer (docs/architecture.md, "Add an operator").

Pair operators act on r_w = Σ_k w_k r_k with w = e_i − e_j, the inter-particle vector
r_ij = r_i − r_j (hartree atomic units: lengths in bohr). The core symmetrises a matrix like the
overlap, Σ_P c_P ⟨φ_I|O|Pφ_J⟩, which is ⟨Yφ_I|O|Yφ_J⟩ only for an O that commutes with the
permutations of identical particles. A single r_ij² does not when particle i or j has an identical
partner, and is not an observable then; its average over the class of equivalent pairs (all pairs
of the same two particle names) does commute, and is what is reported, one value per class.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import InputError


@dataclass(frozen=True)
class PairOperator:
    """An operator of the inter-particle vectors, one expectation value per class of equivalent pairs.

    name: the core's operator name; unit: of its expectation value; meaning: one line for reports."""

    name: str
    unit: str
    meaning: str

    @staticmethod
    def classes(system) -> dict[str, np.ndarray]:
        """{"a-b": LFCC vectors w = e_i − e_j (p, n) of every pair i < j of a particle named a and
        one named b}, in the order the pairs first occur."""
        out: dict[str, list] = {}
        for i, j, w in system.pairs():
            names = sorted((system.particles[i].name, system.particles[j].name))
            out.setdefault("-".join(names), []).append(w)
        return {label: np.array(w) for label, w in out.items()}


OPERATORS: dict[str, PairOperator] = {
    "r": PairOperator("r", "bohr", "⟨r_ij⟩, the mean distance of particles i and j"),
    "r2": PairOperator("r2", "bohr²", "⟨r_ij²⟩, the mean square distance of particles i and j"),
    "inv_r": PairOperator("inv_r", "bohr⁻¹", "⟨1/r_ij⟩, the mean inverse distance of particles i and j"),
    "inv_r2": PairOperator("inv_r2", "bohr⁻²", "⟨1/r_ij²⟩, the mean inverse square distance of particles i and j"),
    "delta": PairOperator("delta", "bohr⁻³", "⟨δ³(r_ij)⟩, the density of particles i and j at one point "
                                             "(direct: converges slowly in Gaussians, which lack the cusp)"),
}


def operator(name: str) -> PairOperator:
    """The registered operator `name`; InputError naming the registered ones otherwise."""
    if name not in OPERATORS:
        raise InputError(f"unknown operator {name!r}: registered are {', '.join(OPERATORS)}")
    return OPERATORS[name]


def expectation(rep, basis, C: np.ndarray, name: str) -> list[dict[str, float]]:
    """⟨Ψ|O|Ψ⟩ of the registered operator `name` for each state Ψ = Σ_k c_k Yφ_k, c a column of `C`
    with cᵀSc = 1 (the operator's matrices are built once for all of them).

    rep: the representation (integrals.laboratory or translationally_invariant) whose matrices gave
    C; basis: a prebo.Basis. Returns, per column, {pair class "a-b": the class average, in the
    operator's unit}."""
    op = operator(name)
    classes = op.classes(basis.system)
    O = rep.operator(op.name, basis, np.concatenate(list(classes.values())))
    states = []
    for c in C.T:
        values, k = {}, 0
        for label, w in classes.items():
            values[label] = float(np.mean([c @ O[k + m] @ c for m in range(len(w))]))
            k += len(w)
        states.append(values)
    return states
