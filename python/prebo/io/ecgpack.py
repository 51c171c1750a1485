"""Read and write the real-ECG basis files of ecgpack / ATOM-MOL-nonBO (``*.inout.txt``).

The format (RG_0S: real plain ECGs, L = 0, S states)
----------------------------------------------------
Sections are separated by lines of ``=====``::

     BASIS_TYPE RG_0S
     PARTICLES      3
     MASSES  0.7294299541700000E+04  0.1000000000000000E+01  0.1000000000000000E+01
     CHARGES  0.2000000000000000E+01 -0.1000000000000000E+01 -0.1000000000000000E+01
     SYMMETRY (1+P23)
     BASIS_SIZE    490
     CURRENT_ENERGY -0.2903304557617398E+01
     ... (other keyword lines: solver and generator settings, kept as read)
     ==============================
        490 -0.2903304557617398E+01      0    415      0        (status line)
     ==============================
     BASIS_ENL G ...                                            (command list)
     ==============================
          1 -0.1850658781660858E+01      0      0      0        (energy history)
     ==============================
          1 -0.1193763003061485E+01 -0.3408111207694432E-01 -0.8266391106951689E+00
        ...                                                     (the basis)

Each basis line is a 1-based index and the n(n+1)/2 reals vech(L), n = PARTICLES - 1:
the lower triangle of L stored column by column. 𝒜 = L Lᵀ and
φ = exp(−rᵀ(𝒜 ⊗ I₃)r) with r_i = R_{i+1} − R_1, coordinates relative to particle 1:
prebo's heavy-particle-centred set ``hpc:0``. A function becomes, in laboratory-frame
Cartesian coordinates, A = U_xᵀ blockdiag(𝒜, c_A) U_x with a c_A of our choosing
(``read_inout(..., c_A=1.0)``); the translation-free energy does not depend on it.
Only the header keywords, the basis section and its size are read; the status line,
commands and energy history are skipped. Fortran ``D`` exponents are accepted.

Symmetry: what the Young string means
-------------------------------------
SYMMETRY is a product of factors such as ``(1+P23)(1-P24)``; ``Pij`` swaps particles i
and j (1-based, file order), acting on the ket as A → PᵀAP. As operators on functions,
(P_a P_b f)(r) = f(Π_b Π_a r), i.e. the product of P_a and P_b is the permutation a∘b.
The string's product is a Young operator Y, which is not Hermitian in general.
ecgpack's energy is the Rayleigh–Ritz energy of the functions Y φ_I, i.e. matrix elements
⟨Yφ_I|H|Yφ_J⟩ = ⟨φ_I|H Y†Y|φ_J⟩: the symmetry coefficients over permutations are those
of the Hermitian element O = Y†Y (we normalise them so that the identity has 1). This
was established on the Li-7 file: O reproduces the file's CURRENT_ENERGY to 1e-15
relative (a 32-digit evaluation to 1e-16), while Y itself gives no symmetric matrix and
the spin-projected operator gives another energy.

prebo's own symmetry (python/prebo/symmetry.py) is the spin-projected operator of one
spin function per group, with the smallest intermediate spins. For He, (1+P23)†(1+P23)
∝ 1 + P23 is exactly prebo's singlet, and the imported system is a plain
`prebo.System`. For Li, (1+P23)(1−P24) gives O ∝ 2 + P23 + P34 − 2 P24 − P234 − P243: the
projector onto the row of the [2,1] representation antisymmetric in particles 2 and 4.
prebo's doublet (spin function [[e2 e3]_0 e4]_1/2) projects onto the row symmetric in
2 and 3 — the same irreducible representation and spin, but a different row, so the same
functions give another energy (−7.4764 instead of −7.4774 Eh for Li-100). No spin state
and no particle order of prebo's Symmetriser gives O (rows symmetric in a pair and rows
antisymmetric in a pair are never conjugate in S3), so such a file's system is a
`YoungSystem`: a `prebo.System` whose `symmetriser` is the file's operator O. Everything
that asks `system.symmetriser` (prebo.evaluate in "lab" and "ti" coordinates,
prebo.integrals, the optimiser) then uses the file's operator. The state's spins are
the ones the operator implies (the irreducible representation O lies in), for labels.

basis.json keeps the operator: `Basis.to_dict` writes the "symmetry" block and
`System.from_dict` honours it whenever it is not the spin state's own operator.

Export
------
`write_inout` writes the header, a status line, an empty command list, a one-line
energy history and the basis, numbers as ``1PE23.16`` (the field width of ecgpack's
``-0.dddE+xx`` numbers, but 17 significant digits, so that doubles survive). A function
read from a file and not changed since is written with the file's own L (bit-exact
round trip); others with the Cholesky factor of their 𝒜 in ``hpc:0``. The Young
string is the imported one when it still describes the basis's symmetry; otherwise
it is searched among products of (1±Pij) factors within each group of identical
particles (Y†Y ∝ prebo's operator; e.g. prebo's doublet of three electrons is
(1−P24)(1+P23)); if there is none, the Hermitian operator itself is written as one
factor with explicit coefficients and transposition products, which `read_inout`
reads back exactly (ecgpack may not).

API: `read_inout(path, c_A=1.0) -> Basis`, `write_inout(basis, path, energy=None)`;
`parse_inout(path) -> InoutFile` for the raw content (e.g. `.energy`, ecgpack's
CURRENT_ENERGY, to print beside prebo's); `young_operator` / `young_string` convert
between SYMMETRY strings and prebo Symmetrisers; `YoungSystem` and `system_with_symmetry`
carry an explicit operator. Errors: `prebo.errors.BasisFileError` with ``file:line:``.
"""
from __future__ import annotations

