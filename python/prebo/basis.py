"""ECG basis sets in laboratory-frame Cartesian coordinates, and the basis.json format.

A plain ECG ("pecg") is phi_I(r) = exp(-r^T (A_I ⊗ I_3) r) (docs/conventions.md); an
ECG-GVR function ("ecg-gvr", paper eq. ecg-gvr) multiplies it by |v|^{2K} (v_x + i v_y)^N,
v = u_I^T r, with the state's N; a floating ECG ("fecg") is exp(-(r - s_I)^T (A_I ⊗ I_3)(r - s_I)).
Exponents are
A_I = U_x^T blockdiag(𝒜_I, c_A) U_x for the coordinate set ("channel") x it was
generated in. basis.json (format "prebo-basis", version 1; docs/basis-format.md)
stores the system, the state, the symmetry, the conventions and, per function,
the full A^(r), c_A and the channel, plus the linear coefficients of the state.
"""
from __future__ import annotations

import json
import os
import tempfile
from dataclasses import dataclass, field
from glob import escape as glob_escape
from pathlib import Path

import numpy as np

from .errors import BasisFileError, InputError, NotPositiveDefiniteError, OutputError, PreboError, SeparabilityError
from .system import System
from .validation import BASIS_TYPES, SETTINGS, check_kind

FORMAT = "prebo-basis"
VERSION = 1
CONVENTIONS = {
    "gaussian": "exp(-r^T (A ⊗ I_3) r), no 1/2 in the exponent",
    "coordinates": "laboratory-frame Cartesian, particles in the order listed",
    "units": "hartree atomic units; masses in electron masses",
    "cm": "A^(r) 1 = c_A m / m_tot (CM-separable); energy has the CM kinetic energy eliminated",
}


#: per basis type, its per-function parameters beyond A and c_A: name -> (shape after nb, dtype)
PARAMETERS = {
    "pecg": {},
    "ecg-gvr": {"u": ("n",), "K": ()},
    "fecg": {"s": ("n", 3)},
}
KINDS = BASIS_TYPES  # the keys of PARAMETERS
K_LIMIT = SETTINGS["K_max"].rule.hi


