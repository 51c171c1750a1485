"""Integrals per second with MPI ranks against threads (issue 41; docs/mpi.md).

    RAYON_NUM_THREADS=1 python benchmarks/mpi_scaling.py CHECKPOINT_FOLDER          # 1 rank x 1 thread
    RAYON_NUM_THREADS=2 python benchmarks/mpi_scaling.py CHECKPOINT_FOLDER          # 1 rank x 2 threads
    RAYON_NUM_THREADS=1 mpiexec -n 2 python benchmarks/mpi_scaling.py CHECKPOINT_FOLDER  # 2 ranks x 1 thread

On the basis of the checkpoint (e.g. benchmarks/checkpoints/h2-auto, 500 ECG-GVR functions): the
full build; the rows of 64 trials (the basis's own first functions, drawn again as trials) against
the basis, as `Expansion.candidates` evaluates a growth or replacement step; one function's row
gradient against the basis, as every energy-and-gradient evaluation of a refinement; REFINED
refinements of one function (L-BFGS, at most EVALUATIONS energies each, with the eigen-updates
every rank repeats), one after the other with every rank on each, and in batches of one function
per rank (methods.together, a run's default `batch`), each rank refining its own; and the same
for REFINED steps of a replacement sweep and of a group refinement with the checkpoint's
settings (its trials, refined newcomer, and refine_group). Each timed after one warm-up, best of
REPEATS (the sweeps' steps once, in order); the bytes each rank receives per build are reported
beside. Rank 0 prints the lines.
"""
import json
import sys
import time
from pathlib import Path

import numpy as np

from prebo.eigen import lapack_threads
from prebo.integrals import laboratory
from prebo.optimise.expansion import Expansion
from prebo.optimise import Optimiser
from prebo.optimise.defaults import resolved
from prebo.optimise.methods import Minimiser, Replace, together
from prebo.optimise.sampler import Sampler
from prebo.optimise.refine import refine_function, refine_group
from prebo import Basis
from prebo.parallel import world

REPEATS = 3
TRIALS = 64
REFINED, EVALUATIONS = 8, 30


def best(f) -> float:
    f()
    times = []
    for _ in range(REPEATS):
        world().agreed(None)  # start together
        t = time.perf_counter()
        f()
        times.append(world().agreed(time.perf_counter() - t))  # rank 0's time
    return min(times)


def main(folder: str) -> None:
    with lapack_threads(0):  # LAPACK on one thread, as an optimisation below 2000 functions runs it
        measure(folder)


def measure(folder: str) -> None:
    ranks = world()
    basis = Basis.load(Path(folder) / "basis.json")
    rep, nb, n = laboratory(basis.system), len(basis), basis.system.n
    trials = basis.subset(list(range(TRIALS)))
    f = basis.subset([nb // 2])
    rng = np.random.default_rng(0)
    P = n * (n + 1) // 2 + (n if basis.u is not None else 0)
    dA = rng.normal(size=(P, n, n)) * 1e-3
    dA = dA + dA.transpose(0, 2, 1)
    dv = None if basis.u is None else rng.normal(size=(P, n)) * 1e-3
    build = best(lambda: rep.matrices(basis))
    ex = Expansion(basis.subset(list(range(nb))), rep, 1e-13)
    step = best(lambda: ex.candidates(trials))
    opts = resolved(Optimiser.from_dict(json.loads((Path(folder) / "basis.json").read_text())["optimiser"]),
                    basis.system)
    sampler = Sampler(basis.system, opts, np.random.default_rng(0))
    sampler.learn(basis)
    replace = Replace(opts.trials, Minimiser(opts.refine_evaluations, opts.refine_method))

    def refinements(ex, batch):
        together(ex, batch, lambda twin, k: refine_function(twin, k, max_evaluations=EVALUATIONS))

    def replacements(ex, batch):
        drawn = {k: sampler.replacements(ex.basis.subset([k]), opts.trials) for k in batch}
        together(ex, batch, lambda twin, k: replace.replace(twin, k, drawn[k]))

    def groups(ex, batch):
        together(ex, batch, lambda twin, k: refine_group(twin, k, opts.refine_group, opts.refine_evaluations,
                                                         opts.refine_method))

    def per_function(step, size: int) -> float:
        """Seconds per function of REFINED sweep steps from nb/3 on, in batches of `size`."""
        ex = Expansion(basis.subset(list(range(nb))), rep, 1e-13)
        start = time.perf_counter()
        for i in range(0, REFINED, size):
            step(ex, range(nb // 3 + i, nb // 3 + i + size))
        return ranks.agreed(time.perf_counter() - start) / REFINED

    kinds = {f"refinement of one function ({EVALUATIONS} evaluations)": refinements,
             f"replacement step ({opts.trials} trials)": replacements,
             f"group refinement ({opts.refine_group} functions)": groups}
    sweeps = {(what, size): per_function(step, size) for what, step in kinds.items() for size in sorted({1, ranks.size})}
    rows = best(lambda: rep.rows(trials, basis))
    gradient = best(lambda: rep.row_gradient(f, dA, dv, basis))
    if ranks.root:
        import os
        who = f"{ranks.size} rank(s) x {os.environ.get('RAYON_NUM_THREADS', 'all')} thread(s)"
        print(f"{who}: {basis.kind} nb = {nb}")
        print(f"  full build            {build:8.3f} s   (gathers {4 * nb * nb * 8 / ranks.size / 1e6 * (ranks.size > 1):.1f} MB per rank)")
        print(f"  {TRIALS} trials' rows        {rows:8.3f} s   {TRIALS / rows:8.1f} trials/s")
        print(f"  {TRIALS} trials' energies     {step:8.3f} s   (rows and objective: a growth or replacement step)")
        print(f"  one row gradient      {gradient:8.4f} s   {1 / gradient:8.1f} evaluations/s ({1 + P} x {nb} x 4 values)")
        for (what, size), t in sweeps.items():
            print(f"  {what}, batches of {size}   {t:8.3f} s   {60 / t:8.1f} per minute")


if __name__ == "__main__":
    main(sys.argv[1])
