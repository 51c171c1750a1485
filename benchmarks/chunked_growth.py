"""He-4 grown as ecgpack grows it (tests/data/ecgpack/ecgpack-He4-490.inout.txt: BASIS_ENL of 10
functions, then OPT_CYCLE over the whole basis): `--chunk` grown functions (competitive selection,
each refined), then `--sweeps` × N_b group refinements cycling over the basis, repeated up to
`--size`; at full size, refinement sweeps until `--budget` seconds. Prints E − E_ref at fixed times.

    python benchmarks/chunked_growth.py --size 500 --chunk 10 --sweeps 1
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from prebo import Optimiser, System, eigen
from prebo.basis import Basis
from prebo.integrals import laboratory
from prebo.optimise.cursor import Cursor
from prebo.optimise.defaults import resolved
from prebo.optimise.expansion import Expansion
from prebo.optimise.methods import Run, methods
from prebo.optimise.report import Reporter
from prebo.optimise.sampler import Sampler

E_REF = -2.903304557729  # Drake, finite-mass 4He (tests/data/reference_energies.toml)
MARKS = (60, 100, 150, 200, 250, 300, 400, 500, 600)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=500)
    ap.add_argument("--chunk", type=int, default=10, help="functions grown between refinement passes")
    ap.add_argument("--sweeps", type=float, default=1.0, help="refinement steps per pass, in units of N_b")
    ap.add_argument("--group", type=int, default=3, help="refine_group")
    ap.add_argument("--evaluations", type=int, default=30, help="refine_evaluations")
    ap.add_argument("--trials", type=int, default=100)
    ap.add_argument("--threshold", type=float, default=1e-14)
    ap.add_argument("--budget", type=float, default=300.0)
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    he = System(["alpha", "e", "e"], spin={"e": 0})
    opts = resolved(Optimiser(size=a.size, trials=a.trials, refine_group=a.group, refine_evaluations=a.evaluations,
                              threshold=a.threshold, seed=a.seed, refine=1, sweeps=0, prune=0, cycles=1), he)
    ex = Expansion(Basis.empty(he, opts.kind), laboratory(he), opts.threshold, opts.min_norm, opts.max_overlap)
    run = Run(ex, Sampler(he, opts, np.random.default_rng(a.seed)), Reporter(opts, False, 0))
    steps, marks, t0, position = methods(opts), list(MARKS), time.perf_counter(), 0

    def going() -> bool:
        t = time.perf_counter() - t0
        while marks and t >= marks[0]:
            print(f"{marks.pop(0)} s: {len(ex.basis)} functions, E - E_ref = {ex.energy - E_REF:.3e}, overlap "
                  f"condition {ex.eig.overlap_condition:.1e}", flush=True)
        return t < a.budget

    with eigen.lapack_threads(a.size):
        while going():
            for _ in range(min(a.chunk, a.size - len(ex.basis))):
                steps["grow"].step(run, Cursor("grow"))
            count = len(ex.basis) if len(ex.basis) == a.size else int(a.sweeps * len(ex.basis))
            for _ in range(count):
                steps["refine"].step(run, Cursor("refine", index=position % len(ex.basis)))
                position += 1
                if not going():
                    break
    print(f"end: {len(ex.basis)} functions, E - E_ref = {ex.energy - E_REF:.3e} after {time.perf_counter() - t0:.1f} s")


if __name__ == "__main__":
    main()
