"""Helium's 1¹S → 2¹P line and 1¹S static dipole polarisability from the stored bases
(examples/bases/he-inf-1s, he-inf-2p: a clamped nucleus; auto-he-400: ⁴He) against the literature
(tests/data/helium_lines_literature.toml, reference_energies.toml); benchmarks/record/helium-lines.md."""
import numpy as np
import pytest

import prebo
from prebo.io.toml import tomllib
from prebo.level.response import polarisability
from prebo.level.transitions import transitions

from conftest import ROOT

BASES = ROOT / "examples" / "bases"
LITERATURE = tomllib.loads((ROOT / "tests" / "data" / "helium_lines_literature.toml").read_text())


def dipole_response_basis(ground: prebo.Basis, near_symmetric: float = 1e-3) -> prebo.Basis:
    """The N = 1, parity −1 ECG-GVR functions (u·r) φ_k, K = 0, of every function φ_k of the He
    1¹S basis `ground` (its A and c_A), u = e_i − e_nucleus for each electron i: d_z φ_k, d the dipole
    −(r_1 − r_n) − (r_2 − r_n), lies in their span, the leading part of the first-order function
    of (H − E₀) ψ₁ = −d_z ψ₀ (a fixed-basis Hylleraas calculation). Under the electrons' symmetriser
    the electron-2 function of A is the electron-1 function of PAPᵀ (P swaps the electrons), so
    where A lies within `near_symmetric` (relative) of PAPᵀ only the electron-1 function is kept:
    the pair is nearly linearly dependent there."""
    system = prebo.System(list(ground.system.particles), N=1, parity=-1, spin={"e": 0})
    P = np.eye(3)[[0, 2, 1]]
    asymmetry = np.array([np.abs(P @ a @ P.T - a).max() / np.abs(a).max() for a in ground.A])
    parts = []
    for u, keep in (([-1.0, 1.0, 0.0], asymmetry >= 0), ([-1.0, 0.0, 1.0], asymmetry >= near_symmetric)):
        g = ground.subset(np.flatnonzero(keep))
        parts.append(prebo.Basis(system, g.A, g.c_A, kind="ecg-gvr", u=np.tile(u, (len(g), 1)),
                                 K=np.zeros(len(g), int)))
    return prebo.Basis.concat(parts)


def response_with(ground: prebo.Basis, *partners: str) -> prebo.Basis:
    """`dipole_response_basis(ground)` and the functions of the stored N = 1 bases `partners`."""
    response = dipole_response_basis(ground)
    extra = [prebo.Basis.load(BASES / name / "basis.json") for name in partners]
    return prebo.Basis.concat([response] + [prebo.Basis(response.system, b.A, b.c_A, kind="ecg-gvr", u=b.u, K=b.K)
                                            for b in extra])


def test_the_1s_2p_line_with_a_clamped_nucleus_meets_drakes_oscillator_strength(references):
    # measured (benchmarks/record/helium-lines.md): f +3.8e-8 from Drake's seven digits in length
    # form and −3.6e-8 in velocity form, both within the ±5e-8 of his last digit; velocity/length
    # − 1 = −1.3e-7 (acceleration/length − 1 = −3.8e-6); the levels 1.48e-10 and 3.72e-9 Eh above the literature
    lower, upper = (prebo.Basis.load(BASES / name / "basis.json") for name in ("he-inf-1s", "he-inf-2p"))
    r = transitions(lower, upper)
    (line,) = r["lines"]
    for level, key, tol in zip(r["levels"], ("He inf", "He 2 1P"), (5e-10, 1e-8)):
        assert 0 < level["energy"] - references[key]["energy"] < tol, (key, level["energy"])
    f = LITERATURE["oscillator_strength_1s_2p"]["value"]
    f_velocity = 2 / 3 * line["Eh"] * line["velocity"] ** 2
    assert abs(line["oscillator_strength"] - f) < 1e-7
    assert abs(f_velocity - f) < 1e-7
    assert abs(line["velocity/length"] - 1) < 4e-7
    assert abs(line["acceleration/length"] - 1) < 1e-5  # −3.8e-6: the acceleration form weighs the cusps


@pytest.mark.parametrize("ground, partners, key, tol", [
    # measured: 4.1e-10 relative above Pachucki & Sapirstein with 1366 + 300 functions
    ("he-inf-1s", ("he-inf-2p",), "infinite", 1.5e-9),
    # measured: 4.5e-8 relative below with the 786 functions of its 400 ground functions (3.0e-9
    # with the 1357 of auto-he-700's 700)
    ("auto-he-400", (), "finite", 1.5e-7),
])
def test_the_1s_static_polarisability_meets_pachucki_and_sapirstein(ground, partners, key, tol):
    lit = LITERATURE["polarisability_1s"][key]
    basis = prebo.Basis.load(BASES / ground / "basis.json")
    assert {p.name: p.mass for p in basis.system.particles}["He" if key == "infinite" else "alpha"] == \
        lit["masses"]["alpha"]
    r = polarisability(basis, response_with(basis, *partners))
    alpha = r["alpha"][0]
    # Hylleraas' functional bounds α from below for the exact ψ₀ and E₀ only: the clamped-nucleus
    # value, with its ground level 1.5e-10 Eh above the literature, stands above the reference
    assert abs(alpha / lit["value"] - 1) < tol
    assert abs(r["sum_over_states"][0] - alpha) < 1e-9 * alpha
