"""Convergence of the Bethe logarithm ln k₀ (level/bethe.py) from first-order bases the driver optimises
on a grid of photon energies k (optimise/current.py `current_bases`), as `prebo properties --qed`
joins them: the unions of the bases of the lowest j photon energies, j = 1 … len(grid), each a row,
with the split point K chosen as given (`--split`: "top", the grid's largest k; "default",
bethe.py's default (`bethe.split` since this record's rows, which were measured with the former
SPLIT = 1e-5 of the bases' kinetic scale); "top/F", the largest k over F; or a number in Eh).

Systems (`system`): "h" — hydrogen 1s (p e, finite proton mass) in even-tempered Gaussians
0.002·1.7^i bohr⁻² up to --ground-hi (default 1e10), against Drake & Swainson's 2.984128556 in the
reduced Rydberg μ/2 (the unit used for h); "he-inf" — helium 1¹S at infinite nuclear mass,
examples/bases/he-inf-1s (700 plain ECGs), against Korobov's 4.37016022306 (arXiv:1203.1404, R_∞);
"h2plus" — para-H2⁺ (p p e, N = 0) level `--root` of examples/bases/h2plus-ladder (250 ECG-GVR, v =
0–3), v = 0 against Korobov's 3.012230335 (same abstract; R_∞). `--ground` replaces the ground basis.

Each k's run is kept in OUT/k=<k> (OUT from the system, root, size, seed and budget unless --out is
given) and read back on a second call, so a finer grid or another split reuses the runs it shares;
the seconds a run took are its checkpoint's. Prints, per split and per union, the functions, K,
ln k₀, the pseudostate sum, the error against the literature, the fitted O(k⁻²) share and the sum
rules' ratios Σs_n/⟨J'²⟩ and Σs_nΔE_n/D. Where a union fails to solve (LinearDependenceError: functions of
neighbouring k nearly coincide), every union is taken again without the functions whose normalised
overlap with an earlier one exceeds --max-overlap, and the table says how many went. Record:
benchmarks/record/bethe-logarithm.md.

    RAYON_NUM_THREADS=1 OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 \\
        python benchmarks/bethe_convergence.py h --decades 0.3 1e4 --per-decade 1 --size 12 --split top default
"""
from __future__ import annotations

import argparse
import json
import math
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

import prebo
from prebo.basis import Basis
from prebo.coordinates import jacobi
from prebo.errors import LinearDependenceError
from prebo.integrals import laboratory
from prebo.io.load import basis_file, load_basis
from prebo.level.bethe import R_INFINITY, bethe_logarithm, kinetic_scale, reduced_rydberg
from prebo.optimise.checkpoint import CHECKPOINT
from prebo.optimise.current import current_bases, folder_of
from prebo.optimise.settings import Optimiser

ROOT = Path(__file__).resolve().parents[1]

#: the literature's ln k₀ per (system, root), and the unit it is quoted in ("reduced" or R_∞)
LITERATURE = {("h", 0): 2.984128556, ("he-inf", 0): 4.37016022306, ("h2plus", 0): 3.012230335}

GROUNDS = {"he-inf": ROOT / "examples/bases/he-inf-1s", "h2plus": ROOT / "examples/bases/h2plus-ladder"}


def hydrogen(hi: float, lo: float = 0.002, ratio: float = 1.7, c_A: float = 0.7) -> Basis:
    """Hydrogen (p e, N = 0) in even-tempered s Gaussians lo·ratio^i of the relative coordinate up to hi."""
    system = prebo.System(["p", "e"], N=0, parity=1)
    coords = jacobi(system.masses)
    exps = lo * ratio ** np.arange(int(math.log(hi / lo) / math.log(ratio)) + 1)
    A = np.array([coords.to_lab(np.array([[a]]), c_A) for a in exps])
    return prebo.Basis(system, A, np.full(len(A), c_A))


