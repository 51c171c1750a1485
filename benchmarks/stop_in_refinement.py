"""Stop a resumed run (SIGTERM) while its checkpoint stands in a refinement or replacement sweep at
the basis size, well before the sweep ends — the state to commit: a checkpoint written during a
pruning holds more functions than the size (tests/test_examples.py refuses it).

    python benchmarks/stop_in_refinement.py benchmarks/checkpoints/h2-cycles
"""
from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import time
from pathlib import Path


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folder", help="the run's folder, as given to `prebo run --resume`")
    ap.add_argument("--margin", type=int, default=10, help="functions before the sweep's end still accepted")
    a = ap.parse_args()
    path = Path(a.folder) / "basis.json"
    pids = subprocess.run(["pgrep", "-f", f"prebo run --resume {a.folder}"], capture_output=True, text=True).stdout
    if not pids.split():
        raise SystemExit(f"no `prebo run --resume {a.folder}` is running")
    while True:
        try:
            d = json.loads(path.read_text())
        except ValueError:  # caught between two writes
            time.sleep(0.5)
            continue
        p, size, nb = d["progress"], d["optimiser"]["size"], len(d["functions"])
        if nb == size and p["phase"] in ("refine", "sweep") and p["index"] < size - a.margin:
            break
        time.sleep(0.5)
    for pid in pids.split():
        os.kill(int(pid), signal.SIGTERM)
    time.sleep(2)
    d = json.loads(path.read_text())
    print(f"{path}: {len(d['functions'])} functions, E = {d['energy']!r}, elapsed {d['elapsed']} s, {d['progress']}")


if __name__ == "__main__":
    main()
