"""The group algebra of permutations of N particles.

A permutation is a tuple p of 0-based positions acting on LFCC as (Π_p r)_i = r_{p(i)}, and
on functions as P_p f(r) = f(Π_p r) (`Symmetriser.matrices` holds the Π_p). Operators
multiply as P_a P_b = P_{a∘b} with (a∘b)(i) = a(b(i)). An element of the group algebra
(a Young operator, a symmetriser) is a dict {permutation: coefficient}.
"""
from __future__ import annotations

import itertools

#: coefficients below this fraction of the identity's are dropped by `normalised`
COEF_TOL = 1e-12


def compose(a, b) -> tuple[int, ...]:
    """a∘b, so that P_a P_b = P_{a∘b}."""
    return tuple(a[i] for i in b)


def inverse(p) -> tuple[int, ...]:
    """p⁻¹ (P_p† = P_{p⁻¹}: permutations are unitary)."""
    inv = [0] * len(p)
    for i, k in enumerate(p):
        inv[k] = i
    return tuple(inv)


def transposition(n: int, i: int, j: int) -> tuple[int, ...]:
    """The permutation of n particles that swaps i and j (0-based)."""
    p = list(range(n))
    p[i], p[j] = j, i
    return tuple(p)


def lift(p, indices, n: int) -> tuple[int, ...]:
    """A permutation p of positions 0..k-1 acting on the particles `indices` of n."""
    q = list(range(n))
    for pos, src in enumerate(p):
        q[indices[pos]] = indices[src]
    return tuple(q)


def sign(p) -> int:
    """(-1)^(number of inversions)."""
    p = list(p)
    s = 1
    for i in range(len(p)):
        for j in range(i + 1, len(p)):
            if p[i] > p[j]:
                s = -s
    return s


def product(x: dict, y: dict) -> dict:
    """The algebra product x y (zero coefficients dropped)."""
    out: dict = {}
    for a, ca in x.items():
        for b, cb in y.items():
            k = compose(a, b)
            out[k] = out.get(k, 0.0) + ca * cb
    return {k: v for k, v in out.items() if v != 0.0}


def adjoint(x: dict) -> dict:
    """x† for real coefficients: P_p → P_{p⁻¹}."""
    return {inverse(p): c for p, c in x.items()}


def normalised(x: dict) -> dict:
    """Coefficients divided by the identity's, those below COEF_TOL of it dropped;
    ValueError if the identity has no positive coefficient."""
    ident = tuple(range(len(next(iter(x)))))
    c0 = x.get(ident, 0.0)
    if not c0 > 0:
        raise ValueError("operator has no positive identity coefficient")
    return {p: c / c0 for p, c in x.items() if abs(c) > COEF_TOL * abs(c0)}


def same(x: dict, y: dict, tol: float = 1e-10) -> bool:
    """Equal coefficients within `tol` (absolute)."""
    return all(abs(x.get(k, 0.0) - y.get(k, 0.0)) <= tol for k in set(x) | set(y))


def class_sum(x: dict, moved) -> dict:
    """Σ_g g x g⁻¹ over the permutations g of the positions `moved`; for x a primitive
    idempotent of that symmetric group it is ∝ the central idempotent of x's irrep."""
    n = len(next(iter(x)))
    out: dict = {}
    for sigma in itertools.permutations(moved):
        g = list(range(n))
        for a, b in zip(moved, sigma):
            g[a] = b
        g = tuple(g)
        gi = inverse(g)
        for p, c in x.items():
            k = compose(compose(g, p), gi)
            out[k] = out.get(k, 0.0) + c
    return out
