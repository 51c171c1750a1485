"""The matrices of a basis — overlap S, kinetic T (with the CM motion), T_ti (without it) and
Coulomb V of its normalised functions, in hartree (integrals.py) — as one record, `Matrices`,
and the one home of their names, `NAMES`, in the order of the core's diagonals [S, T, T_ti, V].
"""
from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np


@dataclass(frozen=True, slots=True)
class Matrices:
    """S, T, T_ti, V of a basis (nb x nb), or rows of functions against one (k x nb), or the
    diagonals of k functions (k); H = T_ti + V."""

    S: np.ndarray
    T: np.ndarray
    T_ti: np.ndarray
    V: np.ndarray

    @property
    def H(self) -> np.ndarray:
        """The Hamiltonian, T_ti + V (the CM kinetic energy eliminated)."""
        return self.T_ti + self.V

    @classmethod
    def of(cls, m: dict) -> Matrices:
        """The record of the engine's mapping {name: array} (integrals.Representation.matrices, rows)."""
        return cls(*(m[k] for k in NAMES))

    @classmethod
    def columns(cls, diag: np.ndarray) -> Matrices:
        """The record of the engine's diagonals, one column per name in the order of NAMES."""
        return cls(*(diag[..., k] for k in range(len(NAMES))))

    @classmethod
    def empty(cls) -> Matrices:
        """The matrices of no function."""
        return cls(*(np.zeros((0, 0)) for _ in NAMES))

    def map(self, f) -> Matrices:
        """The record of `f` applied to each matrix (a copy, a subset)."""
        return Matrices(*(f(getattr(self, k)) for k in NAMES))

    def diagonal(self) -> np.ndarray:
        """The diagonals [S, T, T_ti, V], one row per function (integrals.Representation.resolved)."""
        return np.stack([np.diag(getattr(self, k)) for k in NAMES], axis=1)

    def to_dict(self) -> dict:
        """The mapping {name: array} the engine's callers take."""
        return {k: getattr(self, k) for k in NAMES}


#: the names of the matrices, in the order of the core's diagonals
NAMES = tuple(f.name for f in fields(Matrices))
