"""Read and write the real-ECG basis files of ecgpack / ATOM-MOL-nonBO (``*.inout.txt``).

The format (RG_0S: real plain ECGs, L = 0, S states; RG_1P below)
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
WHICH_EIGENVALUE k (1-based) is the root the basis was optimised for: the imported state
targets root k − 1 (`[state] root`), and an export writes the lowest targeted root back.

RG_1P (real ECGs of a P state, L = 1, odd parity; ecgpack's README): a basis line holds the
index, then the integer i (1..n) of the function φ = z_i exp(−rᵀ(𝒜 ⊗ I₃)r), then vech(L): a
Gaussian times the z coordinate of particle i + 1 relative to particle 1. In prebo that is an
ECG-GVR function (prebo.basis.ecg_gvr) of N = 1 (parity −1) with K = 0 and the global vector
of that coordinate, u^(x) = e_i in ``hpc:0``, u = U_xᵀ e_i = e_{i+1} − e_1 in the laboratory
frame: v = uᵀr = R_{i+1} − R_1 and φ ∝ v_x + i v_y, the M = 1 partner of ecgpack's v_z, of the
same energy (every function rotated alike). A file without BASIS_TYPE is RG_1P when its basis
lines carry that integer (n(n+1)/2 + 1 fields), else RG_0S (ecgpack's own codes do not need
the line either). An export writes ECG-GVR functions of N = 1 and K = 0 whose global vector is
one such coordinate (a multiple of e_i in ``hpc:0``) as RG_1P.

Masses: ecgpack writes an infinite mass (a clamped nucleus, its atomic samples) as 1e30
(INFINITE_MASS); a mass of 1e30 or more is read as infinite (prebo.system.particles), and an
infinite mass is written back as 1e30.

Symmetry
--------
SYMMETRY is a Young string such as ``(1+P23)(1-P24)`` (`prebo.system.young`: ``Pij`` swaps
particles i and j, 1-based, file order; the operator of a string Y is Y†Y). That Y†Y is
ecgpack's operator was established on the Li-7 file: it reproduces the file's
CURRENT_ENERGY to 1e-15 relative (a 32-digit evaluation to 1e-16), while Y itself gives no
symmetric matrix and the spin-projected operator gives another energy.

prebo's own symmetry (`prebo.system.symmetry`) is the spin-projected operator of one spin
function per group, with the smallest intermediate spins. For He, (1+P23)†(1+P23) ∝ 1 + P23
is exactly prebo's singlet, and the imported system carries no explicit operator. For Li,
(1+P23)(1−P24) gives O ∝ 2 + P23 + P34 − 2 P24 − P234 − P243: the projector onto the row of
the [2,1] representation antisymmetric in particles 2 and 4. prebo's doublet (spin function
[[e2 e3]_0 e4]_1/2) projects onto the row symmetric in 2 and 3 — the same irreducible
representation and spin, but a different row, so the same functions give another energy
(−7.4764 instead of −7.4774 Eh for Li-100). No spin state and no particle order gives O
(rows symmetric in a pair and rows antisymmetric in a pair are never conjugate in S3), so
such a file's system is a `System(..., symmetriser=O)` with O labelled by the file's string:
everything that asks `system.symmetriser` (evaluate, the integrals, the optimiser) uses it.
The state's spins are the ones O implies (the irreducible representation it lies in), for
labels. basis.json keeps the operator in its "symmetry" block.

Export
------
`write_inout` writes the header, a status line, an empty command list, a one-line
energy history and the basis, numbers as ``1PE23.16`` (the field width of ecgpack's
``-0.dddE+xx`` numbers, but 17 significant digits, so that doubles survive). A function
still bitwise as read from the file it came from (`source=`) is written with the file's
own L (bit-exact round trip); others with the Cholesky factor of their 𝒜 in ``hpc:0``.
The Young string is `prebo.system.young.young_string`: the imported one when it still
describes the symmetry, else a product of (1±Pij) factors, else one explicit factor.

API: `read_inout(path, c_A=1.0) -> Basis`, `write_inout(basis, path, energy=None, source=None)`;
`parse_inout(path) -> InoutFile` for the raw content (e.g. `.energy`, ecgpack's
CURRENT_ENERGY, to print beside prebo's) and `InoutFile.to_basis`. Errors:
`prebo.errors.BasisFileError` with ``file:line:``.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path

import numpy as np

from ..basis import Basis
from ..coordinates import heavy_particle_centred
from ..errors import BasisFileError, InputError, PreboError, UnsupportedError
from ..system import KNOWN, State, System, particle
from ..system.symmetry import implied_spins
from ..system.young import young_operator, young_product, young_string
from ..optimise.settings import check
from ..validation import MAX_PARTICLES, MAX_SIZE, path_name
from .basis_json import MAX_DIGITS, read_text
from . import stored
from .files import write_atomic

__all__ = ["read_inout", "write_inout", "parse_inout", "InoutFile"]

#: the basis types read and written: real plain ECGs of S states, and of P states (module docstring)
S_TYPE, P_TYPE = "RG_0S", "RG_1P"
#: ecgpack's infinite mass (m_e): a mass at or above it is read as infinite, and written as it
INFINITE_MASS = 1e30
_SEP = re.compile(r"^\s*={5,}\s*$")
#: nuclei prebo has no name for: name -> (mass / m_e, charge, spin); used to name particles only
#: (the file's masses are kept). Nuclear masses from the atomic masses (AME 2020) less Z m_e.
EXTRA_NUCLEI = {
    "li6": (10961.898, 3.0, Fraction(1)),
    "li7": (12786.393, 3.0, Fraction(3, 2)),
    "be9": (16424.205, 4.0, Fraction(3, 2)),
}
_NAME_RTOL = 1e-5


# --- particles and spin states -----------------------------------------------------------
def _particle_spec(mass: float, charge: float) -> dict | str | None:
    for name, (m, q, s) in list(KNOWN.items()) + list(EXTRA_NUCLEI.items()):
        if q == charge and abs(m - mass) <= _NAME_RTOL * m:
            if name in KNOWN and KNOWN[name][0] == mass:
                return name
            return {"name": name, "mass": mass, "charge": charge, "spin": float(s)}
    return None


# --- the file --------------------------------------------------------------------------
@dataclass
class InoutFile:
    """A parsed ``*.inout.txt``: BASIS_TYPE (S_TYPE or P_TYPE), MASSES (m_e; ∞ for ecgpack's
    INFINITE_MASS), CHARGES (e), the SYMMETRY string, CURRENT_ENERGY (Eh; None if absent), each
    function's vech(L), every header line, the root the basis was optimised for (WHICH_EIGENVALUE
    − 1; 0 if absent), which its state targets, and, for RG_1P, each function's coordinate index i
    (1..n: its factor z_i)."""

    path: Path
    basis_type: str
    masses: np.ndarray
    charges: np.ndarray
    symmetry: str
    energy: float | None
    L: np.ndarray  # (K, n(n+1)/2) vech(L), column by column
    header: dict = field(default_factory=dict)  # keyword -> (line number, rest of the line)
    root: int = 0
    z: np.ndarray | None = None  # (K,) RG_1P's coordinate indices i, 1-based; None for RG_0S

    @property
    def n_particles(self) -> int:
        """PARTICLES."""
        return len(self.masses)

    def exponents(self) -> np.ndarray:
        """𝒜 = L Lᵀ of every function, (K, n, n), in ecgpack's coordinates r_i = R_{i+1} − R_1."""
        n = self.n_particles - 1
        Ls = np.zeros((len(self.L), n, n))
        rows, cols = _vech_indices(n)
        Ls[:, rows, cols] = self.L
        return Ls @ Ls.transpose(0, 2, 1)

    def to_basis(self, c_A: float = 1.0) -> Basis:
        """The file's basis with CM exponent `c_A` (bohr⁻²), as `read_inout` describes."""
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


