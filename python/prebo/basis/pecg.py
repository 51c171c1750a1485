"""Plain ECGs ("pecg"): φ(r) = exp(-r^T (A ⊗ I_3) r), no parameters beyond A and c_A.

Spherical (N = 0), even-parity functions (Muolo, Mátyus & Reiher, J. Chem. Phys. 149, 184105
(2018), Sec. III.A); matrix elements by the core's SIMD kernel (crates/prebo-core/src/pecg.rs).
"""
from __future__ import annotations

import numpy as np

from .. import _core
from ..errors import InputError
from .family import Family


class PlainECG(Family):
    """Plain ECGs: A and c_A only; N = 0, parity +1 states."""

    name = "pecg"
    shapes = {}
    conserves_L = True

    def check_state(self, state) -> None:
        if (state.N, state.parity) != (0, 1):
            raise InputError(f"plain ECGs (pecg) describe N = 0, parity +1 states only, not N = {state.N}, "
                             f"parity {state.parity:+d} (use ecg-gvr)")

    def engine(self, ops: tuple, N: int) -> "Engine":
        return Engine(ops)


class Engine:
    """The core's plain-ECG functions for one representation. Rows have the trial as bra and are
    not in full-build orientation (`oriented` False: an accepted function rebuilds the matrices)."""

    oriented = False

    def __init__(self, ops: tuple):
        self.ops = ops

    def matrices(self, params: tuple) -> dict:
        return _core.matrices(*params, *self.ops)

    def rows(self, trials: tuple, basis: tuple, position: int | None = None) -> tuple[dict, np.ndarray]:
        return _core.rows(*trials, *basis, *self.ops)

    def row_gradient(self, f: tuple, dA: np.ndarray, dv, basis: tuple) -> tuple[dict, np.ndarray]:
        """Through the ECG-GVR kernel at K = N = 0, where the global vector drops out
        (crates/prebo-core/src/gvr.rs): any u, here e_1."""
        def as_gvr(A, c_A):
            u = np.zeros(A.shape[:2])
            u[:, 0] = 1.0
            return A, u, np.zeros(len(A), np.uint32), c_A
        n = f[0].shape[1]
        return _core.gvr_row_gradient(*as_gvr(*f), np.ascontiguousarray(dA), np.zeros((len(dA), n)),
                                      *as_gvr(*basis), 0, *self.ops)


FAMILY = PlainECG()
