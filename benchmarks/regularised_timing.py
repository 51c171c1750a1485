"""Seconds of every property of a basis's lowest level with the regularised δ and ⟨p⁴⟩, and those
values (`prebo.properties(basis, regularised=True)`; issue 40).

    RAYON_NUM_THREADS=2 python benchmarks/regularised_timing.py BASIS [--functions K]

BASIS: a basis.json or a folder holding one (its first K functions with --functions).
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import prebo


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("basis", type=Path)
    ap.add_argument("--functions", type=int, default=None)
    args = ap.parse_args()
    path = args.basis / "basis.json" if args.basis.is_dir() else args.basis
    basis = prebo.Basis.load(path)
    basis = basis if args.functions is None else basis.subset(range(args.functions))
    t = time.perf_counter()
    p = prebo.properties(basis, regularised=True)
    seconds = time.perf_counter() - t
    print(f"{path}: {len(basis)} {basis.family.name} functions, every property with the regularised δ and p⁴ "
          f"in {seconds:.2f} s")
    for name in ("delta_regularised", "p4_regularised"):
        print(f"  {name}: " + ", ".join(f"{c} {v:.16g}" for c, v in p[name].items()))


if __name__ == "__main__":
    main()
