"""Dipole polarisabilities of a level of N = 0 from a basis of N = 1 for its first-order function.

The first-order function ψ₁ of the field along z solves (H − E₀) ψ₁ = −d_z ψ₀ in the basis of
N = 1: it minimises Hylleraas' functional J[ψ₁] = ⟨ψ₁|H − E₀|ψ₁⟩ + 2⟨ψ₁|d_z|ψ₀⟩, bounded below
by −α/2 (E. A. Hylleraas, Z. Phys. 65, 209 (1930)), so that the basis's value approaches α from
below as the basis grows. With r_J = ⟨φ_J‖d‖ψ₀⟩, the reduced elements of the basis's functions
(level/transitions.py; ⟨φ_J M=0|d_z|ψ₀⟩ = r_J/√3 for a level of N = 0),

    α(ω) = (1/3) [rᵀ(H − (E₀ + ω)S)⁻¹r + rᵀ(H − (E₀ − ω)S)⁻¹r],   α = α(0) = (2/3) rᵀ(H − E₀S)⁻¹r,

the static value at the minimum, J = −α/2 (a₀³ in atomic units, e² a₀² / E_h), for an exact ψ₀.
The minimiser is taken over the directions of the basis its overlap resolves (`eigen.solve`'s
threshold), through the basis's pseudostates n (S-orthonormal C, energies E_n):
z = −Σ_n c_n (c_nᵀr)/(E_n − E₀ ∓ ω), and the functional is evaluated at it with the basis's own
H and S. Below the first pole ω₁ = E₁ − E₀ (the basis's lowest level of N = 1) it is a minimum.
The sum over states, (1/3) Σ_n S_n [1/(ΔE_n − ω) + 1/(ΔE_n + ω)], S_n = (c_nᵀr)² the line
strengths, is the same number in exact arithmetic and is reported as a check.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import eigen
from ..basis import Basis
from ..errors import InputError, UnsupportedError
from ..integrals import laboratory
from .evaluate import evaluate
from .transitions import dipole_vectors, forbidden, same_particles


@dataclass(frozen=True)
class FirstOrder:
    """The dipole's first-order problem of a level in a basis of N = 1, built once (`first_order`)
    and evaluated at any frequencies (`at`): the level's energy `E0` (Eh), the reduced elements `r`
    of the basis's functions with it, the basis's `H` (T_ti + V) and `S`, its pseudostates `C`
    (S-orthonormal columns, the directions the overlap resolves) and their excitation energies `de`
    (Eh), the first of them the first `pole`."""

    E0: float
    r: np.ndarray
    H: np.ndarray
    S: np.ndarray
    C: np.ndarray
    de: np.ndarray
    operator: str = "dipole"

    @property
    def pole(self) -> float:
        """The first pole, the basis's lowest excitation energy E₁ − E₀ (Eh)."""
        return float(self.de[0])

    def hylleraas(self, shift: float) -> float:
        """J[ψ₁] at its minimiser over the pseudostates, for H − (E₀ + shift) (module docstring)."""
        z = -self.C @ ((self.C.T @ self.r) / (self.de - shift))
        return float(z @ (self.H - (self.E0 + shift) * self.S) @ z + 2 * z @ self.r)

    def at(self, omega) -> dict:
        """α(ω) at the frequencies `omega` (Eh; a number or a list, each below the first pole), as
        `polarisability` returns it; InputError for ω not finite or at or above the pole."""
        omegas = self._frequencies(omega, np.abs)
        strengths = (self.C.T @ self.r) ** 2
        alpha = [-(self.hylleraas(x) + self.hylleraas(-x)) / 3 for x in omegas]
        sos = [float(np.sum(strengths * (1 / (self.de - x) + 1 / (self.de + x)))) / 3 for x in omegas]
        return {"alpha": alpha, "sum_over_states": sos, "omega": omegas.tolist(), "pole": self.pole,
                "energy": self.E0, "hylleraas": self.hylleraas(0.0) / 3}

    def resolvent(self, omega) -> dict:
        """f(ω) = ⟨O(H − E₀ − ω)⁻¹O⟩ summed over the three components, −3 J at its minimum (for the
        current, f at ω = −k is the Bethe logarithm's; level/bethe.py), at the frequencies `omega`
        (Eh, each below the first pole), with the sum over states Σ_n S_n/(ΔE_n − ω) as a check."""
        omegas = self._frequencies(omega, lambda x: x)
        strengths = (self.C.T @ self.r) ** 2
        return {"f": [-self.hylleraas(x) for x in omegas],
                "sum_over_states": [float(np.sum(strengths / (self.de - x))) for x in omegas],
                "omega": omegas.tolist(), "pole": self.pole, "energy": self.E0}

    def _frequencies(self, omega, reach) -> np.ndarray:
        """`omega` as a 1-d array; InputError unless each is finite and `reach(ω)` below the pole."""
        omegas = np.atleast_1d(np.asarray(omega, dtype=float))
        if omegas.ndim != 1 or not np.all(np.isfinite(omegas)):
            raise InputError(f"{self.operator} response: omega = {omega!r}: must be finite frequencies (E_h)")
        above = reach(omegas) >= self.pole
        if np.any(above):
            raise InputError(f"{self.operator} response: omega = {omegas[above][0]:.6g} Eh is at or above the first "
                             f"pole {self.pole:.6g} Eh (the response basis's lowest level of N = 1)")
        return omegas