import itertools
import math
import re
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path

import numpy as np

from ..basis import Basis, read_text, write_atomic
from ..coordinates import heavy_particle_centred
from ..errors import BasisFileError, PreboError, UnsupportedError
from ..system.particles import KNOWN
from ..system.symmetry import Group, Symmetriser
from ..system.system import State, System
from ..validation import check

__all__ = [
    "read_inout", "write_inout", "parse_inout", "InoutFile", "YoungSystem", "system_with_symmetry",
    "young_operator", "young_string",
]

SUPPORTED_TYPE = "RG_0S"
_SEP = re.compile(r"^\s*={5,}\s*$")
#: nuclei prebo has no name for: name -> (mass / m_e, charge, spin); used to name particles only
#: (the file's masses are kept). Nuclear masses from the atomic masses (AME 2020) less Z m_e.
EXTRA_NUCLEI = {
    "li6": (10961.898, 3.0, Fraction(1)),
    "li7": (12786.393, 3.0, Fraction(3, 2)),
    "be9": (16424.205, 4.0, Fraction(3, 2)),
}
_NAME_RTOL = 1e-5
_COEF_TOL = 1e-12


# --- the group algebra of permutations -------------------------------------------------
# A permutation is a tuple p of 0-based positions; P_p f(r) = f(Π_p r), (Π_p r)_i = r_{p(i)}
# (as in prebo.symmetry.Symmetriser). Operators multiply as P_a P_b = P_{a∘b}, (a∘b)(i) = a(b(i)).

def _compose(a, b):
    return tuple(a[i] for i in b)


def _inverse(p):
    inv = [0] * len(p)
    for i, k in enumerate(p):
        inv[k] = i
    return tuple(inv)


def _transposition(n, i, j):
    p = list(range(n))
    p[i], p[j] = j, i
    return tuple(p)


def _mul(x: dict, y: dict) -> dict:
    out: dict = {}
    for a, ca in x.items():
        for b, cb in y.items():
            k = _compose(a, b)
            out[k] = out.get(k, 0.0) + ca * cb
    return {k: v for k, v in out.items() if v != 0.0}


def _adjoint(x: dict) -> dict:
    return {_inverse(p): c for p, c in x.items()}


