"""MPI ranks sharing the integrals of a run (`mpiexec -n R prebo run INPUT.toml`).

Replicated state: every rank runs the same driver with the same seed and holds the same basis,
matrices and eigen-solution. The integrals of a step, which are nearly all of its cost, are split
among the ranks and gathered, so that every rank goes on with the same bits:

- many trials (`Expansion.candidates`): each rank the rows of a contiguous block of trials;
- one function's row or row gradient (growth, refinement): each rank a block of the basis's
  columns, in the orientation of the full row (`Representation.rows`, position);
- a full build: the upper triangle in blocks of rows of about equal area, each block's part left
  of it as rows of the block against the functions before it and its diagonal block as a build
  of the block alone, dealt to the ranks in turn;
- the expectation values and densities of a result: blocks of the operator's instances (its
  pairs or particles).

Every element is evaluated by the core exactly as in one process, so the matrices and rows of R
ranks equal one rank's bit for bit; what is done with them (eigen-solutions, objectives,
minimisers) is repeated on every rank from the same bits. The run's clock is rank 0's (`agreed`),
so that decisions taken by time (budget, the choices of a schedule by rates) are the same on every rank.

Threads: unless RAYON_NUM_THREADS is set, each rank's core uses its node's cores divided by the
node's ranks, so that ranks x threads does not oversubscribe it; LAPACK stays on one thread below
eigen.SERIAL_BELOW functions, as in one process, and above on the same count
(`eigen.lapack_threads`). The variable is read when the core first runs in parallel: `world()` is
called before (cli.main).

Without an MPI launcher (no PMI_SIZE, OMPI_COMM_WORLD_SIZE or PMIX_SIZE above 1 in the
environment) prebo imports nothing of MPI and `world()` is one rank.
"""
from __future__ import annotations

import os
import sys
import time
from functools import lru_cache

import numpy as np

from .errors import NotPositiveDefiniteError, RanksDivergedError, UnsupportedError
from .matrices import NAMES

#: environment variables by which MPI launchers (MPICH/Hydra and Slurm's PMI, Open MPI, PMIx) give
#: the number of ranks
LAUNCHERS = ("PMI_SIZE", "OMPI_COMM_WORLD_SIZE", "PMIX_SIZE")
#: blocks of a full build per rank (`Ranks.matrices`): more even work, more calls
BLOCKS_PER_RANK = 4
#: seconds a failing rank waits before it stops every rank, for the launcher to forward its report
#: (a rank stopped at once by another's abort can lose the lines it wrote last; `stop_all`)
FORWARD = 0.5


def launched() -> int:
    """The number of ranks an MPI launcher started (1 without one)."""
    for name in LAUNCHERS:
        if os.environ.get(name, "").isdigit():
            return int(os.environ[name])
    return 1