def _clip(text: str) -> str:
    """`text`, cut after MAX_DIGITS characters (for messages)."""
    return text if len(text) <= MAX_DIGITS else text[:MAX_DIGITS] + "..."


def _count(values: list) -> int | None:
    """The one non-negative integer of a header line's `values` (at most MAX_DIGITS digits), or None."""
    if len(values) != 1 or not values[0].isdigit() or len(values[0]) > MAX_DIGITS:
        return None
    return int(values[0])


def parse_inout(path, text: str | None = None) -> InoutFile:
    """Read an ecgpack ``*.inout.txt`` (or its `text`, read already: io.stored) without converting
    it; BasisFileError names the line."""
    path = Path(path_name(path, "parse_inout: path", "a file name (a str or path)"))
    lines = (read_text(path, BasisFileError) if text is None else text).splitlines()
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

    btype = None  # absent: told by the basis lines below
    if "BASIS_TYPE" in header:
        ln, vals, _ = header["BASIS_TYPE"]
        btype = " ".join(vals).upper()
        if btype not in (S_TYPE, P_TYPE):
            if btype.startswith("C"):
                why = f"complex ECGs are not supported (prebo reads real ECGs, {S_TYPE} and {P_TYPE})"
            else:
                why = f"prebo reads {S_TYPE} (real ECGs, S states) and {P_TYPE} (P states) only"
            _fail(path, ln, f"BASIS_TYPE {' '.join(vals)}: {why}")

    ln, vals, _ = header["PARTICLES"]
    n = _count(vals)
    if n is None or not 2 <= n <= MAX_PARTICLES:
        _fail(path, ln, f"PARTICLES must be one integer in 2..{MAX_PARTICLES}, got {_clip(' '.join(vals))!r}")
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
    arrays["MASSES"][arrays["MASSES"] >= INFINITE_MASS] = math.inf
    ln, vals, _ = header["BASIS_SIZE"]
    size = _count(vals)
    if size is None or size > MAX_SIZE:
        _fail(path, ln, f"BASIS_SIZE must be one integer in 0..{MAX_SIZE} (what this machine's memory holds), "
                        f"got {_clip(' '.join(vals))!r}")
    energy = None
    if "CURRENT_ENERGY" in header:
        ln, vals, _ = header["CURRENT_ENERGY"]
        xs = _reals(path, ln, vals, "CURRENT_ENERGY")
        if len(xs) != 1:
            _fail(path, ln, f"CURRENT_ENERGY must be one number, got {' '.join(vals)!r}")
        energy = xs[0]
    root = 0
    if "WHICH_EIGENVALUE" in header:
        ln, vals, _ = header["WHICH_EIGENVALUE"]
        which = _count(vals)
        if which is None or not 1 <= which <= max(size, 1):
            _fail(path, ln, f"WHICH_EIGENVALUE must be one integer in 1..BASIS_SIZE ({size}), got "
                            f"{_clip(' '.join(vals))!r}")
        root = which - 1
    ln, vals, raw = header["SYMMETRY"]
    symmetry = raw.split(None, 1)[1].strip() if len(raw.split(None, 1)) > 1 else ""
    try:
        young_product(symmetry, n)
    except ValueError as exc:
        _fail(path, ln, f"SYMMETRY {symmetry!r}: {exc}")

    # the basis: the last section
    m = n * (n - 1) // 2
    start = seps[-1] + 1
    basis_lines = [(i, lines[i].split()) for i in range(start, len(lines)) if lines[i].split()]
    if btype is None:  # RG_1P lines carry the coordinate index before vech(L)
        first = basis_lines[0][1] if basis_lines else []
        btype = P_TYPE if len(first) == m + 2 and _count(first[1:2]) is not None else S_TYPE
    L, z = [], []
    for i, parts in basis_lines:
        if len(L) == size:
            _fail(path, i + 1, f"more basis lines than BASIS_SIZE {size} (line {header['BASIS_SIZE'][0]})")
        idx = parts[0]
        if not idx.lstrip("-").isdigit():
            _fail(path, i + 1, f"basis line must start with the function's index, got {_clip(idx)!r}")
        if _count([idx]) != len(L) + 1:
            _fail(path, i + 1, f"basis function index {_clip(idx)}, expected {len(L) + 1}")
        vals = parts[1:]
        if btype == P_TYPE:
            k = _count(vals[:1])
            if k is None or not 1 <= k <= n - 1:
                got = repr(_clip(vals[0])) if vals else "nothing"
                _fail(path, i + 1, f"basis function {idx}: {got} after the index: {P_TYPE} gives there the "
                                   f"coordinate i of the factor z_i, an integer in 1..{n - 1}")
            z.append(k)
            vals = vals[1:]
        if len(vals) != m:
            extra = (f" (twice as many: a complex ECG? only real {S_TYPE} and {P_TYPE} are supported)"
                     if len(vals) == 2 * m else "")
            what = " after the coordinate index" if btype == P_TYPE else ""
            _fail(path, i + 1, f"basis function {idx}: {len(vals)} reals{what}, expected n(n+1)/2 = {m} "
                               f"for n = {n - 1} coordinates{extra}")
        L.append(_reals(path, i + 1, vals, f"basis function {idx}"))
    if len(L) != size:
        _fail(path, len(lines), f"{len(L)} basis lines after the last ===== (line {start}), "
                                f"BASIS_SIZE says {size} (line {header['BASIS_SIZE'][0]})")
    return InoutFile(path, btype, arrays["MASSES"], arrays["CHARGES"], symmetry, energy,
                     np.array(L, dtype=float).reshape(size, m), {k: (v[0], " ".join(v[1])) for k, v in header.items()},
                     root, np.array(z, dtype=int) if btype == P_TYPE else None)


