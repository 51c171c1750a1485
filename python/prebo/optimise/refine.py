"""Local refinement of one basis function with all others fixed (the paper's Powell step: Muolo,
Mátyus & Reiher, J. Chem. Phys. 148, 084112 (2018), Sec. IV.E).

The function moves in its parameters θ (parametrisation.py). The energy of a trial θ is the
objective (objective.py: the lowest root, or a weighted sum of roots) of the secular equation
(eigen.roots_with_added)
against the basis without the function: one row of integrals and O(N_b^2) per evaluation.

Two minimisers: Powell's method on the energy (the paper's), and L-BFGS on the energy and its
exact gradient — the row's derivatives along ∂(A, u or s)/∂θ_p by forward-mode dual numbers
in the Rust core (Representation.row_gradient), then eigen.roots_with_added_gradient.

A group (`refine_group`): function i and the functions it overlaps most (`partners`) move
together, L-BFGS on all their θ, the energy the root of the block update against the basis
without them (eigen.roots_with_block). Strongly overlapping functions of an optimised
basis act together (a near-duplicate pair is a derivative of a Gaussian): moved one at a time,
each is held by the other.
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import minimize

from ..basis import Basis
from ..errors import PreboError
from ..matrices import Matrices
from .parametrisation import Parametrisation


class FunctionEnergy:
    """The energy as a function of θ of function i, all others fixed: the objective's root of the
    secular equation against the basis without i. Remembers the best function seen. A θ that
    leaves the valid region (an ill-conditioned 𝒜, elements failing `Representation.plausible`),
    or makes the function linearly dependent on the others, scores worse than the current energy (a finite value keeps the line searches sane).
    `f`: parametrise this function (a newcomer for slot i; i = N_b appends it) instead of function
    i; the expansion is not changed, and the best seen starts at f's own energy."""

    def __init__(self, expansion, i: int, rest=None, f: Basis | None = None):
        self.expansion, self.i = expansion, i
        basis = expansion.basis
        self.keep = np.arange(len(basis)) != i
        if rest is None:
            rest = expansion.eig if i == len(basis) else expansion.without(i)
        sub = rest
        self.E, self.C = (sub.energies, sub.vectors) if sub is not None else (np.zeros(0), np.zeros((0, 0)))
        self.rest = basis.subset(np.flatnonzero(self.keep))
        self.S_rest = np.diag(expansion.m.S)[self.keep]
        self.p = Parametrisation.of(basis.subset([i]) if f is None else f)
        self.worse = expansion.energy + 1.0
        self.best_E, self.best_f = expansion.energy, None
        if f is not None:
            self.best_E = np.inf
            e = self.energy(self.p.theta())
            if not np.isfinite(self.worse):  # no function yet: worse than the newcomer's own energy
                self.worse = e + 1.0

    def _seen(self, e: float, f: Basis) -> None:
        if e < self.best_E:
            self.best_E, self.best_f = e, f

    def energy(self, theta: np.ndarray) -> float:
        """The energy (hartree) with function i at θ (`worse` outside the valid region)."""
        st = self.expansion
        try:
            f = self.p.function(theta)
            rows, diag = st.rep.rows(f, st.basis, self.i)
        except PreboError:
            return self.worse
        if not st.rep.plausible({"S": rows["S"][:, self.keep]}, diag, self.S_rest)[0]:
            return self.worse
        r, d = Matrices.of(rows), Matrices.columns(diag[0])
        e = st.objective.with_added(self.E, self.C, r.H[0, self.keep], r.S[0, self.keep], d.H, d.S, st.min_norm,
                                    st.sources(rows.get("b", [None])[0], self.keep))
        if not np.isfinite(e):
            return self.worse
        self._seen(e, f)
        return e

    def energy_and_gradient(self, theta: np.ndarray) -> tuple[float, np.ndarray]:
        """`energy` and its exact gradient ∂E/∂θ (hartree per unit of θ)."""
        st = self.expansion
        try:
            f = self.p.function(theta)
            dA, dv = self.p.directions(theta)
            rows, diag = st.rep.row_gradient(f, dA, dv, self.rest)
        except PreboError:
            return self.worse, np.zeros_like(theta)
        if not st.rep.plausible({"S": rows["S"][:1]}, diag[:1], self.S_rest)[0]:
            return self.worse, np.zeros_like(theta)
        r, d = Matrices.of(rows), Matrices.columns(diag)
        H, S, h_nn, s_nn = r.H, r.S, d.H, d.S
        e, g = st.objective.with_added_gradient(self.E, self.C, H[0], S[0], h_nn[0], s_nn[0], H[1:], S[1:],
                                                h_nn[1:], s_nn[1:], st.min_norm, st.sources(rows.get("b"), self.keep))
        if not (np.isfinite(e) and np.all(np.isfinite(g))):
            return self.worse, np.zeros_like(theta)
        self._seen(e, f)
        return e, g


