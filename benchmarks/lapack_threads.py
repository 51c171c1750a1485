"""LAPACK's symmetric eigensolver (numpy.linalg.eigh, what eigen.solve calls twice) on one thread
and on the machine's default count, for random symmetric matrices of the sizes an optimisation
meets: why eigen.lapack_threads runs LAPACK on one thread below SERIAL_BELOW functions.

    python benchmarks/lapack_threads.py [--sizes 150 500 1500 3000] [--threads 1 2]
"""
from __future__ import annotations

import argparse
import time

import numpy as np
from threadpoolctl import threadpool_limits


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[150, 500, 1500, 3000])
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    args = ap.parse_args()
    rng = np.random.default_rng(1)
    print("| n | " + " | ".join(f"{t} thread{'s' * (t > 1)} (ms)" for t in args.threads) + " |")
    print("|---" * (1 + len(args.threads)) + "|")
    for n in args.sizes:
        a = rng.normal(size=(n, n))
        a = a + a.T
        repeat = max(2, int(2e8 / n**3))
        row = []
        for t in args.threads:
            with threadpool_limits(t, user_api="blas"):
                np.linalg.eigh(a)  # warm up
                t0 = time.perf_counter()
                for _ in range(repeat):
                    np.linalg.eigh(a)
                row.append((time.perf_counter() - t0) / repeat * 1e3)
        print(f"| {n} | " + " | ".join(f"{ms:.1f}" for ms in row) + " |", flush=True)


if __name__ == "__main__":
    main()
