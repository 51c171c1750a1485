"""The objective: the quantity the optimisation methods lower, and the levels it belongs to.

`Objective` is the interface: what the driver, the expansion and the methods ask of it — its
value from an eigen-solution of the basis's matrices (`solve`, `holds`, `value`, `uncertainty`,
`levels`, `vector(s)`), its value with functions added or removed without a new solve
(`with_added`, `with_added_gradient`, `with_added_many`, `with_block`, `without_each`: the
secular-equation updates of the eigen module), its update after a change of the basis
(`follow`, `to`: the root indices it stands at, `roots`) and what a run reports and stores
(`lowest`: nothing to follow, the checkpoint's "levels" and "followed" absent). `Levels` is one
implementation; another, a response functional, Hylleraas' J[ψ₁] of a first-order function
(response.Hylleraas), implements the same methods and runs through the same driver
(driver.optimise). Its functional also reads each function's source term ⟨φ_j|V|ψ₀⟩, which a
driven representation adds to the rows (response.Driven, the key "b"): every method takes them as
`b` (the basis's for a solution; the basis's and the added functions' for an update), and `Levels`,
whose roots need none, takes None.

`Levels` is the weighted sum Σ_k w_k E_k of the targeted roots k of H c = E S c — the lowest root E_0
alone by default — each an upper bound to the exact level k of the symmetry the basis is
projected on (Hylleraas–Undheim–MacDonald: J. K. L. MacDonald, Phys. Rev. 43, 830 (1933)), so
the sum of positive weights is an upper bound to the same sum of exact levels. Everything that
reads the roots goes through `Levels`: the solve that refines them (eigen.solve), the
secular-equation updates for added or removed functions and their gradients (eigen module
docstring), each evaluated per targeted root and summed with its weight.

Following (`Levels.follow`): after a change of the basis, each targeted level is the root whose
eigenvector overlaps most with the level's eigenvector before the change, so an avoided crossing
or a new low root (a level the basis did not hold before) does not silently swap the target: the
level keeps its identity and moves to another root index, and the run says so (driver.py). A
level never moves below the index it targets: root r of the basis is an upper bound to the exact
level r, so E_r' with r' ≥ r is one too, while a level followed down to r' < r could fall below
its exact level (a fake gain the variational principle forbids; He's 2¹S followed down to the
ground state's root did). Only a bound level is followed, one below the lowest dissociation
threshold: above it a root is a discretised continuum state whose identity means nothing (He's
root 1 in the first functions of a run, followed up, locked growth at two functions). By
interlacing, adding, replacing or removing one function never moves a level up and lowers it
(E'_{r+1} ≥ E_r), so following there could only refuse the change by which growth brings a
missing lower level in (H's root 1 stalled at three functions): levels are followed through
changes of several functions at once (group refinements, joint steps, momentum moves;
optimise/expansion.py), which can gain while a new root comes in below a level. A
basis too small to hold every targeted root has no objective (inf): growth then adds functions
by the sum over the targeted roots the grown basis holds (`with_added_many`).
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass

import numpy as np

from .. import eigen
from ..matrices import Matrices


#: the smallest squared overlap with a root by which a level is followed to it (`Levels.follow`)
FOLLOW = 0.5


@dataclass(frozen=True, slots=True)
class Level:
    """One targeted level of an eigen-solution: its `weight`, `root` index, energy `E` (Eh) and
    S-normalised eigenvector `c`."""

    weight: float
    root: int
    E: float
    c: np.ndarray


@dataclass(frozen=True, slots=True)
class Followed:
    """A re-assignment of the targeted levels by following (module docstring): their root indices
    `before` and `after` it, and the run's `seconds` at it (None until the driver records it);
    stored as [seconds, roots before, roots after] (`row`, `of`)."""

    before: tuple
    after: tuple
    seconds: float | None = None

    def row(self) -> list:
        """The row of a checkpoint's or a result's "followed"."""
        return [self.seconds, list(self.before), list(self.after)]

    @classmethod
    def of(cls, row: list) -> Followed:
        """The re-assignment of a stored row (`row`)."""
        seconds, before, after = row
        return cls(tuple(before), tuple(after), seconds)


@dataclass(frozen=True, slots=True)
class BlockLevel:
    """One level of an objective with a block of functions added (`with_block`): its `weight`,
    energy `e` (Eh) and eigenvector (C `a`, `beta`) in the basis and the block, of squared norm
    `norm2` = c^T S c."""

    weight: float
    e: float
    a: np.ndarray
    beta: np.ndarray
    norm2: float


class Objective(ABC):
    """What the driver, the expansion and the methods ask of an objective (module docstring). (E,
    C): the eigenvalues and S-orthonormal eigenvectors of the basis functions are added to or
    removed from; h, s: the new functions' rows, h_nn, s_nn their diagonals (H = T_ti + V); b:
    the source terms (module docstring), None for `Levels`."""

    #: the root indices the objective stands at (the checkpoint's "levels")
    roots: tuple
    #: the objective's symbol on the progress line
    symbol: str

    @property
    @abstractmethod
    def lowest(self) -> bool:
        """Whether the objective is the lowest root alone: nothing to follow or to store beside it."""

    @property
    @abstractmethod
    def recorded(self) -> bool:
        """Whether a checkpoint, lowest.json and the convergence report record the objective's value
        ("objective") beside the lowest root's energy."""

    @abstractmethod
    def to(self, roots: tuple) -> Objective:
        """The objective standing at the root indices `roots`."""

    @abstractmethod
    def solve(self, H: np.ndarray, S: np.ndarray, threshold: float) -> eigen.Eigen:
        """The eigen-solution of (H, S) the objective needs."""

    @abstractmethod
    def holds(self, eig: eigen.Eigen) -> bool:
        """Whether the eigen-solution holds what the objective needs (else its value is inf)."""

    @abstractmethod
    def levels(self, eig: eigen.Eigen, b=None) -> list[Level]:
        """The levels the objective is made of, as the solution holds them (reported, checked sound)."""

    @abstractmethod
    def value(self, eig: eigen.Eigen, b=None) -> float:
        """The objective (Eh) of an eigen-solution; inf where it does not hold it."""

    @abstractmethod
    def vector(self, eig: eigen.Eigen, b=None) -> np.ndarray:
        """The coefficients a basis stores (S-normalised)."""

    @abstractmethod
    def vectors(self, eig: eigen.Eigen, b=None) -> np.ndarray:
        """The eigenvectors of every level (nb x levels), in the order of `roots`."""

    @abstractmethod
    def uncertainty(self, eig: eigen.Eigen, m: Matrices, b=None) -> float:
        """The objective's numerical uncertainty (Eh) for the basis's matrices `m`."""

    @abstractmethod
    def with_added(self, E, C, h, s, h_nn, s_nn, min_norm: float, b=None) -> float:
        """The objective with one function added."""

    @abstractmethod
    def with_added_gradient(self, E, C, h, s, h_nn, s_nn, dh, ds, dh_nn, ds_nn, min_norm: float, b=None):
        """`with_added` and its gradient along the function's parameters (rows dh, ds, dh_nn, ds_nn)."""

    @abstractmethod
    def with_added_many(self, E, C, H, S, h_nn, s_nn, min_norm: float, b=None) -> np.ndarray:
        """`with_added` for each of many functions."""

    @abstractmethod
    def with_block(self, E, C, h, s, H_ff, S_ff, min_norm: float,
                   near: np.ndarray | None = None, b=None) -> tuple[float, list[BlockLevel]]:
        """The objective with a block of functions added, and its levels for the gradient."""

    @abstractmethod
    def without_each(self, E: np.ndarray, C: np.ndarray, b=None) -> np.ndarray:
        """The objective without each function in turn."""

    @abstractmethod
    def follow(self, before: tuple, S: np.ndarray, eig: eigen.Eigen) -> tuple:
        """The root indices the objective stands at after a change of the basis (`before`: its
        vectors before it, in the changed basis's functions, and their energies)."""


