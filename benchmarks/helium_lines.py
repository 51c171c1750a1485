"""Helium's 1¹S → 2¹P line (clamped nucleus) and 1¹S static dipole polarisability (clamped nucleus
and ⁴He) from the stored bases, against the literature (benchmarks/record/helium-lines.md).

The line: `prebo.transitions` on examples/bases/he-inf-1s and he-inf-2p. The polarisability: the
fixed N = 1 basis of tests/test_transitions_helium.py (u·r times every ground function, u on each
electron, with the 2¹P functions where the masses agree) and `prebo.level.response.polarisability`;
every figure with the seconds it took.

    nice -n 5 python benchmarks/helium_lines.py [GROUND_4HE ...]
"""
import sys
import time
from pathlib import Path

import prebo
from prebo.io.toml import tomllib
from prebo.level.response import polarisability

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
from test_transitions_helium import LITERATURE, dipole_response_basis  # noqa: E402

BASES = ROOT / "examples" / "bases"
REFERENCES = tomllib.loads((ROOT / "tests" / "data" / "reference_energies.toml").read_text())


def line():
    lower, upper = (prebo.Basis.load(BASES / name / "basis.json") for name in ("he-inf-1s", "he-inf-2p"))
    t = time.perf_counter()
    r = prebo.transitions(lower, upper)
    seconds = time.perf_counter() - t
    (ln,) = r["lines"]
    f_ref = LITERATURE["oscillator_strength_1s_2p"]["value"]
    f_v = 2 / 3 * ln["Eh"] * ln["velocity"] ** 2
    print(f"He (mass = inf) 1¹S ({len(lower)} pECG) → 2¹P ({len(upper)} ECG-GVR), {seconds:.1f} s")
    for level, key in zip(r["levels"], ("He inf", "He 2 1P")):
        E_ref = REFERENCES[key]["energy"]
        print(f"  E {level['energy']:.12f}  reference {E_ref:.12f}  E − E_ref {level['energy'] - E_ref:.2e} Eh")
    print(f"  ΔE {ln['Eh']:.10f} Eh ({ln['cm-1']:.4f} cm⁻¹), reference {REFERENCES['He 2 1P']['energy'] - REFERENCES['He inf']['energy']:.10f}")
    print(f"  <1‖d‖0> length {abs(ln['length']):.9f}, velocity {abs(ln['velocity']):.9f}, "
          f"velocity/length − 1 {ln['velocity/length'] - 1:.2e}")
    print(f"  f length {ln['oscillator_strength']:.9f} ({ln['oscillator_strength'] - f_ref:+.2e}), "
          f"velocity {f_v:.9f} ({f_v - f_ref:+.2e}) against Drake's {f_ref}")
    print(f"  A {ln['einstein_A']:.6e} s⁻¹, lifetime {r['lifetimes'][0]['lifetime']:.6e} s")


def alpha(ground_name: str, extra_name: str | None, key: str):
    ground = prebo.Basis.load(BASES / ground_name / "basis.json")
    t = time.perf_counter()
    response = dipole_response_basis(ground)
    if extra_name is not None:
        extra = prebo.Basis.load(BASES / extra_name / "basis.json")
        response = prebo.Basis.concat([response, prebo.Basis(response.system, extra.A, extra.c_A,
                                                             kind="ecg-gvr", u=extra.u, K=extra.K)])
    r = polarisability(ground, response)
    seconds = time.perf_counter() - t
    ref = LITERATURE["polarisability_1s"][key]["value"]
    a, sos = r["alpha"][0], r["sum_over_states"][0]
    print(f"α He 1¹S {key}: ground {ground_name} ({len(ground)}), response {len(response)} functions"
          f"{' with ' + extra_name if extra_name else ''}, {seconds:.1f} s: α {a:.12f}, "
          f"α/α_ref − 1 {a / ref - 1:.2e} (reference {ref}), sum over states − α {sos - a:.1e}, "
          f"first pole {r['pole']:.9f} Eh")


if __name__ == "__main__":
    line()
    alpha("he-inf-1s", None, "infinite")
    alpha("he-inf-1s", "he-inf-2p", "infinite")
    for name in sys.argv[1:] or ["auto-he-400", "auto-he-700"]:
        alpha(name, None, "finite")
