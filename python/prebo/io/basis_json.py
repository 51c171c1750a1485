"""basis.json (format "prebo-basis", version 1; docs/basis-format.md).

A basis file stores the system, the state, the symmetry, the conventions and, per function, the
full A^(r), c_A, the channel and the family's parameters (u and K, or s), plus the linear
coefficients of the state; a run's checkpoint adds its settings and progress (prebo.optimise).
Every file is written by files.write_json_atomic: a killed writer leaves the old file or the new one.

A file is a claim to be checked, not a source of truth (docs/basis-format.md): `read` takes at
most MAX_BYTES, integers of at most MAX_DIGITS digits and MAX_DEPTH levels of nesting; `arguments`
refuses unknown keys, a function with keys of another family or values of the wrong type (no
boolean for an integer, no string for a number), more than MAX_SIZE functions, a stored symmetry
that is not the state's (`System.from_dict`) and settings out of their range.

prebo.basis.basis imports this module, not the reverse: `Basis.from_dict` builds the basis of the
checked `arguments` and validates its functions; `to_dict` reads a basis through its attributes.
"""
from __future__ import annotations

import json
import math
import re
import reprlib
import sys
from pathlib import Path

import numpy as np

from ..basis.families import FAMILIES, family
from ..basis.family import Family
from ..coordinates import by_name
from ..errors import BasisFileError, InputError, PreboError
from ..provenance import provenance
from ..system import System
from ..validation import MAX_SIZE, number
from .files import write_json_atomic

FORMAT = "prebo-basis"
VERSION = 1
CONVENTIONS = {
    "gaussian": "exp(-r^T (A ⊗ I_3) r), no 1/2 in the exponent",
    "coordinates": "laboratory-frame Cartesian, particles in the order listed",
    "units": "hartree atomic units; masses in electron masses",
    "cm": "A^(r) 1 = c_A m / m_tot (CM-separable); energy has the CM kinetic energy eliminated",
}
#: the keys of a basis file: the basis, then the energy, the settings and a run's state (prebo.optimise.resume)
KEYS = ("format", "version", "conventions", "system", "symmetry", "basis_type", "functions", "coefficients",
        "energy", "objective", "optimiser", "progress", "rng", "history", "elapsed", "schedule", "stopped", "momentum",
        "levels", "followed", "response", "provenance")
#: every function's arrays beside its family's extras (name -> shape, "n": particles); and a channel
COMMON = {"A": ("n", "n"), "c_A": ()}
#: bytes allowed per function (twice a checkpoint's two copies of a function of 8 particles) and
#: for a run's history (2.8 million rows, 50 days of one run of H2)
FUNCTION_BYTES, HISTORY_BYTES = 8 << 10, 128 << 20
#: the largest file `read_text` reads: MAX_SIZE functions and a history
MAX_BYTES = MAX_SIZE * FUNCTION_BYTES + HISTORY_BYTES
#: the most digits of an integer (a random-number state has 39) and levels of nesting (a checkpoint has 6)
MAX_DIGITS, MAX_DEPTH = 100, 16
TOO_DEEP = f"nested more than {MAX_DEPTH} levels deep"


def to_dict(basis, extra: dict | None = None) -> dict:
    """The basis.json mapping of `basis` (a prebo.Basis), with the keys of `extra` added (a checkpoint's run state)."""
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


def _function_dict(basis, i: int) -> dict:
    f = {"A": basis.A[i].tolist(), "c_A": float(basis.c_A[i]), "channel": basis.channels[i]}
    for name, v in basis.parameters.items():
        f[name] = v[i].tolist()
    return f


def save(basis, path, extra: dict | None = None) -> None:
    """Write `to_dict(basis, extra)` to `path` atomically, with the provenance of the writer (what
    made the file; not in `to_dict`, whose mapping also serves as a checkpoint's momentum block)."""
    write_json_atomic(path, to_dict(basis, extra) | {"provenance": provenance()})