def _normalised(x: dict) -> dict:
    """Coefficients divided by the identity's, those below 1e-12 of it dropped."""
    ident = tuple(range(len(next(iter(x)))))
    c0 = x.get(ident, 0.0)
    if not c0 > 0:
        raise ValueError("operator has no positive identity coefficient")
    return {p: c / c0 for p, c in x.items() if abs(c) > _COEF_TOL * abs(c0)}


def _same(x: dict, y: dict, tol: float = 1e-10) -> bool:
    keys = set(x) | set(y)
    return all(abs(x.get(k, 0.0) - y.get(k, 0.0)) <= tol for k in keys)


def _symmetriser(op: dict) -> Symmetriser:
    """A Symmetriser from a normalised operator, identity first, then in lexicographic order."""
    perms = sorted(op)
    return Symmetriser(tuple(perms), tuple(float(op[p]) for p in perms))


def _as_operator(sym: Symmetriser) -> dict:
    return _normalised({tuple(p): float(c) for p, c in zip(sym.permutations, sym.coefficients)})


# --- Young strings -------------------------------------------------------------------------
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
        if ps.strip():
            for t in _PTOK.finditer(ps):
                i, j = (t.group(1), t.group(2)) if t.group(1) else (t.group(3), t.group(4))
                i, j = int(i), int(j)
                if not (1 <= i <= n and 1 <= j <= n) or i == j:
                    raise ValueError(f"P{i}{j}: particles are numbered 1..{n}, two different ones")
                perm = _compose(perm, _transposition(n, i - 1, j - 1))
        out[perm] = out.get(perm, 0.0) + coef
        pos, first = m.end(), False
    return {k: v for k, v in out.items() if v != 0.0}


def young_product(string: str, n: int) -> dict:
    """The group-algebra element Y of a SYMMETRY string: the product of its factors, in order.

    A factor is ``(t ± t ± ...)`` with terms ``1``, ``Pij`` / ``P(i,j)`` and products of them,
    optionally with a numeric coefficient (``0.5P23P24``). ``1``, ``(1)`` or ``none`` is the
    identity. ValueError on anything else."""
    s = string.strip()
    ident = {tuple(range(n)): 1.0}
    if s.lower() in ("", "1", "none", "(1)"):
        return ident
    y = ident
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
        y = _mul(y, _parse_factor(s[pos + 1:end], n))
        pos, found = end + 1, True
    if not found:
        raise ValueError("expected factors in parentheses, e.g. (1+P23)(1-P24)")
    if not y:
        raise ValueError("the product of the factors is zero")
    return y


def young_operator(string: str, n: int) -> Symmetriser:
    """The symmetry of ``SYMMETRY string`` as prebo coefficients: Y†Y, identity coefficient 1."""
    y = young_product(string, n)
    return _symmetriser(_normalised(_mul(_adjoint(y), y)))


def _format_perm_term(p) -> str:
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
    n = len(next(iter(op)))
    ident = tuple(range(n))
    terms = ["1"]
    for p in sorted(op):
        if p == ident:
            continue
        c = op[p]
        num = "" if abs(abs(c) - 1.0) < 1e-15 else repr(abs(c))
        terms.append(("-" if c < 0 else "+") + num + _format_perm_term(p))
    return "(" + "".join(terms) + ")"


def _group_products(indices, n, max_factors=4):
    """Young strings over one group: ordered products of distinct (1±Pij) factors."""
    pairs = list(itertools.combinations(indices, 2))
    for k in range(1, min(len(pairs), max_factors) + 1):
        for seq in itertools.permutations(pairs, k):
            for signs in itertools.product((1.0, -1.0), repeat=k):
                yield seq, signs


