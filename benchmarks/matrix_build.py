"""Overlap + Hamiltonian matrix build speed for the ecgpack bases He-490 and Li-100.

    python benchmarks/matrix_build.py                 # 1 and 2 threads, both bases, table
    python benchmarks/matrix_build.py --threads 1 2 4 --repeat 7 --json out.json

Other work on the machine distorts the figures (2 cores here): before each run the script
waits up to --wait-idle seconds for a 90 % idle machine and reports the idle share it saw.

Each measurement runs in a fresh subprocess with RAYON_NUM_THREADS set (rayon's pool
is fixed when it starts) and times what prebo.evaluate uses: the laboratory-frame
representation's `matrices` call (prebo.integrals.laboratory(system).matrices(basis):
S, T, T_TI and V of the symmetrised basis through prebo._core.Engine.matrices, from the basis
object to the four numpy arrays; freeing them afterwards is not timed), best of
`--repeat` after one warm-up. `--representation ti` times the translationally invariant
(Jacobi) representation instead. Speed is in matrix elements per second, ecgpack's
measure: K²/2 × (number of symmetry terms) / seconds, the symmetry terms being the
permutations prebo sums over (He: 2, Li: 6 — ecgpack's Young string (1+P23)(1−P24)
expands to Y†Y with 6 terms).
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "tests" / "data" / "ecgpack"
BASES = {"He-490": DATA / "ecgpack-He4-490.inout.txt", "Li-100": DATA / "ecgpack-Li7-100.inout.txt"}
#: ecgpack's own figures (M elements/s) on a machine of this kind, from issue 5
ECGPACK = {("He-490", 1): (10.1, 10.8), ("He-490", 2): (17.8, 19.4),
           ("Li-100", 1): (8.3, 9.5), ("Li-100", 2): (14.0, 15.4)}


def measure(name: str, repeat: int, representation: str) -> dict:
    """Runs inside the subprocess."""
    from prebo import _core
    from prebo.io.ecgpack import read_inout
    from prebo.integrals import laboratory, translationally_invariant

    basis = read_inout(BASES[name])
    system = basis.system
    rep = laboratory(system) if representation == "lab" else translationally_invariant(system)
    rep.matrices(basis)  # warm-up (pool start, page faults)
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        m = rep.matrices(basis)
        times.append(time.perf_counter() - t0)
        del m  # freeing the four matrices is not part of the build
    K, terms = len(basis), len(system.symmetriser.coefficients)
    elements = K * K / 2 * terms
    best = min(times)
    return {"basis": name, "threads": _core.num_threads(), "K": K, "terms": terms,
            "representation": representation, "seconds_best": best,
            "seconds_median": sorted(times)[len(times) // 2],
            "M_elements_per_s": elements / best / 1e6}


def _cpu_times():
    with open("/proc/stat") as f:
        v = [float(x) for x in f.readline().split()[1:]]
    return v[3] + v[4], sum(v)  # idle + iowait, total


def idle_fraction(seconds: float = 1.0) -> float:
    """Share of all CPUs idle over `seconds` (1.0: nothing else running); 1.0 where unknown."""
    try:
        i0, t0 = _cpu_times()
        time.sleep(seconds)
        i1, t1 = _cpu_times()
        return (i1 - i0) / max(t1 - t0, 1e-9)
    except OSError:
        return 1.0


def wait_idle(limit: float, need: float = 0.9) -> float:
    """Wait up to `limit` seconds for a machine at least `need` idle; the last idle share seen."""
    deadline = time.monotonic() + limit
    idle = idle_fraction()
    while idle < need and time.monotonic() < deadline:
        idle = idle_fraction()
    return idle


def machine() -> dict:
    model = "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return {"nproc": os.cpu_count(), "cpu": model, "python": platform.python_version()}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--bases", nargs="+", default=list(BASES), choices=list(BASES))
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--representation", choices=["lab", "ti"], default="lab")
    ap.add_argument("--json", help="also write the results to this file")
    ap.add_argument("--wait-idle", type=float, default=60.0, metavar="S",
                    help="before each run wait up to S seconds for a >= 90%% idle machine (default 60)")
    ap.add_argument("--one", help=argparse.SUPPRESS)  # internal: measure one basis here
    args = ap.parse_args(argv)
    if args.one:
        print(json.dumps(measure(args.one, args.repeat, args.representation)))
        return 0
    rows = []
    for name in args.bases:
        for t in args.threads:
            env = dict(os.environ, RAYON_NUM_THREADS=str(t))
            idle = wait_idle(args.wait_idle)
            out = subprocess.run([sys.executable, __file__, "--one", name, "--repeat", str(args.repeat),
                                  "--representation", args.representation],
                                 env=env, capture_output=True, text=True, check=True)
            rows.append(json.loads(out.stdout.strip().splitlines()[-1]) | {"idle_before": idle})
    m = machine()
    print(f"# {m['cpu']}, nproc {m['nproc']}, representation {args.representation}")
    print(f"{'basis':8s} {'threads':>7s} {'K':>5s} {'terms':>5s} {'best s':>9s} {'M el/s':>8s} "
          f"{'ecgpack M/s':>12s} {'x':>5s} {'idle':>5s}")
    for r in rows:
        ref = ECGPACK.get((r["basis"], r["threads"]))
        ratio = f"{r['M_elements_per_s'] / ref[1]:5.1f}" if ref else "    -"
        refs = f"{ref[0]}-{ref[1]}" if ref else "-"
        print(f"{r['basis']:8s} {r['threads']:7d} {r['K']:5d} {r['terms']:5d} {r['seconds_best']:9.5f} "
              f"{r['M_elements_per_s']:8.1f} {refs:>12s} {ratio} {r['idle_before']:5.0%}")
    if args.json:
        Path(args.json).write_text(json.dumps({"machine": m, "results": rows}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
