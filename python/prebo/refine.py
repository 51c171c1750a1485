"""Local refinement of one basis function with all others fixed (the paper's Powell step).

A function generated in coordinate set x is refined in x: its parameters are
θ = (ln diag L, strict lower L, u' or s') with 𝒜^(x) = L L^T (positive definite for every θ),
A^(r) = U_x^T blockdiag(𝒜, c_A) U_x; for ECG-GVR u^(r) = U_x^T v/|v|, v = (u', c_U) (the
normalised function does not depend on the length of u, which is kept at 1), for floating ECGs
s^(r) = U_x^-1 (s', μ^T s); c_A, c_U, the CM centre μ^T s and K stay fixed. A θ whose 𝒜 has a
condition number above MAX_CONDITION is refused (IllConditionedError): the optimised bases stay
below 1e5, and integrals of far more extreme exponents lose their digits. A function from the pair sampler is refined in the first Jacobi set.
The energy of a trial θ is the lowest root of the secular equation (eigen.lowest_with_added)
against the basis without the function: one row of integrals and O(N_b^2) per evaluation.

Two minimisers: Powell's method on the energy (the paper's), and L-BFGS on the energy and its
exact gradient — the row's derivatives along ∂(A, u or s)/∂θ_p by forward-mode dual numbers
in the Rust core (Representation.row_gradient), then eigen.lowest_with_added_gradient.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize

from . import coordinates as coords
from . import eigen
from .basis import Basis
from .errors import IllConditionedError, PreboError
from .validation import REFINE_METHODS


@dataclass
class Parametrisation:
    """θ <-> one function, in the coordinate set `x`: θ = (ln diag L, strict lower L, tail), the
    tail being the family's (Family.theta_tail: u' of ECG-GVR, s' of floating ECGs)."""

    f: Basis
    x: coords.CoordinateSet

    @classmethod
    def of(cls, f: Basis) -> "Parametrisation":
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
        A_int, _ = self.x.from_lab(self.f.A[0])
        L = np.linalg.cholesky(A_int)
        d = len(L)
        return np.concatenate([np.log(np.diag(L)), L[np.tril_indices(d, -1)], self.f.family.theta_tail(self.f, self.x)])

    def _L(self, theta: np.ndarray) -> np.ndarray:
        d = self.f.system.n - 1
        L = np.diag(np.exp(np.clip(theta[:d], *LOG_DIAG)))
        L[np.tril_indices(d, -1)] = theta[d:self._split]
        sv = np.linalg.svd(L, compute_uv=False)
        if not sv[-1] > 0 or (sv[0] / sv[-1]) ** 2 > MAX_CONDITION:
            raise IllConditionedError(f"exponent matrix with condition number above {MAX_CONDITION:.0e}")
        return L

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
        inside = (theta[:d] > LOG_DIAG[0]) & (theta[:d] < LOG_DIAG[1])
        entries = [(k, k, L[k, k] * inside[k]) for k in range(d)]
        entries += [(a, b, 1.0) for a, b in zip(*np.tril_indices(d, -1))]
        dA = np.zeros((P, n, n))
        for p, (a, b, v) in enumerate(entries):
            dL = np.zeros((d, d))
            dL[a, b] = v
            dA[p] = self.x.to_lab(dL @ L.T + L @ dL.T, 0.0)
        return dA, self.f.family.tail_directions(self.f, self.x, theta[self._split:], P, self._split)


LOG_DIAG = (-8.0, 10.0)  # ln L_kk: exponents within ~1e-7..5e8
MAX_CONDITION = 1e8  # of 𝒜 (module docstring)
METHODS = REFINE_METHODS


