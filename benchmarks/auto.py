"""Textbook systems from inputs with no [optimiser] table (issue 17): `prebo run` of each
examples/auto/NAME.toml, its wall time, basis size and error against the literature
(tests/data/reference_energies.toml), and the seconds of optimisation to 1e-6 relative and to
1e-8, 1e-9 and 1e-10 Eh (time to accuracy), as a markdown table.

    python benchmarks/auto.py [NAME ...] [--out runs/auto] [--reuse] [--errors 1e-8 1e-9 1e-10]
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

from prebo.io.toml import tomllib

ROOT = Path(__file__).resolve().parents[1]
#: example -> reference key in tests/data/reference_energies.toml
REFERENCE = {"h": "H", "he": "He", "h-": "H-", "ps-": "Ps-", "li": "Li", "h2+": "H2+", "h2": "H2",
             "he-400": "He", "he-600": "He", "he-700": "He", "li-100": "Li", "li-150": "Li"}
#: relative error, then errors in Eh, whose first time the table reports (time to accuracy)
MILESTONES = (1e-6, 1e-8, 1e-9, 1e-10)


def reference(key: str, particles: list) -> float:
    ref = tomllib.loads((ROOT / "tests" / "data" / "reference_energies.toml").read_text())[key]
    if ref["energy"] == "exact":  # hydrogen-like: -mu/(2 n^2)
        m1, m2 = (p["mass"] for p in particles)
        return -0.5 * m1 * m2 / (m1 + m2) / ref["n"] ** 2
    return ref["energy"]


def reached(history: list, E_ref: float, error: float, relative: bool) -> float | None:
    """The seconds of optimisation at which the run first came within `error` of E_ref (relative
    to |E_ref| if `relative`), or None."""
    bound = error * abs(E_ref) if relative else error
    return next((h[3] for h in history if h[1] - E_ref <= bound), None)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("names", nargs="*", default=list(REFERENCE))
    ap.add_argument("--out", type=Path, default=Path("runs/auto"))
    ap.add_argument("--reuse", action="store_true", help="tabulate finished runs in --out instead of running them")
    ap.add_argument("--errors", type=float, nargs="+", default=MILESTONES[1:],
                    help="errors (Eh) whose first time to report, besides 1e-6 relative")
    args = ap.parse_args()
    milestones = (MILESTONES[0], *args.errors)
    print("| system | N_b | basis | E / Eh | E − E_ref | relative | wall (s) | stopped | s to 1e-6 rel. | "
          + " | ".join(f"s to {e:g} Eh" for e in milestones[1:]) + " | command |")
    print("|---" * (9 + len(milestones)) + "|")
    for name in args.names:
        inp, out = f"examples/auto/{name}.toml", (args.out / name).resolve()
        t = time.perf_counter()
        if not args.reuse:
            for stale in ("basis.json", "lowest.json"):  # a new run refuses a folder holding a checkpoint
                (out / stale).unlink(missing_ok=True)
            subprocess.run([sys.executable, "-m", "prebo", "run", inp, "--out", str(out), "--quiet"], check=True,
                           cwd=ROOT)
        r = json.loads((out / "result.json").read_text())
        wall = r["wall_seconds"] if args.reuse else time.perf_counter() - t
        E_ref = reference(REFERENCE[name], r["particles"])
        err = r["energy"] - E_ref
        history = json.loads((out / "basis.json").read_text())["history"]
        times = [reached(history, E_ref, milestones[0], True)] + [reached(history, E_ref, e, False)
                                                                 for e in milestones[1:]]
        print(f"| {name} | {r['n_basis']} | {r['basis_type']} | {r['energy']:.10f} | {err:.2e} | "
              f"{err / abs(E_ref):.1e} | {wall:.0f} | {r['convergence']['stopped']} | "
              + " | ".join("–" if t is None else f"{t:.0f}" for t in times)
              + f" | `prebo run examples/auto/{name}.toml` |", flush=True)


if __name__ == "__main__":
    main()
