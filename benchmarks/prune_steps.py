"""One pruning of a run's basis, taken apart (benchmarks/record/h2.md, "Pruning that refines after
each removal"): `--grow N` growth steps past the size as methods.PruneStep makes them (the best of
the run's trials, refined, then refined with its partners), then the removals back to the size,
each of the function whose removal raises the energy least — as PruneStep.remove (the function it
overlapped most then refined with its partners), or with `--plain` removed only (the code before
b0c1d27). First, what removing each function alone would cost (eigen.root_without_each);
then per seed: each growth step's gain and seconds, each removal's cost, the net gain and the
seconds.

    RAYON_NUM_THREADS=1 python benchmarks/prune_steps.py benchmarks/checkpoints/h2-auto --grow 12 --seeds 11,12,13
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from prebo import eigen
from prebo.integrals import laboratory
from prebo.optimise.cursor import Cursor
from prebo.optimise.expansion import Expansion
from prebo.optimise.methods import Grow, Minimiser, PruneStep, Run
from prebo.optimise.report import Reporter
from prebo.optimise.resume import load_checkpoint, resumed
from prebo.optimise.sampler import Sampler


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("checkpoint", help="run folder with basis.json")
    ap.add_argument("--grow", type=int, default=20, help="functions grown past the size and removed again")
    ap.add_argument("--seeds", default="11", help="comma-separated seeds of the growth trials, one pruning each")
    ap.add_argument("--plain", action="store_true", help="remove only, nothing refined after a removal")
    a = ap.parse_args()
    d, system, opts = load_checkpoint(a.checkpoint)
    basis, *_ = resumed(d, opts, np.random.default_rng(0), a.checkpoint)
    refinement = Minimiser(opts.refine_evaluations, opts.refine_method, opts.refine_group)
    prune = PruneStep(Grow(opts.trials, refinement), refinement)
    with eigen.lapack_threads(len(basis)), Reporter(opts, False) as report:
        for k, seed in enumerate(int(s) for s in a.seeds.split(",")):
            ex = Expansion(basis.subset(slice(None)), laboratory(system), opts.threshold, opts.min_norm,
                           opts.max_overlap)
            if k == 0:
                alone = eigen.root_without_each(ex.eig.energies, ex.eig.vectors) - ex.energy
                print(f"removing one function alone costs {alone.min():.2e} Eh at least, median "
                      f"{np.median(alone):.2e}; {int(np.sum(alone < 1e-10))} below 1e-10")
            run = Run(ex, Sampler(system, opts, np.random.default_rng(seed)), report)
            E0, nb, t0 = ex.energy, len(basis), time.perf_counter()
            steps = []
            for _ in range(a.grow):
                before, ts = ex.energy, time.perf_counter()
                prune.add(run, Cursor("prune"))
                steps.append(f"{before - ex.energy:.1e} ({time.perf_counter() - ts:.1f} s)")
            print(f"seed {seed}: growth steps {', '.join(steps)}")
            grown, t1, costs = E0 - ex.energy, time.perf_counter() - t0, []
            while len(ex.basis) > nb:
                before = ex.energy
                if a.plain:
                    ex.remove(int(np.argmin(eigen.root_without_each(ex.eig.energies, ex.eig.vectors))))
                else:
                    prune.remove(run)
                costs.append(ex.energy - before)
            print(f"seed {seed}: grew {grown:.3e} Eh in {t1:.1f} s; removals cost {sum(costs):.3e} Eh "
                  f"({', '.join(f'{c:.1e}' for c in costs)}); net {E0 - ex.energy:.3e} Eh in "
                  f"{time.perf_counter() - t0:.1f} s", flush=True)


if __name__ == "__main__":
    main()
