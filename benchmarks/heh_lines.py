"""HeH⁺ (⁴He p e e, every particle quantum) lines (issue 57): `prebo run` of examples/heh+-n0.toml
(N = 0, parity +1) and examples/heh+-n1.toml (N = 1, parity −1), v = 0 and 1 in each, into
DIR/heh+-n0 and DIR/heh+-n1, then one `prebo transitions DIR/heh+-n0 DIR/heh+-n1 --roots 2 --json`:
the four levels, every line between them (wavenumber, reduced moment in length and velocity form
and their ratio, line and oscillator strength, Einstein A), the lifetimes, and the wall times of
the two runs and of the transitions command, as markdown.

    python benchmarks/heh_lines.py --out DIR
    python benchmarks/heh_lines.py --out examples/bases --reuse   # the stored bases
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RUNS = ("heh+-n0", "heh+-n1")


def prebo(*args: str) -> tuple[str, float]:
    """The standard output of `prebo ARGS` and its wall time (s), start-up included."""
    t = time.perf_counter()
    r = subprocess.run([sys.executable, "-m", "prebo", *args], check=True, capture_output=True, text=True)
    return r.stdout, time.perf_counter() - t


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, required=True, help="the folder of the two runs")
    ap.add_argument("--reuse", action="store_true", help="the runs' bases in --out, not run again")
    args = ap.parse_args()
    for name in RUNS:
        if not args.reuse:
            _, wall = prebo("run", str(ROOT / "examples" / f"{name}.toml"), "--out", str(args.out / name), "--quiet")
            print(f"prebo run examples/{name}.toml: {wall:.0f} s wall")
        r = json.loads((args.out / name / "result.json").read_text())
        print(f"{name}: {r['n_basis']} {r['basis_type']} functions, state {r['state']}, stopped: "
              f"{r['convergence']['stopped']} after {r['convergence']['seconds']:.0f} s of optimisation, "
              f"{r['wall_seconds']:.1f} s wall")
    out, wall = prebo("transitions", *(str(args.out / name) for name in RUNS), "--roots", "2", "--json")
    r = json.loads(out)
    print(f"\nprebo transitions {' '.join(str(args.out / n) for n in RUNS)} --roots 2 --json: {wall:.1f} s wall")
    label = [f"N = {v['N']}, v = {v['root']}" for v in r["levels"]]
    print("\n| level | E / Eh |\n|---|---|")
    for k, v in enumerate(r["levels"]):
        print(f"| {label[k]} | {v['energy']:.12f} |")
    print("\n| lower → upper | ν / cm⁻¹ | <‖d‖> length / e a₀ | velocity / e a₀ | velocity/length | S / e² a₀² "
          "| f | A / s⁻¹ |\n|---|---|---|---|---|---|---|---|")
    for line in r["lines"]:
        pair = f"{label[line['lower']]} → {label[line['upper']]}"
        if "forbidden" in line:
            print(f"| {pair} | {line['cm-1']:.4f} | {line['forbidden']} | | | | | |")
            continue
        print(f"| {pair} | {line['cm-1']:.4f} | {line['length']:.9f} | {line['velocity']:.9f} | "
              f"{line['velocity/length']:.6f} | {line['line_strength']:.6e} | {line['oscillator_strength']:.6e} | "
              f"{line['einstein_A']:.6e} |")
    print("\n| level | lifetime / s | lines below it computed |\n|---|---|---|")
    for v in r["lifetimes"]:
        print(f"| {label[v['level']]} | {v['lifetime']:.6e} | {v['lines']} |")


if __name__ == "__main__":
    main()
