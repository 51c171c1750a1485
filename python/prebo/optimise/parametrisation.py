"""The parameters θ of one basis function, in which refinement and learned sampling move it.

A function generated in coordinate set x is parametrised in x: θ = (ln diag L, strict lower L,
tail) with 𝒜^(x) = L L^T (positive definite for every θ) and A^(r) = U_x^T blockdiag(𝒜, c_A) U_x
(Muolo, Mátyus & Reiher, J. Chem. Phys. 148, 084112 (2018), Sec. IV: the transformation of
exponents between coordinate sets); c_A stays fixed. The tail is the family's
(Family.theta_tail): for ECG-GVR u' with u^(r) = U_x^T v/|v|, v = (u', c_U) (the normalised
function does not depend on the length of u, which is kept at 1; c_U and K fixed), for floating
ECGs s' with s^(r) = U_x^-1 (s', μ^T s) (the CM centre μ^T s fixed), none for plain ECGs.
A θ whose 𝒜 has a condition number above MAX_CONDITION is refused (IllConditionedError): the
optimised bases stay below 1e5, and integrals of far more extreme exponents lose their digits.
A function from the pair sampler is parametrised in the first Jacobi set.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from .. import coordinates as coords
from ..basis import Basis
from ..errors import IllConditionedError

LOG_DIAG = (-8.0, 10.0)  # ln L_kk: exponents within ~1e-7..5e8
MAX_CONDITION = 1e8  # of 𝒜 (module docstring)


@lru_cache
def _entries(d: int) -> tuple[np.ndarray, np.ndarray]:
    """Row and column of each entry of L that θ moves: the diagonal, then the strict lower part."""
    rows, cols = np.tril_indices(d, -1)
    return np.concatenate([np.arange(d), rows]), np.concatenate([np.arange(d), cols])


@dataclass
class Parametrisation:
    """θ <-> one function, in the coordinate set `x`: θ = (ln diag L, strict lower L, tail), the
    tail being the family's (Family.theta_tail: u' of ECG-GVR, s' of floating ECGs)."""

    f: Basis
    x: coords.CoordinateSet

    @classmethod
    def of(cls, f: Basis) -> "Parametrisation":
        """The parametrisation of the one-function basis `f` in the coordinate set of its channel."""
        m = f.system.masses
        name = f.channels[0]
        x = coords.by_name(m, name) if name.split(":")[0] in ("jacobi", "hpc", "cmc") else coords.jacobi(m)
        return cls(f.family.prepared(f, x), x)

    @property
    def _split(self) -> int:
        """Where the tail of θ starts: after the d + d(d-1)/2 parameters of L, d = n - 1."""
        d = self.f.system.n - 1
        return d + d * (d - 1) // 2

    def theta(self) -> np.ndarray:
        """θ of the function (module docstring)."""
        A_int, _ = self.x.from_lab(self.f.A[0])
        L = np.linalg.cholesky(A_int)
        d = len(L)
        return np.concatenate([np.log(np.diag(L)), L[_entries(d)][d:], self.f.family.theta_tail(self.f, self.x)])

    def _L(self, theta: np.ndarray) -> np.ndarray:
        d = self.f.system.n - 1
        L = np.zeros((d, d))
        L[_entries(d)] = np.concatenate([np.exp(np.clip(theta[:d], *LOG_DIAG)), theta[d:self._split]])
        sv = np.linalg.svd(L, compute_uv=False)
        if not sv[-1] > 0 or (sv[0] / sv[-1]) ** 2 > MAX_CONDITION:
            raise IllConditionedError(f"exponent matrix with condition number above {MAX_CONDITION:.0e}")
        return L

    def transformed(self, theta: np.ndarray, T: np.ndarray) -> np.ndarray:
        """θ of 𝒜 = (L T)(L T)^T for a lower-triangular T with positive diagonal, the tail kept."""
        LT = self._L(theta) @ T
        d = len(LT)
        return np.concatenate([np.log(np.diag(LT)), LT[_entries(d)][d:], theta[self._split:]])

    def function(self, theta: np.ndarray, K: int | None = None) -> Basis:
        """The one-function basis of θ (`K`: a power to set instead of the function's own)."""
        f, L = self.f, self._L(theta)
        c_A = f.c_A[0]
        extras = f.family.from_tail(f, self.x, theta[self._split:], K)
        return Basis.single(f.system, self.x.to_lab(L @ L.T, c_A), c_A, self.x.name, f.kind, extras)

    def directions(self, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
        """∂A^(r)/∂θ_p (P x n x n) and the family's ∂(u or s)^(r)/∂θ_p (None for plain ECGs).
        With 𝒜 = L L^T: ∂𝒜 = ∂L L^T + L ∂L^T, ∂L = L_kk E_kk for θ = ln L_kk (0 where clipped),
        E_ab for a strict-lower entry; A^(r) is linear in 𝒜."""
        n = self.f.system.n
        d, P = n - 1, len(theta)
        L = self._L(theta)
        rows, cols = _entries(d)
        inside = (theta[:d] > LOG_DIAG[0]) & (theta[:d] < LOG_DIAG[1])
        dL = np.zeros((self._split, d, d))
        dL[np.arange(self._split), rows, cols] = np.concatenate([np.diag(L) * inside, np.ones(self._split - d)])
        dA_int = np.zeros((P, n, n))  # ∂A^(x): ∂𝒜 in the internal block, nothing on the CM
        dA_int[:self._split, :-1, :-1] = dL @ L.T + L @ dL.transpose(0, 2, 1)
        U = self.x.U
        return U.T @ dA_int @ U, self.f.family.tail_directions(self.f, self.x, theta[self._split:], P, self._split)
