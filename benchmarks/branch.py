"""A branch of a run: its checkpoint copied to another folder with settings changed, the cursor
put at the start of a phase of the checkpoint's cycle and a wall-time budget of so many more
seconds, for design changes measured from one start (benchmarks/record/h2.md, "The H2 campaign").
Resume the branch with `prebo run --resume DST`.

    python benchmarks/branch.py benchmarks/checkpoints/h2-cycles runs/k-moves --phase sweep --seconds 600 \
        sweeps=100 refine=1 polish=0 cycles=31
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

from prebo.optimise.settings import SETTINGS


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("src", type=Path, help="run folder with basis.json")
    ap.add_argument("dst", type=Path, help="folder of the branch")
    ap.add_argument("settings", nargs="*", help="optimiser settings, key=JSON value")
    ap.add_argument("--phase", choices=("prune", "sweep", "refine", "polish"), help="start of this phase of the cycle")
    ap.add_argument("--seconds", type=float, help="budget: the checkpoint's elapsed seconds plus these")
    a = ap.parse_intermixed_args()
    d = json.loads((a.src / "basis.json").read_text())
    for item in a.settings:
        key, value = item.split("=", 1)
        if key not in SETTINGS:
            ap.error(f"unknown setting {key!r}")
        d["optimiser"][key] = json.loads(value)
    if a.phase:
        d["progress"] = {"phase": a.phase, "sweep": 0, "index": 0, "cycle": d["progress"]["cycle"]}
    if a.seconds is not None:
        d["optimiser"]["budget"] = d["elapsed"] + a.seconds
    d["stopped"] = None
    a.dst.mkdir(parents=True, exist_ok=True)
    (a.dst / "basis.json").write_text(json.dumps(d))
    print(f"{a.dst / 'basis.json'}: {d['elapsed']} s, E = {d['energy']}, progress {d['progress']}")


if __name__ == "__main__":
    main()
