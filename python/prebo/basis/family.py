"""What a basis family is: the parameters one kind of ECG adds to its exponents, and everything
that depends on them.

Every family shares the exponent matrix A^(r) (n x n, laboratory-frame Cartesian coordinates)
and c_A, the exponent of the centre-of-mass coordinate (A^(r) 1 = c_A m/m_tot); a family adds
its own per-function arrays (`extras`: the global vector u and power K of ECG-GVR functions, the
centres s of floating ECGs) and supplies, for those arrays only:

- validation: their dtype and shape (`coerce`; in a basis file: `shapes`, `integers`), the states
  they can describe (`check_state`), the values a function may hold (`check_function`);
- the engine calls: the core's parameter tuple of a function set in a representation (`params`,
  the TICC transformation of the extras) and the engine object that builds matrices, rows and
  row gradients from it (`engine`);
- sampling: the part of a random draw that depends on the family (`draw_power`, `drawn`,
  `powers`, `draw_learned_power`, `neighbours`) and its limits (`K_limit`);
- refinement: the tail of the parameter vector θ ↔ the extras (`prepared`, `theta_tail`,
  `from_tail`, `tail_directions`; the exponent part of θ is common, optimise/parametrisation.py).

The families are registered in `prebo.basis.families`; nothing outside `prebo.basis` asks
which family a basis is, it asks the family.
"""
from __future__ import annotations

import numpy as np

from .. import _core


class Family:
    """One basis family. Subclasses set the class attributes and override the hooks they need;
    the defaults are those of plain ECGs (no extra parameters)."""

    #: the basis.json `basis_type` string
    name: str = ""
    #: per-function extra arrays beyond A and c_A: name -> shape after nb ("n": particles)
    shapes: dict = {}
    #: the extras whose values are integers (the others are real numbers)
    integers: frozenset = frozenset()
    #: whether the functions are eigenfunctions of the total orbital angular momentum N
    conserves_L: bool = True
    #: the largest power K a function may hold, the bound of the setting K_max (0: no powers)
    K_limit: int = 0

    @property
    def parameters(self) -> tuple[str, ...]:
        """The names of the per-function arrays, in the order of the core's parameter tuple."""
        return ("A", *self.shapes, "c_A")

    def __repr__(self) -> str:
        return f"family({self.name!r})"

    # --- validation ----------------------------------------------------------------
    def check_state(self, state) -> None:
        """Refuse (InputError) a state this family cannot describe; any state by default."""

    def coerce(self, name: str, value) -> np.ndarray:
        """The values of extra array `name` with the dtype the core takes (InputError if out of range)."""
        return np.asarray(value).astype(float)

    def check_function(self, basis, i: int) -> None:
        """Refuse (InputError, BasisFileError) extras of function i the integrals cannot take."""

    # --- engine calls --------------------------------------------------------------
    def params(self, f, coords=None) -> tuple:
        """The core's parameter tuple of the function set `f` (a Basis): (A, extras..., c_A) in the
        laboratory frame, or in the TICC of the coordinate set `coords` (A and c_A from
        U_x^-T A^(r) U_x^-1; the extras by `ticc_extras`)."""
        A, c_A = f.A, f.c_A
        extras = tuple(getattr(f, name) for name in self.shapes)
        if coords is not None:
            Ui = coords.U_inv
            Ax = np.einsum("ki,nkl,lj->nij", Ui, A, Ui)
            A, c_A = Ax[:, :-1, :-1], Ax[:, -1, -1]
            extras = self.ticc_extras(extras, coords)
        c = np.ascontiguousarray
        return (c(A), *(c(v) for v in extras), c(c_A))

    def ticc_extras(self, extras: tuple, coords) -> tuple:
        """The extras in the TICC of `coords` (SeparabilityError where they have a CM part)."""
        return extras

    def engine(self, ops: tuple, N: int) -> _core.Engine:
        """The core's engine of this family for the representation's operators `ops` = (Λ, pair_w,
        pair_q, sym_t, sym_c, cm_mass) and the state's N: `.matrices(params)`, `.rows(trials, basis,
        position)`, `.row_gradient(f, dA, dv, basis)`, `.operator(name, params, v)`, `.oriented`."""
        return _core.Engine(self.name, *ops, N=N)

    # --- sampling ------------------------------------------------------------------
    def draw_power(self, rng, K_max: int, N: int) -> tuple[int, float]:
        """(K, p) of a fresh function: its power K, and p, the power of |v| its drawn length is the
        peak of (|v|^{2K+N} peaks at |v| = (p/α)^½ with p = K + N/2; 0: no power)."""
        return 0, 0.0

    def drawn(self, rng, system, carrier, K: int) -> dict:
        """The extras of a fresh function of power K whose draw singled out `carrier`
        (optimise.sampler.Carrier: the coordinate v = u^T r and particle centres displaced along
        it); any further random numbers from `rng`, after those of the common draw."""
        return {}

    def powers(self, basis, idx) -> np.ndarray | None:
        """The powers K of functions `idx`, learned per channel by the sampler (None: no powers)."""
        return None

    def draw_learned_power(self, rng, powers, K_max: int) -> int | None:
        """A power near the learned ones (None where the family has no powers)."""
        return None

    def neighbours(self, f, K_max: int) -> list:
        """One-function bases next to the one-function basis `f` in its power (none without powers)."""
        return []

    # --- refinement: θ = (exponent part, tail) ---------------------------------------
    def prepared(self, f, x):
        """The one-function basis `f` as it is parametrised in coordinate set x (the same
        normalised function)."""
        return f

    def theta_tail(self, f, x) -> np.ndarray:
        """The extras' part of θ of the one-function basis `f` in coordinate set x."""
        return np.zeros(0)

    def from_tail(self, f, x, tail: np.ndarray, K: int | None = None) -> dict:
        """The extras of the function with θ tail `tail` (`f`: the parametrised function; `K`: a
        power to set instead of f's)."""
        return {}

    def tail_directions(self, f, x, tail: np.ndarray, P: int, offset: int):
        """∂(extras)/∂θ_p for the P parameters of θ, the tail starting at `offset`; None when the
        family has no extras (the engine then takes none)."""
        return None