def _system(f: InoutFile) -> System:
    """The file's particles (named as `read_inout` says) with its symmetry and the spins it implies."""
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
    sym = young_operator(f.symmetry, n)
    op = sym.operator()
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
    spins = [particle(specs[idx[0]]).spin for idx in raw_groups]
    implied = implied_spins(op, raw_groups, spins, n) if raw_groups else []
    if implied is None:
        # unknown identical particles: try spin 1/2 instead of 0
        alt = [Fraction(1, 2) if not isinstance(specs[idx[0]], str) and specs[idx[0]]["name"].startswith("x")
               else s for idx, s in zip(raw_groups, spins)]
        implied = implied_spins(op, raw_groups, alt, n)
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
    N = 1 if f.basis_type == P_TYPE else 0
    state = State(N=N, parity=(-1) ** N, spin=spin, root=f.root)
    try:
        return System(specs, state, symmetriser=sym)
    except PreboError as exc:
        _fail(f.path, None, f"cannot build the system: {exc}")


def _basis(f: InoutFile, c_A: float) -> Basis:
    c_A = check("c_A", c_A)
    system = _system(f)
    hpc = heavy_particle_centred(system.masses, 0)
    with np.errstate(over="ignore", invalid="ignore"):  # a function that overflows is refused below, by its line
        A_int = f.exponents()
        A = np.array([_to_lab(hpc, a, c_A) for a in A_int]).reshape(len(A_int), system.n, system.n)
    for k in range(len(A)):
        if not np.all(np.isfinite(A[k])):
            line, values = _basis_line(f, k)
            largest = max(values, key=lambda v: abs(float(v.replace("D", "E").replace("d", "e"))), default="")
            _fail(f.path, line, f"basis function {k + 1}: {largest!r} overflows: L Lᵀ exceeds the largest double "
                                f"({np.finfo(float).max:.3g})")
        if not _pd(A_int[k]):
            _fail(f.path, _basis_line(f, k)[0], f"basis function {k + 1}: L Lᵀ is not positive definite "
                                                "(a zero on the diagonal of L)")
        if not _pd(A[k]):
            _fail(f.path, _basis_line(f, k)[0], f"basis function {k + 1}: its laboratory-frame exponent is not "
                                                "positive definite in double precision (L's reals span too many "
                                                "orders of magnitude)")
    extras = {} if f.z is None else {"kind": "ecg-gvr", "u": hpc.U[f.z - 1], "K": np.zeros(len(A), dtype=int)}
    basis = Basis(system, A, np.full(len(A), float(c_A)), [hpc.name] * len(A), **extras)
    try:
        basis.validate()
    except PreboError as exc:
        _fail(f.path, None, f"converted basis is invalid: {exc}")
    return basis


