"""Expectation values ⟨Ψ|O|Ψ⟩ of the registered operators: the Python end of the operator axis.

An operator registered here is evaluated for every basis family by the core's generic path
(`prebo._core.Engine.operator`, crates/prebo-core/src/operators/), symmetrised like the overlap,
in the laboratory frame or in translationally invariant coordinates. `results.evaluate` reports
every registered operator for the state it solved, so a new operator is one core module plus one
registration line per layer (docs/architecture.md, "Add an operator").

Pair operators act on r_w = Σ_k w_k r_k with w = e_i − e_j, i.e. on the inter-particle vector
r_ij = r_i − r_j, one value per pair i < j (hartree atomic units: lengths in bohr).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import InputError


@dataclass(frozen=True)
class PairOperator:
    """An operator of the inter-particle vectors, one expectation value per pair i < j.

    name: the core's operator name; unit: of its expectation value; meaning: one line for reports."""

    name: str
    unit: str
    meaning: str

    @staticmethod
    def pairs(system) -> tuple[list[str], np.ndarray]:
        """Pair labels "i-j" (1-based, particle names in brackets) and LFCC vectors w = e_i − e_j (p, n)."""
        labels, w = [], []
        for i in range(system.n):
            for j in range(i + 1, system.n):
                e = np.zeros(system.n)
                e[i], e[j] = 1.0, -1.0
                names = system.particles[i].name, system.particles[j].name
                labels.append(f"{i + 1}-{j + 1} ({names[0]},{names[1]})")
                w.append(e)
        return labels, np.array(w).reshape(len(labels), system.n)


OPERATORS: dict[str, PairOperator] = {
}


def expectation(rep, basis, c: np.ndarray, name: str) -> dict[str, float]:
    """⟨Ψ|O|Ψ⟩ of the registered operator `name` for Ψ = Σ_k c_k φ_k with cᵀSc = 1.

    rep: the representation (integrals.laboratory or translationally_invariant) whose matrices gave
    c; basis: a prebo.Basis; returns {pair label: value in the operator's unit}."""
    if name not in OPERATORS:
        raise InputError(f"unknown operator {name!r}: known are {', '.join(OPERATORS)}")
    op = OPERATORS[name]
    labels, w = op.pairs(basis.system)
    O = rep.operator(op.name, basis, w)
    return {label: float(c @ O[k] @ c) for k, label in enumerate(labels)}
