"""Drachmann's regularised contact densities (docs/properties-derivations.md §6, eq. 27): for an
eigenstate Ψ of T_TI + V with energy E,

    ⟨δ³(r_ij)⟩ = (μ_ij/π) [E⟨1/r_ij⟩ − ⟨V/r_ij⟩ − ⟨∇Ψ|Λ/r_ij|∇Ψ⟩],   μ_ij = m_i m_j/(m_i + m_j),

with Λ the kinetic matrix of T_TI = −∇ᵀΛ∇. The right side holds global operators, so in Gaussians,
which lack the cusp, it converges faster with the basis than the direct ⟨δ³(r_ij)⟩ ("delta"), the
density at one point. Its elements are the core's "inv_r", "coulomb_inv_r" and "gradient_inv_r"
(crates/prebo-core/src/operators/drachmann/), for every family. ⟨V/r_ij⟩ is in closed form for
plain ECGs (eq. 19) and a quadrature over the family's damped ⟨1/r⟩ elements for floating ECGs and
ECG-GVR (eq. 38), tens of damped elements per product (H2-500's properties take 55 s with it,
26 s without): `CLOSED_FORM` says where it is cheap.

The bracket is multiplied by μ_ij/π, so its basis error is too: for two heavy particles that repel
(p-p in H₂⁺ and H₂, d-t), whose contact density is tiny, a ~1000-fold amplified error swamps it and
the regularised value is worse than the direct one, even negative (H₂⁺ in 400 floating ECGs: direct
1.1e-6, regularised −2.0e-3 bohr⁻³; benchmarks/record/relativistic.md, "⟨V/r_ij⟩ for floating ECGs
and ECG-GVR"). Such pairs keep the direct value: a pair is regularised where it attracts or holds
one of the lightest particles (`regularisable`).

The same eigenvalue equation regularises ⟨p_i⁴⟩ (eq. 27'): T_TI = Σ_i p_i²/(2m_i) with the momenta
in the centre-of-mass frame, so ⟨T_TI²⟩ = ⟨(E − V)²⟩ = E² − 2E⟨V⟩ + ⟨V²⟩, ⟨V²⟩ = Σ_{i<j} q_iq_j⟨V/r_ij⟩,
and for the class a of the lightest particles (n_a of mass m_a)

    n_a ⟨p_a⁴⟩/(4m_a²) = ⟨(E − V)²⟩ − Σ_{i∉a} ⟨p_i⁴⟩/(4m_i²) − Σ_{i≠j} ⟨p_i²p_j²⟩/(4m_im_j):

the cusps that Gaussians lack enter the right side only through heavier particles' ⟨p_i⁴⟩ and the
products of distinct particles' momenta, weighted by their masses (`p4_regularised`).
"""
from __future__ import annotations

import numpy as np

from ..system import reduced_mass
from .expectation import expectation, members, operator, vanishing

#: the operators of eq. (27): ⟨1/r_ij⟩, ⟨V/r_ij⟩, ⟨∇Ψ|Λ/r_ij|∇Ψ⟩
TERMS = ("inv_r", "coulomb_inv_r", "gradient_inv_r")

#: the operators of eq. (27'): those of ⟨V⟩ and ⟨V²⟩, ⟨p_i⁴⟩ and ⟨p_i²p_j²⟩
P4_TERMS = ("inv_r", "coulomb_inv_r", "p4", "p2p2")

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


def regularisable(system) -> list[str]:
    """The pair classes "a-b" of `system` whose ⟨δ³(r_ij)⟩ is regularised (module docstring): those
    that attract (q_a q_b < 0) or hold a particle of the lightest mass; not two heavier particles
    that repel."""
    light = min(p.mass for p in system.particles)
    out = []
    for label, ms in members(system, pairs=True).items():
        a, b = (system.particles[k] for k in ms[0])
        if a.charge * b.charge < 0 or min(a.mass, b.mass) == light:
            out.append(label)
    return out


def regularised(system, expectation: dict, energy: float) -> dict[str, float]:
    """{pair class "a-b": the regularised ⟨δ³(r_ij)⟩ (bohr⁻³)} of one eigenstate of `system` with
    the energy `energy` (Eh) from its expectation values of TERMS ({operator: {class: value}}, as
    `evaluate` gives them), for the `regularisable` classes; 0.0 where the state vanishes
    at the coalescence by symmetry (`expectation.vanishing`): there the direct value is exact, and
    the identity would only return the rounding of its three terms (He 2³S: −1.6e-8)."""
    mu = {label: reduced_mass(*system.masses[list(ms[0])]) for label, ms in members(system, pairs=True).items()}
    inv_r, potential, gradient = (expectation[name] for name in TERMS)
    zero = vanishing(system)
    return {label: 0.0 if label in zero else
            float(mu[label] / np.pi * (energy * inv_r[label] - potential[label] - gradient[label]))
            for label in regularisable(system)}


def p4_regularised(system, expectation: dict, energy: float) -> dict[str, float]:
    """{particle class "a": the regularised ⟨p_a⁴⟩ (ħ⁴/bohr⁴)} of one eigenstate of `system` with the
    energy `energy` (Eh) from its expectation values of P4_TERMS (eq. 27', module docstring), for
    the class of the lightest particles where no other class has their mass (else {}: the identity
    gives only the sum over the classes of one mass)."""
    light = min(p.mass for p in system.particles)
    classes = members(system, pairs=False)
    lightest = [label for label, ms in classes.items() if system.particles[ms[0][0]].mass == light]
    if len(lightest) != 1:
        return {}
    (a,) = lightest
    potential = squared = products = 0.0
    for label, ms in members(system, pairs=True).items():
        i, j = ms[0]
        qq, mm = system.particles[i].charge * system.particles[j].charge, system.masses[i] * system.masses[j]
        potential += len(ms) * qq * expectation["inv_r"][label]
        squared += len(ms) * qq * expectation["coulomb_inv_r"][label]
        products += 2 * len(ms) * expectation["p2p2"][label] / (4 * mm)
    heavy = sum(len(ms) * expectation["p4"][label] / (4 * system.masses[ms[0][0]] ** 2)
                for label, ms in classes.items() if label != a)
    kinetic_squared = energy**2 - 2 * energy * potential + squared
    return {a: float(4 * light**2 / len(classes[a]) * (kinetic_squared - heavy - products))}
