"""The response objective: Hylleraas' functional of a first-order function, optimised like a level.

A perturbation V (the dipole's component d_z) mixes the level ψ₀ (energy E₀) of one symmetry with
the functions of another; the first-order function ψ₁ solves (H − E₀ − ω) ψ₁ = −V ψ₀ and minimises

    J[ψ₁] = ⟨ψ₁|H − E₀ − ω|ψ₁⟩ + 2⟨ψ₁|V|ψ₀⟩,          J ≥ J_exact = −⟨ψ₀|V (H − E₀ − ω)⁻¹ V|ψ₀⟩,

(E. A. Hylleraas, Z. Phys. 65, 209 (1930)) below the first pole, where H − E₀ − ω is positive on
the other symmetry: the functional is an upper bound to its exact minimum as the energy is to a
level, so the optimiser's methods lower it with the same steps (objective.Objective). In a basis
of matrices H, S and source terms b_j = ⟨φ_j|V|ψ₀⟩, with G = H − (E₀ + ω)S, the minimiser is
z = −G⁻¹b and J = −bᵀG⁻¹b; through the basis's pseudostates (E_k, S-orthonormal C; y = Cᵀb,
δ_k = E_k − E₀ − ω > 0) J = −Σ_k y_k²/δ_k over the directions the overlap resolves. For the
dipole of a level of N = 0, J = −α(ω)/2-type: J_exact(0) = −α/2 (level/response.py).

Updates, as the eigen module's for levels (the Schur complement of G):
- one function added, rows g = h − (E₀+ω)s, diagonal g_nn, source b_n: with p = Cᵀg,
  J' = J − ν²/μ, ν = b_n − p·(y/δ), μ = g_nn − p·(p/δ) (μ > 0: G stays positive); its gradient
  along the function's parameters dJ' = −2ν dν/μ + ν² dμ/μ², dν = db_n − (Cᵀdg)·(y/δ),
  dμ = dg_nn − 2(Cᵀdg)·(p/δ);
- k functions (rows of G P = g C, block G_ff, sources b_f): J' = J − νᵀM⁻¹ν, ν = b_f − P(y/δ),
  M = G_ff − P diag(1/δ) Pᵀ; the minimiser is β = −M⁻¹ν on the new functions and a = −(y + Pᵀβ)/δ
  on the pseudostates, and at a minimiser dJ = zᵀ dG z + 2 zᵀ db (refine.GroupEnergy);
- function i removed: J_{−i} = J + z_i²/(G⁻¹)_ii (the minimum with z_i held at 0).
Its numerical uncertainty is first-order like the energy's (eigen.energy_uncertainty): δJ =
zᵀ δG z + 2 zᵀ δb at the minimiser.

The source terms come with the rows: `Driven`, the representation of the basis with the level
ψ₀ = Σ c_I φ_I of its `Source`, adds each function's b ("b") to the rows, matrices and row
gradients it returns (Representation.between, between_gradient).
"""
from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from .. import eigen
from ..basis import Basis
from ..errors import BasisFileError, InputError, UnsupportedError
from ..integrals import Representation
from ..level.response import MOMENTUM
from ..matrices import Matrices
from .objective import BlockLevel, Level, Objective

#: the operators a response objective can be driven by (level/response.py `MOMENTUM`: the dipole d and
#: its velocity form ∇_w', the current J' = −i∇_w' of the Bethe logarithm, whose f(k) =
#: ⟨J'(H − E₀ + k)⁻¹J'⟩ is −3 J at ω = −k; level/bethe.py): whether their vector is momentum-like, and
#: the factor of the reduced element that gives the source of the component along z,
#: ⟨φ_J M=0|O_z|ψ₀⟩ = ⟨φ_J‖O‖ψ₀⟩/√3 for ψ₀ of N = 0 (Edmonds; level/transitions.py)
OPERATORS = {name: (momentum, 1.0 / np.sqrt(3.0)) for name, momentum in MOMENTUM.items()}


def contract(M: np.ndarray, c: np.ndarray) -> np.ndarray:
    """M c, each row summed alone along its contiguous copy: the same bits for a row whatever rows
    come with it (BLAS's M @ c blocks by the shape, so a trial's source term would depend on its
    batch, and a resumed run would leave the whole run's trajectory)."""
    return (np.ascontiguousarray(M) * c).sum(axis=1)


