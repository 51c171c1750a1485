"""Optimiser steps per minute on a run's checkpoint: `--steps` consecutive steps of one phase
("sweep": replacement with `trials` random functions, the winner refined; "refine": L-BFGS
refinement of one function or group; "grow": the basis cut to its first `--first` functions,
the best of `trials` random functions appended and refined) from function `--first` on, with the checkpoint's settings, random
state and basis, LAPACK threads as the driver sets them — the quantity the optimiser feels. The matrices of the basis are built before
the clock starts. The energy after the steps shows that two builds took the same path. `--roots K`:
the objective of the K lowest levels (issue 39: the sum of roots 0..K-1, optimise/objective.py) in
place of the lowest alone, on the same basis and steps.

    python benchmarks/step_rate.py benchmarks/checkpoints/h2-cycles --phase refine --first 100 --steps 10
    python benchmarks/step_rate.py benchmarks/checkpoints/h2-cycles --phase sweep --first 100 --steps 5
    python benchmarks/step_rate.py examples/bases/auto-he-400 --phase refine --steps 20 --blas-threads 2
    python benchmarks/step_rate.py examples/bases/auto-he-400 --phase grow --first 350 --steps 30
    python benchmarks/step_rate.py examples/bases/h2plus --phase refine --first 0 --steps 20 --roots 4
"""
from __future__ import annotations

import argparse
import time

import numpy as np
from threadpoolctl import threadpool_limits

try:
    from prebo.eigen import lapack_threads as threads
except ImportError:  # code before the LAPACK thread limit
    from contextlib import nullcontext as threads

from prebo import eigen
from prebo.integrals import laboratory
from prebo.optimise.cursor import Cursor
from prebo.optimise.expansion import Expansion
from prebo.optimise.methods import Run, methods
from prebo.optimise.objective import Levels
from prebo.optimise.report import Reporter
from prebo.optimise.resume import load_checkpoint, resumed
from prebo.optimise.sampler import Sampler


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("checkpoint", help="a run's folder (its basis.json)")
    ap.add_argument("--phase", choices=("sweep", "refine", "grow"), default="refine")
    ap.add_argument("--first", type=int, default=100, help="the function of the first step")
    ap.add_argument("--steps", type=int, default=10)
    ap.add_argument("--blas-threads", type=int, help="LAPACK/BLAS threads instead of the driver's choice")
    ap.add_argument("--roots", type=int, default=1, help="the objective: the sum of the lowest ROOTS levels")
    args = ap.parse_args()
    d, system, opts = load_checkpoint(args.checkpoint)
    rng = np.random.default_rng(opts.seed)
    sampler = Sampler(system, opts, rng)
    basis, *_ = resumed(d, opts, rng, args.checkpoint)
    if args.phase == "grow":
        basis = basis.subset(np.arange(args.first))
    ex = Expansion(basis, laboratory(system), opts.threshold, opts.min_norm, opts.max_overlap,
                   Levels(tuple(range(args.roots))))
    sampler.learn(ex.basis)
    run = Run(ex, sampler, Reporter(opts, False))
    step = methods(opts)[args.phase]
    e0, times = ex.energy, []
    if args.blas_threads is not None and hasattr(eigen, "SERIAL_BELOW"):
        eigen.SERIAL_BELOW = 0  # no one-thread limit in eigen.solve either
    with (threads(len(ex.basis)) if args.blas_threads is None  # as the driver runs its steps
          else threadpool_limits(args.blas_threads, user_api="blas")):
        for i in range(args.first, args.first + args.steps):
            t0 = time.perf_counter()
            step.step(run, Cursor(args.phase, index=i))
            times.append(time.perf_counter() - t0)
    t = np.array(times)
    print(f"{args.checkpoint}: {args.steps} {args.phase} steps from function {args.first} "
          f"({opts.kind}, {len(ex.basis)} functions, roots {args.roots}, trials {opts.trials}, "
          f"{opts.refine_evaluations} energies per refinement)")
    print(f"steps per minute {60 / t.mean():.1f} (seconds per step: mean {t.mean():.2f}, "
          f"min {t.min():.2f}, max {t.max():.2f}); E {e0:.12f} -> {ex.energy:.12f}")


if __name__ == "__main__":
    main()
