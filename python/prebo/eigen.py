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
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

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
    """Lowest eigenvalue after adding one function (secular equation); +inf if it is
    linearly dependent on the basis (orthogonal remainder below `min_norm` of its norm)."""
    if len(E) == 0:
        return h_nn / s_nn
    d = C.T @ s
    b = C.T @ h
    nu = s_nn - d @ d
    if not nu > min_norm * s_nn:
        return np.inf
    gamma2 = (b - E * d) ** 2 / nu
    hp = (h_nn - 2.0 * b @ d + E @ (d * d)) / nu

    def f(x):
        return hp - x - np.sum(gamma2 / (E - x))

    top = E[0]
    lo = min(top, hp) - np.sqrt(gamma2.sum()) - 1e-3 * max(1.0, abs(top))
    while f(lo) < 0:  # widen until the root is bracketed
        lo -= 2.0 * (top - lo)
    hi = top
    x = lo
    for _ in range(200):
        fx = f(x)
        if fx == 0.0 or hi - lo < 1e-15 * max(1.0, abs(x)):
            break
        if fx > 0:
            lo = x
        else:
            hi = x
        # Newton (f is concave and decreasing below E_0), bisection when it leaves the bracket
        step = x - fx / (-1.0 - np.sum(gamma2 / (E - x) ** 2))
        x = step if lo < step < hi else 0.5 * (lo + hi)
        if abs(step - x) == 0.0 and abs(fx) < 1e-15 * max(1.0, abs(x)):
            break
    return float(x)