def arguments(d: dict, where: str) -> dict:
    """The prebo.Basis arguments (system, A, c_A, channels, coefficients, kind and the family's
    extras) of a basis.json mapping; BasisFileError naming `where` (and the function and key) for
    anything wrong in the file (module docstring). A run's state is checked by prebo.optimise.resume."""
    if not isinstance(d, dict) or d.get("format") != FORMAT:
        raise BasisFileError(f"{where}: not a prebo basis file (format must be {FORMAT!r})")
    version = d.get("version")
    if not isinstance(version, int) or isinstance(version, bool):
        raise BasisFileError(f"{where}: version = {reprlib.repr(version)}: must be an integer (this prebo reads {VERSION})")
    if version != VERSION:
        raise BasisFileError(f"{where}: unsupported version {reprlib.repr(version)} (this prebo reads {VERSION})")
    unknown = [k for k in d if k not in KEYS]
    if unknown:
        raise BasisFileError(f"{where}: unknown keys {reprlib.repr(unknown)} (a basis file holds {', '.join(KEYS)})")
    conventions = d.get("conventions", CONVENTIONS)
    if conventions != CONVENTIONS:
        raise BasisFileError(f"{where}: conventions = {reprlib.repr(conventions)}: not prebo's (docs/conventions.md)")
    kind = d.get("basis_type")
    try:
        fam = family(kind)
    except PreboError:
        raise BasisFileError(f"{where}: basis type {reprlib.repr(kind)} is not supported by this version") from None
    funcs = d.get("functions")
    if isinstance(funcs, list) and len(funcs) > MAX_SIZE:
        raise BasisFileError(f"{where}: {len(funcs)} functions, more than the {MAX_SIZE} this machine's memory holds")
    try:
        system = System.from_dict(d.get("system"), d.get("symmetry"))
        n = system.n
        check_functions(funcs, system, fam)
        coef = d.get("coefficients")
        if coef is not None and not _holds(coef, (len(funcs),), False):
            raise BasisFileError(f"coefficients must be {len(funcs)} numbers, one per function, or null")
        check_settings(d.get("optimiser"))
        if not isinstance(d.get("provenance", {}), dict):
            raise BasisFileError(f"provenance = {reprlib.repr(d['provenance'])}: must be an object (what wrote the file)")
        for key in ("energy", "objective"):
            if d.get(key) is not None:
                number(d[key], key)
        A = np.array([f["A"] for f in funcs], dtype=float).reshape(len(funcs), n, n)
        c_A = np.array([f["c_A"] for f in funcs], dtype=float)
        channels = [f.get("channel", "unknown") for f in funcs]
        extra = {name: np.array([f[name] for f in funcs]) for name in fam.shapes}
    except PreboError as exc:
        raise BasisFileError(f"{where}: {exc}") from exc
    return dict(system=system, A=A, c_A=c_A, channels=channels, coefficients=coef, kind=kind, **extra)


def check_functions(funcs, system: System, fam: Family) -> None:
    """Each function of a `fam` basis of `system` holds A (n x n) and c_A, the family's extras
    (`Family.shapes`; integers where `Family.integers` says, else numbers; no booleans, no
    strings) and optionally its channel (a string; a coordinate set of the system's particles if
    it names one), and no other key; BasisFileError naming the first function and key that do not."""
    if not isinstance(funcs, list):
        raise BasisFileError("functions must be a list")
    fields = COMMON | fam.shapes
    for i, f in enumerate(funcs):
        if not isinstance(f, dict):
            raise BasisFileError(f"function {i} must be a mapping of {', '.join(fields)} and channel")
        for key in f:
            if key not in fields and key != "channel":
                owners = [g.name for g in FAMILIES.values() if key in g.shapes]
                why = (f"belongs to {' and '.join(owners)} functions, not to the file's basis_type {fam.name!r}"
                       if owners else f"is unknown (a {fam.name} function has {', '.join(fields)} and channel)")
                raise BasisFileError(f"function {i}: key {key!r} {why}")
        missing = [k for k in fields if k not in f]
        if missing:
            raise BasisFileError(f"function {i} has no {', '.join(map(repr, missing))} (each {fam.name} function "
                                 f"has {', '.join(fields)})")
        for key, shape in fields.items():
            dims = tuple(system.n if d == "n" else d for d in shape)
            integer = key in fam.integers
            if not _holds(f[key], dims, integer):
                what = ("an integer" if integer else "a number") if not dims else \
                    f"{' x '.join(map(str, dims))} {'integers' if integer else 'numbers'}"
                raise BasisFileError(f"function {i}: {key} must be {what}, not {reprlib.repr(f[key])}")
        for key in fam.integers:  # powers (K): within the family's limit before numpy holds them
            if not 0 <= f[key] <= fam.K_limit:
                raise BasisFileError(f"function {i}: {key} = {reprlib.repr(f[key])}: must be an integer in "
                                     f"0..{fam.K_limit}")
        if not isinstance(f.get("channel", ""), str):
            raise BasisFileError(f"function {i}: channel must be a string, not {reprlib.repr(f['channel'])}")
    for name in {f["channel"] for f in funcs if "channel" in f}:
        if name.partition(":")[0] in ("jacobi", "hpc", "cmc"):
            try:
                by_name(system.masses, name)
            except InputError as exc:
                raise BasisFileError(f"channel {name!r}: {exc}") from None


def _holds(value, dims: tuple, integer: bool) -> bool:
    """Whether `value` is nested lists of shape `dims` of integers (`integer`) or numbers, booleans
    and strings excluded."""
    if dims:
        return isinstance(value, list) and len(value) == dims[0] and all(_holds(v, dims[1:], integer) for v in value)
    return isinstance(value, int if integer else (int, float)) and not isinstance(value, bool)


