"""The generalised eigenproblem H c = E S c and its O(N^2) update for one added function.

Solve: functions are scaled to unit self-overlap, then canonical orthogonalisation
(Löwdin): S = V s V^T, keep s_k > threshold * max(s), X = V_k s_k^{-1/2}, diagonalise
X^T H X. No explicit inverse; near-linear dependence costs the dropped directions only.

Update (Suzuki & Varga, Lect. Notes Phys. m54, sec. 4.2, the secular equation):
with S-orthonormal eigenvectors C and eigenvalues E_k of the current basis and a new
function n with rows h, s and diagonal h_nn, s_nn, let d = C^T s, b = C^T h. The part
of n orthogonal to the basis has norm^2 ν = s_nn - d·d, couplings γ_k = (b_k - E_k d_k)/√ν
and energy h' = (h_nn - 2 b·d + Σ E_k d_k^2)/ν. The new lowest eigenvalue is the root
below E_0 of f(x) = h' - x - Σ γ_k^2 / (E_k - x), strictly decreasing there.

Gradient (Hellmann–Feynman for the augmented problem): at the root e the eigenvector is
c = (C a, 1) with a_k = -(b_k - e d_k)/(E_k - e); when only the new function's parameters move,
de = [2 (C a)·(dh - e ds) + dh_nn - e ds_nn] / (|a|^2 + 2 a·d + s_nn).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import _core
from .errors import LinearDependenceError, NotPositiveDefiniteError


@dataclass
class Eigen:
    energies: np.ndarray  # ascending
    vectors: np.ndarray  # columns, S-orthonormal, in the original (unscaled) basis
    kept: int  # number of overlap eigenvectors kept
    overlap_condition: float  # max(s)/min(s) of the unit-diagonal overlap


def solve(H: np.ndarray, S: np.ndarray, threshold: float = 1e-13) -> Eigen:
    """All eigenpairs of H c = E S c by canonical orthogonalisation (see module docstring)."""
    diag = np.diag(S).copy()
    if np.any(~(diag > 0)):
        bad = int(np.argmin(diag))
        raise NotPositiveDefiniteError(f"overlap matrix: diagonal element {bad} is {diag[bad]:.3g}, not positive")
    d = 1.0 / np.sqrt(diag)
    Ss = S * np.outer(d, d)
    s, V = np.linalg.eigh(Ss)
    if s[0] < -1e3 * threshold * s[-1] - 1e-10:
        raise NotPositiveDefiniteError(f"overlap matrix is not positive definite (lowest eigenvalue {s[0]:.3g})")
    keep = s > threshold * s[-1]
    if not np.any(keep):
        raise LinearDependenceError("overlap matrix has no eigenvalue above the threshold")
    X = V[:, keep] / np.sqrt(s[keep])
    Hs = H * np.outer(d, d)
    E, Y = np.linalg.eigh(X.T @ Hs @ X)
    return Eigen(E, d[:, None] * (X @ Y), int(keep.sum()), float(s[-1] / max(s[0], 1e-300)))


def lowest_with_added(E, C, h, s, h_nn, s_nn, min_norm: float = 1e-10) -> float:
    """Lowest eigenvalue after adding one function (secular equation, in the Rust core); +inf if
    it is linearly dependent on the basis (orthogonal remainder below `min_norm` of its norm)."""
    return float(lowest_with_added_many(E, C, np.atleast_2d(h), np.atleast_2d(s), [h_nn], [s_nn], min_norm)[0])


def lowest_with_added_gradient(E, C, h, s, h_nn, s_nn, dh, ds, dh_nn, ds_nn, min_norm: float = 1e-10):
    """`lowest_with_added` and its gradient with respect to parameters of the new function, given the
    derivatives dh, ds (P x nb) and dh_nn, ds_nn (P) of its rows and diagonal (module docstring)."""
    e = lowest_with_added(E, C, h, s, h_nn, s_nn, min_norm)
    if not np.isfinite(e):
        return e, np.zeros(len(dh_nn))
    if len(E) == 0:
        return e, (dh_nn - e * ds_nn) / s_nn
    d, b = C.T @ s, C.T @ h
    a = -(b - e * d) / (E - e)
    c_old = C @ a
    norm2 = a @ a + 2.0 * a @ d + s_nn
    return e, (2.0 * (dh - e * ds) @ c_old + dh_nn - e * ds_nn) / norm2


def lowest_with_added_many(E, C, H, S, h_nn, s_nn, min_norm: float = 1e-10) -> np.ndarray:
    """`lowest_with_added` for k trials at once: rows H, S (k x nb), diagonals h_nn, s_nn (k)."""
    c = np.ascontiguousarray
    E = c(E, dtype=float)
    C = c(np.asarray(C, dtype=float).reshape(-1, len(E)) if len(E) else np.zeros((0, 0)))
    out = _core.lowest_with_added(E, C, c(H, dtype=float), c(S, dtype=float), c(h_nn, dtype=float),
                                  c(s_nn, dtype=float), float(min_norm))
    out[~np.isfinite(out)] = np.inf  # NaN elements (a near-singular trial) never win
    return out
