"""Powell vs gradient (L-BFGS with exact dual-number derivatives) refinement, head to head.

Starting from one optimised basis, each method refines the same functions in turn, as a
refinement sweep does; the table gives the energy after the sweep and the wall time.

    python benchmarks/refine_methods.py examples/bases/h2plus-gvr/basis.json --functions 60
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from prebo.basis import Basis
from prebo.integrals import laboratory
from prebo.optimise import Expansion
from prebo.optimise.refine import refine_function


def sweep(basis: Basis, method: str, functions: int, evaluations: int) -> tuple[float, float, float]:
    st = Expansion(basis.subset(np.arange(len(basis))), laboratory(basis.system), 1e-13)
    e0, t0 = st.energy, time.perf_counter()
    for i in range(min(functions, len(basis))):
        refine_function(st, i, evaluations, method)
    return e0, st.energy, time.perf_counter() - t0


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("basis")
    ap.add_argument("--functions", type=int, default=60)
    ap.add_argument("--runs", default="powell:200,gradient:60,gradient:200",
                    help="method:evaluations, comma-separated")
    args = ap.parse_args()
    basis = Basis.load(args.basis)
    print(f"{args.basis}: {len(basis)} functions, refining the first {args.functions}")
    print("| method | evaluations/function | E before | E after | gain | wall time (s) | gain per s |")
    print("|---|---|---|---|---|---|---|")
    for run in args.runs.split(","):
        method, ev = run.split(":")
        e0, e1, t = sweep(basis, method, args.functions, int(ev))
        print(f"| {method} | {ev} | {e0:.12f} | {e1:.12f} | {e0 - e1:.3e} | {t:.1f} | {(e0 - e1) / t:.2e} |", flush=True)


if __name__ == "__main__":
    main()
