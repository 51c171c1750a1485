"""Symmetrised overlap, kinetic and Coulomb matrices from the Rust core, in two representations.

- `laboratory(system)`: LFCC, kinetic matrix M; the core returns T (with CM motion)
  and T_ti (CM kinetic energy eliminated by paper eq. ecg-transl, see crates/prebo-core/src/pecg.rs).
- `laboratory(system, kinetic="internal")`: LFCC with M - 1 1^T/(2 m_tot), the CM
  kinetic operator removed exactly (an independent check of the elimination).
- `translationally_invariant(system, coords)`: TICC of a coordinate set x, kinetic
  matrix μ, exponents 𝒜 (possible only when every function shares one c_A).

Each representation returns dict(S, T, T_ti, V) of normalised functions, for plain ECGs
(`_core.matrices`) or ECG-GVR functions (`_core.gvr_matrices`, the state's N), whichever the
basis holds.
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

    def arrays(self, f) -> tuple:
        """The core's arrays of a function set `f` (a Basis) in this representation:
        (A, c_A) for plain ECGs, (A, u, K, c_A) for ECG-GVR, (A, s, c_A) for floating ECGs."""
        A, c_A = f.A, f.c_A
        u = f.u if f.kind == "ecg-gvr" else None
        s = f.s if f.kind == "fecg" else None
        if self.coords is not None:
            Ui = self.coords.U_inv
            Ax = np.einsum("ki,nkl,lj->nij", Ui, A, Ui)
            A, c_A = Ax[:, :-1, :-1], Ax[:, -1, -1]
            if u is not None:
                ux = self.coords.transform_vectors_to_x(u)  # u^(x) = U^-T u^(r) = (u', c_U)
                if np.any(np.abs(ux[:, -1]) > 1e-12 * np.max(np.abs(ux), axis=1)):
                    raise SeparabilityError("a global vector has a CM component (c_U != 0): "
                                            "no translationally invariant evaluation (use --coordinates lab)")
                u = ux[:, :-1]
            if s is not None:
                sx = np.einsum("ki,nij->nkj", self.coords.U, s)  # s^(x) = U s
                if np.any(np.abs(sx[:, -1]) > 1e-12 * max(1.0, np.max(np.abs(sx)))):
                    raise SeparabilityError("a centre set has a CM component (μ^T s != 0): "
                                            "no translationally invariant evaluation (use --coordinates lab)")
                s = sx[:, :-1]
        c = np.ascontiguousarray
        if u is not None:
            return c(A), c(u), c(f.K, dtype=np.uint32), c(c_A)
        if s is not None:
            return c(A), c(s), c(c_A)
        return c(A), c(c_A)

    def _ops(self):
        return self.lam, self.pair_w, self.pair_q, self.sym_t, self.sym_c, self.cm_mass

    def matrices(self, f) -> dict:
        """Symmetrised S, T, T_ti, V of the basis `f`."""
        if f.kind == "ecg-gvr":
            return _core.gvr_matrices(*self.arrays(f), f.N, *self._ops())
        if f.kind == "fecg":
            return _core.fecg_matrices(*self.arrays(f), *self._ops())
        return _core.matrices(*self.arrays(f), *self._ops())

    def rows(self, trials, f, position: int | None = None) -> tuple[dict, np.ndarray]:
        """Rows (k x nb) of `trials` against the basis `f`, and the trials' diagonals [S, T, T_ti, V].

        `position`: where a trial would sit in the basis (default: appended). ECG-GVR and FECG rows
        are then evaluated in the orientation of a full build, so patching them into the matrices
        gives the bits of `matrices` (`oriented`); plain-ECG rows always have the trial as bra."""
        if f.kind == "ecg-gvr":
            return _core.gvr_rows(*self.arrays(trials), *self.arrays(f), f.N, *self._ops(), position)
        if f.kind == "fecg":
            return _core.fecg_rows(*self.arrays(trials), *self.arrays(f), *self._ops(), position)
        return _core.rows(*self.arrays(trials), *self.arrays(f), *self._ops())

    def row_gradient(self, f, dA: np.ndarray, dv: np.ndarray | None, basis) -> tuple[dict, np.ndarray]:
        """Row of the one-function basis `f` against `basis` (f as bra) and its diagonal, with the
        derivatives along P directions: dA (P x n x n) of A and dv (P x n) of u or (P x n x 3) of s.
        Returns dict of (1 + P) x nb arrays (row 0 the values) and the (1 + P) x 4 diagonal.
        Laboratory frame only; a plain ECG goes through the ECG-GVR kernel at K = N = 0, where
        u drops out (crates/prebo-core/src/gvr.rs)."""
        if self.coords is not None:
            raise ValueError("row gradients are computed in the laboratory frame")
        c = np.ascontiguousarray
        if f.kind == "fecg":
            return _core.fecg_row_gradient(*self.arrays(f), c(dA), c(dv), *self.arrays(basis), *self._ops())
        if f.kind == "ecg-gvr":
            return _core.gvr_row_gradient(*self.arrays(f), c(dA), c(dv), *self.arrays(basis), basis.N, *self._ops())
        as_gvr = []
        for g in (f, basis):
            u = np.zeros((len(g), g.system.n))
            u[:, 0] = 1.0
            as_gvr.append((c(g.A), u, np.zeros(len(g), np.uint32), c(g.c_A)))
        P = len(dA)
        return _core.gvr_row_gradient(*as_gvr[0], c(dA), np.zeros((P, f.system.n)), *as_gvr[1], 0, *self._ops())

    def plausible(self, rows: dict, diag: np.ndarray, S_basis: np.ndarray) -> np.ndarray:
        """Per trial, whether its elements pass the bounds exact integrals obey: 0 < S_nn ≤ Σ_P |c_P|,
        T_nn, T_ti,nn ≥ 0, |S_nj| ≤ (S_nn S_jj)^{1/2} (Cauchy–Schwarz). Integrals of extreme
        parameters that lost their digits fail them, and would otherwise break the variational bound."""
        S_nn = diag[:, 0]
        ok = (S_nn > 0) & (S_nn <= np.abs(self.sym_c).sum() * (1 + 1e-10)) & (diag[:, 1] >= 0) & (diag[:, 2] >= 0)
        if rows["S"].shape[1]:
            bound = np.sqrt(np.outer(np.maximum(S_nn, 0), S_basis)) * (1 + 1e-8)
            ok &= np.all(np.abs(rows["S"]) <= bound, axis=1)
        return ok & np.all(np.isfinite(diag), axis=1)

    @staticmethod
    def oriented(kind: str) -> bool:
        """Whether `rows(..., position)` reproduces full-build bits for this basis type."""
        return kind in ("ecg-gvr", "fecg")

    def angular(self, f, mu: np.ndarray) -> np.ndarray:
        """The symmetrised translation-free <N²> matrix of a floating-ECG basis (laboratory frame)."""
        if f.kind != "fecg" or self.coords is not None:
            raise ValueError("<N²> matrices are computed for floating ECGs in the laboratory frame")
        return _core.fecg_angular(*self.arrays(f), np.ascontiguousarray(mu), *self._ops()[:5])


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
