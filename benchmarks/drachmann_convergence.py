"""Convergence of the contact density ⟨δ³(r_ij)⟩ with the basis size, direct ("delta") against
Drachmann's regularised form (prebo.drachmann; docs/properties-derivations.md §6, eq. 27).

Hydrogen (finite proton mass) 1s in the n even-tempered s Gaussians 3e-3 · 1.6^k bohr⁻², k < n,
against μ³/π; ⁴He ground state in the first k functions of
examples/bases/auto-he-700 (grown in that order), against the 700-function regularised values;
H2⁺ (p p e) ground state in the first k functions of the floating-ECG (400) and ECG-GVR (180)
examples, whose ⟨V/r_ij⟩ is the quadrature of eq. (38), with the seconds each row took.

    nice -n 19 python benchmarks/drachmann_convergence.py
"""
import sys
import time
from pathlib import Path

import numpy as np

import prebo
from prebo import eigen
from prebo.drachmann import delta_regularised
from prebo.expectation import expectation
from prebo.integrals import laboratory

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
from conftest import hydrogen_s  # noqa: E402


def contact(basis):
    """(E, direct, regularised) of the lowest state of `basis`."""
    rep = laboratory(basis.system)
    m = rep.matrices(basis)
    ti = eigen.solve(m["T_ti"] + m["V"], m["S"], eigen.THRESHOLD, 1)
    C, E = ti.vectors[:, :1], ti.energies[:1]
    return E[0], expectation(rep, basis, C, "delta")[0], delta_regularised(rep, basis, C, E)[0]


def hydrogen():
    print("H 1s (finite proton mass), n Gaussians 3e-3 · 1.6^k bohr⁻²; relative errors against μ³/π")
    print(f"{'n':>4} {'E + μ/2 (Eh)':>14} {'direct':>10} {'regularised':>12}")
    for n in (10, 20, 30, 40, 50):
        basis, mu = hydrogen_s(3e-3 * 1.6 ** np.arange(n))
        E, d, r = contact(basis)
        exact = mu**3 / np.pi
        print(f"{n:>4} {E + mu / 2:>14.3e} {d['e-p'] / exact - 1:>10.2e} {r['e-p'] / exact - 1:>12.2e}")


def helium():
    full = prebo.Basis.load(ROOT / "examples" / "bases" / "auto-he-700" / "basis.json")
    rows = [(k, *contact(full.subset(np.arange(k)))) for k in (50, 100, 200, 400, 700)]
    ref = rows[-1][3]
    print("\n⁴He 1¹S, first k functions of auto-he-700; values and (in brackets) differences from the "
          "700-function regularised value")
    print(f"{'k':>4} {'E (Eh)':>16} {'δ(r_αe) direct':>26} {'regularised':>26} {'δ(r_ee) direct':>26} {'regularised':>26}")
    for k, E, d, r in rows:
        cells = [f"{x[label]:.8f} ({x[label] - ref[label]:+.1e})" for label in ("alpha-e",) for x in (d, r)]
        cells += [f"{x[label]:.8f} ({x[label] - ref[label]:+.1e})" for label in ("e-e",) for x in (d, r)]
        print(f"{k:>4} {E:>16.10f} " + " ".join(f"{c:>26}" for c in cells))


def h2plus():
    print("\nH2⁺ ground state, first k functions of the examples; ⟨δ³(r_ep)⟩ and ⟨δ³(r_pp)⟩ (bohr⁻³)")
    print(f"{'basis':>12} {'k':>4} {'E (Eh)':>16} {'δ(r_ep) direct':>15} {'regularised':>12} "
          f"{'δ(r_pp) direct':>15} {'regularised':>12} {'s':>6}")
    for name, sizes in (("h2plus-fecg", (30, 100, 400)), ("h2plus-gvr", (20, 60, 180))):
        full = prebo.Basis.load(ROOT / "examples" / "bases" / name / "basis.json")
        for k in sizes:
            t = time.perf_counter()
            E, d, r = contact(full.subset(np.arange(k)))
            print(f"{name:>12} {k:>4} {E:>16.10f} {d['e-p']:>15.8f} {r['e-p']:>12.8f} {d['p-p']:>15.3e} "
                  f"{r['p-p']:>12.3e} {time.perf_counter() - t:>6.1f}", flush=True)


if __name__ == "__main__":
    hydrogen()
    helium()
    h2plus()
