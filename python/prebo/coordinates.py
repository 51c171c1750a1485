"""Coordinate sets x = U_x r (Muolo, Mátyus & Reiher, J. Chem. Phys. 148, 084112 (2018),
sec. II; equation numbers below are that paper's).

Every U_x is N_p x N_p and dimensionless: rows 1..N_p-1 are translationally invariant
(each sums to zero, eq. (3)), the last row is m_j / m_tot (eq. (4)). Exponents transform
as A^(x) = U^-T A^(r) U^-1 = blockdiag(𝒜, c_A) and global vectors as u^(x) = U^-T u^(r)
= (u', c_U) (eqs. (24), (25)). The kinetic matrix in x is U M U^T = blockdiag(μ, 1/(2 m_tot))
(eq. (9)). Exponents are in bohr⁻², masses in m_e, μ in 1/m_e.

One mass may be infinite (a clamped particle, prebo.system.particles): every m_j / m_tot takes
its limit (`mass_fractions`), 1 on that particle and 0 elsewhere, so the last row of U_x is its
position, the centre of mass, and U_x stays finite.
"""
from __future__ import annotations

import itertools
import reprlib
from dataclasses import dataclass

import numpy as np

from .errors import InputError, SeparabilityError


@dataclass(frozen=True)
class CoordinateSet:
    """A named coordinate set ("channel") and its matrix U_x.

    Parameters: `name`, as `by_name` reads it (``"jacobi:0-1-2"``, ``"hpc:0"``, ``"cmc:2"``);
    `U`, the (N_p, N_p) matrix U_x of eq. (2) (dimensionless).
    """

    name: str
    U: np.ndarray

    def __post_init__(self):
        if not isinstance(self.name, str):
            raise InputError(f"CoordinateSet: name = {reprlib.repr(self.name)}: must be a str")
        U = _reals(self.U)
        if U is None or U.ndim != 2 or U.shape[0] != U.shape[1] or not np.all(np.isfinite(U)):
            got = reprlib.repr(self.U if U is None else U.tolist())
            raise InputError(f"CoordinateSet {self.name}: U = {got}: must be a square matrix of finite real numbers")
        object.__setattr__(self, "U", U)

    def check(self, masses: np.ndarray, tol: float = 1e-12) -> None:
        """Raise InputError unless U satisfies eqs. (3) and (4) for `masses` (m_e) and is invertible."""
        masses = _masses(masses, f"{self.name}: check")
        n = len(masses)
        if self.U.shape != (n, n):
            raise InputError(f"{self.name}: U has shape {self.U.shape}, expected {(n, n)}")
        if np.max(np.abs(self.U[:-1].sum(axis=1))) > tol:
            raise InputError(f"{self.name}: a translationally invariant row does not sum to zero")
        if np.max(np.abs(self.U[-1] - mass_fractions(masses))) > tol:
            raise InputError(f"{self.name}: last row is not m_j / m_tot")
        if abs(np.linalg.det(self.U)) < 1e-12:
            raise InputError(f"{self.name}: U is singular")

    @property
    def U_inv(self) -> np.ndarray:
        """U_x⁻¹."""
        return np.linalg.inv(self.U)

    def mu(self, M: np.ndarray) -> np.ndarray:
        """Internal kinetic matrix μ (1/m_e): the TI block of U M U^T for the mass matrix M (eq. (9))."""
        return (self.U @ M @ self.U.T)[:-1, :-1]

    def to_lab(self, A_int: np.ndarray, c_A: float) -> np.ndarray:
        """A^(r) = U^T blockdiag(𝒜, c_A) U (eq. (24)); 𝒜 (N_p-1 square) and c_A in bohr⁻²."""
        n = self.U.shape[0]
        Ax = np.zeros((n, n))
        Ax[:-1, :-1] = A_int
        Ax[-1, -1] = c_A
        return self.U.T @ Ax @ self.U

    def from_lab(self, A_r: np.ndarray, tol: float = 1e-9) -> tuple[np.ndarray, float]:
        """(𝒜, c_A) from A^(r) (eq. (24)); SeparabilityError if A^(x) couples the CM to internal
        coordinates by more than `tol` of its largest element."""
        Ui = self.U_inv
        Ax = Ui.T @ A_r @ Ui
        scale = max(np.max(np.abs(Ax)), 1e-300)
        if np.max(np.abs(Ax[-1, :-1])) > tol * scale:
            raise SeparabilityError(f"{self.name}: exponent couples the CM to internal coordinates")
        return Ax[:-1, :-1], float(Ax[-1, -1])

    def transform_vectors_to_x(self, w: np.ndarray) -> np.ndarray:
        """Coulomb / global vectors w^(x) = U^-T w^(r), one per row."""
        return w @ self.U_inv

    def transform_operation(self, Pi: np.ndarray) -> np.ndarray:
        """A permutation matrix of LFCC in x: U Π U^-1 (block-diagonal for equal-mass permutations)."""
        return self.U @ Pi @ self.U_inv


