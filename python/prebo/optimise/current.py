"""The current's first-order bases of the Bethe logarithm, one per photon energy k, optimised by the
one driver and kept in a folder for reuse.

The Bethe logarithm (level/bethe.py) needs f(k) = ⟨J'(H − E₀ + k)⁻¹J'⟩ from k of the level's
excitation energies to the split point K, where the first-order function ψ₁(k), the minimiser of
Hylleraas' functional ⟨ψ₁|H − E₀ + k|ψ₁⟩ + 2⟨ψ₁|J'_z|ψ₀⟩ in the symmetry the current reaches (N = 1,
the other parity), shrinks from the size of the level to r ~ (2μk)^(−1/2). One basis optimised at
one k resolves f near that k only; as Korobov (arXiv:1203.1404) and Pachucki & Komasa (Li, Be with
ECGs) do, each k of a grid gets its own basis, optimised on its functional at ω = −k by
driver.optimise (optimise/response.py, operator "velocity"). bethe.py takes their union (`union`:
without the functions it cannot resolve), whose pseudostates resolve f at every k of the grid and
between.

Each run's folder is folder/k=<k> (the checkpoint basis.json): a finished run is read back and
its basis reused, an unfinished one (a killed run) resumed where it stopped, so `prebo properties
--qed` computes a level's bases once.
"""
from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np

from .. import eigen
from ..basis import Basis
from ..errors import InputError, OutputError
from ..integrals import laboratory
from ..level.bethe import coulomb_scale, split
from ..system import State, System
from .checkpoint import CHECKPOINT
from .driver import optimise, resume_from
from .response import Source
from .resume import load_checkpoint
from .settings import Optimiser

#: the default grid (`grid`): from LOWEST × the Coulomb scale, PER_DECADE points per decade, up to
#: BEYOND × the split point (bethe.split): a basis optimised at k does not resolve f at k itself, so
#: the integral is split below the grid's top (benchmarks/record/bethe-logarithm.md: hydrogen, 30
#: functions per k, 2.7e-6 at the top, −5.9e-7 at a third of it)
LOWEST, PER_DECADE, BEYOND = 0.3, 1, 3.0

#: the default number of functions of each k's basis
SIZE = 30

#: the smallest part of a function orthogonal to those before it in a union of the bases, relative
#: to its norm (`union`): bases optimised at neighbouring k share directions, and their union's
#: overlap has eigenvalues at the elements' rounding (−1e-12 relative for hydrogen's), where its
#: pseudostates would be noise
UNION_NORM = 1e-5


def reached(system: System) -> System:
    """The system the current reaches from a level of `system` (N = 0): its particles, N = 1, the
    other parity, the same total spin of every group."""
    spin = {g.name: float(g.total_spin) for g in system.groups}
    return System(system.particles, State(N=1, parity=-system.state.parity, spin=spin))


def grid(ground: Basis, k=None) -> list[float]:
    """The photon energies (Eh), ascending: `k` as given, else from LOWEST × the Coulomb scale to
    BEYOND × the split point bethe.split(ground), PER_DECADE points per decade (at least two).
    InputError unless a non-empty list of finite positive numbers."""
    if k is None:
        lo, hi = LOWEST * coulomb_scale(ground.system), BEYOND * split(ground)
        n = max(2, math.ceil(PER_DECADE * math.log10(max(hi / lo, 10.0))) + 1)
        return np.geomspace(lo, max(hi, 10 * lo), n).tolist()
    ks = list(k) if isinstance(k, (list, tuple)) else [k]
    if not ks or not all(isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) and x > 0
                         for x in ks):
        raise InputError(f"current bases: k = {k!r}: must be a non-empty list of finite photon energies > 0 (Eh)")
    return sorted(float(x) for x in ks)


def folder_of(out: Path, k: float) -> Path:
    """The run folder of the photon energy k under `out`."""
    return Path(out) / f"k={k:.6g}"


