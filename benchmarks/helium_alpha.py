"""Helium's 1¹S static dipole polarisability from an optimised first-order function: `prebo run`
of the four-line inputs examples/lines/he-alpha.toml (clamped nucleus, the ground basis
examples/bases/he-inf-1s) and he4-alpha.toml (⁴He, auto-he-700), each to the end of its adaptive
schedule or `--budget` seconds, against Pachucki & Sapirstein (tests/data/helium_lines_literature.toml);
the functional and α are read from the run's checkpoint as it goes, so the table gives α after 5
and 10 minutes and at the end, with the wall time (benchmarks/record/helium-lines.md).

    nice -n 5 python benchmarks/helium_alpha.py [he-alpha he4-alpha] [--out runs/alpha] [--budget 900]
"""
import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

from prebo.io.toml import tomllib

ROOT = Path(__file__).resolve().parents[1]
LITERATURE = tomllib.loads((ROOT / "tests" / "data" / "helium_lines_literature.toml").read_text())["polarisability_1s"]
REFERENCE = {"he-alpha": LITERATURE["infinite"]["value"], "he4-alpha": LITERATURE["finite"]["value"]}
#: seconds after which α is reported from the checkpoint while the run goes on
MARKS = (300, 600)


def run(name: str, out: Path, budget: float | None) -> None:
    """Run examples/lines/NAME.toml into out/NAME (with `budget` seconds, if given) and print α's
    relative error at MARKS and at the end."""
    folder = out / name
    t0 = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-m", "prebo", "run", str(ROOT / "examples" / "lines" / f"{name}.toml"),
                             "--out", str(folder), "--force", "--quiet"]
                            + ([] if budget is None else ["--budget", str(budget)]))
    marks = list(MARKS)
    while proc.poll() is None:
        time.sleep(1)
        if marks and time.perf_counter() - t0 >= marks[0]:
            d = json.loads((folder / "basis.json").read_text())
            alpha = -2 * d["objective"]
            print(f"{name} after {marks.pop(0)} s: {len(d['functions'])} functions, α {alpha:.12f}, "
                  f"{alpha / REFERENCE[name] - 1:+.2e} relative", flush=True)
    r = json.loads((folder / "result.json").read_text())
    alpha = r["response"]["alpha"][0]
    print(f"{name} done in {time.perf_counter() - t0:.0f} s ({r['convergence']['stopped']}): "
          f"{r['n_basis']} functions, α {alpha:.12f} "
          f"(sum over states {r['response']['sum_over_states'][0]:.12f}), {alpha / REFERENCE[name] - 1:+.2e} relative "
          f"to {REFERENCE[name]}", flush=True)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("names", nargs="*", default=["he-alpha", "he4-alpha"])
    p.add_argument("--out", type=Path, default=Path("runs") / "alpha")
    p.add_argument("--budget", type=float, help="seconds of each run (default: to the end of its schedule)")
    args = p.parse_args()
    for name in args.names:
        run(name, args.out, args.budget)


if __name__ == "__main__":
    main()
