"""Joint refinement: L-BFGS over the parameters of every function at once, on the exact gradient.

Refinement sweeps move one function at a time; near the optimum, where the functions' parameters
are coupled, that coordinate descent crawls. Here θ = (θ_1, ..., θ_N) (Parametrisation of
each function in its own channel; K fixed) and, with E and c a targeted root and its
S-normalised eigenvector (objective.py; Hellmann–Feynman; the objective's gradient is the
weighted sum over its levels),

    ∂E/∂θ_i = 2 c_i Σ_{j≠i} c_j (∂H_ij − E ∂S_ij) + c_i² (∂H_ii − E ∂S_ii),

where ∂H_ij, ∂S_ij are the derivatives of function i's row (i as bra) and ∂H_ii, ∂S_ii those of
its diagonal — exactly what Representation.row_gradient returns for function i against the basis.
A response functional (response.py) is one 'level' c = z at E = E₀ + ω, plus 2 z_i ∂b_i/∂θ_i
from its source terms.
N such rows give the matrices and the gradient: the cost of ~(1 + W/4) matrix builds per step.
A θ that leaves the valid region (Parametrisation, Representation.plausible) or lets the
overlap matrix's condition number grow beyond max(10 × its start, 1e9) scores worse than the start:
refinement may not buy energy with near-linear dependence, where rounding is amplified.
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import minimize

from ..basis import Basis
from ..errors import PreboError
from ..matrices import Matrices
from .parametrisation import Parametrisation


class Joint:
    """E(θ) and ∂E/∂θ of a whole basis; remembers the best basis seen."""

    def __init__(self, expansion):
        self.expansion = expansion
        basis = expansion.basis
        self.ps = [Parametrisation.of(basis.subset([i])) for i in range(len(basis))]
        thetas = [p.theta() for p in self.ps]
        self.cut = np.cumsum([0] + [len(t) for t in thetas])
        self.theta0 = np.concatenate(thetas)
        self.worse = expansion.energy + 1.0
        self.max_condition = max(10 * expansion.eig.overlap_condition, 1e9)
        self.best_E, self.best = expansion.energy, None

    def basis(self, theta: np.ndarray) -> Basis:
        """The basis of the joint parameter vector θ = (θ_1, ..., θ_N)."""
        return Basis.concat([p.function(theta[a:b]) for p, a, b in zip(self.ps, self.cut[:-1], self.cut[1:])])

    def __call__(self, theta: np.ndarray) -> tuple[float, np.ndarray]:
        st, nb = self.expansion, len(self.ps)
        fail = (self.worse, np.zeros_like(theta))
        try:
            basis = self.basis(theta)
            parts = [st.rep.row_gradient(basis.subset([i]), *p.directions(theta[a:b]), basis)
                     for i, (p, a, b) in enumerate(zip(self.ps, self.cut[:-1], self.cut[1:]))]
        except PreboError:
            return fail
        rows = [Matrices.of(r) for r, _ in parts]  # function i's row (the values, then the derivatives)
        derivatives = [Matrices.columns(d[1:]) for _, d in parts]  # and those of its diagonal
        diag = np.array([d[0] for _, d in parts])  # (nb, 4): the diagonals, matrices.NAMES

        def matrix(name: str) -> np.ndarray:
            """The matrix `name` of the rows and diagonals."""
            M = np.array([getattr(r, name)[0] for r in rows])
            M[np.diag_indices(nb)] = getattr(Matrices.columns(diag), name)
            return 0.5 * (M + M.T)  # i as bra and j as bra agree to rounding

        S, T_ti, V = matrix("S"), matrix("T_ti"), matrix("V")
        b = None if st.b is None else np.array([r["b"][0] for r, _ in parts])  # a response functional's sources
        if not st.rep.plausible({"S": S}, diag, np.diag(S)).all():
            return fail
        try:
            eig = st.objective.solve(T_ti + V, S, st.threshold)
        except PreboError:
            return fail
        if eig.kept < nb or eig.overlap_condition > self.max_condition:
            return fail
        total = st.objective.value(eig, b)
        if not np.isfinite(total):
            return fail
        gradient = 0.0
        for level in st.objective.levels(eig, b):  # Σ_levels w ∂E/∂θ
            E, c, grad = level.E, level.c, []
            for i, (r, d) in enumerate(zip(rows, derivatives)):
                dH, dS = r.T_ti[1:] + r.V[1:], r.S[1:]
                off = (dH - E * dS) @ c - (dH[:, i] - E * dS[:, i]) * c[i]  # Σ_{j≠i}
                g = 2.0 * c[i] * off + c[i] ** 2 * ((d.T_ti + d.V) - E * d.S)
                grad.append(g if b is None else g + 2.0 * c[i] * parts[i][0]["b"][1:])  # and 2 zᵀ∂b
            gradient = gradient + level.weight * np.concatenate(grad)
        if total < self.best_E:
            self.best_E, self.best = total, basis
        return total, gradient


def polish(expansion, iterations: int) -> bool:
    """At most `iterations` L-BFGS iterations over all parameters; the expansion takes the best basis
    seen (rebuilt from scratch, so it is a function of the basis alone). True if it improved."""
    joint = Joint(expansion)
    minimize(joint, joint.theta0, jac=True, method="L-BFGS-B",
             options={"maxiter": iterations, "maxfun": 2 * iterations, "ftol": 1e-16, "gtol": 1e-12, "maxcor": 20})
    if joint.best is None or not expansion.gains(joint.best_E):
        return False
    return expansion.replace_basis(joint.best)
