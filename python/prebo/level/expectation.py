"""Expectation values ⟨Ψ|O|Ψ⟩ of the registered operators: the Python end of the operator axis.

An operator registered here is evaluated for every basis family that has its element by the core's
generic path (`prebo._core.Engine.operator`, crates/prebo-core/src/operators/; `_core.OPERATORS`
names the operators of each family), in the laboratory frame or in translationally invariant
coordinates; `evaluate(basis, operators=...)` and `prebo energy --operator NAME` report it
for the state they solve. A new operator is one core module plus one registration line per layer
(docs/architecture.md, "Add an operator"). The core's "n2", ⟨N²⟩_TI of floating ECGs, is an
operator of the whole system (its vector the mass fractions), reported per level by
`evaluate`, not per class here.

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

from .. import _core
from ..errors import InputError, UnsupportedError


#: the kinds of operator vectors (`vector`)
KINDS = frozenset({"r_ij", "r_i", "p_i", "p_j"})


def vector(system, kind: str, i: int, j: int | None = None) -> np.ndarray:
    """The LFCC vector of `kind` for particle i (of the pair i, j): "r_ij" w = e_i − e_j (r_ij =
    r_i − r_j), "r_i" w = e_i − μ (r_i − R, the position about the centre of mass R; μ the mass
    fractions m/m_tot), "p_i" or "p_j" g = e_k − μ_k 1 for k = i or j (p_k − μ_k P, the momentum in
    the centre-of-mass frame, which transforms like ∇, not like r)."""
    mu = system.cm_vector
    if kind == "r_ij":
        return np.eye(system.n)[i] - np.eye(system.n)[j]
    if kind == "r_i":
        return np.eye(system.n)[i] - mu
    k = j if kind == "p_j" else i
    return np.eye(system.n)[k] - mu[k]


def members(system, pairs: bool) -> dict[str, list[tuple[int, ...]]]:
    """{label: its members} of every class of equivalent pairs ("a-b": every pair (i, j), i < j, of
    a particle named a and one named b) or, without `pairs`, of particles ("a": every (i,) named a),
    in the order of first occurrence. A class's members share their masses, charges and spins."""
    out: dict[str, list] = {}
    if pairs:
        for i, j, _ in system.pairs():
            out.setdefault("-".join(sorted((system.particles[i].name, system.particles[j].name))), []).append((i, j))
    else:
        for i, p in enumerate(system.particles):
            out.setdefault(p.name, []).append((i,))
    return out


def vanishing(system) -> list[str]:
    """The pair classes "a-b" of `system` at whose every coalescence r_i = r_j each of its states
    vanishes: its symmetry operator makes each pair antisymmetric (`Symmetriser.antisymmetric`,
    the electrons of a triplet). A contact operator's value there is zero exactly (`Operator.contact`)."""
    symmetriser = system.symmetriser
    return [label for label, ms in members(system, pairs=True).items()
            if all(symmetriser.antisymmetric(i, j) for i, j in ms)]


def classes(system, kinds: tuple[str, ...]) -> dict[str, np.ndarray]:
    """{label: vectors (instances, len(kinds), n)} of the `kinds` (see `vector`) per class of
    equivalent pairs if a kind names a pair ("r_ij", "p_j"), else per class of particles
    (`members`)."""
    pairs = bool({"r_ij", "p_j"} & set(kinds))
    return {label: np.array([[vector(system, kind, *m) for kind in kinds] for m in ms])
            for label, ms in members(system, pairs).items()}


def pair_classes(system) -> dict[str, np.ndarray]:
    """{"a-b": the vectors w = e_i − e_j (p, n) of the class's pairs} (`classes` of "r_ij")."""
    return {label: v[:, 0] for label, v in classes(system, ("r_ij",)).items()}


def particle_classes(system, momentum: bool = False) -> dict[str, np.ndarray]:
    """{"a": the vectors (p, n) of the class's particles}: e_i − μ of r_i − R, or with `momentum`
    e_i − μ_i 1 of p_i − μ_i P (`classes` of "r_i" or "p_i")."""
    return {label: v[:, 0] for label, v in classes(system, ("p_i",) if momentum else ("r_i",)).items()}