class Objective:
    """The energy as a function of θ of function i, all others fixed: the lowest root of the
    secular equation against the basis without i. Remembers the best function seen. A θ that
    leaves the valid region (an ill-conditioned 𝒜, elements failing `Representation.plausible`),
    or makes the function linearly dependent on the others, scores worse than the current energy (a finite value keeps the line searches sane).
    `f`: parametrise this function (a newcomer for slot i) instead of function i; the state is
    not changed, and the best seen starts at f's own energy."""

    def __init__(self, state, i: int, rest=None, f: Basis | None = None):
        self.state, self.i = state, i
        basis = state.basis
        self.keep = np.arange(len(basis)) != i
        sub = state.without(i) if rest is None else rest
        self.E, self.C = (sub.energies, sub.vectors) if sub is not None else (np.zeros(0), np.zeros((0, 0)))
        self.rest = basis.subset(np.flatnonzero(self.keep))
        self.S_rest = np.diag(state.m["S"])[self.keep]
        self.p = Parametrisation.of(basis.subset([i]) if f is None else f)
        self.worse = state.energy + 1.0
        self.best_E, self.best_f = state.energy, None
        if f is not None:
            self.best_E = np.inf
            self.energy(self.p.theta())

    def _seen(self, e: float, f: Basis) -> None:
        if e < self.best_E:
            self.best_E, self.best_f = e, f

    def energy(self, theta: np.ndarray) -> float:
        st = self.state
        try:
            f = self.p.function(theta)
            rows, diag = st.rep.rows(f, st.basis, self.i)
        except PreboError:
            return self.worse
        if not st.rep.plausible({"S": rows["S"][:, self.keep]}, diag, self.S_rest)[0]:
            return self.worse
        e = eigen.lowest_with_added(self.E, self.C, (rows["T_ti"] + rows["V"])[0, self.keep],
                                    rows["S"][0, self.keep], diag[0, 2] + diag[0, 3], diag[0, 0], st.min_norm)
        if not np.isfinite(e):
            return self.worse
        self._seen(e, f)
        return e

    def energy_and_gradient(self, theta: np.ndarray) -> tuple[float, np.ndarray]:
        st = self.state
        try:
            f = self.p.function(theta)
            dA, dv = self.p.directions(theta)
            rows, diag = st.rep.row_gradient(f, dA, dv, self.rest)
        except PreboError:
            return self.worse, np.zeros_like(theta)
        if not st.rep.plausible({"S": rows["S"][:1]}, diag[:1], self.S_rest)[0]:
            return self.worse, np.zeros_like(theta)
        H, S = rows["T_ti"] + rows["V"], rows["S"]
        h_nn, s_nn = diag[:, 2] + diag[:, 3], diag[:, 0]
        e, g = eigen.lowest_with_added_gradient(self.E, self.C, H[0], S[0], h_nn[0], s_nn[0], H[1:], S[1:],
                                                h_nn[1:], s_nn[1:], st.min_norm)
        if not (np.isfinite(e) and np.all(np.isfinite(g))):
            return self.worse, np.zeros_like(theta)
        self._seen(e, f)
        return e, g


def minimise(obj: Objective, max_evaluations: int, method: str) -> None:
    """Powell's method, or L-BFGS with exact gradients, from the objective's function, with at
    most `max_evaluations` energies; the best function seen is kept in the objective."""
    theta0 = obj.p.theta()
    if method == "gradient":
        minimize(obj.energy_and_gradient, theta0, jac=True, method="L-BFGS-B",
                 options={"maxfun": max_evaluations, "maxiter": max_evaluations, "ftol": 1e-16, "gtol": 1e-12,
                          "maxcor": 20})
    else:
        minimize(obj.energy, theta0, method="Powell",
                 options={"maxfev": max_evaluations, "xtol": 1e-4, "ftol": 1e-14, "direc": 0.1 * np.eye(len(theta0))})


def accept(state, i: int, obj: Objective) -> bool:
    """Put the objective's best function in slot i if it lowers the energy beyond its numerical
    uncertainty (optimise.State.put); True if it did."""
    if obj.best_f is None or not state.gains(obj.best_E):
        return False
    rows, diag = state.rep.rows(obj.best_f, state.basis, i)  # oriented: patched matrices equal a rebuild
    return state.put(i, obj.best_f, {k: v[0] for k, v in rows.items()}, diag[0])


def refine_function(state, i: int, max_evaluations: int = 200, method: str = "gradient", rest=None) -> bool:
    """Minimise the energy over the parameters of function i — Powell, or L-BFGS with exact
    gradients — with at most `max_evaluations` energies; True if it improved. `rest`: the
    eigen-solution of the basis without i (State.without), if already at hand."""
    obj = Objective(state, i, rest)
    minimise(obj, max_evaluations, method)
    return accept(state, i, obj)


def regenerate_function(state, i: int, f: Basis, max_evaluations: int = 200, method: str = "gradient",
                        rest=None) -> bool:
    """A replacement sweep's step with refinement: `f` (the competitive winner for position i) is
    refined in slot i and takes it if it then lowers the energy; otherwise function i is refined.
    A refined newcomer can leave the basin the incumbent's refinement is confined to. True if it
    improved. Both refinements share `rest`, the eigen-solution of the basis without i
    (State.without), and the state is changed (and its eigenproblem solved) once at most."""
    rest = state.without(i) if rest is None else rest
    newcomer = Objective(state, i, rest, f)
    minimise(newcomer, max_evaluations, method)
    return accept(state, i, newcomer) or refine_function(state, i, max_evaluations, method, rest)
