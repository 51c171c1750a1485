"""Textbook systems from inputs with no [optimiser] table (issue 17): `prebo run` of each
examples/auto/NAME.toml, its wall time, basis size and error against the literature
(tests/data/reference_energies.toml), as a markdown table.

    python benchmarks/auto.py [NAME ...] [--out runs/auto] [--budget SECONDS]
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

import tomllib

ROOT = Path(__file__).resolve().parents[1]
#: example -> reference key in tests/data/reference_energies.toml
REFERENCE = {"h": "H", "he": "He", "h-": "H-", "ps-": "Ps-", "li": "Li", "h2+": "H2+", "h2": "H2"}


def reference(key: str, particles: list) -> float:
    ref = tomllib.loads((ROOT / "tests" / "data" / "reference_energies.toml").read_text())[key]
    if ref["energy"] == "exact":  # hydrogen-like: -mu/(2 n^2)
        m1, m2 = (p["mass"] for p in particles)
        return -0.5 * m1 * m2 / (m1 + m2) / ref["n"] ** 2
    return ref["energy"]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("names", nargs="*", default=list(REFERENCE))
    ap.add_argument("--out", type=Path, default=Path("runs/auto"))
    args = ap.parse_args()
    print("| system | N_b | basis | E / Eh | E − E_ref | relative | wall (s) | stopped | command |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name in args.names:
        inp, out = ROOT / "examples" / "auto" / f"{name}.toml", args.out / name
        t = time.perf_counter()
        subprocess.run([sys.executable, "-m", "prebo", "run", str(inp), "--out", str(out), "--quiet"], check=True)
        wall = time.perf_counter() - t
        r = json.loads((out / "result.json").read_text())
        E_ref = reference(REFERENCE[name], r["particles"])
        err = r["energy"] - E_ref
        print(f"| {name} | {r['n_basis']} | {r['basis_type']} | {r['energy']:.10f} | {err:.2e} | "
              f"{err / abs(E_ref):.1e} | {wall:.0f} | {r['convergence']['stopped']} | "
              f"`prebo run examples/auto/{name}.toml` |", flush=True)


if __name__ == "__main__":
    main()
