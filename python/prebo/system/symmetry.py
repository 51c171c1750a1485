"""Permutational symmetry: spin-projected Young operators as coefficients over permutations.

For each group of identical particles with spin s and total spin S we build one
spin function chi_{S, M=S} by sequential angular-momentum coupling
[[[s s]_{S_12} s]_{S_123} ...]_S, taking at each step the smallest intermediate
spin from which S can still be reached. The (anti)symmetrised matrix element is
(Suzuki & Varga, Lect. Notes Phys. m54, sec. 2.3)

    <A phi_I chi | O | A phi_J chi> ∝ sum_P c_P <phi_I | O | P phi_J>,
    c_P = sign(P)^(2s) <chi | P chi>,

with sign(P) applied to fermions only. One spin function per group suffices
because the spatial functions are not restricted. c_P = c_{P^-1}, so the
matrices are symmetric. Groups multiply: the operations are the direct product
of the groups' permutations.
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from fractions import Fraction
from math import factorial, sqrt

import numpy as np

from ..errors import SpinError
from .permutations import adjoint, class_sum, compose, lift, normalised, product, same, sign

#: coefficients (relative to the identity's) that differ by less are the same: rationals written as floats
ROUNDING = 1e-10


def clebsch_gordan(j1: Fraction, m1: Fraction, j2: Fraction, m2: Fraction, j: Fraction, m: Fraction) -> float:
    """<j1 m1 j2 m2 | j m> by Racah's formula (Condon–Shortley phases)."""
    if m1 + m2 != m or not abs(j1 - j2) <= j <= j1 + j2 or max(abs(m1), abs(m2), abs(m)) > max(j1, j2, j):
        return 0.0
    if abs(m1) > j1 or abs(m2) > j2 or abs(m) > j:
        return 0.0
    f = lambda x: factorial(int(x))  # noqa: E731  (all arguments are non-negative integers here)
    pre = (2 * j + 1) * f(j1 + j2 - j) * f(j1 - j2 + j) * f(-j1 + j2 + j) / f(j1 + j2 + j + 1)
    pre *= f(j + m) * f(j - m) * f(j1 - m1) * f(j1 + m1) * f(j2 - m2) * f(j2 + m2)
    total = 0.0
    for k in range(0, int(j1 + j2 - j) + 1):
        args = [k, j1 + j2 - j - k, j1 - m1 - k, j2 + m2 - k, j - j2 + m1 + k, j - j1 - m2 + k]
        if any(a < 0 for a in args):
            continue
        den = 1
        for a in args:
            den *= f(a)
        total += (-1) ** k / den
    return sqrt(pre) * total


def coupling_path(s: Fraction, n: int, S: Fraction) -> list[Fraction]:
    """Intermediate spins S_1 = s, S_2, ..., S_n = S, smallest first; SpinError if S is impossible."""

    def search(path):
        if len(path) == n:
            return path if path[-1] == S else None
        lo, hi = abs(path[-1] - s), path[-1] + s
        k = lo
        while k <= hi:
            found = search(path + [k])
            if found:
                return found
            k += 1
        return None

    path = search([s]) if n >= 1 else None
    if path is None:
        raise SpinError(f"{n} particles of spin {s} cannot couple to total spin {S}")
    return path


