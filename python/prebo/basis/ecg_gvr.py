"""ECG-GVR functions ("ecg-gvr"): φ(r) = |v|^{2K} (v_x + i v_y)^N exp(-r^T (A ⊗ I_3) r), v = u^T r.

A global vector u (n) and a power K per function, the state's N (Muolo, Mátyus & Reiher,
J. Chem. Phys. 148, 084112 (2018), Sec. III.C; docs/gvr.md). The functions have
natural parity (-1)^N. The normalised function does not depend on the length of u; refinement
keeps |(u', c_U)| = 1 in its coordinate set.
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError, SeparabilityError
from .family import Family

#: the steps in K of a function's neighbours (`EcgGvr.neighbours`)
K_STEPS = (1, 2)
#: the range of max |u_k|: a normalised function does not depend on the length of u, the sampler and
#: the stored bases keep it near 1 (1.0-1.73), and u^T A^-1 u overflows far beyond (1e±100: not finite)
U_SCALE = (1e-6, 1e6)


class EcgGvr(Family):
    """ECG-GVR functions: u (n) and K per function; states of natural parity (-1)^N."""

    name = "ecg-gvr"
    shapes = {"u": ("n",), "K": ()}
    integers = frozenset({"K"})
    conserves_L = True
    K_limit = 60

    def check_state(self, state) -> None:
        if state.parity != (-1) ** state.N:
            raise InputError(f"ECG-GVR functions have natural parity (-1)^N = {(-1) ** state.N:+d}, "
                             f"not parity {state.parity:+d} with N = {state.N}")

    def coerce(self, name: str, value) -> np.ndarray:
        value = np.asarray(value)
        if name != "K":
            return value.astype(float)
        if not np.all((value >= 0) & (value <= self.K_limit) & (value == np.round(value))):
            raise InputError(f"basis: every K must be an integer in 0..{self.K_limit}")
        return value.astype(np.uint32)

    def check_function(self, basis, i: int) -> None:
        if not (np.all(np.isfinite(basis.u[i])) and np.any(basis.u[i] != 0)):
            raise InputError(f"function {i}: the global vector u must be finite and non-zero")
        scale = float(np.max(np.abs(basis.u[i])))
        if not U_SCALE[0] <= scale <= U_SCALE[1]:
            raise InputError(f"function {i}: the global vector u = {basis.u[i].tolist()} has its largest component "
                             f"{scale:g}, outside {U_SCALE[0]:g}..{U_SCALE[1]:g} (the normalised function does not "
                             "depend on the length of u; far from 1 its integrals overflow)")

    def ticc_extras(self, extras: tuple, coords) -> tuple:
        u, K = extras
        ux = coords.transform_vectors_to_x(u)  # u^(x) = U^-T u^(r) = (u', c_U)
        if np.any(np.abs(ux[:, -1]) > 1e-12 * np.max(np.abs(ux), axis=1)):
            raise SeparabilityError("a global vector has a CM component (c_U != 0): "
                                    "no translationally invariant evaluation (use --coordinates lab)")
        return ux[:, :-1], K

    # sampling: the drawn length of the coordinate carrying u is the peak of |v|^{2K+N} exp(-α v²)
    def draw_power(self, rng, K_max: int, N: int) -> tuple[int, float]:
        K = int(rng.integers(K_max + 1))
        return K, K + 0.5 * N

    def drawn(self, rng, system, carrier, K: int) -> dict:
        return {"u": carrier.u[None], "K": [K]}

    def powers(self, basis, idx) -> np.ndarray:
        return basis.K[idx]

    def draw_learned_power(self, rng, powers, K_max: int) -> int:
        return int(np.clip(rng.choice(powers) + rng.integers(-2, 3), 0, K_max))

    def neighbours(self, f, K_max: int) -> list:
        """f moved to K ± 1, K ± 2 (K_STEPS; within 0..K_max), the marginal exponent of v = u·r
        scaled by p'/p (p = max(K + N/2, 1)) so that the peak of |v|^{2K+N} stays put:
        A' = A + (p'/p - 1) u u^T / (u^T A^-1 u) (Sherman–Morrison: u^T A'^-1 u = u^T A^-1 u p/p')."""
        K, N = int(f.K[0]), f.N
        A, u = f.A[0], f.u[0]
        p = max(K + 0.5 * N, 1.0)
        uAu = u @ np.linalg.solve(A, u)
        out = []
        for K2 in (K + sign * step for step in K_STEPS for sign in (-1, 1)):
            if 0 <= K2 <= K_max:
                g = (max(K2 + 0.5 * N, 1.0) / p - 1.0) / uAu
                out.append(type(f).single(f.system, A + g * np.outer(u, u), f.c_A[0], f.channels[0], self.name,
                                          {"u": u[None], "K": [K2]}))
        return out

    # refinement: θ tail u' with u^(r) = U_x^T v/|v|, v = (u', c_U), c_U fixed
    def prepared(self, f, x):
        scale = np.linalg.norm(x.transform_vectors_to_x(f.u[0]))
        return type(f)(f.system, f.A, f.c_A, f.channels, kind=self.name, u=f.u / scale, K=f.K)

    def theta_tail(self, f, x) -> np.ndarray:
        return x.transform_vectors_to_x(f.u[0])[:-1]

    @staticmethod
    def _v(f, tail: np.ndarray) -> tuple[np.ndarray, float]:
        """(v/|v|, |v|), v = (u', c_U)."""
        v = np.append(tail, float(f.u[0].sum()))
        norm = np.linalg.norm(v)
        return v / norm, norm

    def from_tail(self, f, x, tail: np.ndarray, K: int | None = None) -> dict:
        u = x.U.T @ self._v(f, tail)[0]
        return {"u": u[None], "K": f.K[:1] if K is None else [K]}

    def tail_directions(self, f, x, tail: np.ndarray, P: int, offset: int) -> np.ndarray:
        """∂u^(r)/∂θ_p (P x n): ∂(v/|v|)/∂u'_k = (e_k - v v_k)/|v|."""
        n = f.system.n
        v, norm = self._v(f, tail)
        dv = np.zeros((P, n))
        for k in range(n - 1):
            dv[offset + k] = x.U.T @ ((np.eye(n)[k] - v * v[k]) / norm)
        return dv


FAMILY = EcgGvr()