@dataclass(frozen=True)
class Source:
    """The level a perturbation acts on: the basis `ground` of its symmetry, its S-normalised
    coefficients `c0` and energy `E0` (Eh) as the level `root` of the basis solved with the overlap
    `threshold`, the `operator` (OPERATORS) with its laboratory-frame vector `w` (n,), and the
    frequency `omega` (Eh) of the first-order equation."""

    ground: Basis
    c0: np.ndarray
    E0: float
    operator: str
    w: np.ndarray
    omega: float = 0.0

    root: int = 0
    threshold: float = eigen.THRESHOLD

    @classmethod
    def of(cls, ground: Basis, operator: str = "dipole", root: int = 0, omega: float = 0.0,
           threshold: float = eigen.THRESHOLD) -> Source:
        """The source of the level `root` of the basis `ground` (its coefficients and energy
        solved with the overlap `threshold`, as prebo.evaluate does) for `operator` at `omega`.
        InputError for an operator that is not in OPERATORS, a ground basis not of N = 0, ω not a
        finite number; UnsupportedError for floating ECGs."""
        from ..level.evaluate import evaluate
        from ..level.transitions import dipole_vectors

        if operator not in OPERATORS:
            raise InputError(f"response: operator = {operator!r}: must be one of {sorted(OPERATORS)}")
        if not isinstance(ground, Basis) or len(ground) == 0:
            raise InputError(f"response: ground = {ground!r}: must be a non-empty prebo.Basis")
        if ground.N != 0:
            raise UnsupportedError(f"response of a level of N = {ground.N}: derived for N = 0 only")
        if isinstance(omega, bool) or not isinstance(omega, (int, float)) or not np.isfinite(omega):
            raise InputError(f"response: omega = {omega!r}: must be a finite frequency (Eh)")
        level = evaluate(ground, threshold=threshold, roots=root + 1, targets=[root])
        w = dipole_vectors(ground.system)[OPERATORS[operator][0]]
        return cls(ground, level["vectors"][:, 0], float(level["energy"]), operator, w, float(omega), root,
                   float(threshold))

    def check(self, system) -> None:
        """InputError unless `system` (a run's) is of the ground's particles and of the symmetry its
        operator reaches from the level: N = 1 and the other parity for the dipole of N = 0."""
        from ..level.transitions import forbidden, multipole, same_particles

        same_particles(self.ground.system, system)
        reached = Basis.empty(system, "ecg-gvr" if system.state.N else "pecg")
        why = forbidden(self.ground, reached) or (
            None if multipole(self.ground, reached) == "dipole" and system.state.N == 1 else
            f"the dipole joins the ground's N = {self.ground.N} to N = 1 of the other parity")
        if why is not None:
            raise InputError(f"response: the run's symmetry (N = {system.state.N}, parity {system.state.parity:+d}) "
                             f"cannot hold the dipole's first-order function of the ground level ({why})")

    def to_dict(self) -> dict:
        """The checkpoint's "response" block: the operator, frequency, root, threshold and ground
        basis (`of` rebuilds the source from it, the same bits)."""
        return {"operator": self.operator, "omega": self.omega, "root": self.root, "threshold": self.threshold,
                "ground": self.ground.to_dict()}

    @classmethod
    def from_dict(cls, d: dict, where: str) -> Source:
        """The source of a checkpoint's "response" block (`to_dict`); BasisFileError naming `where`."""
        try:
            ground = Basis.from_dict(d["ground"], f"{where}: response.ground")
            return cls.of(ground, d["operator"], d["root"], d["omega"], d["threshold"])
        except (KeyError, TypeError) as exc:
            raise BasisFileError(f"{where}: malformed response block ({exc})") from exc
        except (InputError, UnsupportedError) as exc:
            raise BasisFileError(f"{where}: response: {exc}") from exc

    def terms(self, rep: Representation, f: Basis) -> np.ndarray:
        """b_j = ⟨φ_j|V|ψ₀⟩ of the functions of `f` (normalised, symmetrised as `rep`'s)."""
        momentum, factor = OPERATORS[self.operator]
        return contract(rep.between(self.operator, self.ground, f, self.w[None], momentum)[0].T, self.c0) * factor

    def gradient(self, rep: Representation, f: Basis, dA: np.ndarray, dv: np.ndarray | None) -> np.ndarray:
        """b of the one-function basis `f` and its derivatives along the directions (dA, dv) of
        its parameters (Representation.row_gradient's): (1 + P,)."""
        momentum, factor = OPERATORS[self.operator]
        g = rep.between_gradient(self.operator, self.ground, f, dA, dv, self.w[None], momentum)[0]  # (1 + P, n0)
        return contract(g, self.c0) * factor


