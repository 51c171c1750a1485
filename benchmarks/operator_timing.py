"""Time every registered operator the basis family evaluates against one matrix build, and the
densities of every class of pairs and particles on a grid (issue 40).

    RAYON_NUM_THREADS=2 python benchmarks/operator_timing.py BASIS [--functions K] [--roots K] [--points N]

BASIS: a basis.json or checkpoint folder (its first K functions with --functions). Prints, in seconds, the matrix build (S, T, T_TI, V),
each operator's matrices for all its vectors (every pair or every particle, one call), and
`prebo.densities` of the lowest K levels on the default grids of N points (its solves included).
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

import prebo
from prebo.level.expectation import OPERATORS
from prebo.integrals import laboratory


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("basis", type=Path)
    ap.add_argument("--functions", type=int, default=None)
    ap.add_argument("--roots", type=int, default=1)
    ap.add_argument("--points", type=int, default=400)
    args = ap.parse_args()
    path = args.basis / "basis.json" if args.basis.is_dir() else args.basis
    basis = prebo.Basis.load(path)
    basis = basis if args.functions is None else basis.subset(range(args.functions))
    rep = laboratory(basis.system)
    t = time.perf_counter()
    rep.matrices(basis)
    build = time.perf_counter() - t
    print(f"{path}: {len(basis)} {basis.family.name} functions; matrix build {build:.3f} s", flush=True)
    for name, op in OPERATORS.items():
        if not op.evaluates(basis.family):
            print(f"  {name}: not derived for {basis.family.name}")
            continue
        w = np.concatenate(list(op.classes(basis.system).values()))
        t = time.perf_counter()
        rep.operator(name, basis, w, op.momenta)
        seconds = time.perf_counter() - t
        print(f"  {name}: {len(w)} vectors {seconds:.2f} s ({seconds / build:.0f}× the build)", flush=True)
    t = time.perf_counter()
    prebo.densities(basis, roots=list(range(args.roots)), points=args.points)
    print(f"  densities of {args.roots} level(s), {args.points} points per class: {time.perf_counter() - t:.1f} s")


if __name__ == "__main__":
    main()
