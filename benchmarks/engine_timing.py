"""Time the engine's four calls for each basis family, through the Python API the optimiser uses:
the full matrix build, rows of k = 1 and k = 20 trial functions against the basis (appended
position), and one function's row with P = 9 directional derivatives (dual numbers).

    python benchmarks/engine_timing.py --repeat 20 [--json out.json]

Bases: Ps⁻ (plain ECG, 250, 3 particles), H2 pECG (80, 4 particles), H2+ ECG-GVR (180), the H2
ECG-GVR checkpoint (500, 4 particles), H2+ floating ECG (400). Each figure is the median of
`--repeat` calls after one warm-up, in milliseconds, with the rayon threads `RAYON_NUM_THREADS`
gives (default: all cores).
"""
from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path

import numpy as np

import prebo
from prebo.integrals import laboratory

ROOT = Path(__file__).resolve().parents[1]
BASES = {
    "ps- pecg": "examples/bases/ps-/basis.json",
    "h2 pecg": "examples/bases/h2-pecg/basis.json",
    "h2+ gvr": "examples/bases/h2plus-gvr/basis.json",
    "h2 gvr": "benchmarks/checkpoints/h2-cycles/basis.json",
    "h2+ fecg": "examples/bases/h2plus-fecg/basis.json",
}
P = 9  # directional derivatives of the row gradient


def median_ms(call, repeat: int) -> float:
    call()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        call()
        times.append(time.perf_counter() - t0)
    return 1e3 * statistics.median(times)


def directions(f, rng):
    """P random symmetric directions dA (P, n, n) and dv ((P, n) for u, (P, n, 3) for s, else None)."""
    n = f.system.n
    dA = rng.normal(size=(P, n, n))
    dA = dA + dA.transpose(0, 2, 1)
    for name, shape in (("u", (P, n)), ("s", (P, n, 3))):
        if getattr(f, name, None) is not None:
            return dA, rng.normal(size=shape)
    return dA, None


def timings(path: Path, repeat: int) -> dict:
    basis = prebo.Basis.load(path)
    rep = laboratory(basis.system)
    rng = np.random.default_rng(0)
    trials = {k: basis.subset(list(range(k))) for k in (1, 20)}
    rest = basis.subset(list(range(1, len(basis))))
    f = basis.subset([0])
    dA, dv = directions(f, rng)
    return {
        "n_basis": len(basis),
        "matrices": median_ms(lambda: rep.matrices(basis), max(3, repeat // 4)),
        "rows k=1": median_ms(lambda: rep.rows(trials[1], basis, len(basis)), repeat),
        "rows k=20": median_ms(lambda: rep.rows(trials[20], basis, len(basis)), repeat),
        "row gradient": median_ms(lambda: rep.row_gradient(f, dA, dv, rest), repeat),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=20)
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    out = {name: timings(ROOT / rel, args.repeat) for name, rel in BASES.items()}
    keys = ["matrices", "rows k=1", "rows k=20", "row gradient"]
    print("| basis | n_b | " + " | ".join(f"{k} (ms)" for k in keys) + " |")
    print("|---|---|" + "---|" * len(keys))
    for name, t in out.items():
        print(f"| {name} | {t['n_basis']} | " + " | ".join(f"{t[k]:.3g}" for k in keys) + " |")
    if args.json:
        args.json.write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