def lowest_total_spin(s: Fraction, n: int) -> Fraction:
    """The smallest total spin n particles of spin s can form (0 or 1/2 for spin 1/2)."""
    S = Fraction((n * s.numerator * (2 // s.denominator)) % 2, 2)
    while True:
        try:
            coupling_path(s, n, S)
            return S
        except SpinError:
            S += 1


def spin_function(s: Fraction, n: int, S: Fraction) -> np.ndarray:
    """chi_{S, M=S} of n spin-s particles as a tensor of shape (2s+1,)*n (index 0 is m = s)."""
    path = coupling_path(s, n, S)
    d = int(2 * s + 1)
    ms = [s - k for k in range(d)]
    # states[M] = vector over the first k particles with total spin path[k-1], projection M
    states = {m: np.eye(d)[i] for i, m in enumerate(ms)}
    for k in range(1, n):
        J0, J = path[k - 1], path[k]
        new = {}
        M = -J
        while M <= J:
            v = np.zeros(d ** (k + 1))
            for M0, vec in states.items():
                for i, m in enumerate(ms):
                    c = clebsch_gordan(J0, M0, s, m, J, M)
                    if c:
                        v += c * np.kron(vec, np.eye(d)[i])
            new[M] = v
            M += 1
        states = new
    return states[S].reshape((d,) * n)


@dataclass(frozen=True)
class Group:
    """Identical particles: their indices in the system, spin s, fermion or boson, total spin S."""

    name: str
    indices: tuple[int, ...]
    spin: Fraction
    total_spin: Fraction

    @property
    def fermion(self) -> bool:
        """Half-integer spin: permutations carry their sign."""
        return self.spin.denominator == 2

    def coefficients(self) -> dict[tuple[int, ...], float]:
        """c_P for every permutation P of the group (as a tuple of positions 0..n-1)."""
        n = len(self.indices)
        chi = spin_function(self.spin, n, self.total_spin)
        out = {}
        for p in itertools.permutations(range(n)):
            overlap = float(np.sum(chi * np.transpose(chi, p)))
            c = (sign(p) if self.fermion else 1) * overlap
            if abs(c) > 1e-14:
                out[p] = c
        return out


@dataclass(frozen=True)
class Symmetriser:
    """A symmetry operator Σ_P c_P P over permutations of the particles (LFCC order).

    Parameters: `permutations`, tuples p with (Π_p r)_i = r_{p(i)}, so that P φ(r) = φ(Π_p r)
    and a Gaussian's A → Π_pᵀ A Π_p; `coefficients`, the real c_P (dimensionless, only their
    ratios matter); `young`, the Young string (ecgpack SYMMETRY syntax, e.g. "(1+P23)(1-P24)")
    the operator was made from, a label that is not compared and not stored in basis.json.
    A `System` builds its spin state's operator (`from_groups`) or carries an explicit one.
    """

    permutations: tuple[tuple[int, ...], ...]
    coefficients: tuple[float, ...]
    young: str | None = field(default=None, compare=False)

    @classmethod
    def from_groups(cls, n: int, groups: list[Group]) -> "Symmetriser":
        """The spin-projected operator of the module docstring: the product over `groups`."""
        perms, coefs = [tuple(range(n))], [1.0]
        for g in groups:
            new_p, new_c = [], []
            for gp, gc in g.coefficients().items():
                lifted = lift(gp, g.indices, n)
                for p, c in zip(perms, coefs):
                    new_p.append(compose(p, lifted))
                    new_c.append(c * gc)
            perms, coefs = new_p, new_c
        return cls(tuple(perms), tuple(coefs))

    @classmethod
    def from_operator(cls, op: dict, young: str | None = None) -> "Symmetriser":
        """From a group-algebra element {permutation: coefficient}, permutations in
        lexicographic order (the identity first)."""
        perms = sorted(op)
        return cls(tuple(perms), tuple(float(op[p]) for p in perms), young)

    def operator(self) -> dict:
        """The group-algebra element {permutation: coefficient}, identity coefficient 1."""
        return normalised({tuple(p): float(c) for p, c in zip(self.permutations, self.coefficients)})

    @property
    def matrices(self) -> np.ndarray:
        """The LFCC permutation matrices Π_p, shape (operations, N, N)."""
        n = len(self.permutations[0])
        out = np.zeros((len(self.permutations), n, n))
        for k, p in enumerate(self.permutations):
            out[k, np.arange(n), list(p)] = 1.0
        return out

    def as_dict(self) -> dict:
        """basis.json's "symmetry" block."""
        return {"permutations": [list(p) for p in self.permutations], "coefficients": list(self.coefficients)}

    @classmethod
    def from_dict(cls, d: dict) -> "Symmetriser":
        """The operator of an `as_dict` block; SpinError naming what is malformed (no other keys,
        integer positions, real coefficients: no booleans, no strings; no permutation twice)."""
        if not isinstance(d, dict) or set(d) != {"permutations", "coefficients"}:
            raise SpinError("symmetry must be {permutations: [[0, 1, ...], ...], coefficients: [...]}, got keys "
                            f"{sorted(d) if isinstance(d, dict) else type(d).__name__}")
        perms, coefs = d["permutations"], d["coefficients"]
        if not (isinstance(perms, list) and all(isinstance(p, list) and all(type(i) is int for i in p) for p in perms)):
            raise SpinError("symmetry: permutations must be lists of integer positions 0..n-1")
        if not (isinstance(coefs, list) and all(type(c) in (int, float) for c in coefs)):
            raise SpinError("symmetry: coefficients must be numbers (no strings, no booleans)")
        perms, coefs = tuple(map(tuple, perms)), tuple(map(float, coefs))
        if len(perms) != len(coefs) or not perms:
            raise SpinError("symmetry operator: permutations and coefficients do not match")
        k = len(perms[0])
        if any(sorted(p) != list(range(k)) for p in perms) or not all(np.isfinite(coefs)):
            raise SpinError(f"symmetry operator: every permutation must reorder 0..{k - 1} and every "
                            "coefficient be finite")
        if len(set(perms)) != len(perms):
            raise SpinError("symmetry operator: a permutation is listed twice")
        if not dict(zip(perms, coefs)).get(tuple(range(k)), 0.0) > 0:
            raise SpinError("symmetry operator: the identity needs a positive coefficient")
        return cls(perms, coefs)

    def equivalent(self, other: "Symmetriser", tol: float = ROUNDING) -> bool:
        """The same operator up to an overall factor (coefficients relative to the identity's
        within `tol`: rationals written as floats)."""
        a, b = dict(zip(self.permutations, self.coefficients)), dict(zip(other.permutations, other.coefficients))
        identity = tuple(range(len(self.permutations[0])))
        if identity not in a or identity not in b:
            return False
        return all(abs(a.get(p, 0.0) / a[identity] - b.get(p, 0.0) / b[identity]) <= tol for p in set(a) | set(b))

    def antisymmetric(self, i: int, j: int) -> bool:
        """Whether every function the operator O makes changes sign when particles i and j trade
        places, P_ij O = O P_ij = −O (coefficients within ROUNDING of the identity's): then every
        state Ψ = Σ_k c_k O φ_k vanishes where r_i = r_j — two identical fermions whose spins are
        symmetric, like the electrons of a triplet — and its ⟨δ³(r_ij)⟩ is zero exactly."""
        n = len(self.permutations[0])
        swap = tuple(j if k == i else i if k == j else k for k in range(n))
        op = self.operator()
        minus = {p: -c for p, c in op.items()}
        return same(product({swap: 1.0}, op), minus, ROUNDING) and same(product(op, {swap: 1.0}), minus, ROUNDING)

    def check_projector(self, groups: list[Group]) -> None:
        """Refuse (SpinError) an operator O that is not a projector onto functions of the spin state
        of `groups`: O† = O (c_P = c_{P⁻¹}), O² ∝ O, and Z O ∝ O for Z the central idempotent of
        the state's irreducible representation (`central`). Such an O is positive semidefinite
        and lies in that representation, so the Rayleigh–Ritz energy with it is one of that state:
        the spin-projected operator of the state (one row), an ecgpack Young operator Y†Y
        (another row). Coefficients compare within ROUNDING of the identity's."""
        n = len(self.permutations[0])
        if not dict(zip(self.permutations, self.coefficients)).get(tuple(range(n)), 0.0) > 0:
            raise SpinError("the identity needs a positive coefficient")
        op = self.operator()
        if not same(op, adjoint(op), ROUNDING):
            raise SpinError("not Hermitian (the coefficients of P and P⁻¹ differ)")
        if not same(normalised(product(op, op)), op, ROUNDING):
            raise SpinError("not a projector (its square is not a multiple of it)")
        identity, z = tuple(range(n)), central(n, groups)
        zo = product(z, op)
        if not zo.get(identity, 0.0) > ROUNDING * z[identity]:
            raise SpinError("it projects onto functions of another symmetry")
        if not same(normalised(zo), op, ROUNDING):
            raise SpinError("it projects onto functions of other symmetries too")


def central(n: int, groups: list[Group]) -> dict:
    """∝ the central idempotent Z of the spin state of `groups`: the projector onto every function
    of that symmetry (each group's class sum of its spin-projected operator, multiplied)."""
    z = {tuple(range(n)): 1.0}
    for g in groups:
        gop = {lift(gp, g.indices, n): c for gp, c in g.coefficients().items()}
        z = product(z, class_sum(gop, g.indices))
    return z


def implied_spins(op: dict, groups: list[tuple[int, ...]], spins: list[Fraction], n: int) -> list[Fraction] | None:
    """The total spin of each group of identical particles (`groups`: their indices, `spins`:
    their spin s) whose irreducible representation the operator `op` lies in (Z op ∝ op,
    `central`), or None when it lies in no single one (a mixture of spin states, or none)."""
    choices = []
    for idx, s in zip(groups, spins):
        opts = []
        S = Fraction(len(idx) * s).limit_denominator(2)
        cand = S - int(S)  # 0 or 1/2
        while cand <= S:
            try:
                coupling_path(s, len(idx), cand)
                opts.append(cand)
            except SpinError:
                pass
            cand += 1
        choices.append(opts)
    op = normalised(op)
    for combo in itertools.product(*choices):
        zo = product(central(n, [Group("g", idx, s, S) for idx, s, S in zip(groups, spins, combo)]), op)
        if zo.get(tuple(range(n)), 0.0) > 0 and same(normalised(zo), op, ROUNDING):
            return list(combo)
    return None
