"""Lines between the levels of two bases: reduced dipole moments in length and velocity form, line
and oscillator strengths, Einstein A coefficients and radiative lifetimes; reduced quadrupole
moments, their line strengths and Einstein A coefficients (docs/transitions.md).

Conventions (hartree atomic units; constants CODATA 2018, E. Tiesinga et al., Rev. Mod. Phys. 93,
025010 (2021)):
- the dipole about the centre of mass, d = Σ_k q_k (r_k − R_CM) = Σ_k w_k r_k, w = q − Q m/m_tot,
  every particle's charge counted (for a charged system the dipole about the CM, which moves with
  the system and does not depend on the origin);
- the reduced moment <N'‖d‖N> of Edmonds' Wigner–Eckart theorem,
  <N' M'|d_q|N M> = (−1)^{N'−M'} (N' 1 N; −M' q M) <N'‖d‖N>, in e a_0, from the level of N = L + 1
  to the level of N = L (its sign, like an eigenvector's, is arbitrary); in velocity form
  −<L+1‖∇_w'‖L>/(E_{L+1} − E_L) with w' = q/m − Q/m_tot, equal to the length form for exact levels
  ([H, d] = −Σ_k (q_k/m_k) ∇_k, the CM part dropping out), so their ratio measures convergence;
  in acceleration form <1‖∇_w' V‖0>/(E_1 − E_0)² ([H, [H, d]] = ∇_w' V, V the Coulomb potential),
  which weighs the particles' coalescences, where Gaussians are weakest (derived for N = 0 ↔ 1;
  None for the lines of higher N);
- the line strength S = |<L+1‖d‖L>|² (e² a_0², summed over both levels' M);
- the absorption oscillator strength f = (2/3) ΔE S / (2N_l + 1), N_l the lower level's;
- the Einstein coefficient A = (4/3) α³ ΔE³ S / (2N_u + 1) (E_h/ħ), given in s⁻¹;
- the quadrupole about the centre of mass, Q_2q = Σ_k q_k |ρ_k|² C_2q(ρ̂_k), ρ_k = r_k − R_CM, and
  its reduced moment <2‖Q‖0> (Edmonds, e a_0²) from the level of N = 2 to the level of N = 0;
  its line strength S = |<2‖Q‖0>|² (e² a_0⁴) and Einstein coefficient
  A = (1/15) α⁵ ΔE⁵ S / (2N_u + 1) (E_h/ħ), the standard E2 rate (NIST's
  A = 1.1199 × 10¹⁸ S / (g_u λ⁵[Å]) s⁻¹, W. L. Wiese and J. R. Fuhr, J. Phys. Chem. Ref. Data 38,
  565 (2009));
- the lifetime of a level, 1/Σ A over the lines to the lower levels computed (an upper bound to
  the radiative lifetime when other lower levels are missing).
The two bases are of the same particles and one spin state; an electric-dipole line joins levels
of N and N ± 1 of opposite parity (not 0 and 0), an electric-quadrupole line levels of N and
N' ≤ N + 2 of the same parity with N + N' ≥ 2. The elements (crates/prebo-core, registry
"dipole", "velocity", "acceleration" and "quadrupole") are derived for N = L ↔ L + 1 (every L;
the acceleration form N = 0 ↔ 1) and N = 0 ↔ 2.
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


def quadrupole_matrix(system) -> np.ndarray:
    """M = Σ_k q_k m_k m_kᵀ, m_k = e_k − m/m_tot (laboratory frame): the quadrupole's Cartesian tensor
    about the CM, Σ_k q_k ρ_k ρ_kᵀ = Σ_ij M_ij r_i r_jᵀ (ρ_k = m_kᵀr = r_k − R_CM)."""
    m = np.eye(len(system.charges)) - system.cm_vector[None, :]
    return m.T @ (system.charges[:, None] * m)


def multipole(a: Basis, b: Basis) -> str | None:
    """The electric multipole whose lines join the levels of the bases `a` and `b` of one spin state:
    "dipole" (opposite parity, |ΔN| ≤ 1, not N = 0 and 0), "quadrupole" (the same parity,
    |ΔN| ≤ 2 ≤ N_a + N_b), or None."""
    sa, sb = a.system.state, b.system.state
    if sa.parity != sb.parity:
        return "dipole" if abs(sa.N - sb.N) <= 1 and sa.N + sb.N >= 1 else None
    return "quadrupole" if abs(sa.N - sb.N) <= 2 <= sa.N + sb.N else None


def forbidden(a: Basis, b: Basis) -> str | None:
    """Why neither an electric-dipole nor an electric-quadrupole line joins the levels of the bases
    `a` and `b`, or None."""
    sa, sb = a.system.state, b.system.state
    if not a.system.symmetriser.equivalent(b.system.symmetriser):
        return "spin-forbidden: the levels' spin states differ"
    if multipole(a, b) is not None:
        return None
    if sa.parity == sb.parity:
        return (f"forbidden for an electric dipole (both levels of parity {sa.parity:+d}) and quadrupole "
                f"(N = {sa.N} and {sb.N})")
    return f"forbidden for an electric dipole (N = {sa.N} and {sb.N}) and quadrupole (the parities differ)"


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
    """The electric-dipole or electric-quadrupole lines (`multipole`) between the lowest levels of
    the basis `lower` and those of `upper` (each level's energy from `evaluate`), with the
    conventions of the module docstring; `roots`, how many levels of each (K, or (K_lower, K_upper)).

    Returns {"levels": [{basis (0: lower, 1: upper), root, N, parity, energy}], "lines": [{lower,
    upper (indices into levels, by energy), Eh, cm-1, length, velocity, acceleration (None but for
    N = 0 ↔ 1), velocity/length, acceleration/length, line_strength, oscillator_strength,
    einstein_A (s⁻¹)} for a dipole line, {lower, upper, Eh, cm-1, quadrupole, line_strength,
    einstein_A} for a quadrupole line, or, for a forbidden pair, {lower, upper, Eh, cm-1,
    forbidden: why}], "lifetimes": [{level, lifetime (s), lines}]}.
    InputError for bases of different particles, of one symmetry, or of floating ECGs (no definite
    N); UnsupportedError for an allowed pair the elements are not derived for (dipole lines of one N,
    quadrupole lines but N = 0 ↔ 2)."""
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
                         "a line joins N to N ± 1 of opposite parity (E1) or N ± 2 of the same parity (E2)")
    roots = tuple(roots) if isinstance(roots, (tuple, list)) else (roots, roots)
    if len(roots) != 2:
        raise InputError(f"transitions: roots = {roots!r}: must be K or (K_lower, K_upper)")
    energies, vectors = zip(*(_levels(b, k, threshold, coordinates) for b, k in zip(bases, roots)))
    levels = [{"basis": k, "root": i, "N": states[k].N, "parity": states[k].parity, "energy": e}
              for k in (0, 1) for i, e in enumerate(energies[k])]
    why = forbidden(lower, upper)
    kind = multipole(lower, upper) if why is None else None
    if kind == "dipole":
        length, velocity, acceleration = _reduced(bases, vectors, energies, coordinates)
    elif kind == "quadrupole":
        quadrupole = _quadrupole(bases, vectors, coordinates)
    lines = []
    for i, a in enumerate(levels[:len(energies[0])]):
        for j, b in enumerate(levels[len(energies[0]):], len(energies[0])):
            lo, hi = (i, j) if a["energy"] <= b["energy"] else (j, i)
            de = levels[hi]["energy"] - levels[lo]["energy"]
            line = {"lower": lo, "upper": hi, "Eh": de, "cm-1": de * HARTREE_CM}
            if why is not None:
                lines.append(line | {"forbidden": why})
                continue
            if kind == "quadrupole":
                q = quadrupole[a["root"], b["root"]]
                lines.append(line | {
                    "quadrupole": q, "line_strength": q * q,
                    "einstein_A": ALPHA ** 5 * de ** 5 * q * q / 15 / (2 * levels[hi]["N"] + 1) / AU_TIME,
                })
                continue
            d_l, d_v, d_a = (None if x is None else x[a["root"], b["root"]] for x in (length, velocity, acceleration))
            S = d_l * d_l
            lines.append(line | {
                "length": d_l, "velocity": d_v, "acceleration": d_a, "velocity/length": d_v / d_l if d_l else None,
                "acceleration/length": d_a / d_l if d_l and d_a is not None else None,
                "line_strength": S,
                "oscillator_strength": 2 / 3 * de * S / (2 * levels[lo]["N"] + 1),
                "einstein_A": 4 / 3 * ALPHA ** 3 * de ** 3 * S / (2 * levels[hi]["N"] + 1) / AU_TIME,
            })
    return {"levels": levels, "lines": lines, "lifetimes": _lifetimes(lines)}


def _reduced(bases, vectors, energies, coordinates: str) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """<L+1‖d‖L> between every level of the basis of N = L and of the one of N = L + 1, in length,
    velocity and (for L = 0) acceleration form (None for L ≥ 1), rows the levels of `bases[0]`,
    columns those of `bases[1]`, in their order; the core refuses bases of one N (UnsupportedError)."""
    flip = bases[0].N > bases[1].N
    low, high = (1, 0) if flip else (0, 1)
    system = bases[low].system
    rep = laboratory(system) if coordinates == "lab" else translationally_invariant(system)
    w, w_v = dipole_vectors(system)
    L = rep.between("dipole", bases[low], bases[high], w[None])[0]
    V = rep.between("velocity", bases[low], bases[high], w_v[None], momentum=True)[0]
    F = rep.between("acceleration", bases[low], bases[high], w_v[None], momentum=True)[0] if bases[low].N == 0 else None
    c0, c1 = vectors[low], vectors[high]
    length = c0.T @ L @ c1
    de = np.subtract.outer(energies[high], energies[low]).T  # E_{L+1} − E_L, rows the levels of N = L
    with np.errstate(divide="ignore", invalid="ignore"):
        velocity = -(c0.T @ V @ c1) / de
        acceleration = None if F is None else (c0.T @ F @ c1) / de ** 2
    forms = (length, velocity, acceleration)
    return tuple(None if x is None else x.T for x in forms) if flip else forms


def _quadrupole(bases, vectors, coordinates: str) -> np.ndarray:
    """<2‖Q‖0> between every level of `bases[0]` (rows) and of `bases[1]` (columns), one of N = 0 and
    one of N = 2."""
    flip = bases[0].N != 0
    zero, two = (1, 0) if flip else (0, 1)
    if (bases[zero].N, bases[two].N) != (0, 2):
        raise UnsupportedError(f"quadrupole elements between N = {bases[0].N} and N = {bases[1].N}: derived for "
                               "N = 0 ↔ 2 only")
    system = bases[zero].system
    rep = laboratory(system) if coordinates == "lab" else translationally_invariant(system)
    Q = rep.between("quadrupole", bases[zero], bases[two], quadrupole_matrix(system))[0]
    q = vectors[zero].T @ Q @ vectors[two]
    return q.T if flip else q


def _lifetimes(lines: list[dict]) -> list[dict]:
    """Each emitting level's lifetime, 1/Σ A over its computed lines (s)."""
    total: dict[int, list] = {}
    for line in lines:
        if "einstein_A" in line:
            total.setdefault(line["upper"], []).append(line["einstein_A"])
    return [{"level": k, "lifetime": 1 / sum(a), "lines": len(a)} for k, a in sorted(total.items()) if sum(a) > 0]