def young_string(sym: Symmetriser, groups: list[Group], n: int) -> str:
    """A SYMMETRY string whose Y†Y is `sym` up to a factor (see the module docstring)."""
    target = _as_operator(sym)
    if len(target) == 1:
        return "(1)"
    # try a product over groups of per-group factor products
    parts = []
    ident = tuple(range(n))
    for g in groups:
        gop = _normalised({_lift(gp, g.indices, n): c for gp, c in g.coefficients().items()})
        if len(gop) == 1:
            continue
        found = None
        for seq, signs in _group_products(g.indices, n):
            y = {ident: 1.0}
            for (i, j), sg in zip(seq, signs):
                y = _mul(y, {ident: 1.0, _transposition(n, i, j): sg})
            if not y:
                continue
            op = _mul(_adjoint(y), y)
            if ident in op and op[ident] > 0 and _same(_normalised(op), gop):
                found = "".join(f"(1{'+' if sg > 0 else '-'}P{i + 1}{j + 1})" for (i, j), sg in zip(seq, signs))
                break
        if found is None:
            parts = None
            break
        parts.append(found)
    if parts is not None and parts:
        s = "".join(parts)
        if _same(_as_operator(young_operator(s, n)), target):
            return s
    return _explicit_string(target)


def _lift(gp, indices, n):
    q = list(range(n))
    for pos, src in enumerate(gp):
        q[indices[pos]] = indices[src]
    return tuple(q)


# --- systems with an explicit symmetry -----------------------------------------------------
class YoungSystem(System):
    """A `System` whose symmetry operator is given explicitly (`System(symmetriser=...)`)
    instead of by the spin state; `young` is the SYMMETRY string it came from."""

    def __init__(self, particles, state: State | None = None, symmetriser: Symmetriser | None = None,
                 young: str | None = None, **state_kw):
        super().__init__(particles, state, symmetriser=symmetriser, **state_kw)
        self.young = young

    def __repr__(self) -> str:
        return f"YoungSystem({self.label()!r}, {self.state}, {self.young!r})"


def system_with_symmetry(particles, state: State, symmetriser: Symmetriser, young: str | None = None) -> System:
    """A plain `System` if `symmetriser` is the spin state's own operator (up to a factor), else a
    `YoungSystem` carrying it (e.g. for a basis.json whose "symmetry" block must be honoured)."""
    plain = System(particles, state)
    if _same(_as_operator(plain.symmetriser), _as_operator(symmetriser)):
        return plain
    return YoungSystem(particles, state, symmetriser, young)


# --- particles and spin states -----------------------------------------------------------
def _particle_spec(mass: float, charge: float) -> dict | str | None:
    for name, (m, q, s) in list(KNOWN.items()) + list(EXTRA_NUCLEI.items()):
        if q == charge and abs(m - mass) <= _NAME_RTOL * m:
            if name in KNOWN and KNOWN[name][0] == mass:
                return name
            return {"name": name, "mass": mass, "charge": charge, "spin": float(s)}
    return None


def _central(op: dict, moved) -> dict:
    """Σ_g g op g⁻¹ over the permutations g of the positions `moved` (for op a primitive
    idempotent of that symmetric group: ∝ the central idempotent of its irrep)."""
    n = len(next(iter(op)))
    out: dict = {}
    for sigma in itertools.permutations(moved):
        g = list(range(n))
        for a, b in zip(moved, sigma):
            g[a] = b
        g = tuple(g)
        gi = _inverse(g)
        for p, c in op.items():
            k = _compose(_compose(g, p), gi)
            out[k] = out.get(k, 0.0) + c
    return out


def _implied_spins(op: dict, raw_groups: list[tuple[int, ...]], spins: list[Fraction], n: int) -> dict | None:
    """Total spin per group whose spin-projected operator lies in the same irreducible
    representation as `op`, or None when there is no such state."""
    from ..system.symmetry import coupling_path

    choices = []
    for idx, s in zip(raw_groups, spins):
        opts = []
        S = Fraction(len(idx) * s).limit_denominator(2)
        lo = S - int(S)  # 0 or 1/2
        cand = lo
        while cand <= S:
            try:
                coupling_path(s, len(idx), cand)
                opts.append(cand)
            except PreboError:
                pass
            cand += 1
        choices.append(opts)
    scale = max(abs(c) for c in op.values())
    for combo in itertools.product(*choices):
        z = {tuple(range(n)): 1.0}
        for idx, s, S in zip(raw_groups, spins, combo):
            g = Group("g", idx, s, S)
            gop = {_lift(gp, idx, n): c for gp, c in g.coefficients().items()}
            z = _mul(z, _central(gop, idx))
        prod = _mul(op, z)
        if prod and max(abs(c) for c in prod.values()) > 1e-9 * scale * max(abs(c) for c in z.values()):
            return dict(zip(range(len(raw_groups)), combo))
    return None


