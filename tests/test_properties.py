"""Expectation values of the pair operators beyond ⟨r_ij²⟩ (issue 40): ⟨r_ij⟩, ⟨1/r_ij⟩,
⟨1/r_ij²⟩ and ⟨δ³(r_ij)⟩, from the damped overlap's profile for every family
(crates/prebo-core/src/operators/profile.rs; element checks there), here on wave functions
against closed forms."""
import numpy as np
import pytest

import prebo

from conftest import hydrogen_s


def hydrogen_exact(n: int, mu: float) -> dict:
    """⟨r⟩, ⟨r²⟩, ⟨1/r⟩, ⟨1/r²⟩, ⟨δ³(r)⟩ of hydrogen's ns level with reduced mass μ (l = 0;
    e.g. H. A. Bethe, E. E. Salpeter, Quantum Mechanics of One- and Two-Electron Atoms (1957),
    eqs. 3.24–3.26, scaled r → r/μ)."""
    return {"r": 3 * n**2 / (2 * mu), "r2": n**2 * (5 * n**2 + 1) / (2 * mu**2), "inv_r": mu / n**2,
            "inv_r2": 2 * mu**2 / n**3, "delta": mu**3 / (np.pi * n**3)}


#: relative error allowed per operator in 80 even-tempered s Gaussians (measured for 1s and 2s:
#: r, r2, inv_r ≤ 3.6e-12, inv_r2 2.0e-8, δ 1.8e-4 — Gaussians, without the cusp, reach the
#: contact density slowly)
TOLERANCE = {"r": 2e-11, "r2": 2e-11, "inv_r": 2e-11, "inv_r2": 1e-7, "delta": 5e-4}


def test_hydrogen_1s_and_2s_expectation_values_match_the_closed_forms():
    """H (finite proton mass) 1s and 2s as roots 0 and 1 of 80 even-tempered s Gaussians: every
    operator's value within its tolerance of the closed form, from plain ECGs (one pair, p-e); the
    contact density approaches μ³/π from below as the tightest Gaussian sharpens (3.0e-3, 4.7e-4,
    1.8e-4 for 50, 60, 80 functions)."""
    errors = []
    for size, ratio in ((50, 1.45), (60, 1.45), (80, 1.35)):
        basis, mu = hydrogen_s(3e-4 * ratio ** np.arange(size))
        r = prebo.evaluate(basis, roots=2, operators=sorted(TOLERANCE))
        for n, level in zip((1, 2), r["levels"]):
            exact = hydrogen_exact(n, mu)
            errors.append(level["expectation"]["delta"]["e-p"] / exact["delta"] - 1)
            for name, tol in TOLERANCE.items():
                (label, value), = level["expectation"][name].items()
                assert label == "e-p"
                assert size < 80 or abs(value / exact[name] - 1) < tol, (n, name, value, exact[name])
    assert all(e < 0 for e in errors) and errors[0] < errors[2] < errors[4], errors
