"""H₂'s dissociation energy D₀ = 2 E(H) − E(H₂, v = 0) and fundamental ν(0 → 1) from prebo alone (every
particle quantum, N = 0), part by part in α (level/budget.py), against the budget of Piszczatowski et
al. (tests/data/properties_literature.toml: its α⁰, α² and α³ parts as the abstract gives them), with
the wall time of each, as markdown.

    python benchmarks/h2_d0.py                                   # α⁰ and α²
    python benchmarks/h2_d0.py --qed [--qed-out DIR] [--size N] [--k K...] [--fundamental-qed]   # and α³ (long)

The H₂ levels are benchmarks/checkpoints/h2-auto (v = 0, 500 ECG-GVR, 1.05e-8 Eh above the
literature) and benchmarks/checkpoints/h2-v01 (v = 0 and 1, 600 ECG-GVR); H is examples/bases/h
(40 plain ECGs, the proton's mass). α³ (D₀'s levels with --qed, the fundamental's with
--fundamental-qed too) takes the
Bethe logarithm of each level from first-order bases the driver optimises on a grid of photon
energies (optimise/current.py; kept in --qed-out and reused).
"""
from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

from prebo.io.load import basis_file, load_basis
from prebo.io.toml import tomllib
from prebo.level import budget
from prebo.level.evaluate import evaluate
from prebo.level.properties import reported
from prebo.level.qed import of_level
from prebo.optimise.current import SIZE, responses

ROOT = Path(__file__).resolve().parents[1]

#: the literature's budget of D₀ (tests/data/properties_literature.toml)
KEY = "h2_dissociation_alpha2"


def parts_of(name: str, roots: int, args, qed: bool) -> tuple[list[dict], float]:
    """The budgets of the lowest `roots` levels of the stored basis `name` (α³ if `qed`), and the
    seconds they took."""
    basis, threshold = load_basis(basis_file(str(ROOT / name)))
    t = time.perf_counter()
    e = evaluate(basis, threshold=threshold, roots=roots, operators=reported(basis.family, True))
    levels = e.get("levels", [e])
    out = []
    for v in levels:
        q = None
        if qed:
            bases, K = responses(basis, v["root"], args.k, args.size,
                                 args.qed_out / Path(name).name / f"root{v['root']}", threshold)
            q = of_level(basis, bases, v["root"], threshold=threshold, K=K)
        out.append(budget.of_level(basis, v, q))
    return out, time.perf_counter() - t


def row(label: str, parts: dict, ref: dict | None = None) -> str:
    cells = []
    for p in budget.PARTS + ("total",):
        x = parts.get(p)
        cells.append("" if x is None else f"{x['cm-1']:.6f} ± {x['uncertainty_cm-1']:.1e}")
    return f"| {label} | " + " | ".join(cells) + " |"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--qed", action="store_true", help="add α³ (the Bethe logarithm of every level: long)")
    ap.add_argument("--fundamental-qed", action="store_true", help="with --qed: α³ of the fundamental's levels too")
    ap.add_argument("--qed-out", type=Path, default=Path("runs/h2-d0-qed"), help="the first-order bases' folder")
    ap.add_argument("--size", type=int, default=SIZE, help="functions per photon energy")
    ap.add_argument("--k", type=float, nargs="+", help="photon energies (Eh; default current.grid)")
    args = ap.parse_args()
    lit = tomllib.loads((ROOT / "tests" / "data" / "properties_literature.toml").read_text())[KEY]
    (h,), t_h = parts_of("examples/bases/h", 1, args, args.qed)
    (h2,), t_h2 = parts_of("benchmarks/checkpoints/h2-auto", 1, args, args.qed)
    (v0, v1), t_v = parts_of("benchmarks/checkpoints/h2-v01", 2, args, args.qed and args.fundamental_qed)
    d0 = {p: budget.part(2 * h[p]["Eh"] - h2[p]["Eh"], math.hypot(2 * h[p]["uncertainty"], h2[p]["uncertainty"]))
          for p in budget.PARTS if p in h and p in h2}
    d0["total"] = budget.total(d0)
    nu = budget.line(v0, v1)
    print("| quantity | α⁰ (cm⁻¹) | α² (cm⁻¹) | α³ (cm⁻¹) | total (cm⁻¹) |")
    print("|---|---|---|---|---|")
    print(row("H (1s)", h))
    print(row("H₂ v = 0 (500)", h2))
    print(row("D₀ = 2E(H) − E(H₂)", d0))
    print(row("ν(0 → 1) (600)", nu))
    for p, ref in (("alpha0", lit["alpha0"]), ("alpha2", lit["value"]), ("alpha3", lit["alpha3"])):
        if p in d0:
            print(f"D₀'s {p}: prebo {d0[p]['cm-1']:.6f} cm⁻¹, literature {ref['value']} ± {ref['uncertainty']}: "
                  f"{d0[p]['cm-1'] - ref['value']:+.4f} cm⁻¹")
    print(f"wall time: H {t_h:.0f} s, H₂ {t_h2:.0f} s, H₂ v = 0, 1 {t_v:.0f} s")


if __name__ == "__main__":
    main()