def _to_lab(hpc, A_int: np.ndarray, c_A: float) -> np.ndarray:
    """A = U_xᵀ blockdiag(𝒜, c_A) U_x, symmetrised; the same bits in `to_basis` and `write_inout`."""
    A = hpc.to_lab(A_int, c_A)
    return 0.5 * (A + A.T)


def _pd(a) -> bool:
    try:
        np.linalg.cholesky(a)
        return True
    except np.linalg.LinAlgError:
        return False


def _basis_line(f: InoutFile, k: int) -> tuple[int | None, list[str]]:
    """The line number of basis function `k` (0-based) in the file and its reals as written
    (None and [] if the file changed since it was read)."""
    try:
        lines = f.path.read_text().splitlines()
    except OSError:
        return None, []
    last = max(i for i, l in enumerate(lines) if _SEP.match(l))
    count = -1
    for i in range(last + 1, len(lines)):
        if lines[i].split():
            count += 1
            if count == k:
                return i + 1, lines[i].split()[1:]
    return None, []


def read_inout(path, c_A: float = 1.0) -> Basis:
    """An ecgpack ``*.inout.txt`` (RG_0S: plain ECGs; RG_1P: ECG-GVR functions of N = 1) as a
    `prebo.Basis` in laboratory-frame coordinates.

    Particles keep the file's order, masses and charges; each gets prebo's name for it
    (``e``, ``alpha``, ...; nuclei prebo does not know: ``li7`` etc., others ``x1``, ``x2``)
    with the file's mass, which may differ from prebo's CODATA value (ecgpack's 1e30: infinite).
    Each function is A = U_xᵀ blockdiag(L Lᵀ, c_A) U_x with x = ``hpc:0`` (relative to particle
    1) and the given `c_A` (the translation-free energy does not depend on it); an RG_1P
    function's z_i is its global vector (module docstring). The symmetry is the
    file's SYMMETRY string's Y†Y (module docstring): the implied spin state's own operator
    when it is that, else carried explicitly (`System(..., symmetriser=...)`).

    Parameters: `path`, the file; `c_A`, the CM exponent in bohr⁻² (> 0). Returns the
    `Basis`; `parse_inout(path).to_basis(c_A)` is the same with the parsed file kept, for
    `write_inout(..., source=...)`.

    Raises BasisFileError naming the file and line for anything prebo cannot take: complex
    ECGs, basis types other than RG_0S and RG_1P, a malformed header or basis line (an RG_1P
    coordinate index outside 1..n), a size mismatch, two infinite masses, a symmetry
    exchanging different particles, or a file that is not an ecgpack file (recognised by its
    content, io.stored); InputError for a `path` that is not a file name."""
    path = path_name(path, "read_inout: path", "a file name (a str or path)")
    what, text = stored.read(path)
    if what == "json":
        raise BasisFileError(f"{path}: a basis.json, not an ecgpack file (prebo.Basis.load reads it)")
    return parse_inout(path, text).to_basis(c_A)


