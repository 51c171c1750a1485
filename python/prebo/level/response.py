"""Dipole polarisabilities of a level of N = 0 from a basis of N = 1 for its first-order function.

The first-order function ψ₁ of the field along z solves (H − E₀) ψ₁ = −d_z ψ₀ in the basis of
N = 1: it minimises Hylleraas' functional J[ψ₁] = ⟨ψ₁|H − E₀|ψ₁⟩ + 2⟨ψ₁|d_z|ψ₀⟩, bounded below
by −α/2 (E. A. Hylleraas, Z. Phys. 65, 209 (1930)), so that the basis's value approaches α from
below as the basis grows. With r_J = ⟨φ_J‖d‖ψ₀⟩, the reduced elements of the basis's functions
(level/transitions.py; ⟨φ_J M=0|d_z|ψ₀⟩ = r_J/√3 for a level of N = 0),

    α(ω) = (1/3) [rᵀ(H − (E₀ + ω)S)⁻¹r + rᵀ(H − (E₀ − ω)S)⁻¹r],   α = α(0) = (2/3) rᵀ(H − E₀S)⁻¹r,

the static value at the minimum, J = −α/2 (a₀³ in atomic units, e² a₀² / E_h). Below the first
pole ω₁ = E₁ − E₀ (the basis's lowest level of N = 1) H − (E₀ ± ω)S is positive definite. The
sum over the basis's pseudostates n, (1/3) Σ_n S_n [1/(ΔE_n − ω) + 1/(ΔE_n + ω)], S_n their line
strengths, is the same number in exact arithmetic and is reported as a check.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg

from .. import eigen
from ..basis import Basis
from ..errors import InputError, LinearDependenceError, UnsupportedError
from ..integrals import laboratory
from .evaluate import evaluate
from .transitions import dipole_vectors, forbidden, same_particles


def polarisability(ground: Basis, response: Basis, omega=0.0, root: int = 0,
                   threshold: float = eigen.THRESHOLD) -> dict:
    """The dipole polarisability (a₀³) of the level `root` of the N = 0 basis `ground`, with its
    first-order function in the N = 1 basis `response` (module docstring), at the frequencies
    `omega` (E_h; a number or a list, each below the first pole).

    Returns {"alpha": α(ω) per ω (Hylleraas), "sum_over_states": the same from the pseudostates,
    "omega": the frequencies, "pole": the first pole E₁ − E₀ (E_h), "energy": E₀, "hylleraas": J
    at ω = 0 (−α/2)}. InputError for bases of different particles or spin states, a ground basis
    not of N = 0, a response basis not of N = 1 and opposite parity, ω not finite or at or above
    the first pole."""
    for b, what in ((ground, "ground"), (response, "response")):
        if not isinstance(b, Basis) or len(b) == 0:
            raise InputError(f"polarisability: {what} = {b!r}: must be a non-empty prebo.Basis")
    if ground.N != 0:
        raise UnsupportedError(f"polarisability of a level of N = {ground.N}: derived for N = 0 only")
    if response.N != 1:
        raise InputError(f"polarisability: the response basis is of N = {response.N}; a dipole field "
                         "mixes a level of N = 0 with those of N = 1")
    why = forbidden(ground, response)
    if why is not None:
        raise InputError(f"polarisability: the response basis cannot hold the dipole's first-order function ({why})")
    same_particles(ground.system, response.system)
    omegas = np.atleast_1d(np.asarray(omega, dtype=float))
    if omegas.ndim != 1 or not np.all(np.isfinite(omegas)):
        raise InputError(f"polarisability: omega = {omega!r}: must be finite frequencies (E_h)")
    r0 = evaluate(ground, threshold=threshold, roots=root + 1, targets=[root])
    E0, c0 = float(r0["energy"]), r0["vectors"][:, 0]
    rep = laboratory(ground.system)
    w, _ = dipole_vectors(ground.system)
    r = rep.between("dipole", ground, response, w[None])[0].T @ c0
    m = rep.matrices(response)
    rep.require_resolved(m)
    H, S = m["T_ti"] + m["V"], m["S"]
    states = eigen.solve(H, S, threshold, 1)
    pole = float(states.energies[0] - E0)
    if pole <= 0:
        raise InputError(f"polarisability: the response basis has a level {-pole:.6g} Eh below the ground level")
    above = np.abs(omegas) >= pole
    if np.any(above):
        raise InputError(f"polarisability: omega = {omegas[above][0]:.6g} Eh is at or above the first pole "
                         f"{pole:.6g} Eh (the response basis's lowest level of N = 1)")
    strengths = (states.vectors.T @ r) ** 2
    de = states.energies - E0

    def solved(shift: float) -> float:
        try:
            return float(r @ scipy.linalg.solve(H - (E0 + shift) * S, r, assume_a="pos"))
        except np.linalg.LinAlgError:
            raise LinearDependenceError(f"polarisability: H − (E₀ {shift:+.6g}) S of the response basis is not "
                                        "positive definite in double precision (a nearly dependent basis)") from None

    alpha = [(solved(x) + solved(-x)) / 3 for x in omegas]
    sos = [float(np.sum(strengths * (1 / (de - x) + 1 / (de + x)))) / 3 for x in omegas]
    return {"alpha": alpha, "sum_over_states": sos, "omega": omegas.tolist(), "pole": pole, "energy": E0,
            "hylleraas": -alpha[0] / 2 if omegas[0] == 0 else -solved(0.0) / 3}