@dataclass
class Basis:
    """An ECG basis of a system in LFCC: exponents `A` (nb, n, n), `c_A` (nb), channels (nb);
    ECG-GVR adds global vectors `u` (nb, n) and powers `K` (nb); FECG adds centres `s` (nb, n, 3)."""

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
        n = self.system.n
        self.A = np.ascontiguousarray(np.asarray(self.A, dtype=float).reshape(-1, n, n))
        self.c_A = np.ascontiguousarray(np.asarray(self.c_A, dtype=float).reshape(-1))
        nb = len(self.A)
        if len(self.c_A) != nb:
            raise InputError(f"basis: {nb} exponent matrices but {len(self.c_A)} values of c_A")
        if self.kind not in KINDS:
            raise InputError(f"basis type {self.kind!r} is not one of {', '.join(KINDS)}")
        check_kind(self.kind, self.system.state)
        for name, shape in PARAMETERS[self.kind].items():
            value = getattr(self, name)
            if value is None:
                raise InputError(f"a {self.kind} basis needs the parameters {name!r}")
            value = np.asarray(value)
            if name == "K":
                if not np.all((value >= 0) & (value <= K_LIMIT) & (value == np.round(value))):
                    raise InputError(f"basis: every K must be an integer in 0..{K_LIMIT}")
                value = value.astype(np.uint32)
            else:
                value = value.astype(float)
            dims = tuple(n if d == "n" else d for d in shape)
            if value.size != nb * int(np.prod(dims, dtype=int)):
                raise InputError(f"basis: {nb} functions but {value.size} values of {name!r}")
            setattr(self, name, np.ascontiguousarray(value.reshape((nb, *dims))))
        if not self.channels:
            self.channels = ["unknown"] * nb

    @property
    def parameters(self) -> dict:
        """The per-function arrays beyond A and c_A of this basis type."""
        return {name: getattr(self, name) for name in PARAMETERS[self.kind]}

    @classmethod
    def empty(cls, system: System, kind: str = "pecg") -> "Basis":
        n = system.n
        extra = {name: np.zeros((0, *(n if d == "n" else d for d in shape)))
                 for name, shape in PARAMETERS[kind].items()}
        return cls(system, np.zeros((0, n, n)), np.zeros(0), [], kind=kind, **extra)

    def __len__(self) -> int:
        return len(self.A)

    @property
    def N(self) -> int:
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

    def append(self, f: "Basis") -> None:
        """Append the functions of `f` (same system and kind)."""
        self.A = np.ascontiguousarray(np.concatenate([self.A, f.A]))
        self.c_A = np.concatenate([self.c_A, f.c_A])
        for name, v in self.parameters.items():
            setattr(self, name, np.ascontiguousarray(np.concatenate([v, getattr(f, name)])))
        self.channels += list(f.channels)
        self.coefficients = None

    def replace(self, i: int, f: "Basis") -> None:
        """Replace function i by the single function of `f`."""
        self.A[i] = f.A[0]
        self.c_A[i] = f.c_A[0]
        for name, v in self.parameters.items():
            v[i] = getattr(f, name)[0]
        self.channels[i] = f.channels[0]
        self.coefficients = None

    def validate(self) -> None:
        """Every A symmetric, positive definite and CM-separable (A 1 = c_A m/m_tot, c_A > 0)."""
        m = self.system.cm_vector
        for i, (A, c) in enumerate(zip(self.A, self.c_A)):
            if not np.all(np.isfinite(A)) or not np.isfinite(c):
                raise BasisFileError(f"function {i}: non-finite parameters")
            if np.max(np.abs(A - A.T)) > 1e-12 * max(1.0, np.max(np.abs(A))):
                raise InputError(f"function {i}: exponent matrix A is not symmetric")
            if not c > 0:
                raise NotPositiveDefiniteError(f"function {i}: c_A = {c} must be positive")
            if np.max(np.abs(A.sum(axis=1) - c * m)) > 1e-9 * max(1.0, np.max(np.abs(A))):
                raise SeparabilityError(f"function {i}: A^(r) 1 != c_A m/m_tot, the CM does not separate")
            try:
                np.linalg.cholesky(A)
            except np.linalg.LinAlgError:
                raise NotPositiveDefiniteError(f"function {i}: exponent matrix A is not positive definite") from None
            if self.kind == "ecg-gvr" and not (np.all(np.isfinite(self.u[i])) and np.any(self.u[i] != 0)):
                raise InputError(f"function {i}: the global vector u must be finite and non-zero")
            if self.kind == "fecg" and not np.all(np.isfinite(self.s[i])):
                raise BasisFileError(f"function {i}: non-finite centres s")

    # --- basis.json ------------------------------------------------------------
    def to_dict(self, extra: dict | None = None) -> dict:
        d = {
            "format": FORMAT,
            "version": VERSION,
            "conventions": CONVENTIONS,
            "system": self.system.to_dict(),
            "symmetry": self.system.symmetriser.as_dict(),
            "basis_type": self.kind,
            "functions": [self._function_dict(i) for i in range(len(self))],
        }
        if self.coefficients is not None:
            d["coefficients"] = np.asarray(self.coefficients).tolist()
        if extra:
            d.update(extra)
        return d

    def _function_dict(self, i: int) -> dict:
        f = {"A": self.A[i].tolist(), "c_A": float(self.c_A[i]), "channel": self.channels[i]}
        for name, v in self.parameters.items():
            f[name] = v[i].tolist()
        return f

    def save(self, path, extra: dict | None = None) -> None:
        """Write atomically: a killed run leaves either the old or the new file, never half of one."""
        write_json_atomic(path, self.to_dict(extra))

    @classmethod
    def from_dict(cls, d: dict, where: str = "basis", empty: bool = False) -> "Basis":
        """The basis of a basis.json mapping; BasisFileError naming `where` for anything wrong,
        including no functions at all (unless `empty`: a checkpoint before the first one)."""
        if not isinstance(d, dict) or d.get("format") != FORMAT:
            raise BasisFileError(f"{where}: not a prebo basis file (format must be {FORMAT!r})")
        if d.get("version") != VERSION:
            raise BasisFileError(f"{where}: unsupported version {d.get('version')!r} (this prebo reads {VERSION})")
        kind = d.get("basis_type")
        if kind not in KINDS:
            raise BasisFileError(f"{where}: basis type {kind!r} is not supported by this version")
        try:
            system = System.from_dict(d["system"], d.get("symmetry"))
            funcs = d["functions"]
            n = system.n
            A = np.array([f["A"] for f in funcs], dtype=float).reshape(len(funcs), n, n)
            c_A = np.array([f["c_A"] for f in funcs], dtype=float)
            channels = [str(f.get("channel", "unknown")) for f in funcs]
            coef = d.get("coefficients")
            coef = None if coef is None else np.asarray(coef, dtype=float)
            extra = {name: np.array([f[name] for f in funcs]) for name in PARAMETERS[kind]}
            basis = cls(system, A, c_A, channels, coef, kind, **extra)
        except PreboError as exc:
            raise BasisFileError(f"{where}: {exc}") from exc
        except (KeyError, TypeError, ValueError) as exc:
            raise BasisFileError(f"{where}: malformed basis data ({type(exc).__name__}: {exc})") from exc
        if not (empty or len(A)):
            raise BasisFileError(f"{where}: the basis has no functions")
        if coef is not None and (coef.shape != (len(A),) or not np.all(np.isfinite(coef))):
            raise BasisFileError(f"{where}: coefficients must be {len(A)} finite numbers, one per function")
        try:
            basis.validate()
        except PreboError as exc:
            raise BasisFileError(f"{where}: {exc}") from exc
        return basis

    @classmethod
    def load(cls, path) -> "Basis":
        path = Path(path)
        text = read_text(path, BasisFileError)
        try:
            d = json.loads(text)
        except json.JSONDecodeError as exc:
            raise BasisFileError(f"{path}: corrupt or truncated JSON (line {exc.lineno}: {exc.msg})") from exc
        return cls.from_dict(d, str(path))


