"""The basis container: the functions of one family for a system, in laboratory-frame Cartesian
coordinates (LFCC, docs/conventions.md).

Every function has an exponent matrix A^(r) (n x n, symmetric positive definite, in bohr⁻²) with
A^(r) 1 = c_A m/m_tot, so that it factors into a centre-of-mass Gaussian exp(-c_A R_cm²) times an
internal part (Muolo, Mátyus & Reiher, J. Chem. Phys. 148, 084112 (2018), Sec. IV, the
elimination of the CM); A^(r) = U_x^T blockdiag(𝒜, c_A) U_x for the coordinate set ("channel") x
it was generated in. Its family (`Basis.family`) adds its own arrays (u and K, or s).
"""
from __future__ import annotations

import reprlib
from dataclasses import dataclass, field

import numpy as np

from ..errors import BasisFileError, InputError, NotPositiveDefiniteError, PreboError, SeparabilityError
from ..io import basis_json, stored
from ..system import System
from ..validation import path_name
from .families import family as family_of
from .family import Family


@dataclass
class Basis:
    """An ECG basis of `system`.

    Parameters (nb functions, n particles; hartree atomic units, lengths in bohr):
    A: (nb, n, n) exponent matrices A^(r); c_A: (nb,) CM exponents; channels: the coordinate set
    each function was drawn in ("pairs", "jacobi:0-1-2", ...; default "unknown"); coefficients:
    (nb,) linear coefficients of the state, if known; kind: the family's name ("pecg", "ecg-gvr",
    "fecg", the basis.json basis_type); u: (nb, n) global vectors and K: (nb,) powers (ECG-GVR);
    s: (nb, n, 3) centres in bohr (floating ECGs). InputError for shapes or values that do not fit
    (non-finite A, c_A, u, s or coefficients included; also when saving).
    """

    system: System
    A: np.ndarray
    c_A: np.ndarray
    channels: list[str] = field(default_factory=list)
    coefficients: np.ndarray | None = None
    kind: str = "pecg"
    u: np.ndarray | None = None
    K: np.ndarray | None = None
    s: np.ndarray | None = None

    def __post_init__(self):
        if not isinstance(self.system, System):
            raise InputError(f"Basis: system = {self.system!r}: must be a prebo.System")
        n = self.system.n
        self.A = _finite("A", self.A, (n, n), f"{n} x {n} exponent matrices, one per function")
        self.c_A = _finite("c_A", self.c_A, (), "one number per function")
        nb = len(self.A)
        if len(self.c_A) != nb:
            raise InputError(f"basis: {nb} exponent matrices but {len(self.c_A)} values of c_A")
        fam = family_of(self.kind)
        fam.check_state(self.system.state)
        for name, shape in fam.shapes.items():
            value = getattr(self, name)
            if value is None:
                raise InputError(f"a {self.kind} basis needs the parameters {name!r}")
            dims = tuple(n if d == "n" else d for d in shape)
            what = f"{' x '.join(map(str, dims))} numbers per function" if dims else "one number per function"
            value = fam.coerce(name, _finite(name, value, dims, what))
            if value.size != nb * int(np.prod(dims, dtype=int)):
                raise InputError(f"basis: {nb} functions but {value.size} values of {name!r}")
            setattr(self, name, np.ascontiguousarray(value.reshape((nb, *dims))))
        if not isinstance(self.channels, (list, tuple)) or not all(isinstance(c, str) for c in self.channels):
            raise InputError(f"Basis: channels = {reprlib.repr(self.channels)}: must be a list of coordinate-set names")
        self.channels = list(self.channels) or ["unknown"] * nb
        if len(self.channels) != nb:
            raise InputError(f"basis: {nb} functions but {len(self.channels)} channels")
        self.coefficients = _coefficients("basis", self.coefficients, nb)

    @property
    def family(self) -> Family:
        """The basis family (prebo.basis.family(kind))."""
        return family_of(self.kind)

    @property
    def parameters(self) -> dict:
        """The family's per-function arrays beyond A and c_A, by name."""
        return {name: getattr(self, name) for name in self.family.shapes}

    @classmethod
    def empty(cls, system: System, kind: str = "pecg") -> "Basis":
        """A basis of no functions of family `kind`."""
        if not isinstance(system, System):
            raise InputError(f"Basis.empty: system = {system!r}: must be a prebo.System")
        n = system.n
        extra = {name: np.zeros((0, *(n if d == "n" else d for d in shape)))
                 for name, shape in family_of(kind).shapes.items()}
        return cls(system, np.zeros((0, n, n)), np.zeros(0), [], kind=kind, **extra)

    @classmethod
    def single(cls, system: System, A: np.ndarray, c_A: float, channel: str, kind: str, extras: dict) -> "Basis":
        """One function: A (n x n), c_A, its channel and its family's extras (each with a leading 1)."""
        return cls(system, A[None], [c_A], [channel], kind=kind, **extras)

    def __len__(self) -> int:
        return len(self.A)

    @property
    def N(self) -> int:
        """The total orbital angular momentum quantum number of the system's state."""
        return self.system.state.N

    def subset(self, idx) -> "Basis":
        """The functions `idx` (indices or mask) as a new basis."""
        idx = np.arange(len(self))[idx]
        extra = {name: v[idx] for name, v in self.parameters.items()}
        return Basis(self.system, self.A[idx], self.c_A[idx], [self.channels[i] for i in idx], kind=self.kind, **extra)

    @classmethod
    def concat(cls, fs: list["Basis"]) -> "Basis":
        """The functions of several bases (same system and kind), in order."""
        first = fs[0]
        extra = {name: np.concatenate([getattr(f, name) for f in fs]) for name in first.parameters}
        return cls(first.system, np.concatenate([f.A for f in fs]), np.concatenate([f.c_A for f in fs]),
                   [c for f in fs for c in f.channels], kind=first.kind, **extra)

    def differs(self, other: "Basis") -> np.ndarray:
        """The indices of the functions that differ from those of `other` (as many, of one kind)."""
        pairs = [(self.A, other.A), (self.c_A, other.c_A)] + [(v, getattr(other, k)) for k, v in self.parameters.items()]
        return np.flatnonzero(np.any([(a != b).reshape(len(self), -1).any(axis=1) for a, b in pairs], axis=0))

    def append(self, f: "Basis") -> None:
        """Append the functions of `f` (same system and kind); forgets the coefficients."""
        self.A = np.ascontiguousarray(np.concatenate([self.A, f.A]))
        self.c_A = np.concatenate([self.c_A, f.c_A])
        for name, v in self.parameters.items():
            setattr(self, name, np.ascontiguousarray(np.concatenate([v, getattr(f, name)])))
        self.channels += list(f.channels)
        self.coefficients = None

    def replace(self, i: int, f: "Basis") -> None:
        """Replace function i by the single function of `f`; forgets the coefficients."""
        self.A[i] = f.A[0]
        self.c_A[i] = f.c_A[0]
        for name, v in self.parameters.items():
            v[i] = getattr(f, name)[0]
        self.channels[i] = f.channels[0]
        self.coefficients = None

    def validate(self) -> None:
        """Every A symmetric, positive definite and CM-separable (A 1 = c_A m/m_tot, c_A > 0), and
        the family's parameters valid; BasisFileError, InputError, NotPositiveDefiniteError or
        SeparabilityError naming the function otherwise."""
        m = self.system.cm_vector
        fam = self.family
        for i, (A, c) in enumerate(zip(self.A, self.c_A)):
            if not np.all(np.isfinite(A)) or not np.isfinite(c):
                raise BasisFileError(f"function {i}: non-finite parameters")
            if np.max(np.abs(A - A.T)) > 1e-12 * max(1.0, np.max(np.abs(A))):
                raise InputError(f"function {i}: exponent matrix A is not symmetric")
            if not c > 0:
                raise NotPositiveDefiniteError(f"function {i}: c_A = {c} must be positive")
            try:
                np.linalg.cholesky(A)
            except np.linalg.LinAlgError:
                raise NotPositiveDefiniteError(f"function {i}: exponent matrix A is not positive definite") from None
            if np.max(np.abs(A.sum(axis=1) - c * m)) > 1e-9 * max(1.0, np.max(np.abs(A))):
                raise SeparabilityError(f"function {i}: A^(r) 1 != c_A m/m_tot, the CM does not separate")
            fam.check_function(self, i)

    # --- basis.json (docs/basis-format.md; the format is prebo.io.basis_json) ---
    def to_dict(self, extra: dict | None = None) -> dict:
        """The basis.json mapping of this basis, with `extra` keys added."""
        _coefficients("Basis.to_dict", self.coefficients, len(self))  # set since construction
        return basis_json.to_dict(self, extra)

    def save(self, path, extra: dict | None = None) -> None:
        """Write basis.json atomically: a killed run leaves either the old or the new file."""
        _coefficients("Basis.save", self.coefficients, len(self))
        basis_json.save(self, _file("Basis.save", path), extra)

    @classmethod
    def from_dict(cls, d: dict, where: str = "basis", empty: bool = False) -> "Basis":
        """The basis of a basis.json mapping; BasisFileError naming `where` (and the function and
        key) for anything wrong (prebo.io.basis_json.arguments, `validate`), including no functions
        at all (unless `empty`: a checkpoint before the first one)."""
        args = basis_json.arguments(d, where)
        try:
            basis = cls(**args)
            basis.validate()
        except PreboError as exc:
            raise BasisFileError(f"{where}: {exc}") from exc
        if not (empty or len(basis)):
            raise BasisFileError(f"{where}: the basis has no functions")
        return basis

    @classmethod
    def load(cls, path) -> "Basis":
        """The basis of a basis.json file, recognised by its content whatever its name
        (prebo.io.stored); BasisFileError naming the file for anything wrong, an ecgpack file
        included (prebo.io.ecgpack.read_inout reads it)."""
        path = _file("Basis.load", path)
        what, text = stored.read(path)
        if what == "ecgpack":
            raise BasisFileError(f"{path}: an ecgpack file, not a basis.json (prebo.io.ecgpack.read_inout reads it)")
        return cls.from_dict(basis_json.parse(text, path), str(path))


