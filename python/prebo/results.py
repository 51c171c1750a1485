"""Energies of a basis: translation-free and laboratory-frame, with the virial coefficient.

The pipeline's last stage (system → basis → integrals → eigen → results): `evaluate` is what
`prebo energy`, `prebo run` (result.json) and the Python API report. It stays a top-level
module because it uses every earlier stage and none of them uses it.

result.json / `prebo energy --json` keys: energy (translation-free, Eh), energy_uncertainty
(Eh, below), energy_lab (with CM motion), virial (η_TI = |1 + <V>/(2<T>_TI)|), kinetic, potential,
threshold (the lowest dissociation threshold, Eh: `thresholds.lowest`), threshold_fragments (its
fragments, "p-e + e", or "given"), thresholds ({fragments or "given": Eh} of both candidates),
bound (energy < threshold − energy_uncertainty), binding_energy (threshold − energy, Eh),
n_basis, basis_type, particles, state, symmetry, coordinates, overlap_condition, kept; with
`operators`, expectation ({operator: {pair class: value}} of operators registered in
`expectation.OPERATORS`, e.g. ⟨r_ij²⟩ in bohr²); for floating ECGs also n2 = <N²>_TI (their
functions are not angular-momentum eigenfunctions).

The energy is the lowest eigenvalue of the stored matrices refined in extended precision
(`eigen.solve`), the same to ~1e-15 relative on every machine. energy_uncertainty is the standard
deviation that element errors of a few ulp (4 u each, independent) of S, T_TI and V give it,
ε (2 Σ_ij w_ij − Σ_i w_ii)^½ with w_ij = c_i² c_j² (T_ij² + V_ij² + E² S_ij²) (`eigen.energy_uncertainty`;
docs/conventions.md compares it with Monte-Carlo perturbations): an ill-conditioned basis resolves
its energy no better than this. A basis with a function whose elements lost their digits to
cancellation (integrals.py), or whose state has no positive kinetic energy, is refused. A
non-finite element of H or S is an error (`eigen.solve`), never a number.

`bound` is False when the energy is not below the threshold: the basis describes fragments and free
particles, not a bound state. The virial coefficient cannot tell: a basis scaled to its variational
optimum satisfies the virial theorem, 2<T> + <V> = 0, whatever it describes (tests/test_thresholds.py).
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from . import eigen
from .basis import Basis
from .errors import CancellationError, InputError
from .expectation import expectation, operator
from .integrals import laboratory, require_shared_c_A, translationally_invariant
from .optimise.settings import check
from .thresholds import candidates, lowest


def evaluate(basis: Basis, coordinates: str = "lab", threshold: float = eigen.THRESHOLD, operators=()) -> dict:
    """The energies of `basis`'s lowest state.

    Parameters: `basis`, a non-empty `Basis`; `coordinates`, "lab" (LFCC with the CM kinetic
    energy eliminated, Muolo, Mátyus & Reiher, J. Chem. Phys. 148, 084112 (2018)) or "ti"
    (translationally invariant coordinates, only for one c_A shared by every function);
    `threshold`, the relative overlap eigenvalue below which directions are dropped
    (`eigen.solve`); `operators`, names of registered operators (`expectation.OPERATORS`, e.g.
    "r2") whose expectation values to add.

    Returns a dict with the keys of the module docstring — energy, energy_uncertainty,
    energy_lab, kinetic, potential, threshold and binding_energy in Eh; bound a bool; virial,
    overlap_condition dimensionless; n2 in ħ²; expectation in each operator's unit — and
    `coefficients`, the S-normalised ground-state vector. InputError for a basis that is not a
    non-empty `Basis` or does not fit its system (its arrays or system replaced since it was built),
    an unknown `coordinates` or operator; CancellationError for a function whose elements lost
    their digits (Representation.require_resolved); NonFiniteError and the eigen errors as
    `eigen.solve` raises them."""
    if not isinstance(basis, Basis) or len(basis) == 0:
        raise InputError(f"evaluate: basis = {basis!r}: must be a prebo.Basis with at least one function")
    threshold = check("threshold", threshold, "evaluate: threshold")
    if not (isinstance(operators, str) or (isinstance(operators, (list, tuple))
                                           and all(isinstance(o, str) for o in operators))):
        raise InputError(f"evaluate: operators = {operators!r}: must be a name or a list of names")
    operators = (operators,) if isinstance(operators, str) else tuple(operators)
    for name in operators:
        operator(name)
    basis = replace(basis)  # built again: the constructor's checks against the system it has now
    basis.validate()  # a Basis built in Python: symmetric, positive definite, CM-separable A
    system = basis.system
    if coordinates == "lab":
        rep = laboratory(system)
        m = rep.matrices(basis)
        rep.require_resolved(m)
        lab = eigen.solve(m["T"] + m["V"], m["S"], threshold)
        energy_lab = float(lab.energies[0])
    elif coordinates == "ti":
        c_A = require_shared_c_A(basis.c_A)
        rep = translationally_invariant(system)
        m = rep.matrices(basis)
        rep.require_resolved(m)
        energy_lab = None  # filled below: CM factor exp(-c_A X^2) common to all functions
    else:
        raise InputError(f"evaluate: coordinates = {coordinates!r}: must be 'lab' or 'ti'")
    ti = eigen.solve(m["T_ti"] + m["V"], m["S"], threshold)
    c = ti.vectors[:, 0]
    kinetic, potential = float(c @ m["T_ti"] @ c), float(c @ m["V"] @ c)
    energy = float(ti.energies[0])
    uncertainty = eigen.uncertainty(ti, m["S"], m["T_ti"], m["V"], threshold=threshold)
    if not kinetic > uncertainty:
        raise CancellationError(f"the state's internal kinetic energy, {kinetic:.3g} Eh, is not positive beyond the "
                                f"energy's uncertainty ({uncertainty:.1e} Eh): rounding dominates this basis's matrix "
                                "elements, and its energy means nothing")
    if energy_lab is None:
        energy_lab = energy + 1.5 * c_A / system.m_total
    extra = {}
    if not basis.family.conserves_L:  # not an angular-momentum eigenfunction: report <N²>_TI
        n2 = laboratory(system).angular(basis, system.cm_vector)
        extra["n2"] = float(c @ n2 @ c)
    if operators:
        extra["expectation"] = {name: expectation(rep, basis, c, name) for name in operators}
    low = lowest(system)
    return extra | {
        "energy": energy,
        "energy_uncertainty": uncertainty,
        "energy_lab": energy_lab,
        "virial": abs(1.0 + potential / (2.0 * kinetic)),
        "kinetic": kinetic,
        "potential": potential,
        "threshold": low.energy,
        "threshold_fragments": low.fragments,
        "thresholds": {t.fragments: t.energy for t in candidates(system)},
        "bound": energy < low.energy - uncertainty,
        "binding_energy": low.energy - energy,
        "n_basis": len(basis),
        "basis_type": basis.family.name,
        "particles": [p.to_dict() for p in system.particles],
        "state": system.to_dict()["state"],
        "symmetry": system.symmetriser.as_dict(),
        "coordinates": coordinates,
        "overlap_condition": ti.overlap_condition,
        "kept": ti.kept,
        "coefficients": c,
    }


def public(result: dict) -> dict:
    """The JSON-ready part of a result (no arrays)."""
    return {k: v for k, v in result.items() if not isinstance(v, np.ndarray)}
