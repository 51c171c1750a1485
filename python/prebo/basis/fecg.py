"""Floating ECGs ("fecg"): φ(r) = exp(-(r - s)^T (A ⊗ I_3)(r - s)), centres s (n x 3) per function.

Not eigenfunctions of the angular momentum: they take the label N = 0 (the core evaluates no
other) with either parity, and the results report the translation-free <N²> (the core's
operator "n2"). The sampler and refinement keep the CM centre μ^T s at 0, so the functions separate
in the CM coordinate.
"""
from __future__ import annotations

import numpy as np

from ..errors import BasisFileError, InputError, SeparabilityError
from .family import Family


class Fecg(Family):
    """Floating ECGs: centres s (n x 3, bohr) per function; N = 0 labels, <N²> reported."""

    name = "fecg"
    shapes = {"s": ("n", 3)}
    conserves_L = False

    def check_state(self, state) -> None:
        if state.N != 0:
            raise InputError(f"floating ECGs (fecg) take the label N = 0 only (their <N²> is reported), "
                             f"not N = {state.N} (use ecg-gvr)")

    def check_function(self, basis, i: int) -> None:
        if not np.all(np.isfinite(basis.s[i])):
            raise BasisFileError(f"function {i}: non-finite centres s")

    def ticc_extras(self, extras: tuple, coords) -> tuple:
        (s,) = extras
        sx = np.einsum("ki,nij->nkj", coords.U, s)  # s^(x) = U s
        if np.any(np.abs(sx[:, -1]) > 1e-12 * max(1.0, np.max(np.abs(sx)))):
            raise SeparabilityError("a centre set has a CM component (μ^T s != 0): "
                                    "no translationally invariant evaluation (use --coordinates lab)")
        return (sx[:, :-1],)

    def drawn(self, rng, system, carrier, K: int) -> dict:
        c = carrier.centres
        return {"s": (c - system.cm_vector @ c)[None]}  # no CM component: μ^T s = 0

    # refinement: θ tail s' with s^(r) = U_x^-1 (s', μ^T s), μ^T s fixed
    def theta_tail(self, f, x) -> np.ndarray:
        return (x.U @ f.s[0])[:-1].ravel()

    def from_tail(self, f, x, tail: np.ndarray, K: int | None = None) -> dict:
        sx = x.U @ f.s[0]
        sx[:-1] = tail.reshape(-1, 3)
        return {"s": (x.U_inv @ sx)[None]}

    def tail_directions(self, f, x, tail: np.ndarray, P: int, offset: int) -> np.ndarray:
        """∂s^(r)/∂θ_p (P x n x 3): column a of U_x^-1 in component k."""
        n = f.system.n
        ds = np.zeros((P, n, 3))
        for a in range(n - 1):
            for k in range(3):
                ds[offset + 3 * a + k, :, k] = x.U_inv[:, a]
        return ds


FAMILY = Fecg()