def _fmt(x: float) -> str:
    """A blank and then ``1PE23.16``: the field of ecgpack's ``-0.dddE+xx`` numbers (sign or blank,
    23 characters) with 17 significant digits, so that every double reads back unchanged."""
    return " " + f"{float(x): .16E}"


def write_inout(basis: Basis, path, energy: float | None = None, source: InoutFile | None = None) -> None:
    """Write a plain-ECG `basis` as an ecgpack ``*.inout.txt`` (RG_0S), or an ECG-GVR one of a P
    state (N = 1, every K = 0, every global vector one particle's coordinate relative to the
    first: RG_1P, module docstring).

    Parameters: `basis`, plain ECGs or such ECG-GVR functions (UnsupportedError for others); `path`, the
    file, written atomically (`write_atomic`); `energy` (Eh) for CURRENT_ENERGY, default the
    translation-free energy `prebo.evaluate` computes of the level WHICH_EIGENVALUE names, the
    lowest the state targets (`[state] root`; ecgpack optimises one); `source`, the `InoutFile`
    the basis was read from (`parse_inout(path).to_basis()`), if any.

    Each function's internal exponent 𝒜 (bohr⁻²) is taken in prebo's ``hpc:0`` set
    (relative to the first particle; SeparabilityError if a function couples the CM to
    internal motion; c_A is dropped) and written as vech of its Cholesky factor L — except
    a function still bitwise as imported from `source`: it is written with the file's own
    L, so that read → write → read gives the same A bit for bit. (Through basis.json that
    link is lost and A comes back to rounding, ~1e-16 relative, which moves the energy of
    a nearly linearly dependent basis such as He-490 by ~1e-12 relative.) The header gives
    the masses (m_e; an infinite one as INFINITE_MASS) and charges (e) in the basis's particle
    order and the SYMMETRY string (`prebo.system.young.young_string`). InputError for a `basis`
    or `path` of the wrong type."""
    if not isinstance(basis, Basis):
        raise InputError(f"write_inout: basis = {basis!r}: must be a prebo Basis")
    path_name(path, "write_inout: path", "a file name (a str or path)")
    system = basis.system
    n = system.n
    hpc = heavy_particle_centred(system.masses, 0)
    z = _coordinate_indices(basis, hpc)
    rows, cols = _vech_indices(n - 1)
    imported = source.exponents() if source is not None else np.zeros((0, n - 1, n - 1))
    vech = []
    for k, (A, c) in enumerate(zip(basis.A, basis.c_A)):
        if k < len(imported) and imported[k].shape == (n - 1, n - 1) \
                and np.array_equal(_to_lab(hpc, imported[k], c), A):
            vech.append(source.L[k])
            continue
        A_int, _ = hpc.from_lab(A)
        A_int = 0.5 * (A_int + A_int.T)
        try:
            L = np.linalg.cholesky(A_int)
        except np.linalg.LinAlgError:
            raise UnsupportedError(f"function {k}: internal exponent is not positive definite") from None
        vech.append(L[rows, cols])
    young = young_string(system.symmetriser, system.groups, n)
    root = basis.system.state.levels[0][0]
    if energy is None:
        from ..level.evaluate import evaluate

        r = evaluate(basis) if len(basis) > root else {"energy": 0.0}  # the levels up to the targeted one
        energy = r["levels"][root]["energy"] if root else r["energy"]
    K = len(basis)
    out = [
        f" BASIS_TYPE {S_TYPE if z is None else P_TYPE}",
        f" PARTICLES {n:6d}",
        " MASSES " + "".join(_fmt(min(m, INFINITE_MASS)) for m in system.masses),
        " CHARGES " + "".join(_fmt(q) for q in system.charges),
        f" SYMMETRY {young}",
        f" BASIS_SIZE {K:6d}",
        " CURRENT_ENERGY" + _fmt(energy),
        f" WHICH_EIGENVALUE {root + 1:6d}",
        " ==============================",
        f" {K:6d}" + _fmt(energy) + "      0      0      0",
        " ==============================",
        " ==============================",
        f" {K:6d}" + _fmt(energy) + "      0      0      0",
        " ==============================",
    ]
    index = [""] * K if z is None else [f" {i:6d}" for i in z]
    out += [f" {k + 1:6d}" + index[k] + "".join(_fmt(x) for x in v) for k, v in enumerate(vech)]
    write_atomic(path, "\n".join(out) + "\n")