def jacobi(masses: np.ndarray, order=None) -> CoordinateSet:
    """Jacobi set (eq. (5)) for a particle `order` (default 0..N_p-1; `masses` in m_e):
    x_i = Σ_{j<=i} m_j r_j / m_{1..i} - r_{i+1}; named ``jacobi:ORDER``."""
    masses = _masses(masses, "jacobi")
    n = len(masses)
    try:
        indices = list(range(n)) if order is None else list(order)
    except TypeError:  # not a sequence
        indices = []
    if not all(_is_index(k) for k in indices) or sorted(indices) != list(range(n)):
        raise InputError(f"Jacobi order {reprlib.repr(order)} is not a permutation of the particles 0..{n - 1}")
    order = [int(k) for k in indices]
    U = np.zeros((n, n))
    for i in range(n - 1):
        cluster = order[: i + 1]
        U[i, cluster] = mass_fractions(masses[cluster])
        U[i, order[i + 1]] -= 1.0
    U[-1] = mass_fractions(masses)
    return CoordinateSet("jacobi:" + "-".join(map(str, order)), U)


def heavy_particle_centred(masses: np.ndarray, centre: int) -> CoordinateSet:
    """Heavy-particle-centred set (eq. (6)): x_i = r_i - r_centre for i != centre; named ``hpc:CENTRE``."""
    masses = _masses(masses, "heavy_particle_centred")
    n = len(masses)
    _particle_index(centre, n, "hpc", "centre")
    U = np.zeros((n, n))
    for row, i in enumerate(k for k in range(n) if k != centre):
        U[row, i], U[row, centre] = 1.0, -1.0
    U[-1] = mass_fractions(masses)
    return CoordinateSet(f"hpc:{centre}", U)


def cm_centred(masses: np.ndarray, dropped: int | None = None) -> CoordinateSet:
    """CM-centred set: x_i = r_i - X_CM for every particle but `dropped` (default: the last).

    Named ``cmc:DROPPED``. (Eq. (7) divides by m_{i..N}, which violates eq. (3); this is
    the set the paper's figure 1 describes.) With an infinite mass the centre of mass is that
    particle, whose coordinate r_k - X_CM vanishes: it is the one dropped (default; InputError for
    another), and the set is ``hpc:k``'s.
    """
    masses = _masses(masses, "cm_centred")
    n = len(masses)
    clamped = np.flatnonzero(np.isinf(masses))
    default = int(clamped[0]) if len(clamped) else n - 1
    dropped = default if dropped is None else dropped
    _particle_index(dropped, n, "cmc", "dropped")
    if len(clamped) and dropped != default:
        raise InputError(f"coordinate set cmc:{dropped}: particle {default} has an infinite mass and is the centre "
                         f"of mass; the CM-centred set drops it (cmc:{default})")
    U = np.zeros((n, n))
    for row, i in enumerate(k for k in range(n) if k != dropped):
        U[row] = -mass_fractions(masses)
        U[row, i] += 1.0
    U[-1] = mass_fractions(masses)
    return CoordinateSet(f"cmc:{dropped}", U)


