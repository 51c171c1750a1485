"""Late-stage optimisation moves, head to head on one optimised basis, for a fixed wall time each.

- refine: refinement sweeps (each function in turn, L-BFGS on exact gradients, others fixed);
- regenerate: replacement sweeps with refinement (refine.regenerate_function: the competitive
  winner among `trials` random functions takes the function's place and is refined, and stays
  only if it then beats the refined incumbent);
- polish: joint L-BFGS steps of 50 iterations over all parameters (polish.py).

Each method starts from the same basis and runs whole steps until `--seconds` have passed.

    git show 2f2c3bb:examples/bases/h2plus-gvr/basis.json > /tmp/h2plus-2f2c3bb.json
    python benchmarks/sweep_methods.py /tmp/h2plus-2f2c3bb.json --seconds 150
"""
from __future__ import annotations

import argparse
import json
import time

import numpy as np

from prebo.basis import Basis
from prebo.integrals import laboratory
from prebo.optimise import Expansion, Optimiser, Sampler
from prebo.optimise.polish import polish
from prebo.optimise.refine import refine_function, regenerate_function


def run(basis: Basis, opts: Optimiser, method: str, seconds: float, start: int = 0) -> tuple[float, float, float, int]:
    st = Expansion(basis.subset(np.arange(len(basis))), laboratory(basis.system), opts.threshold, opts.min_norm,
               opts.max_overlap)
    sampler = Sampler(basis.system, opts, np.random.default_rng(opts.seed))
    sampler.learn(st.basis)
    e0, t0, steps = st.energy, time.perf_counter(), 0
    while time.perf_counter() - t0 < seconds:
        i = (start + steps) % len(basis)
        if method == "polish":
            polish(st, 50)
        elif method == "refine":
            refine_function(st, i, opts.refine_evaluations)
        else:
            trials = Basis.concat([sampler.draw() for _ in range(opts.trials)])
            rest = st.without(i)
            energies, _, _ = st.candidates(trials, exclude=i, eig=rest)
            k = int(np.argmin(energies))
            if np.isfinite(energies[k]):
                regenerate_function(st, i, trials.subset([k]), opts.refine_evaluations, rest=rest)
                sampler.learn(st.basis)
        steps += 1
    return e0, st.energy, time.perf_counter() - t0, steps


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("basis", help="a run's basis.json (its [optimiser] settings are used)")
    ap.add_argument("--seconds", type=float, default=240.0)
    ap.add_argument("--methods", default="refine,regenerate,polish")
    ap.add_argument("--evaluations", default=None,
                    help="comma-separated refine_evaluations to try for refine and regenerate (default: the run's)")
    ap.add_argument("--start", type=int, default=0, help="function the sweeps start at")
    args = ap.parse_args()
    d = json.loads(open(args.basis).read())
    basis, opts = Basis.from_dict(d, args.basis), Optimiser.from_dict(d["optimiser"])
    print(f"{args.basis}: {len(basis)} functions, {args.seconds:.0f} s per method")
    evaluations = [int(v) for v in args.evaluations.split(",")] if args.evaluations else [opts.refine_evaluations]
    print("| method | evaluations | steps | E before | E after | gain | wall time (s) | gain per s |")
    print("|---|---|---|---|---|---|---|---|")
    for method in args.methods.split(","):
        for n in evaluations if method != "polish" else [None]:
            o = opts if n is None else Optimiser.from_dict({**opts.to_dict(), "refine_evaluations": n})
            e0, e1, t, steps = run(basis, o, method, args.seconds, args.start)
            print(f"| {method} | {n or '—'} | {steps} | {e0:.12f} | {e1:.12f} | {e0 - e1:.3e} | {t:.1f} "
                  f"| {(e0 - e1) / t:.2e} |", flush=True)


if __name__ == "__main__":
    main()