def ground_of(args) -> tuple[Basis, float]:
    """The ground basis and its overlap threshold."""
    if args.ground:
        return load_basis(basis_file(args.ground))
    if args.system == "h":
        return hydrogen(args.ground_hi), prebo.eigen.THRESHOLD
    return load_basis(basis_file(GROUNDS[args.system]))


def photon_energies(args) -> list[float]:
    if args.k:
        return sorted(args.k)
    lo, hi = args.decades
    n = round(args.per_decade * math.log10(hi / lo)) + 1
    return [float(f"{x:.6g}") for x in np.geomspace(lo, hi, n)]


def split_of(choice: str, ks: list[float]):
    if choice == "top":
        return ks[-1]
    if choice == "default":
        return None
    if choice.startswith("top/"):
        return ks[-1] / float(choice[4:])
    return float(choice)


def deduplicated(basis: Basis, largest: float) -> tuple[Basis, int]:
    """`basis` without the functions whose normalised overlap with an earlier kept one exceeds `largest`."""
    S = laboratory(basis.system).matrices(basis)["S"]
    d = 1 / np.sqrt(np.diag(S))
    O = np.abs(S * np.outer(d, d))
    keep = []
    for i in range(len(basis)):
        if all(O[i, j] <= largest for j in keep):
            keep.append(i)
    return basis.subset(np.array(keep)), len(basis) - len(keep)