def current_bases(ground: Basis, root: int = 0, k=None, size: int = SIZE, out: Path | None = None,
                  threshold: float = eigen.THRESHOLD, opts: Optimiser | None = None,
                  progress: bool = False) -> list[Basis]:
    """The N = 1 bases of the current's first-order functions of the level `root` of `ground`, one
    per photon energy of `grid(ground, k)` (ascending), each of `size` functions optimised by the
    driver on Hylleraas' functional at ω = −k (`opts` its other settings), its run in
    `folder_of(out, k)`: read back if it is there (resumed to its end, with `opts.budget` if given),
    else run. InputError as `grid` and response.Source raise it, or for a folder holding another
    run (`require_same`); OutputError for a folder that cannot be made."""
    ks = grid(ground, k)
    system = reached(ground.system)
    settings = replace(opts or Optimiser(), size=size)
    bases = []
    for x in ks:
        source = Source.of(ground, "velocity", root, -x, threshold)
        source.check(system)
        where = None if out is None else folder_of(out, x)
        if where is not None and (where / CHECKPOINT).exists():
            require_same(where, source)
            basis, _ = resume_from(where, progress=progress, budget=settings.budget)
        else:
            if where is not None:
                try:
                    where.mkdir(parents=True, exist_ok=True)
                except OSError as exc:
                    raise OutputError(f"{where}: cannot make the folder of the run ({exc.strerror})") from exc
            basis = optimise(system, settings, out=where, progress=progress, response=source)
        bases.append(basis)
    return bases


def responses(ground: Basis, root: int = 0, k=None, size: int = SIZE, out: Path | None = None,
              threshold: float = eigen.THRESHOLD, opts: Optimiser | None = None,
              progress: bool = False) -> tuple[list[Basis], float]:
    """The Bethe logarithm's N = 1 bases of the level `root` of `ground` from `current_bases` (the
    same arguments), as its convergence table takes them: their unions as they join, k ascending
    (`union`); and the split point K, bethe.split(ground), at most the grid's largest k over BEYOND."""
    ks = grid(ground, k)
    parts = current_bases(ground, root, ks, size, out, threshold, opts, progress)
    return [union(parts[:j + 1]) for j in range(len(parts))], min(split(ground), ks[-1] / BEYOND)


def union(bases: list[Basis], min_norm: float = UNION_NORM) -> Basis:
    """The functions of `bases` in order, each kept only if its part orthogonal to those kept before
    it is at least `min_norm` of its norm (a Cholesky factorisation of the scaled overlap, grown a
    function at a time): a union whose overlap the elements resolve."""
    joined = Basis.concat(bases)
    S = laboratory(joined.system).matrices(joined)["S"]
    d = 1.0 / np.sqrt(np.diag(S))
    S = S * np.outer(d, d)
    kept, L = [], np.zeros((0, 0))
    for n in range(len(S)):
        x = np.linalg.solve(L, S[kept, n]) if kept else np.zeros(0)
        nu = S[n, n] - x @ x
        if nu >= min_norm**2:
            L = np.block([[L, np.zeros((len(kept), 1))], [x[None, :], np.array([[np.sqrt(nu)]])]])
            kept.append(n)
    return joined.subset(kept)


def require_same(where: Path, source: Source) -> None:
    """InputError unless the run in `where` is of `source`: the current at its k, of the same level
    (its energy and coefficients to the bit)."""
    d, _, _ = load_checkpoint(where)
    stored = Source.from_dict(d["response"], str(where / CHECKPOINT)) if "response" in d else None
    if stored is None or (stored.operator, stored.omega, stored.E0) != (source.operator, source.omega, source.E0) \
            or not np.array_equal(stored.c0, source.c0):
        raise InputError(f"{where}: holds a run that is not the current's first-order function of this level at "
                         f"k = {-source.omega:.6g} Eh; remove it or give another folder")
