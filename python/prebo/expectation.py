"""Expectation values ⟨Ψ|O|Ψ⟩ of the registered operators: the Python end of the operator axis.

An operator registered here is evaluated for every basis family that has its element by the core's
generic path (`prebo._core.Engine.operator`, crates/prebo-core/src/operators/; `_core.OPERATORS`
names the operators of each family), in the laboratory frame or in translationally invariant
coordinates; `results.evaluate(basis, operators=...)` and `prebo energy --operator NAME` report it
for the state they solve. A new operator is one core module plus one registration line per layer
(docs/architecture.md, "Add an operator").

Pair operators act on r_w = Σ_k w_k r_k with w = e_i − e_j, the inter-particle vector
r_ij = r_i − r_j (hartree atomic units: lengths in bohr). Particle operators act on particle i's
momentum in the centre-of-mass frame, p_g = Σ_k g_k p_k = p_i − μ_i P with g = e_i − μ_i 1,
μ_i = m_i/m_tot (docs/properties-derivations.md §5: the momentum whose kinetic energies Σ p_i²/2m_i
add up to the translation-free T_TI). The core symmetrises a matrix like the overlap,
Σ_P c_P ⟨φ_I|O|Pφ_J⟩, which is ⟨Yφ_I|O|Yφ_J⟩ only for an O that commutes with the permutations of
identical particles. A single r_ij² (or p_i²) does not when particle i or j has an identical
partner, and is not an observable then; its average over the class of equivalent pairs (all pairs
of the same two particle names) or particles does commute, and is what is reported, one value per
class.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import _core
from .errors import InputError, UnsupportedError


def pair_classes(system) -> dict[str, np.ndarray]:
    """{"a-b": LFCC vectors w = e_i − e_j (p, n) of every pair i < j of a particle named a and one
    named b}, in the order the pairs first occur."""
    out: dict[str, list] = {}
    for i, j, w in system.pairs():
        names = sorted((system.particles[i].name, system.particles[j].name))
        out.setdefault("-".join(names), []).append(w)
    return {label: np.array(w) for label, w in out.items()}


def particle_classes(system, momentum: bool = False) -> dict[str, np.ndarray]:
    """{"a": vectors of every particle i named a}: w = e_i − μ (μ the mass fractions m/m_tot), so
    that r_w = r_i − R is particle i's position about the centre of mass R, or with `momentum`
    g = e_i − μ_i 1, so that p_g = p_i − μ_i P is its momentum in the centre-of-mass frame (g
    transforms like ∇, not like r)."""
    mu = system.cm_vector
    out: dict[str, list] = {}
    for i, p in enumerate(system.particles):
        v = np.full(system.n, -mu[i]) if momentum else -mu
        v[i] += 1.0
        out.setdefault(p.name, []).append(v)
    return {label: np.array(v) for label, v in out.items()}


@dataclass(frozen=True)
class Operator:
    """A registered operator, one expectation value per class of equivalent pairs (`pairs`) or
    particles (momentum operators, `particles`).

    name: the core's operator name; unit: of its expectation value; meaning: one line for reports;
    acts_on: "pairs" or "particles"."""

    name: str
    unit: str
    meaning: str
    acts_on: str = "pairs"

    @property
    def momentum(self) -> bool:
        """Whether its vectors are momentum-like (g, transformed like ∇) rather than position-like."""
        return self.acts_on == "particles"

    def classes(self, system) -> dict[str, np.ndarray]:
        """Its vectors per class: `pair_classes`, or `particle_classes` of the momenta."""
        return particle_classes(system, momentum=True) if self.momentum else pair_classes(system)

    def evaluates(self, family) -> bool:
        """Whether the core has this operator's element for the basis family `family`."""
        return self.name in _core.OPERATORS[family.name]


OPERATORS: dict[str, Operator] = {
    "r": Operator("r", "bohr", "⟨r_ij⟩, the mean distance of particles i and j"),
    "r2": Operator("r2", "bohr²", "⟨r_ij²⟩, the mean square distance of particles i and j"),
    "inv_r": Operator("inv_r", "bohr⁻¹", "⟨1/r_ij⟩, the mean inverse distance of particles i and j"),
    "inv_r2": Operator("inv_r2", "bohr⁻²", "⟨1/r_ij²⟩, the mean inverse square distance of particles i and j"),
    "delta": Operator("delta", "bohr⁻³", "⟨δ³(r_ij)⟩, the density of particles i and j at one point "
                                         "(direct: converges slowly in Gaussians, which lack the cusp)"),
    "p2": Operator("p2", "ħ²/bohr²", "⟨p_i²⟩, particle i's mean square momentum in the centre-of-mass frame",
                   "particles"),
    "p4": Operator("p4", "ħ⁴/bohr⁴", "⟨p_i⁴⟩, the mass–velocity term's −Σ⟨p_i⁴⟩/(8m_i³c²) per particle i",
                   "particles"),
}


def operator(name: str, family=None) -> Operator:
    """The registered operator `name`; InputError naming the registered ones otherwise, and
    UnsupportedError where the basis family `family` (if given) has not its element."""
    if name not in OPERATORS:
        raise InputError(f"unknown operator {name!r}: registered are {', '.join(OPERATORS)}")
    if family is not None and not OPERATORS[name].evaluates(family):
        raise UnsupportedError(f"operator {name!r}: its element is not derived for {family.name} functions "
                               f"(they evaluate {', '.join(_core.OPERATORS[family.name])})")
    return OPERATORS[name]


def expectation(rep, basis, C: np.ndarray, name: str) -> list[dict[str, float]]:
    """⟨Ψ|O|Ψ⟩ of the registered operator `name` for each state Ψ = Σ_k c_k Yφ_k, c a column of `C`
    with cᵀSc = 1 (the operator's matrices are built once for all of them).

    rep: the representation (integrals.laboratory or translationally_invariant) whose matrices gave
    C; basis: a prebo.Basis. Returns, per column, {pair class "a-b": the class average, in the
    operator's unit}."""
    op = operator(name, basis.family)
    classes = op.classes(basis.system)
    O = rep.operator(op.name, basis, np.concatenate(list(classes.values())), op.momentum)
    states = []
    for c in C.T:
        values, k = {}, 0
        for label, w in classes.items():
            values[label] = float(np.mean([c @ O[k + m] @ c for m in range(len(w))]))
            k += len(w)
        states.append(values)
    return states


def density_classes(system) -> dict[str, dict[str, np.ndarray]]:
    """The vectors of the densities, {"pairs": `pair_classes`, "particles": `particle_classes`}."""
    return {"pairs": pair_classes(system), "particles": particle_classes(system)}


def densities(rep, basis, C: np.ndarray, radii: dict) -> list[dict]:
    """The spherically averaged densities ρ̄(r) (bohr⁻³) of each state Ψ = Σ_k c_k Yφ_k, c a column
    of `C` with cᵀSc = 1, at the radii (bohr) `radii[group][class]` of every class of
    `density_classes`: per state {"pairs": {"a-b": ρ̄ of r_ij, the pair correlation function},
    "particles": {"a": ρ̄ of r_i − R, the density about the centre of mass}}, each averaged over its
    class of equivalent pairs or particles (module docstring). ∫ 4πr² ρ̄ dr = 1; 4πr²ρ̄ is the
    distribution of the distance."""
    states = [{group: {} for group in radii} for _ in range(C.shape[1])]
    for group, classes in density_classes(basis.system).items():
        for label, w in classes.items():
            rho = rep.density(basis, w, C, radii[group][label])
            for s, state in enumerate(states):
                state[group][label] = rho[:, s].mean(axis=0)
    return states