def main(argv=None) -> dict:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("system", choices=("h", "he-inf", "h2plus"))
    p.add_argument("--root", type=int, default=0)
    p.add_argument("--ground", help="a ground basis (file or folder) in place of the system's")
    p.add_argument("--ground-hi", type=float, default=1e10, help="h: the ground basis's largest exponent (bohr⁻²)")
    p.add_argument("--k", type=float, nargs="+", help="the photon energies (Eh)")
    p.add_argument("--decades", type=float, nargs=2, default=(0.3, 1e4), metavar=("LO", "HI"),
                   help="without --k: photon energies from LO to HI (Eh), geometric")
    p.add_argument("--per-decade", type=float, default=1.0)
    p.add_argument("--size", type=int, default=12, help="functions per photon energy")
    p.add_argument("--budget", type=float, help="seconds per photon energy's run (default: none)")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--split", nargs="+", default=["top"], help="K choices: top, default, top/F, or Eh")
    p.add_argument("--window", type=float, nargs="+", default=[100.0],
                   help="the fit windows [K/window, K] to try (bethe.py's default 100)")
    p.add_argument("--max-overlap", type=float, default=0.9999,
                   help="where a union fails to solve (LinearDependenceError), drop the functions whose normalised "
                        "overlap with an earlier one exceeds this, and say so")
    p.add_argument("--regularised", choices=("auto", "yes", "no"), default="auto",
                   help="Drachmann's ⟨δ³⟩ in D (auto: bethe.py's choice)")
    p.add_argument("--rows", choices=("all", "last"), default="all", help="every union, or the whole grid's only")
    p.add_argument("--out", help="the runs' folder (default /work/notes/bethe/runs/<settings>)")
    p.add_argument("--json", help="write the rows to this file")
    args = p.parse_args(argv)

    ground, threshold = ground_of(args)
    ks = photon_energies(args)
    tag = f"{args.system}-r{args.root}-n{args.size}-s{args.seed}" + (f"-b{args.budget:g}" if args.budget else "") \
        + (f"-hi{args.ground_hi:g}" if args.system == "h" and not args.ground else "")
    out = Path(args.out or f"/work/notes/bethe/runs/{tag}")
    opts = Optimiser(seed=args.seed, budget=args.budget)
    R = reduced_rydberg(ground.system) if args.system == "h" else R_INFINITY
    exact = LITERATURE.get((args.system, args.root))
    regularised = {"auto": None, "yes": True, "no": False}[args.regularised]

    print(f"{args.system} root {args.root}: ground {len(ground)} functions, kinetic scale {kinetic_scale(ground):.3e} Eh; "
          f"k = {ks}; size {args.size}; runs in {out}")
    parts, seconds = [], []
    for x in ks:
        t = time.perf_counter()
        (b,) = current_bases(ground, args.root, [x], args.size, out, threshold, replace(opts))
        wall = time.perf_counter() - t
        elapsed = json.loads((folder_of(out, x) / CHECKPOINT).read_text()).get("elapsed", wall)
        parts.append(b)
        seconds.append(float(elapsed))
        print(f"  k = {x:<10.4g} {len(b):>3} functions, run {elapsed:7.1f} s (this call {wall:.1f} s)", flush=True)
    unions = [Basis.concat(parts[:j + 1]) for j in range(len(parts))]
    if args.rows == "last":
        unions = unions[-1:]
    rows = []
    header = (f"{'split':>9} {'n':>5} {'k_max':>8} {'K (Eh)':>9} {'ln k0':>13} {'pseudostate':>12} {'error':>10} "
              f"{'fit share':>10} {'Σs/J2-1':>9} {'Σsde/D-1':>9}")
    dropped = [0] * len(unions)
    for choice, window in [(c, w) for c in args.split for w in args.window]:
        t = time.perf_counter()
        try:
            r = bethe_logarithm(ground, unions, args.root, rydberg=R, K=split_of(choice, ks), window=window,
                                regularised=regularised, threshold=threshold)
        except LinearDependenceError as exc:
            if any(dropped):
                raise
            print(f"\nthe unions {[len(u) for u in unions]}: LinearDependenceError: {exc}")
            pairs = [deduplicated(u, args.max_overlap) for u in unions]
            unions, dropped = [u for u, _ in pairs], [n for _, n in pairs]
            print(f"  dropped per union the functions of normalised overlap > {args.max_overlap} with an earlier one: "
                  f"{dropped}")
            r = bethe_logarithm(ground, unions, args.root, rydberg=R, K=split_of(choice, ks), window=window,
                                regularised=regularised, threshold=threshold)
        wall = time.perf_counter() - t
        print(f"\nsplit {choice}, window {window:g}: D = {r['D']:.10g} (regularised {r['regularised']}), J2 = {r['J2']:.10g}, "
              f"bethe_logarithm {wall:.1f} s; fit b = {r['integral']['fit']['b']:.4g}, e = {r['integral']['fit']['e']:.4g}")
        print(header)
        first = len(ks) - len(unions)
        for j, c in enumerate(r["convergence"]):
            err = c["ln_k0"] - exact if exact is not None else float("nan")
            row = {"system": args.system, "root": args.root, "split": choice, "window": window,
                   "dropped": dropped[j], "n_basis": c["n_basis"],
                   "k_max": ks[first + j], "K": c["K"], "ln_k0": c["ln_k0"], "pseudostate": c["pseudostate"],
                   "error": err, "J2_ratio": c["J2_response"] / r["J2"] - 1, "D_ratio": c["D_response"] / r["D"] - 1,
                   "optimise_seconds": sum(seconds[:first + j + 1]), "bethe_seconds": wall, "size": args.size,
                   "ks": ks[:first + j + 1]}
            if j == len(r["convergence"]) - 1:
                row["fit_share"] = r["integral"]["fit"]["share"]
            rows.append(row)
            share = f"{row['fit_share']:10.2e}" if "fit_share" in row else f"{'':>10}"
            print(f"{choice:>9} {c['n_basis']:>5} {row['k_max']:>8.3g} {c['K']:>9.3g} {c['ln_k0']:>13.9f} "
                  f"{c['pseudostate']:>12.7f} {err:>10.2e} {share} {row['J2_ratio']:>9.1e} {row['D_ratio']:>9.1e}")
    print(f"\noptimisation {sum(seconds):.1f} s over {len(ks)} photon energies (run seconds, checkpoints)")
    if args.json:
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        Path(args.json).write_text(json.dumps({"argv": argv, "rows": rows}, indent=1))
    return {"rows": rows}


if __name__ == "__main__":
    main()