@dataclass(frozen=True)
class Driven(Representation):
    """A representation whose rows, matrices and row gradients carry each function's source term
    ⟨φ_j|V|ψ₀⟩ of `source` under the key "b" (module docstring)."""

    source: Source | None = None

    def matrices(self, f) -> dict:
        """Representation.matrices and the functions' sources "b" (nb,)."""
        return super().matrices(f) | {"b": self.source.terms(self, f)}

    def rows(self, trials, f, position: int | None = None) -> tuple[dict, np.ndarray]:
        """Representation.rows and the trials' sources "b" (k,)."""
        rows, diag = super().rows(trials, f, position)
        return rows | {"b": self.source.terms(self, trials)}, diag

    def row_gradient(self, f, dA: np.ndarray, dv: np.ndarray | None, basis) -> tuple[dict, np.ndarray]:
        """Representation.row_gradient and the function's source with its derivatives "b" (1 + P,)."""
        rows, diag = super().row_gradient(f, dA, dv, basis)
        return rows | {"b": self.source.gradient(self, f, dA, dv)}, diag


def driven(rep: Representation, source: Source) -> Driven:
    """The representation `rep` with the source terms of `source` (`Driven`)."""
    return Driven(**{f.name: getattr(rep, f.name) for f in fields(rep)}, source=source)  # its engines shared