# --- the file --------------------------------------------------------------------------
@dataclass
class InoutFile:
    """A parsed ``*.inout.txt``: header values, the L vectors and where each came from."""

    path: Path
    basis_type: str
    masses: np.ndarray
    charges: np.ndarray
    symmetry: str
    energy: float | None
    L: np.ndarray  # (K, n(n+1)/2) vech(L), column by column
    header: dict = field(default_factory=dict)  # keyword -> (line number, rest of the line)

    @property
    def n_particles(self) -> int:
        return len(self.masses)

    def lower(self, k: int) -> np.ndarray:
        """L of function k (0-based) as an (n, n) lower-triangular matrix."""
        n = self.n_particles - 1
        L = np.zeros((n, n))
        L[_vech_indices(n)] = self.L[k]  # the lower triangle, column by column
        return L

    def exponents(self) -> np.ndarray:
        """𝒜 = L Lᵀ of every function, (K, n, n), in ecgpack's coordinates r_i = R_{i+1} − R_1."""
        n = self.n_particles - 1
        Ls = np.zeros((len(self.L), n, n))
        rows, cols = _vech_indices(n)
        Ls[:, rows, cols] = self.L
        return Ls @ Ls.transpose(0, 2, 1)

    def system(self) -> System:
        return _system(self)

    def to_basis(self, c_A: float = 1.0) -> Basis:
        return _basis(self, c_A)


def _vech_indices(n: int):
    rows, cols = [], []
    for j in range(n):
        for i in range(j, n):
            rows.append(i)
            cols.append(j)
    return np.array(rows, dtype=int), np.array(cols, dtype=int)


def _fail(path, line: int | None, msg: str):
    where = f"{path}:{line}" if line else f"{path}"
    raise BasisFileError(f"{where}: {msg}")


def _reals(path, line_no, values, what):
    out = []
    for v in values:
        try:
            x = float(v.replace("D", "E").replace("d", "e"))
        except ValueError:
            _fail(path, line_no, f"{what}: {v!r} is not a number")
        if not math.isfinite(x):
            _fail(path, line_no, f"{what}: {v!r} is not finite")
        out.append(x)
    return out