def read_text(path: Path, error: type[PreboError]) -> str:
    """A file's text, or `error` naming the file when it is unreadable or not text."""
    try:
        return Path(path).read_text()
    except OSError as exc:
        raise error(f"{path}: cannot read ({exc.strerror})") from exc
    except UnicodeDecodeError as exc:
        raise error(f"{path}: not a text file ({exc.reason})") from exc


def write_atomic(path, text: str) -> None:
    """Write `text` to a temporary file in the same folder (PATH.*.tmp), fsync, then os.replace:
    a killed writer leaves the old file or the new one, never half of one. OutputError naming
    the path if it cannot be written."""
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name + ".", suffix=".tmp")
    except OSError as exc:
        raise OutputError(f"{path}: cannot write ({exc.strerror})") from exc
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)  # mkstemp's 0600 would hide results from other users
    try:
        with os.fdopen(fd, "w") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException as exc:
        if os.path.exists(tmp):
            os.unlink(tmp)
        if isinstance(exc, OSError):
            raise OutputError(f"{path}: cannot write ({exc.strerror})") from exc
        raise


def write_json_atomic(path, obj) -> None:
    """`write_atomic` of strict JSON (ValueError on NaN or infinity, which JSON cannot hold)."""
    write_atomic(path, json.dumps(obj, indent=1, allow_nan=False))


def remove_stale_temporaries(path) -> None:
    """Delete the temporary files a killed `write_atomic` of `path` left behind."""
    path = Path(path)
    for f in path.parent.glob(glob_escape(path.name) + ".*.tmp"):
        f.unlink(missing_ok=True)
