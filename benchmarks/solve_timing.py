"""Where eigen.solve spends its time on a run's basis, one BLAS thread: the whole solve and its
parts (the overlap's eigen-decomposition, X^T H X, the eigen-decomposition, X Y, the double-double
refinement), the best of `--repeat` each, in ms.

    python benchmarks/solve_timing.py examples/bases/auto-he-400
"""
from __future__ import annotations

import argparse
import time

import numpy as np
from threadpoolctl import threadpool_limits

from prebo import eigen
from prebo.integrals import laboratory
from prebo.optimise.expansion import Expansion
from prebo.optimise.resume import load_checkpoint, resumed


def best(f, repeat: int) -> float:
    """The shortest of `repeat` calls of f, in ms."""
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return 1e3 * min(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("checkpoint", help="a run's folder (its basis.json)")
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args()
    d, system, opts = load_checkpoint(a.checkpoint)
    basis, *_ = resumed(d, opts, np.random.default_rng(0), a.checkpoint)
    ex = Expansion(basis, laboratory(system), opts.threshold)
    H, S = ex.m.H, ex.m.S
    d = 1.0 / np.sqrt(np.diag(S))
    Ss, Hs = S * np.outer(d, d), H * np.outer(d, d)
    with threadpool_limits(1, user_api="blas"):
        s, V = np.linalg.eigh(Ss)
        keep = s > opts.threshold * s[-1]
        X = V[:, keep] / np.sqrt(s[keep])
        E, Y = np.linalg.eigh(X.T @ Hs @ X)
        eig = eigen.Eigen(E, d[:, None] * (X @ Y), int(keep.sum()), float(s[-1] / s[0]))
        parts = {"solve": lambda: eigen.solve(H, S, opts.threshold), "eigh(S)": lambda: np.linalg.eigh(Ss),
                 "X^T H X": lambda: X.T @ Hs @ X, "eigh(X^T H X)": lambda: np.linalg.eigh(X.T @ Hs @ X),
                 "X Y": lambda: X @ Y, "refine": lambda: eigen.refine(H, S, eig)}
        print(f"{a.checkpoint}: {len(S)} functions, overlap condition {eig.overlap_condition:.2e}")
        for name, f in parts.items():
            print(f"{name:>14}: {best(f, a.repeat):7.1f} ms")


if __name__ == "__main__":
    main()