def parse_inout(path) -> InoutFile:
    """Read an ecgpack ``*.inout.txt`` without converting it; BasisFileError names the line."""
    path = Path(path)
    lines = read_text(path, BasisFileError).splitlines()
    seps = [i for i, l in enumerate(lines) if _SEP.match(l)]
    if not seps:
        _fail(path, None, "no ===== section separators: not an ecgpack .inout file")
    header: dict = {}
    for i, l in enumerate(lines[: seps[0]]):
        parts = l.split()
        if not parts:
            continue
        key = parts[0].upper()
        if key in header:
            _fail(path, i + 1, f"{key} given twice (first on line {header[key][0]})")
        header[key] = (i + 1, parts[1:], l)
    for key in ("PARTICLES", "MASSES", "CHARGES", "SYMMETRY", "BASIS_SIZE"):
        if key not in header:
            _fail(path, None, f"header has no {key} line (lines 1-{seps[0]})")

    btype = "RG_0S"
    if "BASIS_TYPE" in header:
        ln, vals, _ = header["BASIS_TYPE"]
        btype = " ".join(vals)
        if btype.upper() != SUPPORTED_TYPE:
            kind = btype.upper()
            if kind.startswith("C"):
                why = "complex ECGs are not supported (prebo reads real plain ECGs, RG_0S)"
            elif not kind.endswith("0S"):
                why = "L > 0 basis functions are not supported (prebo reads S states, RG_0S)"
            else:
                why = f"only {SUPPORTED_TYPE} (real plain ECGs, L = 0) is supported"
            _fail(path, ln, f"BASIS_TYPE {btype}: {why}")

    ln, vals, _ = header["PARTICLES"]
    if len(vals) != 1 or not vals[0].isdigit() or int(vals[0]) < 2:
        _fail(path, ln, f"PARTICLES must be one integer >= 2, got {' '.join(vals)!r}")
    n = int(vals[0])
    arrays = {}
    for key in ("MASSES", "CHARGES"):
        ln, vals, _ = header[key]
        xs = _reals(path, ln, vals, key)
        if len(xs) != n:
            _fail(path, ln, f"{key} has {len(xs)} values for {n} particles")
        arrays[key] = np.array(xs)
    ln = header["MASSES"][0]
    if not np.all(arrays["MASSES"] > 0):
        _fail(path, ln, "MASSES must be positive")
    ln, vals, _ = header["BASIS_SIZE"]
    if len(vals) != 1 or not vals[0].isdigit():
        _fail(path, ln, f"BASIS_SIZE must be one non-negative integer, got {' '.join(vals)!r}")
    size = int(vals[0])
    energy = None
    if "CURRENT_ENERGY" in header:
        ln, vals, _ = header["CURRENT_ENERGY"]
        xs = _reals(path, ln, vals, "CURRENT_ENERGY")
        if len(xs) != 1:
            _fail(path, ln, f"CURRENT_ENERGY must be one number, got {' '.join(vals)!r}")
        energy = xs[0]
    ln, vals, raw = header["SYMMETRY"]
    symmetry = raw.split(None, 1)[1].strip() if len(raw.split(None, 1)) > 1 else ""
    try:
        young_product(symmetry, n)
    except ValueError as exc:
        _fail(path, ln, f"SYMMETRY {symmetry!r}: {exc}")

    # the basis: the last section
    m = n * (n - 1) // 2
    start = seps[-1] + 1
    L = []
    for i in range(start, len(lines)):
        parts = lines[i].split()
        if not parts:
            continue
        if len(L) == size:
            _fail(path, i + 1, f"more basis lines than BASIS_SIZE {size} (line {header['BASIS_SIZE'][0]})")
        idx = parts[0]
        if not idx.lstrip("-").isdigit():
            _fail(path, i + 1, f"basis line must start with the function's index, got {idx!r}")
        if int(idx) != len(L) + 1:
            _fail(path, i + 1, f"basis function index {idx}, expected {len(L) + 1}")
        vals = parts[1:]
        if len(vals) != m:
            extra = " (twice as many: a complex ECG? only real RG_0S is supported)" if len(vals) == 2 * m else ""
            _fail(path, i + 1, f"basis function {idx}: {len(vals)} reals, expected n(n+1)/2 = {m} "
                               f"for n = {n - 1} coordinates{extra}")
        L.append(_reals(path, i + 1, vals, f"basis function {idx}"))
    if len(L) != size:
        _fail(path, len(lines), f"{len(L)} basis lines after the last ===== (line {start}), "
                                f"BASIS_SIZE says {size} (line {header['BASIS_SIZE'][0]})")
    return InoutFile(path, btype, arrays["MASSES"], arrays["CHARGES"], symmetry, energy,
                     np.array(L, dtype=float).reshape(size, m), {k: (v[0], " ".join(v[1])) for k, v in header.items()})