def check_settings(block) -> None:
    """A basis file's "optimiser" block: settings of prebo.optimise.SETTINGS, each in its range
    (a run's, or an ecgpack import's threshold), or none; BasisFileError naming the setting."""
    from ..optimise.settings import SETTINGS, check  # prebo.optimise reads and writes basis files

    if block is None:
        return
    if not isinstance(block, dict):
        raise BasisFileError(f"optimiser must be a mapping of settings, not {reprlib.repr(block)}")
    for name, value in block.items():
        if name not in SETTINGS:
            raise BasisFileError(f"optimiser: unknown setting {reprlib.repr(name)}")
        try:
            check(name, value, f"optimiser {name}")
        except InputError as exc:
            raise BasisFileError(str(exc)) from None


def read(path):
    """The parsed content of basis.json file `path` (not yet checked: `arguments`, `Basis.from_dict`); BasisFileError
    naming the file when it is unreadable, larger than MAX_BYTES, not JSON, or holds an integer
    of more than MAX_DIGITS digits, a number beyond the largest double, NaN or Infinity (naming
    the line), a key twice in one object, or more than MAX_DEPTH levels of nesting."""
    path = Path(path)
    return parse(read_text(path, BasisFileError), path)


def parse(text: str, path):
    """The parsed content of the basis.json text `text` read from `path` (`read`'s checks)."""
    try:
        d = json.loads(text, parse_int=_integer, parse_float=_real, parse_constant=_constant, object_pairs_hook=_unique)
    except json.JSONDecodeError as exc:
        raise BasisFileError(f"{path}: corrupt or truncated JSON (line {exc.lineno}: {exc.msg})") from exc
    except RecursionError:  # deeper than Python's recursion limit
        raise BasisFileError(f"{path}: JSON {TOO_DEEP}") from None
    except _Refused as exc:
        raise BasisFileError(f"{path}{_line(text, exc.token)}: {exc}") from None
    nested(d, f"{path}: JSON", BasisFileError)
    return d


class _Refused(BasisFileError):
    """A JSON token `read` does not take; `token`, its text, to find its line by."""

    def __init__(self, message: str, token: str | None = None):
        super().__init__(message)
        self.token = token


def _line(text: str, token: str | None) -> str:
    """":LINE" of the first number or constant `token` in the JSON `text` (the first `read` parses), or ""."""
    if token is None:
        return ""
    found = re.search(rf"(?<![\w.+-]){re.escape(token)}(?![\w.])", text)
    return f":{text.count(chr(10), 0, found.start()) + 1}" if found else ""


def _integer(text: str) -> int:
    """A JSON integer, if it has at most MAX_DIGITS digits (Python refuses 4300 with a ValueError)."""
    if len(text.lstrip("-")) > MAX_DIGITS:
        raise _Refused(f"an integer of {len(text.lstrip('-'))} digits (at most {MAX_DIGITS} are read)", text)
    return int(text)


def _real(text: str) -> float:
    """A JSON number with a fraction or exponent, if a double holds it (1e400 is no number prebo computes with)."""
    x = float(text)
    if math.isinf(x):
        raise _Refused(f"{text}: a number beyond the largest double ({sys.float_info.max:.3g})", text)
    return x


def _constant(text: str):
    """NaN, Infinity and -Infinity: refused (JSON has no such numbers; prebo never writes them)."""
    raise _Refused(f"{text}: not a finite number", text)


def _unique(pairs: list) -> dict:
    """A JSON object whose keys are distinct (JSON would keep the last of a key given twice)."""
    d = dict(pairs)
    if len(d) < len(pairs):
        key = next(k for i, (k, _) in enumerate(pairs) if k in dict(pairs[:i]))
        raise _Refused(f"key {reprlib.repr(key)} given twice in one object")
    return d


def nested(obj, where: str, error: type[PreboError]) -> None:
    """`error` naming `where` if the parsed `obj` nests lists and mappings more than MAX_DEPTH
    levels deep (where a message's repr of a value could exceed Python's recursion limit)."""
    level = [obj] if isinstance(obj, (list, dict)) else []
    for _ in range(MAX_DEPTH):
        level = [v for x in level for v in (x.values() if isinstance(x, dict) else x) if isinstance(v, (list, dict))]
        if not level:
            return
    raise error(f"{where} {TOO_DEEP}")


def read_text(path: Path, error: type[PreboError]) -> str:
    """A file's text, or `error` naming the file when it is unreadable, not UTF-8 text, or larger
    than MAX_BYTES (reading stops there: /dev/zero is refused, not read until memory runs out)."""
    try:
        with open(path, "rb") as f:
            data = f.read(MAX_BYTES + 1)
    except OSError as exc:
        raise error(f"{path}: cannot read ({exc.strerror})") from exc
    return decoded(data, path, error)


def decoded(data: bytes, path: Path, error: type[PreboError]) -> str:
    """The text of the first MAX_BYTES + 1 bytes `data` read from `path` (`read_text`'s checks)."""
    if len(data) > MAX_BYTES:
        raise error(f"{path}: larger than {MAX_BYTES} bytes, the most prebo reads (a run's checkpoint of "
                    f"{MAX_SIZE} functions, the largest basis this machine holds)")
    try:
        return data.decode()
    except UnicodeDecodeError as exc:
        raise error(f"{path}: not a text file ({exc.reason})") from exc
