"""Convergence of the contact density ⟨δ³(r_ij)⟩ and of the lightest particles' ⟨p⁴⟩ with the basis
size, direct against regularised (prebo.level.drachmann: Drachmann's δ, eq. 27, and ⟨p⁴⟩ by ⟨T_TI²⟩ =
⟨(E − V)²⟩, eq. 27'; docs/properties-derivations.md §6).

Hydrogen (finite proton mass) 1s in the n even-tempered s Gaussians 3e-3 · 1.6^k bohr⁻², k < n,
against μ³/π and 5μ⁴; ⁴He ground state in the first k functions of examples/bases/auto-he-700
(grown in that order), against the 700-function regularised values; H2⁺ (p p e) ground state in
the first k functions of the floating-ECG (400) and ECG-GVR (180) examples, whose ⟨V/r_ij⟩ is the
quadrature of eq. (38), with the seconds each row took (`prebo.properties`, every property).

    nice -n 19 python benchmarks/drachmann_convergence.py
"""
import sys
import time
from pathlib import Path

import numpy as np

import prebo

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
from conftest import hydrogen_s  # noqa: E402


def contact(basis):
    """(E, direct δ, regularised δ, direct ⟨p⁴⟩, regularised ⟨p⁴⟩) of the lowest state of `basis`."""
    p = prebo.properties(basis, regularised=True)
    return p["energy"], p["expectation"]["delta"], p["delta_regularised"], p["expectation"]["p4"], p["p4_regularised"]


def hydrogen():
    print("H 1s (finite proton mass), n Gaussians 3e-3 · 1.6^k bohr⁻²; relative errors against μ³/π and 5μ⁴")
    print(f"{'n':>4} {'E + μ/2 (Eh)':>14} {'δ direct':>10} {'regularised':>12} {'p_e⁴ direct':>12} {'regularised':>12}")
    for n in (10, 20, 30, 40, 50):
        basis, mu = hydrogen_s(3e-3 * 1.6 ** np.arange(n))
        E, d, r, pd, pr = contact(basis)
        exact = mu**3 / np.pi
        print(f"{n:>4} {E + mu / 2:>14.3e} {d['e-p'] / exact - 1:>10.2e} {r['e-p'] / exact - 1:>12.2e} "
              f"{pd['e'] / (5 * mu**4) - 1:>12.2e} {pr['e'] / (5 * mu**4) - 1:>12.2e}")


def helium():
    full = prebo.Basis.load(ROOT / "examples" / "bases" / "auto-he-700" / "basis.json")
    rows = [(k, *contact(full.subset(np.arange(k)))) for k in (50, 100, 200, 400, 700)]
    ref, ref_p4 = rows[-1][3], rows[-1][5]
    print("\n⁴He 1¹S, first k functions of auto-he-700; values and (in brackets) differences from the "
          "700-function regularised value")
    print(f"{'k':>4} {'E (Eh)':>16} {'δ(r_αe) direct':>26} {'regularised':>26} {'δ(r_ee) direct':>26} {'regularised':>26}"
          f" {'p_e⁴ direct':>24} {'regularised':>24}")
    for k, E, d, r, pd, pr in rows:
        cells = [f"{x[label]:.8f} ({x[label] - ref[label]:+.1e})" for label in ("alpha-e", "e-e") for x in (d, r)]
        cells += [f"{x['e']:.6f} ({x['e'] - ref_p4['e']:+.1e})" for x in (pd, pr)]
        print(f"{k:>4} {E:>16.10f} " + " ".join(f"{c:>26}" for c in cells[:4]) + " " + " ".join(f"{c:>24}" for c in cells[4:]))


def h2plus():
    print("\nH2⁺ ground state, first k functions of the examples; ⟨δ³(r_ep)⟩, ⟨δ³(r_pp)⟩ (bohr⁻³) and ⟨p_e⁴⟩")
    print(f"{'basis':>12} {'k':>4} {'E (Eh)':>16} {'δ(r_ep) direct':>15} {'regularised':>12} "
          f"{'δ(r_pp) direct':>15} {'regularised':>12} {'p_e⁴ direct':>12} {'regularised':>12} {'s':>6}")
    for name, sizes in (("h2plus-fecg", (30, 100, 400)), ("h2plus-gvr", (20, 60, 180))):
        full = prebo.Basis.load(ROOT / "examples" / "bases" / name / "basis.json")
        for k in sizes:
            t = time.perf_counter()
            E, d, r, pd, pr = contact(full.subset(np.arange(k)))
            print(f"{name:>12} {k:>4} {E:>16.10f} {d['e-p']:>15.8f} {r['e-p']:>12.8f} {d['p-p']:>15.3e} "
                  f"{r['p-p']:>12.3e} {pd['e']:>12.6f} {pr['e']:>12.6f} {time.perf_counter() - t:>6.1f}", flush=True)


if __name__ == "__main__":
    hydrogen()
    helium()
    h2plus()
