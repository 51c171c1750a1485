"""Plain ECGs ("pecg"): φ(r) = exp(-r^T (A ⊗ I_3) r), no parameters beyond A and c_A.

Spherical (N = 0), even-parity functions (Muolo, Mátyus & Reiher, J. Chem. Phys. 148, 084112
(2018), Sec. III.A); matrix elements by the core's SIMD kernel
(crates/prebo-core/src/families/pecg/kernel.rs).
"""
from __future__ import annotations

from ..errors import InputError
from .family import Family


class Pecg(Family):
    """Plain ECGs: A and c_A only; N = 0, parity +1 states."""

    name = "pecg"
    shapes = {}
    conserves_L = True

    def check_state(self, state) -> None:
        if (state.N, state.parity) != (0, 1):
            raise InputError(f"plain ECGs (pecg) describe N = 0, parity +1 states only, not N = {state.N}, "
                             f"parity {state.parity:+d} (use ecg-gvr)")


FAMILY = Pecg()