def _is_index(k) -> bool:
    """Whether `k` is an integer (not a bool)."""
    return isinstance(k, (int, np.integer)) and not isinstance(k, bool)


def _particle_index(i, n: int, kind: str, arg: str) -> None:
    """InputError naming argument `arg` of coordinate set `kind` unless `i` is a particle 0..n-1."""
    if not (_is_index(i) and 0 <= i < n):
        raise InputError(f"coordinate set {kind}:{i}: {arg} particle {i!r} is not one of 0..{n - 1}")


def _reals(value) -> np.ndarray | None:
    """`value` as a float array if it is real numbers, else None."""
    try:
        a = np.asarray(value)
    except ValueError:  # ragged nesting
        return None
    return a.astype(float) if a.dtype.kind in "iuf" else None


def _masses(masses, where: str) -> np.ndarray:
    """`masses` as a float array of two or more positive numbers (m_e), finite but for at most one
    infinite mass; InputError naming `where` otherwise."""
    m = _reals(masses)
    if m is None or m.ndim != 1 or len(m) < 2 or not np.all((m > 0) & ~np.isnan(m)) or np.isinf(m).sum() > 1:
        got = reprlib.repr(masses if m is None else m.tolist())
        raise InputError(f"{where}: masses = {got}: must be the masses of two or more particles, positive "
                         "numbers in m_e, finite but for at most one (System.masses)")
    return m


def mass_fractions(masses: np.ndarray) -> np.ndarray:
    """m_j / m_tot (eq. (4)) of the masses `masses` (m_e), and the limit of an infinite mass: 1 on
    that particle, 0 elsewhere (the centre of mass on it)."""
    infinite = np.isinf(masses)
    return infinite.astype(float) if infinite.any() else masses / masses.sum()


def all_sets(masses: np.ndarray, labels=None) -> list[CoordinateSet]:
    """Every Jacobi set, every heavy-particle-centred set and the CM-centred set (but with an
    infinite mass, where it is a heavy-particle-centred one).

    Sets that differ only by a relabelling of identical particles (equal `labels`, e.g. the
    particle names) are counted once, as are Jacobi orders that differ only by swapping the
    first two particles (x_1 changes sign). Without labels every particle is distinct.
    `masses` in m_e; returns the list of `CoordinateSet`s."""
    masses = _masses(masses, "all_sets")
    n = len(masses)
    try:
        labels = list(range(n)) if labels is None else list(labels)
    except TypeError:
        labels = None
    if labels is None or len(labels) != n:
        raise InputError(f"all_sets: labels must be one label per particle ({n}), or None")
    sets, seen = [], set()

    def add(key, make):
        if key not in seen:
            seen.add(key)
            sets.append(make())

    for order in itertools.permutations(range(n)):
        names = [labels[i] for i in order]
        first = tuple(sorted(map(str, names[:2])))
        add(("jacobi", first, tuple(map(str, names[2:]))), lambda o=order: jacobi(masses, o))
    for c in range(n):
        add(("hpc", str(labels[c])), lambda c=c: heavy_particle_centred(masses, c))
    if np.isfinite(masses).all():  # with an infinite mass k it is hpc:k (`cm_centred`)
        sets.append(cm_centred(masses))
    return sets


def by_name(masses: np.ndarray, name: str) -> CoordinateSet:
    """The set named as in `CoordinateSet.name` ("jacobi:0-1-2", "hpc:0", "cmc:2")."""
    kind, _, arg = str(name).partition(":")
    try:
        numbers = [int(k) for k in arg.split("-")] if arg else []
    except ValueError:
        raise InputError(f"malformed coordinate set name {name!r}") from None
    if kind == "jacobi":
        return jacobi(masses, numbers or None)
    if kind == "hpc" and len(numbers) == 1:
        return heavy_particle_centred(masses, numbers[0])
    if kind == "cmc" and len(numbers) <= 1:
        return cm_centred(masses, numbers[0] if numbers else None)
    raise InputError(f"unknown coordinate set {name!r} (jacobi:ORDER, hpc:I or cmc:I with particles "
                     f"0..{len(masses) - 1})")
