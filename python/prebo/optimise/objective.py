"""The objective: the quantity the optimisation methods lower, and the state it belongs to.

It is the lowest eigenvalue E_0 of H c = E S c, an upper bound to the exact ground-state energy
of the symmetry the basis is projected on (Hylleraas–Undheim–MacDonald), with its eigenvector
c_0. Everything that reads the lowest root goes through `LowestRoot`: the solve that refines it
(eigen.solve), the secular-equation updates for added or removed functions and their gradients
(eigen module docstring), so that another root, or a weighted sum of roots, is one class here.
"""
from __future__ import annotations

import numpy as np

from .. import eigen


class LowestRoot:
    """The lowest root E_0 and its eigenvector c_0 (module docstring). (E, C): the eigenvalues and
    S-orthonormal eigenvectors of the basis a function or a block is added to."""

    def solve(self, H: np.ndarray, S: np.ndarray, threshold: float) -> eigen.Eigen:
        """The eigen-solution of the pencil (H, S), its lowest root refined (eigen.solve)."""
        return eigen.solve(H, S, threshold)

    def value(self, eig: eigen.Eigen) -> float:
        """E_0 (hartree) of an eigen-solution."""
        return float(eig.energies[0])

    def vector(self, eig: eigen.Eigen) -> np.ndarray:
        """c_0, S-normalised, of an eigen-solution."""
        return eig.vectors[:, 0]

    def with_added(self, E, C, h, s, h_nn, s_nn, min_norm: float) -> float:
        """E_0 with one function of rows h, s and diagonal h_nn, s_nn added (eigen.lowest_with_added)."""
        return eigen.lowest_with_added(E, C, h, s, h_nn, s_nn, min_norm)

    def with_added_gradient(self, E, C, h, s, h_nn, s_nn, dh, ds, dh_nn, ds_nn, min_norm: float):
        """`with_added` and its gradient along the function's parameters (eigen.lowest_with_added_gradient)."""
        return eigen.lowest_with_added_gradient(E, C, h, s, h_nn, s_nn, dh, ds, dh_nn, ds_nn, min_norm)

    def with_added_many(self, E, C, H, S, h_nn, s_nn, min_norm: float) -> np.ndarray:
        """`with_added` for each of many functions, rows H, S (eigen.lowest_with_added_many)."""
        return eigen.lowest_with_added_many(E, C, H, S, h_nn, s_nn, min_norm)

    def with_block(self, E, C, h, s, H_ff, S_ff, min_norm: float, near: float | None = None):
        """E_0 with a block of functions added, and its eigenvector (eigen.lowest_with_block)."""
        return eigen.lowest_with_block(E, C, h, s, H_ff, S_ff, min_norm, near=near)

    def without_each(self, E: np.ndarray, C: np.ndarray) -> np.ndarray:
        """E_0 without each function in turn (eigen.lowest_without_each)."""
        return eigen.lowest_without_each(E, C)