def _system(f: InoutFile) -> System:
    n = f.n_particles
    ln = f.header["SYMMETRY"][0]
    # particle names: prebo's known name (or a nucleus of EXTRA_NUCLEI) with the file's mass
    specs, key_of = [], {}
    for i, (mass, q) in enumerate(zip(f.masses, f.charges)):
        key = (float(mass), float(q))
        spec = _particle_spec(float(mass), float(q))
        if spec is None:
            name = key_of.get(key) or f"x{len(key_of) + 1}"
            spec = {"name": name, "mass": float(mass), "charge": float(q), "spin": 0.0}
        key_of.setdefault(key, spec if isinstance(spec, str) else spec["name"])
        specs.append(spec)
    # every named group: one set of identical particles
    names = [s if isinstance(s, str) else s["name"] for s in specs]
    if len(set(names)) != len(set(zip(f.masses.tolist(), f.charges.tolist()))):
        _fail(f.path, f.header["MASSES"][0], "particles with one name but different masses or charges")
    op = _as_operator(young_operator(f.symmetry, n))
    for p in op:
        for i in range(n):
            if names[p[i]] != names[i]:
                _fail(f.path, ln, f"SYMMETRY {f.symmetry!r} exchanges particles {i + 1} and {p[i] + 1}, "
                                  "which differ in mass or charge")
    raw_groups = []
    for nm in dict.fromkeys(names):
        idx = tuple(i for i, x in enumerate(names) if x == nm)
        if len(idx) > 1:
            raw_groups.append(idx)
    from ..system.particles import particle

    spins = [particle(specs[idx[0]]).spin for idx in raw_groups]
    implied = _implied_spins(op, raw_groups, spins, n) if raw_groups else {}
    if implied is None:
        # unknown identical particles: try spin 1/2 instead of 0
        alt = [Fraction(1, 2) if not isinstance(specs[idx[0]], str) and specs[idx[0]]["name"].startswith("x")
               else s for idx, s in zip(raw_groups, spins)]
        implied = _implied_spins(op, raw_groups, alt, n)
        if implied is not None:
            for idx in raw_groups:
                for i in idx:
                    if isinstance(specs[i], dict) and specs[i]["name"].startswith("x"):
                        specs[i] = dict(specs[i], spin=0.5)
    if implied is None:
        _fail(f.path, ln, f"SYMMETRY {f.symmetry!r} is no spin state of the identical particles "
                          f"({', '.join('+'.join(str(i + 1) for i in g) for g in raw_groups) or 'none'}): "
                          "prebo cannot label it")
    spin = {names[idx[0]]: float(implied[k]) for k, idx in enumerate(raw_groups)}
    state = State(N=0, parity=1, spin=spin)
    try:
        return system_with_symmetry(specs, state, _symmetriser(op), f.symmetry)
    except PreboError as exc:
        _fail(f.path, None, f"cannot build the system: {exc}")


def _basis(f: InoutFile, c_A: float) -> Basis:
    c_A = check("c_A", c_A)
    system = _system(f)
    hpc = heavy_particle_centred(system.masses, 0)
    A_int = f.exponents()
    bad = [k for k, a in enumerate(A_int) if not _pd(a)]
    if bad:
        k = bad[0]
        _fail(f.path, _basis_line(f, k), f"basis function {k + 1}: L Lᵀ is not positive definite "
                                         "(a zero on the diagonal of L)")
    A = np.array([hpc.to_lab(a, c_A) for a in A_int]).reshape(len(A_int), system.n, system.n)
    A = 0.5 * (A + A.transpose(0, 2, 1))
    basis = Basis(system, A, np.full(len(A), float(c_A)), [hpc.name] * len(A))
    try:
        basis.validate()
    except PreboError as exc:
        _fail(f.path, None, f"converted basis is invalid: {exc}")
    # the file's own L, for write_inout: a function still equal to its import is written back
    # with these exact parameters (an exact round trip), others from their Cholesky factor
    basis.ecgpack_source = (basis.A.copy(), f.L.copy())
    return basis


def _pd(a) -> bool:
    try:
        np.linalg.cholesky(a)
        return True
    except np.linalg.LinAlgError:
        return False


def _basis_line(f: InoutFile, k: int) -> int | None:
    try:
        lines = f.path.read_text().splitlines()
    except OSError:
        return None
    last = max(i for i, l in enumerate(lines) if _SEP.match(l))
    count = -1
    for i in range(last + 1, len(lines)):
        if lines[i].split():
            count += 1
            if count == k:
                return i + 1
    return None