def _coordinate_indices(basis: Basis, hpc) -> np.ndarray | None:
    """RG_1P's coordinate index i (1..n − 1) of every function of an ECG-GVR `basis` of N = 1 and
    K = 0 whose global vector is a multiple of e_i in `hpc` (``hpc:0``; module docstring); None for
    plain ECGs; UnsupportedError naming the first function ecgpack's formats do not hold."""
    fam = basis.family
    if fam.parameters == ("A", "c_A"):
        return None
    if fam.parameters != ("A", "u", "K", "c_A") or basis.N != 1:
        raise UnsupportedError(f"ecgpack's {S_TYPE} and {P_TYPE} formats hold plain ECGs and ECG-GVR functions of "
                               f"N = 1, not {fam.name} functions of N = {basis.N}")
    ux = hpc.transform_vectors_to_x(basis.u)
    z = np.argmax(np.abs(ux), axis=1)
    for k, (v, i) in enumerate(zip(ux, z)):
        others = np.delete(v, i)
        if basis.K[k] != 0 or np.any(np.abs(others) > 1e-12 * abs(v[i])) or i == len(v) - 1:
            raise UnsupportedError(f"function {k}: {P_TYPE} holds z_i exp(-r^T A r), K = 0 and the global vector one "
                                   f"particle's position relative to the first; this one has K = {int(basis.K[k])} and "
                                   f"u = {np.round(v, 12).tolist()} in those coordinates (hpc:0, the CM last)")
    return z + 1
