"""Momentum over refinement: the basis moved on along its own displacement.

Refinement of groups (refine.py) is coordinate descent. Near the optimum of a large basis it
moves every function a little along a narrow valley, which it crosses slowly; most of the gain of
such a move needs all functions together. So, every EVERY passes at full size that move
functions (the schedule's `due`, schedule.py), the basis is moved on to θ + α d, d = θ − θ_ref over all
functions, θ_ref the basis before the last move (heavy-ball momentum: the moves accumulate), α the
vertex of the parabola through the energies at α = 0, ½, 1 (else the lowest of those), and kept
only if the energy falls (Expansion.replace_basis). A function whose channel or K differs from its reference, or that
moved by MAX_STEP or more in θ (a replacement), stays where it is. H2 with 500 ECG-GVR functions
at 4.3e-8 Eh above the exact energy: 600 group steps with a move after every 200 gained 1.82× as
much as without (benchmarks/record/h2.md, "The fresh run's tail, and momentum over the group
refinements"); at 2.8e-8, a move after every two passes of 50 gained 1.23× as much in 1500 s as
after every four, after every one 0.90× (benchmarks/record/h2.md, "A stale rate, and momentum
every one, two or four passes").
"""
from __future__ import annotations

import numpy as np

from ..basis import Basis
from ..errors import BasisFileError, PreboError
from ..io import basis_json
from .checkpoint import of_this_run
from .expansion import Expansion
from .parametrisation import Parametrisation

#: passes at full size that move functions between two moves (the schedule's `due`)
EVERY = 2
#: a function that moved this far in θ since its reference was replaced: it does not move on
MAX_STEP = 0.5


class Momentum:
    """The reference basis θ_ref of the next move (module docstring), None before the first move;
    renumbered after a pruning (`follow`)."""

    def __init__(self, reference: Basis | None = None):
        self.reference = reference

    def follow(self, basis: Basis, origin: list) -> None:
        """After a pruning that was kept: function k of `basis` was function origin[k] of the basis
        before it, or was grown (None). A survivor keeps its reference, a grown function takes
        itself (no displacement): the next move goes on along the survivors' displacement (with
        the reference dropped instead, the moves on H2 took several rounds to grow back)."""
        if self.reference is not None:
            self.reference = Basis.concat([basis.subset([k]) if j is None else self.reference.subset([j])
                                           for k, j in enumerate(origin)])

    def move(self, expansion) -> bool:
        """Move the expansion's basis on along its displacement since the reference (module
        docstring), which then becomes the basis before the move; True if the energy fell. The
        first move only takes the reference."""
        basis = expansion.basis.subset(slice(None))
        basis.coefficients = None
        reference, self.reference = self.reference, basis
        if reference is None or len(reference) != len(basis):
            return False
        fs, ps, theta, d = [], [], [], []
        for i in range(len(basis)):
            f, f0 = basis.subset([i]), reference.subset([i])
            p = Parametrisation.of(f)
            t = p.theta()
            step = np.zeros_like(t)
            if f.channels == f0.channels and np.array_equal(f.family.powers(f, [0]), f0.family.powers(f0, [0])):
                step = t - Parametrisation.of(f0).theta()
            fs.append(f)
            ps.append(p)
            theta.append(t)
            d.append(step if np.linalg.norm(step) < MAX_STEP else np.zeros_like(t))

        def moved(alpha: float) -> Basis:
            return Basis.concat([p.function(t + alpha * s) if s.any() else f for f, p, t, s in zip(fs, ps, theta, d)])

        def energy(alpha: float) -> float:
            try:
                ex = Expansion(moved(alpha), expansion.rep, expansion.threshold, expansion.min_norm,
                               expansion.max_overlap, expansion.objective)
                return ex.energy if ex.resolved() else np.inf
            except PreboError:
                return np.inf

        E0 = expansion.energy
        E = {0.5: energy(0.5), 1.0: energy(1.0)}
        curvature = 2.0 * (E[1.0] - 2.0 * E[0.5] + E0)
        if np.isfinite(curvature) and curvature > 0:
            vertex = 0.5 - (E[1.0] - E0) / (2.0 * curvature)
            if 0.0 < vertex < 2.0:
                E[vertex] = energy(vertex)
        alpha = min(E, key=E.get)
        return bool(E[alpha] < E0) and expansion.replace_basis(moved(alpha))

    def to_dict(self) -> dict | None:
        """The checkpoint's "momentum" block: the reference as a basis file's content, or None."""
        return None if self.reference is None else basis_json.to_dict(self.reference)

    @classmethod
    def from_dict(cls, block, basis: Basis, where: str) -> "Momentum":
        """The momentum of a checkpoint's "momentum" block (`to_dict`; absent before 671d9a1) for
        the run of `basis`; BasisFileError naming `where` for one that is not of this run."""
        if block is None:
            return cls()
        reference = Basis.from_dict(block, f"{where}: momentum")
        if not of_this_run(reference, basis):
            raise BasisFileError(f"{where}: momentum: the reference is not a basis of this run")
        return cls(reference)
