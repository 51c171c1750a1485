"""A ladder of levels optimised in one basis (issue 39): `prebo run INPUT --out DIR` of an input
with `[state] roots`, then each level of DIR/result.json against its literature energy
(tests/data/reference_energies.toml, by key, in the order of the roots), the transitions from the
lowest level against the literature ones in cm⁻¹, and the run's wall time, as markdown.

    python benchmarks/ladder.py examples/excited/h2plus-ladder.toml --out DIR --references "H2+" "H2+ v=1" "H2+ v=2" "H2+ v=3"
    python benchmarks/ladder.py examples/excited/h2plus-n1.toml --out DIR --references "H2+ N=1" "H2+ N=1 v=1"
    python benchmarks/ladder.py examples/excited/he-2-1s.toml --out DIR --references He "He-4 2 1S" --reuse
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

from prebo.io.toml import tomllib
from prebo.level.evaluate import HARTREE_CM

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("input")
    ap.add_argument("--out", type=Path, required=True)
    ap.add_argument("--references", nargs="+", required=True, help="reference keys, one per root from 0")
    ap.add_argument("--reuse", action="store_true", help="tabulate the finished run in --out instead of running it")
    args = ap.parse_args()
    refs = tomllib.loads((ROOT / "tests" / "data" / "reference_energies.toml").read_text())
    t = time.perf_counter()
    if not args.reuse:
        subprocess.run([sys.executable, "-m", "prebo", "run", args.input, "--out", str(args.out), "--quiet"], check=True)
    wall = time.perf_counter() - t
    r = json.loads((args.out / "result.json").read_text())
    levels = r.get("levels", [r | {"root": 0}])
    print(f"{args.input}: {r['n_basis']} {r['basis_type']} functions, targets {r.get('targets', [0])}, "
          f"stopped: {r['convergence']['stopped']} after {r['convergence']['seconds']:.0f} s of optimisation"
          + ("" if args.reuse else f", {wall:.0f} s wall"))
    print("\n| root | E / Eh | σ / Eh | reference / Eh | E − E_ref / Eh | E − E_0 / cm⁻¹ | reference / cm⁻¹ | source |")
    print("|---|---|---|---|---|---|---|---|")
    E_ref = [refs[k]["energy"] for k in args.references]
    for v in levels[:len(args.references)]:
        k = v["root"]
        gap = (v["energy"] - levels[0]["energy"]) * HARTREE_CM
        ref_gap = (E_ref[k] - E_ref[0]) * HARTREE_CM
        print(f"| {k} | {v['energy']:.12f} | {v['energy_uncertainty']:.1e} | {E_ref[k]:.12f} | "
              f"{v['energy'] - E_ref[k]:.2e} | {gap:.4f} | {ref_gap:.4f} | {refs[args.references[k]]['source']} |")


if __name__ == "__main__":
    main()