class GroupEnergy:
    """The energy as a function of the θ of functions `idx` (concatenated), all others fixed: the
    objective's root of the block update against the basis without them, and its exact gradient.
    Remembers the best group seen (`best_E`, `best_f`: one-function bases in the order of idx);
    outside the valid region it scores `worse`, like `FunctionEnergy`."""

    def __init__(self, expansion, idx: list[int]):
        self.expansion, self.idx = expansion, list(idx)
        basis = expansion.basis
        keep = np.ones(len(basis), bool)
        keep[self.idx] = False
        sub = expansion.without(self.idx)
        self.E, self.C = (sub.energies, sub.vectors) if sub is not None else (np.zeros(0), np.zeros((0, 0)))
        self.keep, self.rest = keep, basis.subset(np.flatnonzero(keep))
        self.S_rest = np.diag(expansion.m.S)[keep]
        self.p = [Parametrisation.of(basis.subset([i])) for i in self.idx]
        self.split = np.cumsum([len(p.theta()) for p in self.p])[:-1]
        self.worse = expansion.energy + 1.0
        self.best_E, self.best_f = expansion.energy, None

    def theta(self) -> np.ndarray:
        """The θ of the group's functions, concatenated."""
        return np.concatenate([p.theta() for p in self.p])

    def energy_and_gradient(self, theta: np.ndarray) -> tuple[float, np.ndarray]:
        """The energy (hartree) with the group at θ and ∂E/∂θ (eigen module docstring)."""
        st, k, nr = self.expansion, len(self.p), len(self.rest)
        thetas = np.split(theta, self.split)
        try:
            fs = [p.function(t) for p, t in zip(self.p, thetas)]
            rows = []
            for m, (p, t) in enumerate(zip(self.p, thetas)):  # member m against the rest, then the others
                others = Basis.concat([self.rest] + fs[:m] + fs[m + 1:])
                rows.append(st.rep.row_gradient(fs[m], *p.directions(t), others))
        except PreboError:
            return self.worse, np.zeros_like(theta)
        if not all(st.rep.plausible({"S": r["S"][:1, :nr]}, d[:1], self.S_rest)[0] for r, d in rows):
            return self.worse, np.zeros_like(theta)
        # member m's rows (the values, then the derivatives) against the rest, then the others, and its diagonal
        full, diag = [Matrices.of(r) for r, _ in rows], [Matrices.columns(d) for _, d in rows]
        H, S, H_nn, S_nn = [x.H for x in full], [x.S for x in full], [d.H for d in diag], [d.S for d in diag]
        h = np.array([x[0, :nr] for x in H])
        s = np.array([x[0, :nr] for x in S])
        others = [[o for o in range(k) if o != m] for m in range(k)]  # column nr + c of member m is others[m][c]

        def block(M: list, M_nn: list) -> np.ndarray:
            """The group's own matrix (k x k) of the members' rows M and diagonals M_nn."""
            B = np.diag([x[0] for x in M_nn])
            for m in range(k):
                for c, o in enumerate(others[m]):
                    if m < o:
                        B[m, o] = B[o, m] = M[m][0, nr + c]
            return B

        sources = None if st.b is None else [r["b"] for r, _ in rows]  # member m's source and its derivatives
        total, levels = st.objective.with_block(self.E, self.C, h, s, block(H, H_nn), block(S, S_nn), st.min_norm,
                                                near=st.eig.energies,
                                                b=st.sources(sources and np.array([b[0] for b in sources]), self.keep))
        if not np.isfinite(total):
            return self.worse, np.zeros_like(theta)
        grad = 0.0
        for level in levels:  # Σ_levels w ∂e/∂θ (eigen module docstring, block update)
            e, beta = level.e, level.beta
            c_rest, g_level = self.C @ level.a, []
            for m in range(k):
                dX = H[m][1:] - e * S[m][1:]
                g = 2.0 * beta[m] * (dX[:, :nr] @ c_rest + dX[:, nr:] @ beta[others[m]])
                if sources is not None:  # a response functional's 2 zᵀ∂b (response.py)
                    g = g + 2.0 * beta[m] * sources[m][1:]
                g_level.append((g + beta[m] ** 2 * (H_nn[m][1:] - e * S_nn[m][1:])) / level.norm2)
            grad = grad + level.weight * np.concatenate(g_level)
        if not np.all(np.isfinite(grad)):
            return self.worse, np.zeros_like(theta)
        if total < self.best_E:
            self.best_E, self.best_f = total, fs
        return total, grad


def partners(expansion, i: int, count: int) -> list[int]:
    """The `count` functions with the largest normalised overlap |S_ij| / (S_ii S_jj)^½ with
    function i (a function of the basis alone)."""
    S = expansion.m.S
    overlap = np.abs(S[i]) / np.sqrt(S[i, i] * np.diag(S))
    overlap[i] = -1.0
    return [int(j) for j in np.argsort(-overlap, kind="stable")[:count]]


