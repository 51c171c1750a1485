"""Local refinement of one basis function with all others fixed (the paper's Powell step).

A function generated in coordinate set x is refined in x: its parameters are
θ = (ln diag L, strict lower L, u' or s') with 𝒜^(x) = L L^T (positive definite for every θ),
A^(r) = U_x^T blockdiag(𝒜, c_A) U_x; for ECG-GVR u^(r) = U_x^T (u', c_U), for floating ECGs
s^(r) = U_x^-1 (s', μ^T s); c_A, c_U, the CM centre μ^T s and K stay fixed. A function from the pair sampler is refined in the first Jacobi set.
The energy of a trial θ is the lowest root of the secular equation (eigen.lowest_with_added)
against the basis without the function: one row of integrals and O(N_b^2) per evaluation.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize

from . import coordinates as coords
from . import eigen
from .basis import Basis
from .errors import PreboError


@dataclass
class Parametrisation:
    """θ <-> one function, in the coordinate set `x`."""

    f: Basis
    x: coords.CoordinateSet

    @classmethod
    def of(cls, f: Basis) -> "Parametrisation":
        m = f.system.masses
        name = f.channels[0]
        x = coords.by_name(m, name) if name.split(":")[0] in ("jacobi", "hpc", "cmc") else coords.jacobi(m)
        return cls(f, x)

    def theta(self) -> np.ndarray:
        A_int, _ = self.x.from_lab(self.f.A[0])
        L = np.linalg.cholesky(A_int)
        d = len(L)
        parts = [np.log(np.diag(L)), L[np.tril_indices(d, -1)]]
        if self.f.kind == "ecg-gvr":
            parts.append(self.x.transform_vectors_to_x(self.f.u[0])[:-1])
        if self.f.kind == "fecg":
            parts.append((self.x.U @ self.f.s[0])[:-1].ravel())
        return np.concatenate(parts)

    def function(self, theta: np.ndarray, K: int | None = None) -> Basis:
        d = self.f.system.n - 1
        L = np.diag(np.exp(np.clip(theta[:d], -8.0, 10.0)))  # exponents within ~1e-7..5e8
        nl = d * (d - 1) // 2
        L[np.tril_indices(d, -1)] = theta[d:d + nl]
        c_A = self.f.c_A[0]
        A = self.x.to_lab(L @ L.T, c_A)
        if self.f.kind == "pecg":
            return Basis(self.f.system, A[None], [c_A], [self.x.name])
        if self.f.kind == "fecg":
            sx = self.x.U @ self.f.s[0]
            sx[:-1] = theta[d + nl:].reshape(d, 3)
            return Basis(self.f.system, A[None], [c_A], [self.x.name], kind="fecg", s=(self.x.U_inv @ sx)[None])
        c_U = float(self.f.u[0].sum())
        u = self.x.U.T @ np.append(theta[d + nl:], c_U)
        return Basis(self.f.system, A[None], [c_A], [self.x.name], kind="ecg-gvr", u=u[None],
                     K=self.f.K[:1] if K is None else [K])


def refine_function(state, i: int, max_evaluations: int = 200) -> bool:
    """Powell-minimise the energy over the parameters of function i; True if it improved."""
    basis = state.basis
    keep = np.arange(len(basis)) != i
    sub = state.without(i)
    E, C = (sub.energies, sub.vectors) if sub is not None else (np.zeros(0), np.zeros((0, 0)))
    p = Parametrisation.of(basis.subset([i]))
    best = {"E": state.energy, "f": None, "row": None, "diag": None}

    def energy(theta):
        f = p.function(theta)
        # a θ that leaves the valid region, or a function linearly dependent on the others,
        # scores worse than the current energy (a finite value keeps Powell's line search sane)
        worse = state.energy + 1.0
        try:
            rows, diag = state.rep.rows(f, basis, i)
        except PreboError:
            return worse
        e = eigen.lowest_with_added(E, C, (rows["T_ti"] + rows["V"])[0, keep],
                                    rows["S"][0, keep], diag[0, 2] + diag[0, 3], diag[0, 0], state.min_norm)
        if not np.isfinite(e):
            return worse
        if e < best["E"]:
            best.update(E=e, f=f, row={k: v[0] for k, v in rows.items()}, diag=diag[0])
        return e

    theta0 = p.theta()
    minimize(energy, theta0, method="Powell",
             options={"maxfev": max_evaluations, "xtol": 1e-4, "ftol": 1e-14, "direc": 0.1 * np.eye(len(theta0))})
    if best["f"] is not None and best["E"] < state.energy - 1e-15 * abs(state.energy):
        state.put(i, best["f"], best["row"], best["diag"])
        return True
    return False