@lru_cache(maxsize=1)
def world() -> Ranks:
    """The ranks of this run: MPI's world communicator if a launcher started more than one, else
    one rank (module docstring)."""
    if launched() <= 1:
        return Ranks()
    try:
        from mpi4py import MPI  # only under a launcher: a single process imports nothing of MPI
    except ImportError as exc:
        raise UnsupportedError(f"started as one of {launched()} MPI ranks, but mpi4py cannot be imported ({exc}): "
                               "install prebo with its MPI extra, pip install \".[mpi]\" (docs/mpi.md)") from None

    sys.excepthook = _stop_all_on_exception
    node = MPI.COMM_WORLD.Split_type(MPI.COMM_TYPE_SHARED)  # the ranks on this node
    os.environ.setdefault("RAYON_NUM_THREADS", str(max(1, cores() // node.Get_size())))
    node.Free()
    return Ranks(MPI.COMM_WORLD)


def cores() -> int:
    """The cores this process may run on."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


def slices(n: int, parts: int) -> list[slice]:
    """`n` items in `parts` contiguous slices of sizes differing by at most one, in order."""
    edges = [n * k // parts for k in range(parts + 1)]
    return [slice(a, b) for a, b in zip(edges[:-1], edges[1:])]


def triangle_blocks(nb: int, parts: int) -> list[slice]:
    """Row blocks [a, b) of an nb x nb triangle of about equal area (rows i < b, columns ≤ i):
    boundaries at nb √(k/parts), without empty blocks."""
    edges = sorted({round(nb * np.sqrt(k / parts)) for k in range(parts + 1)})
    return [slice(a, b) for a, b in zip(edges[:-1], edges[1:])]


def take(params: tuple, s: slice) -> tuple:
    """The functions `s` of a core parameter tuple (every array's leading axis is the function)."""
    return tuple(np.ascontiguousarray(x[s]) for x in params)


class Ranks:
    """The ranks of a run (`world()`): `comm`, an mpi4py communicator (None: one process), `rank`,
    `size`, and the integrals split among them (module docstring)."""

    def __init__(self, comm=None):
        self.comm = comm
        self.rank, self.size = (0, 1) if comm is None else (comm.Get_rank(), comm.Get_size())

    @property
    def root(self) -> bool:
        """Whether this is rank 0, the one that writes checkpoints, results and progress."""
        return self.rank == 0

    def agreed(self, value, what: str = "value"):
        """Rank 0's `value` on every rank (a collective call: every rank makes it, for the same
        `what`; RanksDivergedError otherwise, as for `gathered`)."""
        return self.each(value, ("agreed", what))[0]

    def gathered(self, mine: list, call: tuple) -> list:
        """The (index, item) pairs of every rank, ordered by index (a collective call; one process:
        its own); `call` names what they are (the kind of call and its sizes), and
        RanksDivergedError if the ranks made different ones."""
        if self.comm is None:
            return sorted(mine, key=lambda x: x[0])
        parts = self.comm.allgather((call, mine))
        if any(c != call for c, _ in parts):
            raise RanksDivergedError(f"MPI ranks diverged: they made the calls {[c for c, _ in parts]} together "
                                     "(their copies of the run differ: nodes of different CPUs or BLAS? docs/mpi.md)")
        return sorted((x for _, part in parts for x in part), key=lambda x: x[0])

    def each(self, value, call: tuple) -> list:
        """Every rank's `value`, in rank order (`gathered`)."""
        return [x for _, x in self.gathered([(self.rank, value)], call)]

    def mine(self, n: int) -> slice:
        """This rank's block of `n` items (`slices`)."""
        return slices(n, self.size)[self.rank]

    def matrices(self, engine, params: tuple) -> dict:
        """`engine.matrices(params)`, its row blocks evaluated by the ranks in turn."""
        nb = len(params[0])
        if self.size == 1 or nb < 2 * self.size:
            return engine.matrices(params)
        blocks = triangle_blocks(nb, BLOCKS_PER_RANK * self.size)
        dealt = []  # this rank's blocks
        for k in range(self.rank, len(blocks), self.size):
            s = blocks[k]
            left = engine.rows(take(params, s), take(params, slice(0, s.start)), None)[0] if s.start else None
            dealt.append((k, left, engine.matrices(take(params, s))))
        out = {}
        for k, left, square in self.gathered(dealt, ("matrices", nb)):
            s = blocks[k]
            for name, block in square.items():
                M = out.setdefault(name, np.zeros((nb, nb)))
                M[s, s] = block
                if left is not None:
                    M[s, :s.start] = left[name]
                    M[:s.start, s] = left[name].T
        return out

    def rows(self, engine, trials: tuple, params: tuple, position: int | None) -> tuple[dict, np.ndarray]:
        """`engine.rows(trials, params, position)`: blocks of the trials, or of a few trials' columns,
        evaluated by the ranks."""
        k, nb = len(trials[0]), len(params[0])
        if self.size == 1 or max(k, nb) < self.size:
            return refusing(engine, trials, params, position)
        if k >= self.size:
            parts = self.each(refusing(engine, take(trials, self.mine(k)), params, position), ("rows", k, nb, position))
            return joined([rows for rows, _ in parts], axis=0), np.concatenate([diag for _, diag in parts])
        return self._columns(lambda basis, at: refusing(engine, trials, basis, at), params, position,
                             ("row", k, nb, position))

    def row_gradient(self, engine, f: tuple, dA, dv, params: tuple) -> tuple[dict, np.ndarray]:
        """`engine.row_gradient(f, dA, dv, params)`, blocks of its columns evaluated by the ranks."""
        if self.size == 1 or len(params[0]) < self.size:
            return engine.row_gradient(f, dA, dv, params)
        return self._columns(lambda basis, _: engine.row_gradient(f, dA, dv, basis), params, None,
                             ("row gradient", len(params[0]), len(dA)))

    def instances(self, evaluate, v: np.ndarray) -> np.ndarray:
        """`evaluate(v)` of an operator's or a density's instances `v` (first axis), one contiguous
        block of them per rank, joined in order (`Representation.operator`, `.density`)."""
        if self.size == 1 or len(v) < self.size:
            return evaluate(v)
        return np.concatenate(self.each(evaluate(np.ascontiguousarray(v[self.mine(len(v))])), ("instances", v.shape)))

    def _columns(self, evaluate, params: tuple, position: int | None, call: tuple) -> tuple[dict, np.ndarray]:
        """Rows evaluated by blocks of the basis's columns, one per rank, each with the position
        of the function within the block (clipped), so in the orientation of the full row; the
        diagonal, which every rank evaluates alike, is this rank's."""
        nb = len(params[0])
        at = nb if position is None else position
        s = self.mine(nb)
        rows, diag = evaluate(take(params, s), min(max(at - s.start, 0), s.stop - s.start))
        return joined(self.each(rows, call), axis=1), diag


def refusing(engine, trials: tuple, params: tuple, position: int | None) -> tuple[dict, np.ndarray]:
    """`engine.rows(trials, params, position)`, with NaN elements (which `plausible` refuses) for a
    trial whose A has no Cholesky factor in the core — exponents far from c_A round it away, as for a
    pair of very heavy particles (optimise/methods.py, `unresolved`) — instead of the run stopping
    on it: the trials are then evaluated one at a time. On each rank alike, for its own trials."""
    try:
        return engine.rows(trials, params, position)
    except NotPositiveDefiniteError:
        k, nb = len(trials[0]), len(params[0])
        if k == 1:
            return {name: np.full((1, nb), np.nan) for name in NAMES}, np.full((1, len(NAMES)), np.nan)
    parts = [refusing(engine, take(trials, slice(i, i + 1)), params, position) for i in range(k)]
    return joined([rows for rows, _ in parts], axis=0), np.concatenate([diag for _, diag in parts])


def joined(parts: list[dict], axis: int) -> dict:
    """Rows {name: array} of consecutive parts joined along `axis`."""
    return {name: np.concatenate([part[name] for part in parts], axis=axis) for name in parts[0]}


def stop_all(status: int, report: str | None = None) -> int:
    """`status`, after a failure on this rank, and its one-line `report` on stderr; under MPI every
    rank is stopped (exit status `status`), since the others would wait for this one in a
    collective call for ever. A failure every rank meets (a bad input) is reported once: rank 0
    reports at once and stops every rank FORWARD seconds later (the launcher forwards the report
    meanwhile), another rank reports only after twice that, when a rank 0 that failed too has
    stopped it. The standard error is then pointed at /dev/null: the report is the one line, not
    followed by the MPI library's own of the abort."""
    try:
        ranks = world()
    except UnsupportedError:  # no MPI to stop with: every rank ends by itself
        ranks = Ranks()
    if report is not None:
        if not ranks.root:
            time.sleep(2 * FORWARD)
        print(report, file=sys.stderr)
    if ranks.comm is not None:
        sys.stderr.flush()
        time.sleep(FORWARD)
        null = os.open(os.devnull, os.O_WRONLY)  # MPI's own "Abort(...)" line: the report above says it
        os.dup2(null, 2)
        ranks.comm.Abort(status)
    return status


def _stop_all_on_exception(kind, value, traceback) -> None:
    """sys.excepthook under MPI: the traceback, then every rank stopped (`stop_all`)."""
    sys.__excepthook__(kind, value, traceback)
    stop_all(1)
