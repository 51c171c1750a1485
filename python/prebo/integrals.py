"""Symmetrised overlap, kinetic and Coulomb matrices from the Rust core, in two representations.

- `laboratory(system)`: LFCC, kinetic matrix M; the core returns T (with CM motion)
  and T_ti (CM kinetic energy eliminated by paper eq. ecg-transl, see crates/prebo-core/src/pecg.rs).
- `laboratory(system, kinetic="internal")`: LFCC with M - 1 1^T/(2 m_tot), the CM
  kinetic operator removed exactly (an independent check of the elimination).
- `translationally_invariant(system, coords)`: TICC of a coordinate set x, kinetic
  matrix μ, exponents 𝒜 (possible only when every function shares one c_A).

Each representation returns dict(S, T, T_ti, V) of normalised functions.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import _core
from .coordinates import CoordinateSet, jacobi
from .errors import SeparabilityError
from .system import System


@dataclass(frozen=True)
class Representation:
    """Kinetic matrix Λ, Coulomb vectors w and charges q, symmetry operations T and coefficients."""

    lam: np.ndarray
    pair_w: np.ndarray
    pair_q: np.ndarray
    sym_t: np.ndarray
    sym_c: np.ndarray
    cm_mass: float | None
    coords: CoordinateSet | None = None  # None: laboratory frame

    def exponents(self, A: np.ndarray, c_A: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(A, c_A) as the core needs them in this representation."""
        if self.coords is None:
            return np.ascontiguousarray(A), np.ascontiguousarray(c_A)
        Ui = self.coords.U_inv
        Ax = np.einsum("ki,nkl,lj->nij", Ui, A, Ui)
        return np.ascontiguousarray(Ax[:, :-1, :-1]), np.ascontiguousarray(Ax[:, -1, -1])

    def matrices(self, A: np.ndarray, c_A: np.ndarray) -> dict:
        a, c = self.exponents(A, c_A)
        return _core.matrices(a, c, self.lam, self.pair_w, self.pair_q, self.sym_t, self.sym_c, self.cm_mass)

    def rows(self, trial_A, trial_c_A, A, c_A) -> tuple[dict, np.ndarray]:
        """Rows (k x nb) of trials against the basis, and the trials' diagonals [S, T, T_ti, V]."""
        ta, tc = self.exponents(np.asarray(trial_A, float).reshape(-1, *A.shape[1:]), np.atleast_1d(trial_c_A))
        a, c = self.exponents(A, c_A)
        return _core.rows(ta, tc, a, c, self.lam, self.pair_w, self.pair_q, self.sym_t, self.sym_c, self.cm_mass)


def laboratory(system: System, kinetic: str = "M") -> Representation:
    """LFCC with kinetic matrix M (and the c_A elimination), or "internal": M - 1 1^T/(2 m_tot)."""
    w, q = system.coulomb_pairs()
    sym = system.symmetriser
    if kinetic == "M":
        lam, cm = system.M, system.m_total
    elif kinetic == "internal":
        lam, cm = system.M_internal, None
    else:
        raise ValueError(f"kinetic must be 'M' or 'internal', not {kinetic!r}")
    c = np.ascontiguousarray
    return Representation(c(lam), c(w), c(q), c(sym.matrices), np.array(sym.coefficients), cm)


def translationally_invariant(system: System, coords: CoordinateSet | None = None) -> Representation:
    """TICC of `coords` (default: Jacobi in input order): kinetic μ, w' = (U^-T w)_{1..n-1}, 𝒯 = (U Π U^-1)_{TI}."""
    coords = coords or jacobi(system.masses)
    coords.check(system.masses)
    w, q = system.coulomb_pairs()
    wx = coords.transform_vectors_to_x(w)
    sym = system.symmetriser
    tx = np.array([coords.transform_operation(P) for P in sym.matrices])
    c = np.ascontiguousarray
    return Representation(
        c(coords.mu(system.M)), c(wx[:, :-1]), c(q), c(tx[:, :-1, :-1]), np.array(sym.coefficients), None, coords
    )


def require_shared_c_A(c_A: np.ndarray, rtol: float = 1e-12) -> float:
    """The common c_A of a CM-separable basis, or SeparabilityError naming the spread."""
    lo, hi = float(np.min(c_A)), float(np.max(c_A))
    if hi - lo > rtol * hi:
        raise SeparabilityError(
            f"the basis is not separable in the CM coordinate: c_A ranges from {lo:.6g} to {hi:.6g}; "
            "a translationally invariant evaluation needs one shared c_A (use --coordinates lab)"
        )
    return hi
