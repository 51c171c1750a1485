"""Lines between the levels of two bases: reduced dipole moments in length and velocity form, line
and oscillator strengths, Einstein A coefficients and radiative lifetimes (docs/transitions.md).

Conventions (hartree atomic units; constants CODATA 2018, E. Tiesinga et al., Rev. Mod. Phys. 93,
025010 (2021)):
- the dipole about the centre of mass, d = Σ_k q_k (r_k − R_CM) = Σ_k w_k r_k, w = q − Q m/m_tot,
  every particle's charge counted (for a charged system the dipole about the CM, which moves with
  the system and does not depend on the origin);
- the reduced moment <N'‖d‖N> of Edmonds' Wigner–Eckart theorem,
  <N' M'|d_q|N M> = (−1)^{N'−M'} (N' 1 N; −M' q M) <N'‖d‖N>, in e a_0, from the level of N = 1 to
  the level of N = 0 (its sign, like an eigenvector's, is arbitrary); in velocity form
  −<1‖∇_w'‖0>/(E_1 − E_0) with w' = q/m − Q/m_tot, equal to the length form for exact levels
  ([H, d] = −Σ_k (q_k/m_k) ∇_k, the CM part dropping out), so their ratio measures convergence;
- the line strength S = |<1‖d‖0>|² (e² a_0², summed over both levels' M);
- the absorption oscillator strength f = (2/3) ΔE S / (2N_l + 1), N_l the lower level's;
- the Einstein coefficient A = (4/3) α³ ΔE³ S / (2N_u + 1) (E_h/ħ), given in s⁻¹;
- the lifetime of a level, 1/Σ A over the lines to the lower levels computed (an upper bound to
  the radiative lifetime when other lower levels are missing).
The two bases are of the same particles; a line joins levels of N and N ± 1 of opposite parity and
one spin state (electric-dipole selection rules). The elements (crates/prebo-core, registry
"dipole" and "velocity") are derived for N = 0 ↔ 1.
"""
from __future__ import annotations

import numpy as np

from .. import eigen
from ..basis import Basis
from ..errors import InputError, UnsupportedError
from ..integrals import laboratory, translationally_invariant
from .evaluate import HARTREE_CM, evaluate

#: the fine-structure constant α (CODATA 2018)
ALPHA = 7.2973525693e-3
#: the atomic unit of time ħ/E_h in s (CODATA 2018)
AU_TIME = 2.4188843265857e-17


def dipole_vectors(system) -> tuple[np.ndarray, np.ndarray]:
    """The laboratory-frame vectors of the dipole about the CM, w = q − Q m/m_tot (length form,
    position-like), and of its velocity form, w' = q/m − Q/m_tot (momentum-like)."""
    q = system.charges
    return q - q.sum() * system.cm_vector, q / system.masses - q.sum() / system.m_total


def forbidden(a: Basis, b: Basis) -> str | None:
    """Why no electric-dipole line joins the levels of the bases `a` and `b`, or None."""
    sa, sb = a.system.state, b.system.state
    if not a.system.symmetriser.equivalent(b.system.symmetriser):
        return "spin-forbidden: the levels' spin states differ"
    if sa.parity == sb.parity:
        return f"parity-forbidden: both levels have parity {sa.parity:+d}"
    if abs(sa.N - sb.N) > 1 or sa.N == sb.N == 0:
        return f"forbidden for an electric dipole: N = {sa.N} and {sb.N}"
    return None


def same_particles(a, b) -> None:
    """InputError unless the systems `a` and `b` are of the same particles (names, masses, charges,
    spins, in one order)."""
    pa = [p.to_dict() for p in a.particles]
    pb = [p.to_dict() for p in b.particles]
    if pa != pb:
        raise InputError(f"the two bases are of different particles or masses: {pa} and {pb}")


def _levels(basis: Basis, roots: int, threshold: float, coordinates: str) -> tuple[list[float], np.ndarray]:
    """The energies of the `roots` lowest levels of `basis` and their S-normalised vectors (nb, roots)."""
    r = evaluate(basis, coordinates, threshold, roots=roots, targets=list(range(roots)))
    return [float(v["energy"]) for v in r.get("levels", [r])][:roots], r["vectors"]