def _finite(name: str, value, shape: tuple, what: str) -> np.ndarray:
    """`value` as a C-contiguous float array of shape (nb, *shape); InputError naming argument
    `name` and `what` it must be unless it is finite real numbers of that shape."""
    try:
        a = np.asarray(value)
        if a.dtype.kind not in "iuf":
            raise ValueError
        a = a.astype(float, copy=False).reshape(-1, *shape)
    except ValueError:
        got = f"an array of shape {value.shape}" if isinstance(value, np.ndarray) else reprlib.repr(value)
        raise InputError(f"Basis: {name} = {got}: must be {what} (real numbers)") from None
    if not np.isfinite(a).all():
        at = tuple(np.argwhere(~np.isfinite(a))[0])
        raise InputError(f"Basis: {name}[{', '.join(map(str, at))}] = {a[at]}: must be a finite number")
    return np.ascontiguousarray(a)


def _coefficients(where: str, value, nb: int) -> np.ndarray | None:
    """`value` (None: not known) as nb finite floats, one per function; InputError naming `where` otherwise."""
    if value is None:
        return None
    c = _finite("coefficients", value, (), "one number per function")
    if len(c) != nb:
        raise InputError(f"{where}: {nb} functions but {len(c)} coefficients")
    return c


def _file(where: str, path):
    """`path` if it names a file (a non-empty str or os.PathLike), else InputError naming `where`."""
    return path_name(path, f"{where}: path", "a file name (a str or path)")