#: the operators whose first-order function a basis of N = 1 holds for a level of N = 0, and whether
#: their laboratory-frame vector is momentum-like (transitions.py `dipole_vectors`): the dipole d
#: (polarisabilities) and its velocity form ∇_w' (the current J' = −i∇_w' of the Bethe logarithm, bethe.py)
MOMENTUM = {"dipole": False, "velocity": True}


def require(ground, responses, who: str, holds: str) -> None:
    """InputError unless `ground` and each of `responses` are non-empty bases of definite N, the
    ground's of N = 0 (UnsupportedError for N > 0) and each response's of N = 1 and the other parity,
    of the same particles and spin state, able to hold `holds`; every message begins with `who`."""
    for b, what in [(ground, "ground")] + [(r, "response") for r in responses]:
        if not isinstance(b, Basis) or len(b) == 0:
            raise InputError(f"{who}: {what} = {b!r}: must be a non-empty prebo.Basis")
        if not b.family.conserves_L:
            raise InputError(f"{who}: the {what} basis is of {b.family.name} functions, which have no definite N; "
                             "it needs bases of definite N (pecg, ecg-gvr)")
    if ground.N != 0:
        raise UnsupportedError(f"{who}: a level of N = {ground.N}: derived for N = 0 only")
    for r in responses:
        if r.N != 1:
            raise InputError(f"{who}: the response basis is of N = {r.N}; {holds} of a level of N = 0 is of N = 1")
        why = forbidden(ground, r)
        if why is not None:
            raise InputError(f"{who}: the response basis cannot hold {holds} ({why})")
        same_particles(ground.system, r.system)


def problem(ground: Basis, response: Basis, E0: float, c0: np.ndarray, threshold: float,
            operator: str = "dipole") -> FirstOrder:
    """The `FirstOrder` problem of the level (energy E0, S-normalised coefficients c0 in `ground`) in
    the N = 1 basis `response` (laboratory frame), its pseudostates as they fall, below E0 or not."""
    rep = laboratory(ground.system)
    momentum = MOMENTUM[operator]
    w = dipole_vectors(ground.system)[momentum]
    r = rep.between(operator, ground, response, w[None], momentum)[0].T @ c0
    m = rep.matrices(response)
    rep.require_resolved(m)
    H, S = m["T_ti"] + m["V"], m["S"]
    states = eigen.solve(H, S, threshold, 1)
    return FirstOrder(E0, r, H, S, states.vectors, states.energies - E0, operator)


def first_order(ground: Basis, response: Basis, root: int = 0, threshold: float = eigen.THRESHOLD,
                operator: str = "dipole") -> FirstOrder:
    """The `FirstOrder` problem of the level `root` of the N = 0 basis `ground` in the N = 1 basis
    `response`, for the dipole or its velocity form ∇_w' (`operator`; r their reduced elements).
    InputError as `require` raises it, or for a response basis with a level below the ground level."""
    require(ground, [response], "polarisability", "the first-order function")
    r0 = evaluate(ground, threshold=threshold, roots=root + 1, targets=[root])
    order = problem(ground, response, float(r0["energy"]), r0["vectors"][:, 0], threshold, operator)
    if order.de[0] <= 0:
        raise InputError(f"polarisability: the response basis has a level {-order.de[0]:.6g} Eh below the ground level")
    return order


def polarisability(ground: Basis, response: Basis, omega=0.0, root: int = 0,
                   threshold: float = eigen.THRESHOLD) -> dict:
    """The dipole polarisability (a₀³) of the level `root` of the N = 0 basis `ground`, with its
    first-order function in the N = 1 basis `response` (module docstring), at the frequencies
    `omega` (E_h; a number or a list, each below the first pole): `first_order(...).at(omega)`.

    Returns {"alpha": α(ω) per ω (Hylleraas), "sum_over_states": the same from the pseudostates,
    "omega": the frequencies, "pole": the first pole E₁ − E₀ (E_h), "energy": E₀, "hylleraas": J
    at ω = 0 (−α/2)}. InputError as `first_order` and `FirstOrder.at` raise it."""
    return first_order(ground, response, root, threshold).at(omega)
