"""Energies of a basis: translation-free and laboratory-frame, with the virial coefficient.

The pipeline's last stage (system → basis → integrals → eigen → results): `evaluate` is what
`prebo energy`, `prebo run` (result.json) and the Python API report; it uses every earlier stage
and none of them uses it.

result.json / `prebo energy --json` keys: energy (translation-free, Eh), energy_uncertainty
(Eh, below), energy_lab (with CM motion), virial (η_TI = |1 + <V>/(2<T>_TI)|), kinetic, potential,
threshold (the lowest dissociation threshold, Eh: `thresholds.lowest`), threshold_fragments (its
fragments, "p-e + e", or "given"), threshold_unchecked (a break-up into a fragment of three or more
particles that was not computed and may lie lower, "alpha-e-e + e"; None where none can or the
threshold was given: `thresholds`), thresholds ({fragments or "given": Eh} of both candidates),
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

With `roots` = K > 1 the lowest K levels of the symmetry are reported too: `levels`, one dict per
root k = 0..K-1 (root, energy, energy_uncertainty, virial, kinetic, potential, bound,
binding_energy, and n2 and expectation where the ground state has them), each eigenvalue an upper
bound to its exact level (Hylleraas–Undheim–MacDonald), and `transitions`, one dict per pair of
levels i < j: lower, upper, Eh (E_j − E_i), cm-1 (× HARTREE_CM) and uncertainty (the levels'
uncertainties added in quadrature, Eh). A basis optimised for other levels than the lowest
(`[state] root`/`roots`) reports the levels up to the highest it targets by default, and their
indices as `targets`; the top-level keys are those of the lowest targeted root (root k of a
`root = k` state, root 0 by default), named by `root`.

`bound` is False when the energy is not below the threshold: the basis describes fragments and free
particles, not a bound state. The virial coefficient cannot tell: a basis scaled to its variational
optimum satisfies the virial theorem, 2<T> + <V> = 0, whatever it describes (tests/test_thresholds.py).
"""
from __future__ import annotations

import math
import reprlib
from dataclasses import replace

import numpy as np

from .. import eigen
from ..basis import Basis
from ..errors import CancellationError, InputError
from ..integrals import laboratory, require_shared_c_A, translationally_invariant
from ..optimise.settings import check
from ..system.thresholds import candidates, lowest
from ..validation import Integer, checked
from .expectation import densities, density_classes, expectation, operator

#: the hartree in wavenumbers, E_h/(hc) in cm⁻¹ (CODATA 2018: E. Tiesinga et al., Rev. Mod. Phys.
#: 93, 025010 (2021), hartree-inverse meter relationship 2.1947463136320e7 m⁻¹)
HARTREE_CM = 219474.6313632


