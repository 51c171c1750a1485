"""Plain-ECG matrix-build throughput for 3- and 4-particle systems (issue 2, item 8).

Counts symmetrised-term evaluations: nb(nb+1)/2 pairs × number of permutations, each giving
S, T, T_TI and V. Runs each case in a subprocess per thread count (rayon's pool is fixed at start).

    python benchmarks/pecg_throughput.py            # prints a Markdown table
"""
import json
import os
import subprocess
import sys
import time

CASES = {"H- (p e e), 3 particles": (["p", "e", "e"], {"e": 0}),
         "H2 (p p e e), 4 particles": (["p", "p", "e", "e"], {"p": 0, "e": 0})}
NB = 400


def measure(case: str) -> dict:
    import numpy as np

    import prebo
    from prebo.integrals import laboratory
    sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "tests"))
    from conftest import random_basis

    particles, spin = CASES[case]
    system = prebo.System(particles, spin=spin)
    basis = random_basis(system, NB, np.random.default_rng(0), c_A=1.0)
    rep = laboratory(system)
    rep.matrices(basis.subset(slice(0, 10)))  # warm-up
    best = float("inf")
    for _ in range(3):
        t0 = time.perf_counter()
        rep.matrices(basis)
        best = min(best, time.perf_counter() - t0)
    terms = NB * (NB + 1) / 2 * len(rep.sym_c)
    return {"case": case, "nb": NB, "n_sym": len(rep.sym_c), "seconds": best, "M_terms_per_s": terms / best / 1e6}


def main():
    if len(sys.argv) == 3 and sys.argv[1] == "--one":
        print(json.dumps(measure(sys.argv[2])))
        return
    print("| case | nb | permutations | threads | seconds | M terms/s |\n|---|---|---|---|---|---|")
    for case in CASES:
        for threads in (1, 2):
            env = dict(os.environ, RAYON_NUM_THREADS=str(threads))
            out = subprocess.run([sys.executable, __file__, "--one", case], env=env, capture_output=True,
                                 text=True, check=True).stdout
            r = json.loads(out)
            print(f"| {case} | {r['nb']} | {r['n_sym']} | {threads} | {r['seconds']:.3f} | {r['M_terms_per_s']:.1f} |")


if __name__ == "__main__":
    main()