def transitions(lower: Basis, upper: Basis, roots: int | tuple = 1, threshold: float = eigen.THRESHOLD,
                coordinates: str = "lab") -> dict:
    """The electric-dipole lines between the lowest levels of the basis `lower` and those of `upper`
    (each level's energy from `evaluate`), with the conventions of the module docstring; `roots`,
    how many levels of each (K, or (K_lower, K_upper)).

    Returns {"levels": [{basis (0: lower, 1: upper), root, N, parity, energy}], "lines": [{lower,
    upper (indices into levels, by energy), Eh, cm-1, length, velocity, velocity/length,
    line_strength, oscillator_strength, einstein_A (s⁻¹)} or, for a forbidden pair, {lower, upper,
    Eh, cm-1, forbidden: why}], "lifetimes": [{level, lifetime (s), lines}]}.
    InputError for bases of different particles, of one symmetry, or of floating ECGs (no definite
    N); UnsupportedError for an allowed pair the elements are not derived for (N > 1)."""
    bases = (lower, upper)
    for b in bases:
        if not isinstance(b, Basis) or len(b) == 0:
            raise InputError(f"transitions: {b!r} is not a non-empty prebo.Basis")
        if not b.family.conserves_L:
            raise InputError(f"transitions: a basis of {b.family.name} functions, which have no definite N; "
                             "lines need bases of definite N (pecg, ecg-gvr)")
    same_particles(lower.system, upper.system)
    states = [b.system.state for b in bases]
    if (states[0].N, states[0].parity) == (states[1].N, states[1].parity) and \
            lower.system.symmetriser.equivalent(upper.system.symmetriser):
        raise InputError(f"both bases are of one symmetry (N = {states[0].N}, parity {states[0].parity:+d}); "
                         "an electric-dipole line joins N to N ± 1 of opposite parity")
    roots = tuple(roots) if isinstance(roots, (tuple, list)) else (roots, roots)
    if len(roots) != 2:
        raise InputError(f"transitions: roots = {roots!r}: must be K or (K_lower, K_upper)")
    energies, vectors = zip(*(_levels(b, k, threshold, coordinates) for b, k in zip(bases, roots)))
    levels = [{"basis": k, "root": i, "N": states[k].N, "parity": states[k].parity, "energy": e}
              for k in (0, 1) for i, e in enumerate(energies[k])]
    why = forbidden(lower, upper)
    if why is None:
        length, velocity = _reduced(bases, vectors, energies, coordinates)
    lines = []
    for i, a in enumerate(levels[:len(energies[0])]):
        for j, b in enumerate(levels[len(energies[0]):], len(energies[0])):
            lo, hi = (i, j) if a["energy"] <= b["energy"] else (j, i)
            de = levels[hi]["energy"] - levels[lo]["energy"]
            line = {"lower": lo, "upper": hi, "Eh": de, "cm-1": de * HARTREE_CM}
            if why is not None:
                lines.append(line | {"forbidden": why})
                continue
            d_l, d_v = length[a["root"], b["root"]], velocity[a["root"], b["root"]]
            S = d_l * d_l
            lines.append(line | {
                "length": d_l, "velocity": d_v, "velocity/length": d_v / d_l if d_l else None,
                "line_strength": S,
                "oscillator_strength": 2 / 3 * de * S / (2 * levels[lo]["N"] + 1),
                "einstein_A": 4 / 3 * ALPHA ** 3 * de ** 3 * S / (2 * levels[hi]["N"] + 1) / AU_TIME,
            })
    return {"levels": levels, "lines": lines, "lifetimes": _lifetimes(lines)}


def _reduced(bases, vectors, energies, coordinates: str) -> tuple[np.ndarray, np.ndarray]:
    """<1‖d‖0> between every level of the N = 0 basis (rows) and of the N = 1 one (columns), in
    length and velocity form, rows and columns in the order of `bases`' levels."""
    flip = bases[0].N != 0
    zero, one = (1, 0) if flip else (0, 1)
    if {bases[zero].N, bases[one].N} != {0, 1}:
        raise UnsupportedError(f"dipole elements between N = {bases[zero].N} and N = {bases[one].N}: derived for "
                               "N = 0 ↔ 1 only")
    system = bases[zero].system
    rep = laboratory(system) if coordinates == "lab" else translationally_invariant(system)
    w, w_v = dipole_vectors(system)
    L = rep.between("dipole", bases[zero], bases[one], w[None])[0]
    V = rep.between("velocity", bases[zero], bases[one], w_v[None], momentum=True)[0]
    c0, c1 = vectors[zero], vectors[one]
    length = c0.T @ L @ c1
    de = np.subtract.outer(energies[one], energies[zero]).T  # E_1 − E_0, rows the N = 0 levels
    with np.errstate(divide="ignore", invalid="ignore"):
        velocity = -(c0.T @ V @ c1) / de
    return (length.T, velocity.T) if flip else (length, velocity)


def _lifetimes(lines: list[dict]) -> list[dict]:
    """Each emitting level's lifetime, 1/Σ A over its computed lines (s)."""
    total: dict[int, list] = {}
    for line in lines:
        if "einstein_A" in line:
            total.setdefault(line["upper"], []).append(line["einstein_A"])
    return [{"level": k, "lifetime": 1 / sum(a), "lines": len(a)} for k, a in sorted(total.items()) if sum(a) > 0]
