"""Drachmann's regularised contact densities (docs/properties-derivations.md §6, eq. 27): for an
eigenstate Ψ of T_TI + V with energy E,

    ⟨δ³(r_ij)⟩ = (μ_ij/π) [E⟨1/r_ij⟩ − ⟨V/r_ij⟩ − ⟨∇Ψ|Λ/r_ij|∇Ψ⟩],   μ_ij = m_i m_j/(m_i + m_j),

with Λ the kinetic matrix of T_TI = −∇ᵀΛ∇. The right side holds global operators, so in Gaussians,
which lack the cusp, it converges faster with the basis than the direct ⟨δ³(r_ij)⟩ ("delta"), the
density at one point. Its elements are the core's "inv_r", "coulomb_inv_r" and "gradient_inv_r"
(crates/prebo-core/src/operators/drachmann.rs), for every family. ⟨V/r_ij⟩ is in closed form for
plain ECGs (eq. 19) and a quadrature over the family's damped ⟨1/r⟩ elements for floating ECGs and
ECG-GVR (eq. 38), up to a millisecond per element: `CLOSED_FORM` says where it is cheap.
"""
from __future__ import annotations

import numpy as np

from .expectation import expectation, members, operator
from .system import reduced_mass

#: the operators of eq. (27): ⟨1/r_ij⟩, ⟨V/r_ij⟩, ⟨∇Ψ|Λ/r_ij|∇Ψ⟩
TERMS = ("inv_r", "coulomb_inv_r", "gradient_inv_r")

#: the basis families whose ⟨V/r_ij⟩ is in closed form (eq. 19), as cheap as ⟨1/r_ij⟩
CLOSED_FORM = ("pecg",)


def delta_regularised(rep, basis, C: np.ndarray, energies) -> list[dict[str, float]]:
    """Per state Ψ = Σ_k c_k Yφ_k (c a column of `C`, cᵀSc = 1, an eigenvector of the
    representation `rep`'s T_TI + V with the energy `energies[s]` in Eh): {pair class "a-b": the
    regularised ⟨δ³(r_ij)⟩ in bohr⁻³, averaged over the class like `expectation`}.
    UnsupportedError for a basis family without the three elements (`expectation.operator`)."""
    for name in TERMS:
        operator(name, basis.family)
    values = {name: expectation(rep, basis, C, name) for name in TERMS}
    return [regularised(basis.system, {name: values[name][s] for name in TERMS}, E) for s, E in enumerate(energies)]


def regularised(system, expectation: dict, energy: float) -> dict[str, float]:
    """{pair class "a-b": the regularised ⟨δ³(r_ij)⟩ (bohr⁻³)} of one eigenstate of `system` with
    the energy `energy` (Eh) from its expectation values of TERMS ({operator: {class: value}}, as
    `results.evaluate` gives them)."""
    mu = {label: reduced_mass(*system.masses[list(ms[0])]) for label, ms in members(system, pairs=True).items()}
    inv_r, potential, gradient = (expectation[name] for name in TERMS)
    return {label: float(mu[label] / np.pi * (energy * inv_r[label] - potential[label] - gradient[label]))
            for label in inv_r}
