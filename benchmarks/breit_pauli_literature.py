"""The Breit–Pauli correction of stored ECG-GVR bases against the literature, with the seconds each
took (`prebo.properties`, direct ⟨δ³⟩; docs/relativistic.md).

- H2 (p p e e) v = 0 in the 500-function checkpoint benchmarks/checkpoints/h2-auto: the order-α²
  part of the dissociation energy, 2 E_BP(H) − E_BP(H2), E_BP(H) the finite-mass hydrogen 1s
  closed form (Barker & Glover; docs/relativistic.md), against the adiabatic −0.5319(3) cm⁻¹ of
  tests/data/properties_literature.toml, whose authors put the neglected recoil terms at ±0.0004.
- H2⁺ (p p e) v = 0–3 in the 250-function ladder examples/bases/h2plus-ladder: each level's
  correction and the α² shift of the transitions from v = 0 (no literature value reached).

    nice -n 19 python benchmarks/breit_pauli_literature.py [--regularised]

--regularised: H2 with the regularised δ and p⁴ (docs/relativistic.md), the ⟨V/r_ij⟩ quadrature of
ECG-GVR functions included (about five minutes), instead of the direct ones.
"""
import argparse
import time
import tomllib
from pathlib import Path

import prebo
from prebo.level.evaluate import HARTREE_CM
from prebo.level.relativistic import ALPHA

ROOT = Path(__file__).resolve().parents[1]


def hydrogen_1s(M: float) -> float:
    """E_BP of hydrogen 1s with a proton of mass M (Eh): −μα²/8 − μ²α²/(8(1 + M))."""
    mu = M / (1 + M)
    return -mu * ALPHA**2 / 8 - mu**2 * ALPHA**2 / (8 * (1 + M))


def timed(basis, root=0, regularised=None):
    start = time.perf_counter()
    p = prebo.properties(basis, root=root, regularised=regularised)
    return p, time.perf_counter() - start


def h2(regularised: bool):
    lit = tomllib.loads((ROOT / "tests" / "data" / "properties_literature.toml").read_text())["h2_dissociation_alpha2"]
    basis = prebo.Basis.load(ROOT / "benchmarks" / "checkpoints" / "h2-auto" / "basis.json")
    p, seconds = timed(basis, regularised=regularised or None)
    bp = p["breit_pauli"]["Eh"]
    M = basis.system.particles[0].mass
    d0 = (2 * hydrogen_1s(M) - bp["total"]) * HARTREE_CM
    kind = "regularised" if p["breit_pauli"]["regularised"] else "direct"
    print(f"H2 v = 0, {len(basis)} ECG-GVR functions, E = {p['energy']:.12f} Eh, {kind} δ and p⁴ ({seconds:.1f} s)")
    for term, value in bp.items():
        print(f"  {term:14s} {value: .9e} Eh {value * HARTREE_CM: .6f} cm⁻¹")
    print(f"  2 E_BP(H) = {2 * hydrogen_1s(M) * HARTREE_CM:.6f} cm⁻¹; α² part of D0: {d0:.6f} cm⁻¹, "
          f"literature {lit['value']['value']} ± {lit['value']['uncertainty']} (recoil ± {lit['recoil']['value']}): "
          f"{d0 - lit['value']['value']:+.6f} cm⁻¹")


def h2plus():
    basis = prebo.Basis.load(ROOT / "examples" / "bases" / "h2plus-ladder" / "basis.json")
    print(f"H2⁺ N = 0, {len(basis)} ECG-GVR functions")
    totals = []
    for v in range(4):
        p, seconds = timed(basis, root=v)
        totals.append(p["breit_pauli"]["cm-1"]["total"])
        shift = f", v = 0 → {v} shifted {totals[-1] - totals[0]:+.6f} cm⁻¹" if v else ""
        print(f"  v = {v}: E = {p['energy']:.12f} Eh, E_BP = {totals[-1]:.6f} cm⁻¹{shift} ({seconds:.1f} s)")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--regularised", action="store_true", help="H2 with the regularised δ and p⁴")
    args = ap.parse_args()
    h2plus()
    h2(args.regularised)
