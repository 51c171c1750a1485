"""Powell vs gradient refinement in a whole optimisation: para-H2+ ECG-GVR grown to --size
functions (every winner refined), then one refinement sweep, for several seeds.

    python benchmarks/growth_methods.py --size 60 --seeds 1 2 3 4
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

INPUT = """
[system]
particles = [{{ name = "p", mass = 1836.15267 }}, {{ name = "p", mass = 1836.15267 }}, "e"]
[state]
N = 0
spin = {{ p = 0 }}
[basis]
type = "ecg-gvr"
size = {size}
K_max = 30
[optimiser]
trials = 30
refine = 1
refine_method = "{method}"
seed = {seed}
channels = "all"
length_range = [0.005, 15.0]
"""


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=60)
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3, 4])
    args = ap.parse_args()
    print("| seed | method | E after growth | s | E after one sweep | s |")
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for seed in args.seeds:
            for method in ("gradient", "powell"):
                path = Path(tmp) / f"{method}-{seed}.toml"
                path.write_text(INPUT.format(size=args.size, method=method, seed=seed))
                out = Path(tmp) / f"{method}-{seed}"
                subprocess.run([sys.executable, "-m", "prebo", "run", path, "--out", out, "--quiet"], check=True)
                history = json.loads((out / "basis.json").read_text())["history"]
                grown = [h for h in history if h[2] == "grow"][-1]
                print(f"| {seed} | {method} | {grown[1]:.9f} | {grown[3]:.1f} | {history[-1][1]:.9f} | {history[-1][3]:.1f} |",
                      flush=True)


if __name__ == "__main__":
    main()
