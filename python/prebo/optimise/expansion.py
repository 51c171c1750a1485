"""`Expansion`: the basis being optimised, with its matrices and the eigen-solution of H c = E S c.

The wave function is expanded in the basis; every method (methods.py) proposes changes to it and
the expansion keeps a change only if it lowers the energy by more than the energy's numerical
uncertainty before and after it (eigen.energy_uncertainty): a gain rounding can fake is refused,
never accepted. The matrices are a function of the basis alone (patched from oriented rows with
the bits of a rebuild, or rebuilt), so a resumed run continues bit for bit. (Named to keep it
apart from prebo.State, the quantum numbers of a system.)
"""
from __future__ import annotations

import copy
from dataclasses import dataclass

import numpy as np

from .. import eigen
from ..basis import Basis
from ..errors import LinearDependenceError
from ..matrices import Matrices
from .objective import Followed, Levels, Objective
from .response import Driven


#: how many times what a change adds to the uncertainty it must gain (`Expansion.keep_if_lower`)
SIGMA_PRICE = 100.0


@dataclass(frozen=True, slots=True)
class Snapshot:
    """The state of an expansion to restore if a change does not pay (Expansion.keep_if_lower):
    its basis, matrices, eigen-solution, energy and uncertainty (Eh), objective and the
    re-assignment `followed` not yet taken."""

    basis: Basis
    m: Matrices
    b: np.ndarray | None
    eig: eigen.Eigen | None
    energy: float
    sigma: float
    objective: Objective
    followed: Followed | None


