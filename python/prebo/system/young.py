"""Young strings: symmetry operators written as products of factors, ``(1+P23)(1-P24)``.

This is the SYMMETRY syntax of ecgpack files (`prebo.io.ecgpack`). ``Pij`` swaps particles
i and j (1-based); as operators on functions (P_a P_b f)(r) = f(Π_b Π_a r), i.e. the product
of P_a and P_b is the permutation a∘b (`permutations.compose`). A string's product Y is not
Hermitian in general; the Rayleigh–Ritz energy of the functions Y φ_I has the matrix elements
⟨Yφ_I|H|Yφ_J⟩ = ⟨φ_I|H Y†Y|φ_J⟩, so the symmetry operator of a string is Y†Y, normalised
to identity coefficient 1 (`young_operator`).
"""
from __future__ import annotations

import itertools
import re

from .permutations import adjoint, compose, lift, normalised, product, same, transposition
from .symmetry import Group, Symmetriser

_TERM = re.compile(r"\s*([+-])?\s*(\d+(?:\.\d*)?(?:[eEdD][+-]?\d+)?)?\s*\*?\s*((?:P(?:\d\d|\(\s*\d+\s*,\s*\d+\s*\))\s*\*?\s*)*)")
_PTOK = re.compile(r"P(?:(\d)(\d)|\(\s*(\d+)\s*,\s*(\d+)\s*\))")


def _parse_factor(text: str, n: int) -> dict:
    out: dict = {}
    pos, first = 0, True
    text = text.strip()
    if not text:
        raise ValueError("empty factor ()")
    while pos < len(text):
        m = _TERM.match(text, pos)
        if not m or m.end() == pos:
            raise ValueError(f"cannot read {text[pos:]!r}")
        sign, num, ps = m.group(1), m.group(2), m.group(3)
        if sign is None and not first:
            raise ValueError(f"missing + or - before {text[pos:]!r}")
        if not num and not ps.strip():
            raise ValueError(f"cannot read {text[pos:]!r}")
        coef = float(num.replace("d", "e").replace("D", "e")) if num else 1.0
        if sign == "-":
            coef = -coef
        perm = tuple(range(n))
        for t in _PTOK.finditer(ps):
            i, j = (int(t.group(1)), int(t.group(2))) if t.group(1) else (int(t.group(3)), int(t.group(4)))
            if not (1 <= i <= n and 1 <= j <= n) or i == j:
                raise ValueError(f"P{i}{j}: particles are numbered 1..{n}, two different ones")
            perm = compose(perm, transposition(n, i - 1, j - 1))
        out[perm] = out.get(perm, 0.0) + coef
        pos, first = m.end(), False
    return {k: v for k, v in out.items() if v != 0.0}


def young_product(string: str, n: int) -> dict:
    """The group-algebra element Y of a Young string for n particles: its factors' product, in order.

    A factor is ``(t ± t ± ...)`` with terms ``1``, ``Pij`` / ``P(i,j)`` and products of them,
    optionally with a numeric coefficient (``0.5P23P24``). ``1``, ``(1)`` or ``none`` is the
    identity. ValueError on anything else."""
    s = string.strip()
    y = {tuple(range(n)): 1.0}
    if s.lower() in ("", "1", "none", "(1)"):
        return y
    pos, found = 0, False
    while pos < len(s):
        if s[pos] in " \t*":
            pos += 1
            continue
        if s[pos] != "(":
            raise ValueError(f"unexpected {s[pos:]!r}: expected factors in parentheses, e.g. (1+P23)(1-P24)")
        depth, end = 0, None
        for k in range(pos, len(s)):
            depth += {"(": 1, ")": -1}.get(s[k], 0)
            if depth == 0:
                end = k
                break
        if end is None:
            raise ValueError(f"unbalanced parentheses in {s[pos:]!r}")
        y = product(y, _parse_factor(s[pos + 1:end], n))
        pos, found = end + 1, True
    if not found:
        raise ValueError("expected factors in parentheses, e.g. (1+P23)(1-P24)")
    if not y:
        raise ValueError("the product of the factors is zero")
    return y


def young_operator(string: str, n: int) -> Symmetriser:
    """The symmetry operator Y†Y of a Young string (identity coefficient 1), labelled with it."""
    y = young_product(string, n)
    return Symmetriser.from_operator(normalised(product(adjoint(y), y)), young=string)


def _transpositions(p) -> str:
    """A permutation as a product of transpositions Pij (1-based) whose operator product is P_p."""
    cur, swaps = list(p), []
    for i in range(len(cur)):
        if cur[i] != i:
            j = cur.index(i)
            cur[i], cur[j] = cur[j], cur[i]
            swaps.append((i, j))
    # p ∘ t_1 ∘ ... ∘ t_m = id  =>  p = t_m ∘ ... ∘ t_1
    return "".join(f"P{a + 1}{b + 1}" if max(a, b) < 9 else f"P({a + 1},{b + 1})" for a, b in reversed(swaps))


def _explicit_string(op: dict) -> str:
    """One factor with every coefficient: ``(1+0.5P23-P24...)``."""
    ident = tuple(range(len(next(iter(op)))))
    terms = ["1"]
    for p in sorted(op):
        if p != ident:
            c = op[p]
            num = "" if abs(abs(c) - 1.0) < 1e-15 else repr(abs(c))
            terms.append(("-" if c < 0 else "+") + num + _transpositions(p))
    return "(" + "".join(terms) + ")"


def _group_string(group: Group, n: int, max_factors: int = 4) -> str | None:
    """An ordered product of distinct (1±Pij) factors within `group` whose Y†Y is the group's
    spin-projected operator, or None."""
    ident = tuple(range(n))
    target = normalised({lift(gp, group.indices, n): c for gp, c in group.coefficients().items()})
    if len(target) == 1:
        return ""
    pairs = list(itertools.combinations(group.indices, 2))
    for k in range(1, min(len(pairs), max_factors) + 1):
        for seq in itertools.permutations(pairs, k):
            for signs in itertools.product((1.0, -1.0), repeat=k):
                y = {ident: 1.0}
                for (i, j), sg in zip(seq, signs):
                    y = product(y, {ident: 1.0, transposition(n, i, j): sg})
                op = product(adjoint(y), y) if y else {}
                if op.get(ident, 0.0) > 0 and same(normalised(op), target):
                    return "".join(f"(1{'+' if sg > 0 else '-'}P{i + 1}{j + 1})" for (i, j), sg in zip(seq, signs))
    return None


def young_string(sym: Symmetriser, groups: list[Group], n: int) -> str:
    """A Young string whose Y†Y is `sym` up to a factor: `sym.young` if it has one, else a
    product over `groups` of (1±Pij) factors (prebo's doublet of three electrons 2, 3, 4 is
    (1-P24)(1+P23)), else one explicit factor with every coefficient (`young_product` reads
    it back exactly; ecgpack may not)."""
    target = sym.operator()
    if sym.young is not None and same(young_operator(sym.young, n).operator(), target):
        return sym.young
    if len(target) == 1:
        return "(1)"
    parts = [_group_string(g, n) for g in groups]
    if None not in parts and "".join(parts):
        s = "".join(parts)
        if same(young_operator(s, n).operator(), target):
            return s
    return _explicit_string(target)