def read_inout(path, c_A: float = 1.0) -> Basis:
    """An ecgpack ``*.inout.txt`` (RG_0S) as a `prebo.Basis` in laboratory-frame coordinates.

    Particles keep the file's order, masses and charges; each gets prebo's name for it
    (``e``, ``alpha``, ...; nuclei prebo does not know: ``li7`` etc., others ``x1``, ``x2``)
    with the file's mass, which may differ from prebo's CODATA value. Each function is
    A = U_xᵀ blockdiag(L Lᵀ, c_A) U_x with x = ``hpc:0`` (relative to particle 1) and the
    given `c_A` (the translation-free energy does not depend on it). The symmetry is the
    file's SYMMETRY string's Y†Y (module docstring): a plain `System` with the implied spin
    state when that is prebo's own operator, else a `YoungSystem` carrying the operator.

    Raises BasisFileError naming the file and line for anything prebo cannot take: complex
    ECGs, L > 0 basis types, a malformed header or basis line, a size mismatch, a symmetry
    exchanging different particles."""
    return parse_inout(path).to_basis(c_A)


def _fmt(x: float) -> str:
    """A blank and then ``1PE23.16``: the field of ecgpack's ``-0.dddE+xx`` numbers (sign or blank,
    23 characters) with 17 significant digits, so that every double reads back unchanged."""
    return " " + f"{float(x): .16E}"


def write_inout(basis: Basis, path, energy: float | None = None) -> None:
    """Write a plain-ECG `basis` as an ecgpack ``*.inout.txt`` (RG_0S).

    Each function's internal exponent 𝒜 is taken in prebo's ``hpc:0`` set (relative to the
    first particle, SeparabilityError if a function couples the CM to internal motion; c_A
    is dropped) and written as vech of its Cholesky factor L — except a function of a
    basis from `read_inout` that is still bitwise the imported one: it is written with the
    file's own L, so that read → write → read gives the same A bit for bit. (Through
    basis.json that link is lost and A comes back to rounding, ~1e-16 relative, which moves
    the energy of a nearly linearly dependent basis such as He-490 by ~1e-12 relative.) The header gives the masses
    and charges in the basis's particle order, the SYMMETRY string (`young_string`) and
    CURRENT_ENERGY: `energy` if given, else the translation-free energy prebo.evaluate
    computes. The file is written atomically (basis.write_atomic)."""
    system = basis.system
    n = system.n
    if n < 2:
        raise UnsupportedError("ecgpack needs at least two particles")
    hpc = heavy_particle_centred(system.masses, 0)
    rows, cols = _vech_indices(n - 1)
    src_A, src_L = getattr(basis, "ecgpack_source", (np.zeros((0, n, n)), None))
    vech = []
    for k, (A, c) in enumerate(zip(basis.A, basis.c_A)):
        if k < len(src_A) and src_A[k].shape == A.shape and np.array_equal(src_A[k], A):
            vech.append(src_L[k])
            continue
        A_int, _ = hpc.from_lab(A)
        A_int = 0.5 * (A_int + A_int.T)
        try:
            L = np.linalg.cholesky(A_int)
        except np.linalg.LinAlgError:
            raise UnsupportedError(f"function {k}: internal exponent is not positive definite") from None
        vech.append(L[rows, cols])
    sym = system.symmetriser
    young = getattr(system, "young", None)
    if not (young and _same(_as_operator(young_operator(young, n)), _as_operator(sym))):
        young = young_string(sym, system.groups, n)
    if energy is None:
        from ..results import evaluate

        energy = evaluate(basis)["energy"] if len(basis) else 0.0
    K = len(basis)
    out = [
        f" BASIS_TYPE {SUPPORTED_TYPE}",
        f" PARTICLES {n:6d}",
        " MASSES " + "".join(_fmt(m) for m in system.masses),
        " CHARGES " + "".join(_fmt(q) for q in system.charges),
        f" SYMMETRY {young}",
        f" BASIS_SIZE {K:6d}",
        " CURRENT_ENERGY" + _fmt(energy),
        " WHICH_EIGENVALUE      1",
        " ==============================",
        f" {K:6d}" + _fmt(energy) + "      0      0      0",
        " ==============================",
        " ==============================",
        f" {K:6d}" + _fmt(energy) + "      0      0      0",
        " ==============================",
    ]
    out += [f" {k + 1:6d}" + "".join(_fmt(x) for x in v) for k, v in enumerate(vech)]
    write_atomic(path, "\n".join(out) + "\n")