class Hylleraas(Objective):
    """J[ψ₁] of the first-order equation with the level at `E0` (Eh) and frequency `omega` (module
    docstring). Its methods take the sources `b` where Levels takes none: the basis's (nb,) for a
    solution, (b of the basis the functions are added to, b of the added functions) for an
    update; with a gradient, the added function's b is (1 + P,), the value then its derivatives."""

    roots, symbol = (0,), "J"

    def __init__(self, E0: float, omega: float = 0.0):
        self.E0, self.omega = float(E0), float(omega)
        self.shift = self.E0 + self.omega

    @property
    def lowest(self) -> bool:
        """Nothing to follow: the functional has one minimiser."""
        return True

    @property
    def recorded(self) -> bool:
        """The functional is not the lowest root's energy: recorded beside it."""
        return True

    def to(self, roots: tuple) -> Hylleraas:
        """The objective itself (it has no roots to stand at)."""
        return self

    def solve(self, H: np.ndarray, S: np.ndarray, threshold: float) -> eigen.Eigen:
        """Every pseudostate of the pencil (H, S), the lowest refined (eigen.solve)."""
        return eigen.solve(H, S, threshold, 1)

    def holds(self, eig: eigen.Eigen) -> bool:
        """Whether every pseudostate lies above E₀ + ω (else the functional has no minimum)."""
        return eig.kept > 0 and eig.energies[0] > self.shift

    def minimiser(self, eig: eigen.Eigen, b: np.ndarray) -> np.ndarray:
        """z = −G⁻¹b over the resolved directions."""
        return -eig.vectors @ ((eig.vectors.T @ b) / (eig.energies - self.shift))

    def levels(self, eig: eigen.Eigen, b=None) -> list[Level]:
        """The first-order function as one 'level' at E₀ + ω: Σ w cᵀ(∂H − E ∂S)c is the part of
        the gradient the functional shares with an energy (polish.Joint adds 2 zᵀ∂b)."""
        return [Level(1.0, 0, self.shift, self.minimiser(eig, b))] if self.holds(eig) else []

    def value(self, eig: eigen.Eigen, b=None) -> float:
        """J = −Σ_k y_k²/δ_k (hartree); inf where a pseudostate lies at or below E₀ + ω."""
        if not self.holds(eig):
            return np.inf
        y = eig.vectors.T @ b
        return float(-np.sum(y * y / (eig.energies - self.shift)))

    def vector(self, eig: eigen.Eigen, b=None) -> np.ndarray:
        """The coefficients a basis stores: its lowest pseudostate's (the basis file's energy)."""
        return eig.vectors[:, 0]

    def vectors(self, eig: eigen.Eigen, b=None) -> np.ndarray:
        """The lowest pseudostate's eigenvector (nb x 1)."""
        return eig.vectors[:, :1]

    def uncertainty(self, eig: eigen.Eigen, m: Matrices, b=None) -> float:
        """σ_J from independent relative errors of S, T_ti, V and b (module docstring); inf where
        first order fails (eigen.FIRST_ORDER) or the functional has no minimum."""
        if not (eigen.first_order(eig) and self.holds(eig)):
            return np.inf
        z = self.minimiser(eig, b)
        sigma = eigen.energy_uncertainty(z, self.shift, m.S, m.T_ti, m.V)
        return float(np.hypot(sigma, 2.0 * eigen.ELEMENT_ERROR * np.linalg.norm(z * b)))

    def _rest(self, E, C, b_rest):
        """(y/δ, 1/δ) of the basis the functions are added to; None where it has a pseudostate at
        or below E₀ + ω."""
        delta = np.asarray(E) - self.shift
        if len(E) and delta[0] <= 0:
            return None
        inv = 1.0 / delta
        return (C.T @ b_rest) * inv if len(E) else np.zeros(0), inv

    def with_added(self, E, C, h, s, h_nn, s_nn, min_norm: float, b=None) -> float:
        """J with one function of rows h, s, diagonal h_nn, s_nn and source b = (b_rest, b_n) added."""
        return float(self.with_added_many(E, C, np.atleast_2d(h), np.atleast_2d(s), np.atleast_1d(h_nn),
                                          np.atleast_1d(s_nn), min_norm, (b[0], np.atleast_1d(b[1])))[0])

    def with_added_many(self, E, C, H, S, h_nn, s_nn, min_norm: float, b=None) -> np.ndarray:
        """`with_added` for each of k functions (rows H, S (k x nb), sources b[1] (k,)); inf for a
        function whose part orthogonal to the basis is below `min_norm` of its norm."""
        rest = self._rest(E, C, b[0])
        if rest is None:
            return np.full(len(H), np.inf)
        yd, inv = rest
        J = -float(np.sum((C.T @ b[0]) * yd)) if len(E) else 0.0
        D, P = (S @ C, (H - self.shift * S) @ C) if len(E) else (np.zeros((len(H), 0)),) * 2
        g_nn = h_nn - self.shift * s_nn
        with np.errstate(divide="ignore", invalid="ignore"):
            nu, mu = b[1] - P @ yd, g_nn - (P * P) @ inv
            out = J - nu * nu / mu
            orthogonal = s_nn - np.sum(D * D, axis=1)
        out[~((orthogonal > min_norm * s_nn) & (mu > 0) & np.isfinite(out))] = np.inf
        return out

    def with_added_gradient(self, E, C, h, s, h_nn, s_nn, dh, ds, dh_nn, ds_nn, min_norm: float, b=None):
        """`with_added` and its gradient (module docstring); b = (b_rest, [b_n, ∂b_n/∂θ_p ...])."""
        b_n = np.asarray(b[1])
        J = self.with_added(E, C, h, s, h_nn, s_nn, min_norm, (b[0], b_n[0]))
        if not np.isfinite(J):
            return J, np.zeros(len(dh_nn))
        yd, inv = self._rest(E, C, b[0])
        dg, dg_nn = dh - self.shift * ds, dh_nn - self.shift * ds_nn
        if len(E):
            p, dp = C.T @ (h - self.shift * s), dg @ C
        else:
            p, dp = np.zeros(0), np.zeros((len(dg_nn), 0))
        nu, mu = b_n[0] - p @ yd, (h_nn - self.shift * s_nn) - p @ (p * inv)
        d_nu, d_mu = b_n[1:] - dp @ yd, dg_nn - 2.0 * dp @ (p * inv)
        return J, -2.0 * nu * d_nu / mu + nu * nu * d_mu / mu**2

    def with_block(self, E, C, h, s, H_ff, S_ff, min_norm: float, near=None, b=None):
        """J with k functions added at once (module docstring) and the minimiser as one BlockLevel
        (e = E₀ + ω, c = (C a, β), cᵀSc taken as 1: refine.GroupEnergy's sum is then zᵀ dG z);
        (inf, []) for a block linearly dependent on the basis (its orthogonal part's smallest
        eigenvalue below `min_norm` of its diagonal) or one that leaves G not positive."""
        rest = self._rest(E, C, b[0])
        if rest is None:
            return np.inf, []
        yd, inv = rest
        D, P = (s @ C, (h - self.shift * s) @ C) if len(E) else (np.zeros((len(h), 0)),) * 2
        if not eigen.independent(D, S_ff, min_norm):
            return np.inf, []
        M = (H_ff - self.shift * S_ff) - (P * inv) @ P.T
        nu = np.asarray(b[1]) - P @ yd
        try:
            L = np.linalg.cholesky(M)
        except np.linalg.LinAlgError:
            return np.inf, []
        beta = -np.linalg.solve(L.T, np.linalg.solve(L, nu))
        J = (-float(np.sum((C.T @ b[0]) * yd)) if len(E) else 0.0) + float(nu @ beta)
        a = -(C.T @ b[0] + P.T @ beta) * inv if len(E) else np.zeros(0)
        return J, [BlockLevel(1.0, self.shift, a, beta, 1.0)]

    def without_each(self, E: np.ndarray, C: np.ndarray, b=None) -> np.ndarray:
        """J without each function in turn: J + z_i²/(G⁻¹)_ii (module docstring)."""
        inv = 1.0 / (E - self.shift)
        y = C.T @ b
        z = -C @ (y * inv)
        J = -float(np.sum(y * y * inv))
        return J + z * z / ((C * C) @ inv)

    def follow(self, before: tuple, S: np.ndarray, eig: eigen.Eigen) -> tuple:
        """Nothing to follow."""
        return self.roots