def refine_group(expansion, i: int, size: int, max_evaluations: int = 200, method: str = "gradient") -> bool:
    """Refine function i together with its `size` - 1 `partners` (module docstring) by L-BFGS with
    exact gradients, with at most `max_evaluations` energies; True if the energy fell beyond its
    uncertainty (Expansion.put_group). A group of one is `refine_function` by `method`. A group
    the linear-dependence guard refuses where it stands (Expansion.independence below min_norm:
    39 % of the groups of three of an optimised He basis of 700 functions) is not refined: its
    objective would refuse every θ but after the O(N_b^3) solve of the basis without it."""
    single = size == 1 or len(expansion.basis) < 2
    idx = [i] if single else [i] + partners(expansion, i, min(size, len(expansion.basis)) - 1)
    if expansion.independence(idx) < expansion.min_norm:
        return False
    if single:
        return refine_function(expansion, i, max_evaluations, method)
    obj = GroupEnergy(expansion, idx)
    lbfgs(obj.energy_and_gradient, obj.theta(), max_evaluations)
    if obj.best_f is None or not expansion.gains(obj.best_E):
        return False
    return expansion.put_group(obj.idx, obj.best_f)


def lbfgs(energy_and_gradient, theta0: np.ndarray, max_evaluations: int) -> None:
    """L-BFGS from θ0 on an objective returning (E, ∂E/∂θ), at most `max_evaluations` energies."""
    minimize(energy_and_gradient, theta0, jac=True, method="L-BFGS-B",
             options={"maxfun": max_evaluations, "maxiter": max_evaluations, "ftol": 1e-16, "gtol": 1e-12,
                      "maxcor": 20})


def minimise(obj: FunctionEnergy, max_evaluations: int, method: str) -> None:
    """Powell's method, or L-BFGS with exact gradients, from the objective's function, with at
    most `max_evaluations` energies; the best function seen is kept in the objective."""
    theta0 = obj.p.theta()
    if method == "gradient":
        lbfgs(obj.energy_and_gradient, theta0, max_evaluations)
    else:
        minimize(obj.energy, theta0, method="Powell",
                 options={"maxfev": max_evaluations, "xtol": 1e-4, "ftol": 1e-14, "direc": 0.1 * np.eye(len(theta0))})


def accept(expansion, i: int, obj: FunctionEnergy) -> bool:
    """Put the objective's best function in slot i if it lowers the energy beyond its numerical
    uncertainty (Expansion.put); True if it did."""
    if obj.best_f is None or not expansion.gains(obj.best_E):
        return False
    rows, diag = expansion.rep.rows(obj.best_f, expansion.basis, i)  # oriented: patched matrices equal a rebuild
    return expansion.put(i, obj.best_f, {k: v[0] for k, v in rows.items()}, diag[0])


def refine_function(expansion, i: int, max_evaluations: int = 200, method: str = "gradient", rest=None) -> bool:
    """Minimise the energy over the parameters of function i — Powell, or L-BFGS with exact
    gradients — with at most `max_evaluations` energies; True if it improved. `rest`: the
    eigen-solution of the basis without i (Expansion.without), if already at hand."""
    obj = FunctionEnergy(expansion, i, rest)
    minimise(obj, max_evaluations, method)
    return accept(expansion, i, obj)


def regenerate_function(expansion, i: int, f: Basis, max_evaluations: int = 200, method: str = "gradient",
                        rest=None) -> bool:
    """A replacement sweep's step with refinement: `f` (the competitive winner for position i) is
    refined in slot i and takes it if it then lowers the energy; otherwise function i is refined.
    A refined newcomer can leave the basin the incumbent's refinement is confined to. True if it
    improved. Both refinements share `rest`, the eigen-solution of the basis without i
    (Expansion.without), and the expansion is changed (and its eigenproblem solved) once at most."""
    rest = expansion.without(i) if rest is None else rest
    return (refine_newcomer(expansion, i, f, max_evaluations, method, rest)
            or refine_function(expansion, i, max_evaluations, method, rest))


def refine_newcomer(expansion, i: int, f: Basis, max_evaluations: int = 200, method: str = "gradient",
                    rest=None) -> bool:
    """Refine `f` in slot i against the basis without function i (`rest`: its eigen-solution, if
    already at hand) — for i = N_b, against the whole basis — and put it there if it then lowers
    the energy beyond the uncertainty; True if it did. A grown function is refined
    before it joins, so the basis is changed and solved once per step."""
    newcomer = FunctionEnergy(expansion, i, rest, f)
    if not np.isfinite(newcomer.best_E):  # outside the valid region or linearly dependent
        return False
    minimise(newcomer, max_evaluations, method)
    return accept(expansion, i, newcomer)
