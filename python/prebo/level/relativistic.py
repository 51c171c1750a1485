"""The leading relativistic correction of a level: the Breit–Pauli terms of order α² Eh from
expectation values (docs/relativistic.md: formulas, conventions per particle type, sources).

For point particles i of mass m_i, charge q_i and spin s_i (hartree atomic units, c = 1/α), the
spin-independent terms and the spin–spin contact of identical spin-½ particles,

    mass–velocity    −(α²/8) Σ_i ⟨p_i⁴⟩/m_i³                                  every particle
    Darwin           −(πα²/2) Σ_{i<j} q_i q_j (d_i/m_i² + d_j/m_j²) ⟨δ³(r_ij)⟩  d = 1 for spin ½, else 0
    orbit–orbit      −(α²/2) Σ_{i<j} q_i q_j/(m_i m_j) ⟨p_i·(δ + r̂_ij r̂_ij)/r_ij·p_j⟩
    spin–spin        2πα² Σ_{i<j} q_i q_j/(m_i m_j) ⟨δ³(r_ij)⟩                 identical spin-½ pairs,

the last being −(8π/3)α² (g²/4) q_i q_j/(m_i m_j) s_i·s_j δ³(r_ij) with g = 2 and s_i·s_j = −¾:
two identical fermions meet only in their spin singlet (the exchange of their positions leaves
δ³(r_ij)Ψ unchanged, so their spin exchange changes its sign). Every spin-½ particle is a Dirac
point particle (g = 2, a Darwin term); particles of other spins have no Darwin term here.
Momenta are those in the centre-of-mass frame (`expectation`). Left out: spin–orbit and tensor
spin–spin terms (zero for N = 0; they split a level into its J components about an unshifted
mean), the contact terms of distinct particles (hyperfine; e⁺e⁻ annihilation), anomalous
magnetic moments, nuclear size and structure, QED.
"""
from __future__ import annotations

import math

from .evaluate import HARTREE_CM
from .expectation import members

#: the fine-structure constant, CODATA 2018 (E. Tiesinga et al., Rev. Mod. Phys. 93, 025010 (2021))
ALPHA = 7.2973525693e-3

#: the expectation values the terms are made of: ⟨p_i⁴⟩ per particle class, ⟨δ³(r_ij)⟩ and
#: ⟨p_i·(δ + r̂r̂)/r_ij·p_j⟩ per pair class
NEEDS = ("p4", "delta", "orbit_orbit")

#: the terms, in the order reported
TERMS = ("mass_velocity", "darwin", "orbit_orbit", "spin_spin")


def dirac(particle) -> bool:
    """Whether `particle` is taken for a Dirac point particle: spin ½, with g = 2 and the Darwin
    term (1/8m²)∇²V of the Foldy–Wouthuysen reduction. Spin 0 (Klein–Gordon) has no Darwin term;
    the Darwin-like terms of higher spins depend on the particle's structure and are left out."""
    return particle.spin == 0.5


def terms(system, expectation: dict, delta: dict | None = None, p4: dict | None = None) -> dict:
    """The Breit–Pauli terms (module docstring) of one level of `system` from its expectation
    values `expectation` ({operator: {class: value}}, as `evaluate` gives them, with every
    operator of NEEDS); `delta`, contact densities per pair class to use instead of the direct
    ⟨δ³(r_ij)⟩ where given, and `p4`, ⟨p_i⁴⟩ per particle class to use instead of the direct ones where given
    (`drachmann.regularised` and `drachmann.p4_regularised`; docs/relativistic.md on pairing them).

    Returns {"Eh": {term: E, "total": Σ}, "cm-1": the same × HARTREE_CM, "classes": {term:
    {class: E (Eh)}}, "alpha": ALPHA} for the TERMS: the mass–velocity term per particle class,
    the others per pair class (the spin–spin contact only for classes of identical spin-½
    particles), each summed over the class's members."""
    a2 = ALPHA**2
    delta = expectation["delta"] | (delta or {})
    p4 = expectation["p4"] | (p4 or {})
    classes = {term: {} for term in TERMS}
    for label, ms in members(system, pairs=False).items():
        m = system.particles[ms[0][0]].mass
        classes["mass_velocity"][label] = -a2 / 8 * len(ms) * p4[label] / m**3
    for label, ms in members(system, pairs=True).items():
        a, b = (system.particles[k] for k in ms[0])
        qq, pairs = a.charge * b.charge, len(ms)
        classes["darwin"][label] = (-math.pi * a2 / 2 * pairs * qq * (dirac(a) / a.mass**2 + dirac(b) / b.mass**2)
                                    * delta[label])
        classes["orbit_orbit"][label] = -a2 / 2 * pairs * qq / (a.mass * b.mass) * expectation["orbit_orbit"][label]
        if a.name == b.name and dirac(a):
            classes["spin_spin"][label] = 2 * math.pi * a2 * pairs * qq / a.mass**2 * delta[label]
    # a negative factor times a contact density zero by symmetry (expectation.vanishing) is −0.0: give +0.0
    classes = {term: {k: v + 0.0 for k, v in per.items()} for term, per in classes.items()}
    eh = {term: math.fsum(classes[term].values()) for term in TERMS}
    eh["total"] = math.fsum(eh.values())
    return {"Eh": eh, "cm-1": {k: v * HARTREE_CM for k, v in eh.items()}, "classes": classes, "alpha": ALPHA}