def evaluate(basis: Basis, coordinates: str = "lab", threshold: float = eigen.THRESHOLD, operators=(),
             roots: int | None = None, radii=None, targets=None) -> dict:
    """The energies of the level `basis` was optimised for, and of its lowest `roots` levels.

    Parameters: `basis`, a non-empty `Basis`; `coordinates`, "lab" (LFCC with the CM kinetic
    energy eliminated, Muolo, Mátyus & Reiher, J. Chem. Phys. 148, 084112 (2018)) or "ti"
    (translationally invariant coordinates, only for one c_A shared by every function);
    `threshold`, the relative overlap eigenvalue below which directions are dropped
    (`eigen.solve`); `operators`, names of registered operators (`expectation.OPERATORS`, e.g.
    "r2") whose expectation values to add; `roots`, how many of the lowest levels to report
    (`levels` and `transitions` when more than one; default: up to the highest targeted root; never
    short of the lowest one); `radii` (bohr), where to add each level's `densities`
    (`expectation.densities`): one grid for every class, or {"pairs": {"a-b": grid}, "particles":
    {"a": grid}} with a grid per class; `targets`, the roots the optimised levels stand at (default:
    those the basis's state targets, `State.levels`; a run whose levels were followed to other
    roots ends at others), given as `targets` unless root 0 alone.

    Returns a dict with the keys of the module docstring — energy, energy_uncertainty,
    energy_lab, kinetic, potential, threshold and binding_energy in Eh; bound a bool; virial,
    overlap_condition dimensionless; n2 in ħ²; expectation in each operator's unit — those of
    the lowest targeted root, `root` —, `coefficients`, its S-normalised vector, and `vectors`,
    those of the targeted roots (one column each, in the order of `targets`). InputError for a
    basis that is not a non-empty `Basis` or does not fit its system (its arrays or system replaced
    since it was built), an unknown `coordinates` or operator, UnsupportedError for an operator the
    basis family has not (`_core.OPERATORS`), `roots` not a positive integer or above the basis
    size, `targets` not distinct roots of the basis, `radii` empty or not finite non-negative numbers;
    LinearDependenceError for more roots than the basis resolves; CancellationError for a function whose elements lost
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
        operator(name, basis.family)
    if radii is not None:
        radii = grids(basis.system, radii)
    basis = replace(basis)  # built again: the constructor's checks against the system it has now
    if targets is None:
        targets = basis.system.state.levels[0]
        if max(targets) >= len(basis):
            raise InputError(f"state: targets levels {reprlib.repr(list(targets))}: level {max(targets)} is not one "
                             f"of a basis of {len(basis)} functions (0..{len(basis) - 1})")
    elif not isinstance(targets, (list, tuple)) or not targets or len(set(targets)) < len(targets):
        raise InputError(f"evaluate: targets = {reprlib.repr(targets)}: must be a list of distinct root indices")
    targets = tuple(checked(Integer(0, len(basis) - 1), k, "evaluate: targets",
                            f"roots of a basis of {len(basis)} functions") for k in targets)
    top = min(targets)
    roots = max(targets) + 1 if roots is None else roots
    roots = checked(Integer(1, len(basis)), roots, "evaluate: roots", f"levels of a basis of {len(basis)} functions")
    roots = max(roots, top + 1)  # the level at the top is among those reported
    basis.validate()  # a Basis built in Python: symmetric, positive definite, CM-separable A
    system = basis.system
    if coordinates == "lab":
        rep = laboratory(system)
        m = rep.matrices(basis)
        rep.require_resolved(m)
        with np.errstate(over="ignore", invalid="ignore"):  # eigen.solve refuses an H that is not finite
            H = m["T"] + m["V"]
        lab = eigen.solve(H, m["S"], threshold, top + 1)
        energy_lab = float(lab.energies[top])
    elif coordinates == "ti":
        c_A = require_shared_c_A(basis.c_A)
        rep = translationally_invariant(system)
        m = rep.matrices(basis)
        rep.require_resolved(m)
        energy_lab = None  # filled below: CM factor exp(-c_A X^2) common to all functions
    else:
        raise InputError(f"evaluate: coordinates = {coordinates!r}: must be 'lab' or 'ti'")
    with np.errstate(over="ignore", invalid="ignore"):
        H = m["T_ti"] + m["V"]
    ti = eigen.solve(H, m["S"], threshold, max(roots, max(targets) + 1))  # every targeted vector refined
    low = lowest(system)
    n2 = None if basis.family.conserves_L else laboratory(system).operator("n2", basis, system.cm_vector[None])[0]
    values = {name: expectation(rep, basis, ti.vectors[:, :roots], name) for name in operators}
    rho = None if radii is None else densities(rep, basis, ti.vectors[:, :roots], radii)
    levels = [level(ti, k, m, low.energy, threshold, n2, {name: v[k] for name, v in values.items()})
              | ({} if rho is None else {"densities": rho[k]}) for k in range(roots)]
    if energy_lab is None:
        energy_lab = levels[top]["energy"] + 1.5 * c_A / system.m_total
    extra = {}
    if targets != (0,):
        extra["targets"] = list(targets)
    if roots > 1:
        extra["levels"] = levels
        extra["transitions"] = [transition(a, b) for i, a in enumerate(levels) for b in levels[i + 1:]]
    return levels[top] | extra | {
        "energy_lab": energy_lab,
        "threshold": low.energy,
        "threshold_fragments": low.fragments,
        "threshold_unchecked": low.unchecked,
        "thresholds": {t.fragments: t.energy for t in candidates(system)},
        "n_basis": len(basis),
        "basis_type": basis.family.name,
        "particles": [p.to_dict() for p in system.particles],
        "state": system.to_dict()["state"],
        "symmetry": system.symmetriser.as_dict(),
        "coordinates": coordinates,
        "overlap_condition": ti.overlap_condition,
        "kept": ti.kept,
        "coefficients": ti.vectors[:, top],
        "vectors": ti.vectors[:, list(targets)],
    }


def grids(system, radii) -> dict:
    """`radii`, one grid or one per class of `expectation.density_classes`, as {group: {class:
    float array}}; InputError unless every grid is a non-empty list of finite distances ≥ 0 (bohr)
    and a dict names exactly those classes."""
    classes = density_classes(system)
    if isinstance(radii, dict):
        want = {group: set(c) for group, c in classes.items()}
        if {group: set(radii[group]) for group in radii if isinstance(radii[group], dict)} != want:
            raise InputError(f"radii: a grid per class must name exactly the classes {want}")
        return {group: {label: distances(radii[group][label]) for label in c} for group, c in classes.items()}
    r = distances(radii)
    return {group: {label: r for label in c} for group, c in classes.items()}


def distances(radii) -> np.ndarray:
    """`radii` as a float array; InputError unless a non-empty list of finite distances ≥ 0 (bohr)."""
    try:
        r = np.asarray(radii, dtype=float)
    except (TypeError, ValueError):
        r = np.array([np.nan])
    if r.ndim != 1 or len(r) == 0 or not np.all(np.isfinite(r) & (r >= 0)):
        raise InputError(f"radii = {reprlib.repr(radii)}: must be a non-empty list of finite distances ≥ 0 (bohr)")
    return r


def level(eig: eigen.Eigen, k: int, m: dict, threshold_energy: float, threshold: float, n2=None,
          expectations: dict | None = None) -> dict:
    """Root `k` of the solution `eig` of the matrices `m` (S, T_ti, V): its energy and uncertainty
    (`eigen.uncertainty` at overlap `threshold`), virial coefficient, kinetic and potential energies,
    whether it lies below the lowest dissociation threshold `threshold_energy` (Eh) beyond its
    uncertainty, <N²>_TI from the matrix `n2` if given, and `expectations` if any (module
    docstring). CancellationError where its internal kinetic energy is not positive beyond the
    uncertainty: rounding dominates the elements, and the level means nothing."""
    c = eig.vectors[:, k]
    kinetic, potential = float(c @ m["T_ti"] @ c), float(c @ m["V"] @ c)
    energy = float(eig.energies[k])
    uncertainty = eigen.uncertainty(eig, m["S"], m["T_ti"], m["V"], threshold=threshold, root=k)
    state = "the state's" if k == 0 else f"level {k}'s"
    if not kinetic > uncertainty:
        raise CancellationError(f"{state} internal kinetic energy, {kinetic:.3g} Eh, is not positive beyond the "
                                f"energy's uncertainty ({uncertainty:.1e} Eh): rounding dominates this basis's matrix "
                                "elements, and its energy means nothing")
    extra = {} if n2 is None else {"n2": float(c @ n2 @ c)}  # not an angular-momentum eigenfunction
    if expectations:
        extra["expectation"] = expectations
    return extra | {
        "root": k,
        "energy": energy,
        "energy_uncertainty": uncertainty,
        "virial": abs(1.0 + potential / (2.0 * kinetic)),
        "kinetic": kinetic,
        "potential": potential,
        "bound": energy < threshold_energy - uncertainty,
        "binding_energy": threshold_energy - energy,
    }


def transition(lower: dict, upper: dict) -> dict:
    """The transition between two `level`s: E_upper − E_lower in Eh and cm⁻¹, with the levels'
    uncertainties in quadrature (Eh)."""
    gap = upper["energy"] - lower["energy"]
    return {"lower": lower["root"], "upper": upper["root"], "Eh": gap, "cm-1": gap * HARTREE_CM,
            "uncertainty": math.hypot(lower["energy_uncertainty"], upper["energy_uncertainty"])}


def public(result: dict) -> dict:
    """The JSON-ready part of a result (no arrays)."""
    return {k: v for k, v in result.items() if not isinstance(v, np.ndarray)}
