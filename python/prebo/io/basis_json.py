"""basis.json (format "prebo-basis", version 1; docs/basis-format.md) and the atomic writers.

A basis file stores the system, the state, the symmetry, the conventions and, per function, the
full A^(r), c_A, the channel and the family's parameters (u and K, or s), plus the linear
coefficients of the state; a run's checkpoint adds its settings and progress (prebo.optimise).
Every writer goes through `write_atomic`: a killed writer leaves the old file or the new one.
"""
from __future__ import annotations

import json
import os
import tempfile
from glob import escape as glob_escape
from pathlib import Path

import numpy as np

from ..basis import Basis, family
from ..errors import BasisFileError, OutputError, PreboError
from ..system import System

FORMAT = "prebo-basis"
VERSION = 1
CONVENTIONS = {
    "gaussian": "exp(-r^T (A ⊗ I_3) r), no 1/2 in the exponent",
    "coordinates": "laboratory-frame Cartesian, particles in the order listed",
    "units": "hartree atomic units; masses in electron masses",
    "cm": "A^(r) 1 = c_A m / m_tot (CM-separable); energy has the CM kinetic energy eliminated",
}


def to_dict(basis: Basis, extra: dict | None = None) -> dict:
    """The basis.json mapping of `basis`, with the keys of `extra` added (a checkpoint's run state)."""
    d = {
        "format": FORMAT,
        "version": VERSION,
        "conventions": CONVENTIONS,
        "system": basis.system.to_dict(),
        "symmetry": basis.system.symmetriser.as_dict(),
        "basis_type": basis.kind,
        "functions": [_function_dict(basis, i) for i in range(len(basis))],
    }
    if basis.coefficients is not None:
        d["coefficients"] = np.asarray(basis.coefficients).tolist()
    if extra:
        d.update(extra)
    return d


def _function_dict(basis: Basis, i: int) -> dict:
    f = {"A": basis.A[i].tolist(), "c_A": float(basis.c_A[i]), "channel": basis.channels[i]}
    for name, v in basis.parameters.items():
        f[name] = v[i].tolist()
    return f


def save(basis: Basis, path, extra: dict | None = None) -> None:
    """Write `to_dict(basis, extra)` to `path` atomically."""
    write_json_atomic(path, to_dict(basis, extra))


def from_dict(d: dict, where: str = "basis", empty: bool = False) -> Basis:
    """The basis of a basis.json mapping; BasisFileError naming `where` for anything wrong,
    including no functions at all (unless `empty`: a checkpoint before the first one)."""
    if not isinstance(d, dict) or d.get("format") != FORMAT:
        raise BasisFileError(f"{where}: not a prebo basis file (format must be {FORMAT!r})")
    if d.get("version") != VERSION:
        raise BasisFileError(f"{where}: unsupported version {d.get('version')!r} (this prebo reads {VERSION})")
    kind = d.get("basis_type")
    try:
        fam = family(kind)
    except PreboError:
        raise BasisFileError(f"{where}: basis type {kind!r} is not supported by this version") from None
    try:
        system = System.from_dict(d["system"], d.get("symmetry"))
        funcs = d["functions"]
        n = system.n
        check_fields(funcs, n, kind, ("A", "c_A") + tuple(fam.shapes))
        A = np.array([f["A"] for f in funcs], dtype=float).reshape(len(funcs), n, n)
        c_A = np.array([f["c_A"] for f in funcs], dtype=float)
        channels = [str(f.get("channel", "unknown")) for f in funcs]
        coef = d.get("coefficients")
        coef = None if coef is None else np.asarray(coef, dtype=float)
        extra = {name: np.array([f[name] for f in funcs]) for name in fam.shapes}
        basis = Basis(system, A, c_A, channels, coef, kind, **extra)
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


def check_fields(funcs, n: int, kind: str, fields: tuple) -> None:
    """Each function of a `kind` basis of `n` particles has `fields`, and an n x n `A`
    (BasisFileError naming the first function that has not)."""
    if not isinstance(funcs, list):
        raise BasisFileError("functions must be a list")
    for i, f in enumerate(funcs):
        missing = [k for k in fields if not isinstance(f, dict) or k not in f]
        if missing:
            raise BasisFileError(f"function {i} has no {', '.join(map(repr, missing))} (each {kind} function has "
                                 f"{', '.join(fields)})")
        if np.shape(f["A"]) != (n, n):
            raise BasisFileError(f"function {i}: A must be {n} x {n} for the {n} particles of the system, "
                                 "not of shape " + "x".join(map(str, np.shape(f["A"]))))


def load(path) -> Basis:
    """The basis of basis.json file `path`; BasisFileError naming the file for anything wrong."""
    return from_dict(read(path), str(path))


def read(path):
    """The parsed content of basis.json file `path` (not yet checked: `from_dict`); BasisFileError
    naming the file when it is unreadable or not JSON."""
    path = Path(path)
    text = read_text(path, BasisFileError)
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise BasisFileError(f"{path}: corrupt or truncated JSON (line {exc.lineno}: {exc.msg})") from exc


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


_ENCODER = json.JSONEncoder(allow_nan=False)  # the C encoder: `indent` would select the pure-Python one


def write_json_atomic(path, obj: dict) -> None:
    """`write_atomic` of the mapping `obj` as strict JSON (ValueError on NaN or infinity, which
    JSON cannot hold): a key per line and an element per line of a list of lists or mappings
    (the functions, the history). Compact lines keep the C encoder: a checkpoint of 500
    functions is written in 6 ms instead of the 20 ms of `indent=1`, once per step of a run."""
    def value(v):
        if isinstance(v, list) and v and isinstance(v[0], (list, dict)):
            return "[\n  " + ",\n  ".join(map(_ENCODER.encode, v)) + "\n ]"
        return _ENCODER.encode(v)

    write_atomic(path, "{\n" + ",\n".join(f" {_ENCODER.encode(k)}: {value(v)}" for k, v in obj.items()) + "\n}\n")


def remove_stale_temporaries(path) -> None:
    """Delete the temporary files a killed `write_atomic` of `path` left behind."""
    path = Path(path)
    for f in path.parent.glob(glob_escape(path.name) + ".*.tmp"):
        f.unlink(missing_ok=True)