class Levels(Objective):
    """The weighted sum of the `targets` (root indices, ascending; default the lowest) with
    `weights` (positive; default 1 each), the levels standing at the root indices `roots` (default
    the targets; each at or above its target) and followed while below `threshold` (Eh, the lowest
    dissociation threshold; module docstring). (E, C): the eigenvalues and S-orthonormal
    eigenvectors of the basis a function or a block is added to."""

    symbol = "E"

    def __init__(self, targets: tuple = (0,), weights: tuple | None = None, roots: tuple | None = None,
                 threshold: float = -np.inf):
        self.targets = tuple(int(r) for r in targets)
        self.roots = self.targets if roots is None else tuple(int(r) for r in roots)
        self.weights = tuple(float(w) for w in weights) if weights is not None else (1.0,) * len(self.roots)
        self.threshold = threshold

    @property
    def lowest(self) -> bool:
        """Whether the objective is the lowest root alone (nothing to follow)."""
        return self.targets == (0,)

    @property
    def recorded(self) -> bool:
        """Whether the objective is more than the lowest root."""
        return not self.lowest

    def to(self, roots: tuple) -> Levels:
        """The objective with the levels at the root indices `roots`."""
        return Levels(self.targets, self.weights, roots, self.threshold)

    def solve(self, H: np.ndarray, S: np.ndarray, threshold: float) -> eigen.Eigen:
        """The eigen-solution of the pencil (H, S), its roots up to the highest targeted one refined
        (eigen.solve; as many as the basis has functions, if it has fewer)."""
        return eigen.solve(H, S, threshold, min(max(self.roots) + 1, len(S)))

    def holds(self, eig: eigen.Eigen) -> bool:
        """Whether the eigen-solution holds every targeted root."""
        return eig.kept > max(self.roots)

    def levels(self, eig: eigen.Eigen, b=None) -> list[Level]:
        """The targeted levels the eigen-solution holds."""
        return [Level(w, r, float(eig.energies[r]), eig.vectors[:, r])
                for r, w in zip(self.roots, self.weights) if r < eig.kept]

    def value(self, eig: eigen.Eigen, b=None) -> float:
        """Σ w_k E_k (hartree) of an eigen-solution; inf if it does not hold every targeted root."""
        if not self.holds(eig):
            return np.inf
        return sum(lv.weight * lv.E for lv in self.levels(eig))

    def vector(self, eig: eigen.Eigen, b=None) -> np.ndarray:
        """The eigenvector of the first targeted level, S-normalised (the coefficients a basis
        stores; while the basis holds fewer roots, its highest)."""
        return eig.vectors[:, min(self.roots[0], eig.kept - 1)]

    def vectors(self, eig: eigen.Eigen, b=None) -> np.ndarray:
        """The eigenvectors of every targeted level (nb x levels, in the order of the targets; each
        as `vector`), S-normalised."""
        return eig.vectors[:, [min(r, eig.kept - 1) for r in self.roots]]

    def uncertainty(self, eig: eigen.Eigen, m: Matrices, b=None) -> float:
        """Σ w_k σ_k (hartree): the levels' first-order uncertainties (eigen.energy_uncertainty) for
        the matrices `m`, added as if fully correlated (an upper bound); inf where first order
        fails (eigen.FIRST_ORDER)."""
        if not eigen.first_order(eig):
            return np.inf
        return sum(lv.weight * eigen.energy_uncertainty(lv.c, lv.E, m.S, m.T_ti, m.V) for lv in self.levels(eig))

    def held(self, n: int) -> list[tuple[int, float]]:
        """The (root, weight) of the targeted levels a basis of `n` directions holds."""
        return [(r, w) for r, w in zip(self.roots, self.weights) if r < n]

    def with_added(self, E, C, h, s, h_nn, s_nn, min_norm: float, b=None) -> float:
        """The objective with one function of rows h, s and diagonal h_nn, s_nn added
        (eigen.roots_with_added; the roots the grown basis holds, module docstring)."""
        held = self.held(len(E) + 1)
        e = eigen.roots_with_added(E, C, h, s, h_nn, s_nn, min_norm, [r for r, _ in held])
        return float(sum(w * e_r for (_, w), e_r in zip(held, e)))

    def with_added_gradient(self, E, C, h, s, h_nn, s_nn, dh, ds, dh_nn, ds_nn, min_norm: float, b=None):
        """`with_added` and its gradient along the function's parameters (eigen.roots_with_added_gradient)."""
        held = self.held(len(E) + 1)
        e, g = eigen.roots_with_added_gradient(E, C, h, s, h_nn, s_nn, dh, ds, dh_nn, ds_nn, min_norm,
                                               [r for r, _ in held])
        e_sum, g_sum = 0.0, 0.0
        for (_, w), e_r, g_r in zip(held, e, g):
            e_sum, g_sum = e_sum + w * e_r, g_sum + w * g_r
        return float(e_sum), g_sum

    def with_added_many(self, E, C, H, S, h_nn, s_nn, min_norm: float, b=None) -> np.ndarray:
        """`with_added` for each of many functions, rows H, S (eigen.roots_with_added_many): the sum
        over the targeted roots the grown basis holds (module docstring)."""
        held = self.held(len(E) + 1)
        e = eigen.roots_with_added_many(E, C, H, S, h_nn, s_nn, min_norm, [r for r, _ in held])
        total = np.zeros(len(H))
        for (_, w), e_r in zip(held, e.T):
            total += w * e_r
        return total

    def with_block(self, E, C, h, s, H_ff, S_ff, min_norm: float,
                   near: np.ndarray | None = None, b=None) -> tuple[float, list[BlockLevel]]:
        """The objective with a block of functions added (eigen.roots_with_block), and each level
        (BlockLevel: its eigenvector (C a, β)); (inf, []) where a root is not lowered or the block
        is linearly dependent. `near`: the eigenvalues before the block changed, where each root's
        search starts."""
        held = self.held(len(E) + len(H_ff))
        starts = [near[r] if near is not None and r < len(near) else None for r, _ in held]
        found = eigen.roots_with_block(E, C, h, s, H_ff, S_ff, min_norm, starts, [r for r, _ in held])
        total, parts = 0.0, []
        for (_, w), (e, a, beta, norm2) in zip(held, found):
            if not np.isfinite(e):
                return np.inf, []
            total, parts = total + w * e, parts + [BlockLevel(w, e, a, beta, norm2)]
        return total, parts

    def without_each(self, E: np.ndarray, C: np.ndarray, b=None) -> np.ndarray:
        """The objective without each function in turn (eigen.root_without_each per root)."""
        return sum(w * eigen.root_without_each(E, C, r) for r, w in zip(self.roots, self.weights))

    def follow(self, before: tuple, S: np.ndarray, eig: eigen.Eigen) -> tuple:
        """The root indices of the targeted levels after a change (module docstring): `before`,
        their eigenvectors before it (nb x levels), in the changed basis's functions (zero for a
        function that is new), and their energies (Eh); a level that was bound goes to the root at
        or above its target of largest squared overlap if that exceeds FOLLOW and no two levels go
        to one root; otherwise the indices are kept."""
        vectors, energies = before
        SC = S @ eig.vectors
        norms = np.sqrt(np.maximum(np.einsum("il,ij,jl->l", vectors, S, vectors), 1e-300))
        overlap = ((vectors.T @ SC) / norms[:, None]) ** 2
        roots = tuple(t + int(np.argmax(o[t:])) if e < self.threshold else r
                      for o, t, r, e in zip(overlap, self.targets, self.roots, energies))
        if len(set(roots)) < len(roots) or any(o[r] <= FOLLOW for o, r in zip(overlap, roots)):
            return self.roots
        return roots