@dataclass(frozen=True)
class Operator:
    """A registered operator, one expectation value per class of equivalent pairs or particles.

    name: the core's operator name; unit: of its expectation value; meaning: one line for reports;
    vectors: the kinds of its vectors, in the core's order ("r_ij", "r_i", "p_i", "p_j": see
    `vector`); an operator with an "r_ij" or "p_j" acts on pairs, otherwise on particles; contact:
    it measures Ψ at the pair's coalescence (δ³(r_ij)), so its value is zero, not a rounding of
    zero, for a class where symmetry makes Ψ vanish there (`vanishing`)."""

    name: str
    unit: str
    meaning: str
    vectors: tuple[str, ...] = ("r_ij",)
    contact: bool = False

    def __post_init__(self):
        if not isinstance(self.vectors, tuple) or not set(self.vectors) <= KINDS:
            raise ValueError(f"operator {self.name!r}: vectors {self.vectors!r} must be a tuple of {sorted(KINDS)}")

    @property
    def acts_on(self) -> str:
        """"pairs" or "particles" (`classes`)."""
        return "pairs" if {"r_ij", "p_j"} & set(self.vectors) else "particles"

    @property
    def momenta(self) -> tuple[bool, ...]:
        """Per vector, whether it is momentum-like (transformed like ∇) rather than position-like."""
        return tuple(kind.startswith("p") for kind in self.vectors)

    def classes(self, system) -> dict[str, np.ndarray]:
        """Its vectors per class of equivalent pairs or particles, (instances, arity, n) each."""
        return classes(system, self.vectors)

    def evaluates(self, family) -> bool:
        """Whether the core has this operator's element for the basis family `family`."""
        return self.name in _core.OPERATORS[family.name]


OPERATORS: dict[str, Operator] = {
    "r": Operator("r", "bohr", "⟨r_ij⟩, the mean distance of particles i and j"),
    "r2": Operator("r2", "bohr²", "⟨r_ij²⟩, the mean square distance of particles i and j"),
    "inv_r": Operator("inv_r", "bohr⁻¹", "⟨1/r_ij⟩, the mean inverse distance of particles i and j"),
    "inv_r2": Operator("inv_r2", "bohr⁻²", "⟨1/r_ij²⟩, the mean inverse square distance of particles i and j"),
    "delta": Operator("delta", "bohr⁻³", "⟨δ³(r_ij)⟩, the density of particles i and j at one point "
                                         "(direct: converges slowly in Gaussians, which lack the cusp)",
                      contact=True),
    "araki_sucher": Operator("araki_sucher", "bohr⁻³", "⟨P(1/r_ij³)⟩, the Araki–Sucher distribution "
                                                     "lim_{a→0}[θ(r_ij − a)/r_ij³ + 4π(γ + ln a)δ³(r_ij)] of the α³ QED "
                                                     "term (direct: Gaussians lack the cusp, like δ)"),
    "p2": Operator("p2", "ħ²/bohr²", "⟨p_i²⟩, particle i's mean square momentum in the centre-of-mass frame",
                   ("p_i",)),
    "p4": Operator("p4", "ħ⁴/bohr⁴", "⟨p_i⁴⟩, the mass–velocity term's −Σ⟨p_i⁴⟩/(8m_i³c²) per particle i",
                   ("p_i",)),
    "p2p2": Operator("p2p2", "ħ⁴/bohr⁴", "⟨p_i² p_j²⟩, the product of two particles' square momenta in the "
                                         "centre-of-mass frame (a term of the regularised ⟨p_i⁴⟩, prebo.level.drachmann)",
                     ("p_i", "p_j")),
    "coulomb_inv_r": Operator("coulomb_inv_r", "Eh/bohr", "⟨V/r_ij⟩, the Coulomb potential over r_ij "
                                                         "(a term of Drachmann's ⟨δ³(r_ij)⟩, prebo.level.drachmann)"),
    "gradient_inv_r": Operator("gradient_inv_r", "Eh/bohr", "⟨∇Ψ|Λ/r_ij|∇Ψ⟩, the kinetic energy density over r_ij "
                                                           "(a term of Drachmann's ⟨δ³(r_ij)⟩, prebo.level.drachmann)"),
    "orbit_orbit": Operator("orbit_orbit", "ħ²/bohr³", "⟨p_i·(1 + r̂_ij r̂_ij)/r_ij·p_j⟩, the Breit–Pauli orbit–orbit "
                                                     "term −(α²/2) q_i q_j/(m_i m_j) ⟨…⟩ per pair", ("r_ij", "p_i", "p_j")),
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
    operator's unit}; a contact operator's is 0.0 for a class where the state vanishes by symmetry
    (`vanishing`), where its elements would give a rounding error of either sign."""
    op = operator(name, basis.family)
    classes = op.classes(basis.system)
    zero = vanishing(basis.system) if op.contact else []
    O = rep.operator(op.name, basis, np.concatenate(list(classes.values())), op.momenta)
    states = []
    for c in C.T:
        values, k = {}, 0
        for label, w in classes.items():
            values[label] = 0.0 if label in zero else float(np.mean([c @ O[k + m] @ c for m in range(len(w))]))
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