class Expansion:
    """The basis `basis` with its matrices `m` (matrices.Matrices: S, T, T_ti, V; hartree), eigen-solution `eig`, the
    `energy` (hartree) of the `objective` (objective.py: the lowest root, or a weighted sum of
    targeted levels, or a response functional, response.py, whose functions' source terms `b` a
    driven representation adds to the matrices; None without) and `sigma`, the energy's numerical uncertainty (module docstring; inf beyond
    eigen.FIRST_ORDER, where no change is kept: the optimiser does not take the basis where its
    first-order uncertainty fails). After a change of several functions at once (`put_group`,
    `replace_basis`) the targeted levels are followed by overlap (Levels.follow; one function
    added, replaced or removed never moves a level up and lowers it, objective.py); `followed`
    holds the re-assignment (objective.Followed) of the last change that moved a level to another root,
    until the driver takes it; `drafted`: a `draft`, which places changes without solving.

    rep: the integrals' Representation (integrals.laboratory); threshold: eigen.solve's relative
    overlap eigenvalue below which directions are dropped; min_norm, max_overlap: the
    linear-dependence guard of `candidates` (Optimiser settings of the same names)."""

    def __init__(self, basis: Basis, rep, threshold: float, min_norm: float = 1e-8, max_overlap: float = 0.99,
                 objective: Objective = Levels()):
        self.basis, self.rep, self.threshold = basis, rep, threshold
        self.min_norm, self.max_overlap, self.objective = min_norm, max_overlap, objective
        self.followed, self.drafted = None, False
        self.m, self.b = self.built(basis)
        self.solve()

    def built(self, basis: Basis) -> tuple[Matrices, np.ndarray | None]:
        """The matrices of `basis` and its functions' source terms (None where the representation
        adds none)."""
        if not len(basis):
            return Matrices.empty(), np.zeros(0) if isinstance(self.rep, Driven) else None
        m = self.rep.matrices(basis)
        return Matrices.of(m), m.get("b")

    def sources(self, new, keep: np.ndarray | None = None) -> tuple | None:
        """The source terms of an update (objective.py): those of the basis (its functions `keep`)
        and those `new` of the functions added; None without source terms."""
        if self.b is None:
            return None
        return self.b if keep is None else self.b[keep], new

    def solve(self, before: tuple | None = None) -> None:
        """Solve the eigenproblem of the current matrices (energy inf for no functions); `before`:
        the targeted levels' eigenvectors before a change, in the changed basis's functions, and
        their energies, to follow them (`prior`, Levels.follow)."""
        if len(self.basis) == 0:
            self.eig, self.energy, self.sigma = None, np.inf, 0.0
            return
        H = self.m.H
        self.eig = self.objective.solve(H, self.m.S, self.threshold)
        if before is not None and self.objective.holds(self.eig):
            roots = self.objective.follow(before, self.m.S, self.eig)
            if roots != self.objective.roots:
                self.followed = Followed(self.objective.roots, roots)
                self.objective = self.objective.to(roots)
                self.eig = self.objective.solve(H, self.m.S, self.threshold)
        self.energy = self.objective.value(self.eig, self.b)
        self.sigma = self.objective.uncertainty(self.eig, self.m, self.b)

    @staticmethod
    def prior(eig, objective: Levels, mapping: np.ndarray) -> tuple | None:
        """The eigenvectors (nb x levels) of `objective`'s levels in the solution `eig` before a
        change, in the functions of the changed basis, whose function j was function mapping[j]
        (-1: new), and their energies, to follow them (`solve`); None where there is nothing to
        follow (the lowest root alone, or a basis not holding every level)."""
        if objective.lowest or eig is None or not objective.holds(eig):
            return None
        V = eig.vectors[:, list(objective.roots)]
        out = np.zeros((len(mapping), V.shape[1]))
        out[mapping >= 0] = V[mapping[mapping >= 0]]
        return out, eig.energies[list(objective.roots)]

    @property
    def lowest_root(self) -> float | None:
        """The lowest root's energy (Eh), what a basis file's `energy` holds; None before the first
        function. For a run of the lowest level alone it is the objective's `energy`."""
        return float(self.eig.energies[0]) if self.eig is not None and self.eig.kept else None

    @property
    def coefficients(self) -> np.ndarray:
        """The state's coefficients c, S-normalised (the objective's eigenvector)."""
        return self.objective.vector(self.eig, self.b)

    @property
    def vectors(self) -> np.ndarray:
        """The eigenvectors of every targeted level (nb x levels, in the order of the objective's
        `roots`), S-normalised."""
        return self.objective.vectors(self.eig, self.b)

    def sound(self) -> bool:
        """Whether every targeted level's internal kinetic energy c^T T_ti c is positive beyond the
        energy's uncertainty, as that of any wave function is: rounding that dominates an
        ill-conditioned basis's elements (integrals.py, cancellation) can make it negative, and
        its energy then means nothing (two electrons "bound" at -0.13 Eh)."""
        return all(lv.c @ self.m.T_ti @ lv.c > self.sigma for lv in self.objective.levels(self.eig, self.b))

    def gains(self, energy: float) -> bool:
        """Whether `energy` lies below the current energy by more than its uncertainty."""
        return energy < self.energy - self.sigma

    def snapshot(self) -> Snapshot:
        """The state to restore if a change does not pay (`keep_if_lower`)."""
        return Snapshot(self.basis.subset(slice(None)), self.m.map(np.copy), None if self.b is None else self.b.copy(),
                        self.eig, self.energy, self.sigma, self.objective, self.followed)

    def restore(self, before: Snapshot) -> None:
        """Go back to the state `before` (`snapshot`)."""
        self.basis, self.m, self.b, self.eig, self.energy = before.basis, before.m, before.b, before.eig, before.energy
        self.sigma, self.objective, self.followed = before.sigma, before.objective, before.followed

    def keep_if_lower(self, before: Snapshot) -> bool:
        """After a change: keep it if the energy fell by more than the uncertainty before and after
        it and by SIGMA_PRICE times what it added to the uncertainty; otherwise restore the state
        `before` (`snapshot`). True if kept. Every later change must beat the uncertainty: a
        near-duplicate pair with large coefficients that gains 1e-11 Eh but raises σ from 1e-15 to
        1e-11 locks the run (He, 700 functions: 8.5e-12, no change kept for the last 200 s)."""
        gain = before.energy - self.energy
        if self.sound() and (before.energy == np.inf or (gain > max(self.sigma, before.sigma)
                                                         and gain > SIGMA_PRICE * (self.sigma - before.sigma))):
            return True
        self.restore(before)
        return False

    def solve_and_keep_if_lower(self, before: Snapshot, mapping: np.ndarray | None = None) -> bool:
        """Solve after a change and `keep_if_lower`; a change whose lowest root the extended-precision
        refinement cannot resolve (eigen.refine: LinearDependenceError, at an overlap condition
        where double precision runs out) is undone like one that does not gain. `mapping`: function
        j of the changed basis was function mapping[j] before it (-1: new; `prior`), for a change of
        several functions at once, whose levels are followed (objective.py; None: not followed). A
        draft places the change and keeps it unsolved (`draft`)."""
        if self.drafted:  # the expansion the draft is of puts its change (`draft`)
            return True
        try:
            self.solve(None if mapping is None else self.prior(before.eig, before.objective, mapping))
        except LinearDependenceError:
            self.restore(before)
            return False
        return self.keep_if_lower(before)

    def replace_basis(self, basis: Basis) -> bool:
        """Take a whole new basis (matrices rebuilt) if every function kept the digits of its elements
        (`resolved`) and it lowers the energy beyond the uncertainty."""
        before = self.snapshot()
        self.basis = basis
        self.m, self.b = self.built(basis)
        if not self.resolved():
            self.restore(before)
            return False
        return self.solve_and_keep_if_lower(before, np.arange(len(basis)))  # each function moved a little

    def resolved(self) -> bool:
        """Whether every function's elements kept their digits (Representation.resolved, what
        prebo.evaluate requires): a momentum move, the one change not checked function by function
        (trials, refinements and joint steps are: Representation.plausible), is what could have
        carried a function where the symmetriser nearly annihilates it into a He 2³S run with 150
        functions, whose result was then refused."""
        return bool(self.rep.resolved(self.m.diagonal()).all())

    def without(self, i):
        """The eigen-solution of the basis without function i, or without the functions of the
        list i (None if that leaves nothing)."""
        keep = np.ones(len(self.basis), bool)
        keep[i] = False
        if not keep.any():
            return None
        return self.objective.solve(self.m.H[np.ix_(keep, keep)], self.m.S[np.ix_(keep, keep)], self.threshold)

    def independence(self, idx: list[int]) -> float:
        """The smallest eigenvalue of the part of functions `idx` orthogonal to the others, scaled
        to unit diagonal (the quantity the linear-dependence guards bound): with every direction
        kept, S^-1 = C C^T for the S-orthonormal eigenvectors C, and that part's overlap is the
        inverse of (S^-1)_idx,idx (Schur complement), so it is 1/λ_max(W W^T), W = S_ii^½ C_i,
        i in idx — O(N_b k^2), no solve. NaN when directions were dropped."""
        if self.eig is None or self.eig.kept < len(self.basis):
            return np.nan
        W = self.eig.vectors[idx] * np.sqrt(np.diag(self.m.S)[idx])[:, None]
        return float(1.0 / np.linalg.eigvalsh(W @ W.T)[-1])

    def remove(self, i: int) -> None:
        """Remove function i, whatever that costs (the matrices without its row and column, which
        are the bits of a rebuild: an element depends on its two functions and their order)."""
        keep = np.arange(len(self.basis)) != i
        self.basis = self.basis.subset(np.flatnonzero(keep))
        self.m = self.m.map(lambda M: M[np.ix_(keep, keep)])
        self.b = None if self.b is None else self.b[keep]
        self.solve()

    def virial(self) -> float:
        """|1 + <V>/(2<T_ti>)| of the state: 0 for an exact Coulomb eigenstate (virial theorem)."""
        c = self.coefficients
        return abs(1.0 + (c @ self.m.V @ c) / (2.0 * (c @ self.m.T_ti @ c)))

    def candidates(self, trials: Basis, exclude: int | None = None, eig=None):
        """The energy with each trial added (to the basis without `exclude`, where the trial
        would replace it), with the rows and diagonals for `put`. The linear-dependence guard
        gives +inf to a trial whose normalised overlap with a function exceeds `max_overlap`
        or whose part orthogonal to the basis is below `min_norm` of its norm, and so does a
        trial whose elements fail `Representation.plausible`."""
        position = len(self.basis) if exclude is None else exclude
        rows, diag = self.rep.rows(trials, self.basis, position)
        r, d = Matrices.of(rows), Matrices.columns(diag)
        H, S = r.H, r.S
        keep = np.ones(len(self.basis), bool)
        if exclude is not None:
            keep[exclude] = False
        if eig is None:
            eig = self.eig if exclude is None else self.without(exclude)
        E, C = (eig.energies, eig.vectors) if eig is not None else (np.zeros(0), np.zeros((0, 0)))
        energies = self.objective.with_added_many(E, C, H[:, keep], S[:, keep], d.H, d.S, self.min_norm,
                                                  self.sources(rows.get("b"), keep))
        if keep.any():
            with np.errstate(invalid="ignore", divide="ignore"):  # S_nn ≤ 0: refused as implausible below
                overlap = np.abs(S[:, keep]) / np.sqrt(np.outer(d.S, np.diag(self.m.S)[keep]))
            energies[overlap.max(axis=1) > self.max_overlap] = np.inf
        energies[~self.rep.plausible({"S": S[:, keep]}, diag, np.diag(self.m.S)[keep])] = np.inf
        return energies, rows, diag

    def put(self, i: int, f: Basis, row: dict | None = None, d=None) -> bool:
        """Append (i == len) or replace function i by `f` if that lowers the energy beyond the
        uncertainty (class docstring); True if it did. The matrices are patched from the
        function's oriented row (`Representation.rows` with position i) or else rebuilt, so that
        the state is a function of the basis alone and a resumed run continues bit for bit."""
        before = self.snapshot()
        self._place(i, f, row, d)
        return self.solve_and_keep_if_lower(before)

    def put_group(self, idx: list[int], fs: list[Basis]) -> bool:
        """Replace the functions `idx` by `fs` (one-function bases) at once if that lowers the
        energy beyond the uncertainty; True if it did. Rows are patched one function after the
        other, each against the basis with the ones before it in place (as `put`). The levels are
        followed through a change of several functions (one changed never moves a level up and
        lowers it, objective.py)."""
        before = self.snapshot()
        for i, f in zip(idx, fs):
            rows, diag = self.rep.rows(f, self.basis, i)
            self._place(i, f, {k: v[0] for k, v in rows.items()}, diag[0])
        return self.solve_and_keep_if_lower(before, moved(len(self.basis), idx) if len(idx) > 1 else None)

    def draft(self) -> Expansion:
        """A draft of this expansion for a unit of work whose change the expansion itself puts
        (`changes`, methods.together): a copy, its basis and matrices its own, whose integrals
        this process evaluates by itself, without the other MPI ranks, and which places a change
        without solving (`solve_and_keep_if_lower`: the expansion re-checks it)."""
        twin, snapshot = copy.copy(self), self.snapshot()
        twin.basis, twin.m, twin.b = snapshot.basis, snapshot.m, snapshot.b
        twin.rep, twin.drafted = self.rep.alone(), True
        return twin

    def changes(self, before: Expansion) -> tuple[list[int], list[Basis]] | None:
        """The functions this `draft` of `before` changed and their one-function bases (None: none)."""
        idx = [int(i) for i in self.basis.differs(before.basis)]
        return (idx, [self.basis.subset([i]) for i in idx]) if idx else None

    def _place(self, i: int, f: Basis, row: dict | None, d) -> None:
        """Append (i == len) or replace function i by `f`, the matrices patched from its row and
        diagonal `d` (S, T, T_ti, V), or rebuilt without them or for a family that is not oriented."""
        nb = len(self.basis)
        if i == nb:
            self.basis.append(f)
        else:
            self.basis.replace(i, f)
        if row is None or not self.rep.oriented(self.basis):
            self.m, self.b = self.built(self.basis)
            return
        if self.b is not None:  # a function's source term depends on it alone
            self.b = np.append(self.b, row["b"]) if i == nb else self.b.copy()
            self.b[i] = row["b"]
        rows, values = Matrices.of(row).to_dict(), Matrices.columns(d).to_dict()
        patched = {}
        for k, M in self.m.to_dict().items():
            r = np.array(rows[k], copy=True)
            if i == nb:
                grown = np.zeros((nb + 1, nb + 1))
                grown[:nb, :nb] = M
                grown[nb, :nb] = grown[:nb, nb] = r
                grown[nb, nb] = values[k]
                M = grown
            else:
                r[i] = values[k]
                M[i, :] = r
                M[:, i] = r
            patched[k] = M
        self.m = Matrices.of(patched)


def moved(nb: int, new: list[int]) -> np.ndarray:
    """The mapping of a changed basis of `nb` functions to the basis before it (Expansion.prior):
    the same index, -1 for the functions `new` (replaced or appended)."""
    mapping = np.arange(nb)
    mapping[list(new)] = -1
    return mapping
