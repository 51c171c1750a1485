"""Time one trial function's row against a basis: values only (`rows`, f64) and values with the
derivatives along the function's own parameter directions (`row_gradient`, dual numbers), with
the basis's K and with every K set to 0 (ECG-GVR: what the Coulomb quadrature over K costs).

    python benchmarks/row_timing.py benchmarks/checkpoints/h2-cycles/basis.json --function 100

The basis is a prebo basis file (JSON) or an ecgpack / ATOM-MOL-nonBO `.inout` file (plain ECGs,
read with prebo.io.ecgpack), e.g. tests/data/ecgpack/ecgpack-He4-490.inout.txt.
"""
from __future__ import annotations

import argparse
import json
import time

import numpy as np

from prebo.basis import Basis
from prebo.integrals import laboratory
from prebo.io import ecgpack
from prebo.optimise.parametrisation import Parametrisation


def seconds(call, repeat: int) -> float:
    call()  # warm-up
    t0 = time.perf_counter()
    for _ in range(repeat):
        call()
    return (time.perf_counter() - t0) / repeat


def load(path: str) -> Basis:
    """A prebo basis file, or an ecgpack `.inout` file (the name contains `.inout`)."""
    if ".inout" in path:
        return ecgpack.read_inout(path)
    return Basis.from_dict(json.loads(open(path).read()), path)


def with_K(b: Basis, K) -> Basis:
    return Basis(b.system, b.A, b.c_A, b.channels, kind="ecg-gvr", u=b.u, K=K)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("basis")
    ap.add_argument("--function", type=int, default=100, help="the function timed as the trial")
    ap.add_argument("--repeat", type=int, default=20)
    args = ap.parse_args()
    basis = load(args.basis)
    rep, i = laboratory(basis.system), args.function
    p = Parametrisation.of(basis.subset([i]))
    theta = p.theta()
    f, (dA, dv) = p.function(theta), p.directions(theta)
    rest = basis.subset(np.flatnonzero(np.arange(len(basis)) != i))
    cases = [("basis K", f, rest)]
    if "K" in basis.parameters:
        cases.append(("every K = 0", with_K(f, [0]), with_K(rest, [0] * len(rest))))
    print(f"{args.basis}: function {i} (K = {[int(k) for k in f.K] if f.K is not None else '-'}) against {len(rest)}, "
          f"{len(theta)} directions, {args.repeat} repetitions")
    print("| case | row (ms) | row with derivatives (ms) |")
    print("|---|---|---|")
    for name, g, b in cases:
        t_row = seconds(lambda: rep.rows(g, b), args.repeat)
        t_grad = seconds(lambda: rep.row_gradient(g, dA, dv, b), args.repeat)
        print(f"| {name} | {1e3 * t_row:.3f} | {1e3 * t_grad:.3f} |")


if __name__ == "__main__":
    main()
