"""The checks of input values, shared by every reader (Python API, TOML, basis.json, ecgpack).

- the limits: `MAX_PARTICLES` (what the Rust core is compiled for) and `MAX_SIZE`, the largest
  basis whose matrices fit in this machine's memory: 16 dense nb x nb float64 matrices (S, T,
  T_ti, V, their copies while a function is appended or replaced, and the eigensolver's
  working matrices), i.e. nb <= sqrt(memory / 128 bytes);
- the rules of one value (`Integer`, `Sign`, `Real`, `Magnitude`, `Choice`, `Lengths`, `Channels`,
  and `Automatic` for a setting prebo chooses itself when it is absent), with the text of what they
  allow, and `checked`, a value by its rule or an InputError; the optimiser's table of settings is
  prebo.optimise.settings.SETTINGS, the particles' ranges prebo.system.particles;
- `number`, `half_integer`: the checks of one real parameter (energies; spins);
- `path_name`: a file or folder argument;
- `strict_keywords`: unknown keyword arguments of a settings dataclass as InputError.
The states a basis family can describe are checked by the family (prebo.basis.Family.check_state).

Every refusal is an `InputError` whose message names the argument or TOML key, the value and what
is allowed; readers of files prefix the file's name.
"""
from __future__ import annotations

import functools
import math
import numbers
import os
from dataclasses import dataclass, fields
from fractions import Fraction

import numpy as np

from . import _core
from .errors import InputError

MAX_PARTICLES = int(_core.MAX_DIM)
MATRICES = 16  # dense nb x nb float64 matrices held at once (module docstring)


def memory_bytes() -> int:
    """Physical memory, or the cgroup limit where that is lower (8 GiB where neither is known)."""
    try:
        total = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (AttributeError, ValueError, OSError):
        total = 8 << 30
    try:
        with open("/sys/fs/cgroup/memory.max") as f:
            total = min(total, int(f.read()))
    except (OSError, ValueError):  # no cgroup v2 limit, or "max"
        pass
    return total


MAX_SIZE = math.isqrt(memory_bytes() // (MATRICES * 8))


class Refused(Exception):
    """A value a rule does not accept (turned into an InputError by `checked`)."""


def _integer(v) -> int:
    """A Python or numpy integer as an int (bools refused)."""
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, np.integer)):
        raise Refused
    return int(v)


def _real(v) -> float:
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, numbers.Real):
        raise Refused
    v = float(v)
    if not math.isfinite(v):
        raise Refused
    return v


def checked(rule, value, label: str, meaning: str | None = None):
    """`value` as `rule` normalises it; InputError "`label` = value: must be `rule.allowed`
    (`meaning`)" if the rule refuses it."""
    try:
        return rule(value)
    except (Refused, TypeError, ValueError):
        why = f" ({meaning})" if meaning else ""
        raise InputError(f"{label} = {value!r}: must be {rule.allowed}{why}") from None


@dataclass(frozen=True)
class Integer:
    """An integer (bools refused) with lo ≤ value (≤ hi if given)."""

    lo: int
    hi: int | None = None

    @property
    def allowed(self) -> str:
        """What the rule allows, for error messages."""
        return f"an integer ≥ {self.lo}" if self.hi is None else f"an integer in {self.lo}..{self.hi}"

    def __call__(self, v) -> int:
        v = _integer(v)
        if v < self.lo or (self.hi is not None and v > self.hi):
            raise Refused
        return v


class Sign:
    """+1 or -1 (an integer, bools refused)."""

    allowed = "+1 or -1"

    def __call__(self, v) -> int:
        v = _integer(v)
        if v not in (1, -1):
            raise Refused
        return v


@dataclass(frozen=True)
class Real:
    """A finite number x with lo < x (or ≤ with `lo_closed`) and x < hi (or ≤ with `hi_closed`)."""

    lo: float
    hi: float = math.inf
    lo_closed: bool = False
    hi_closed: bool = False

    @property
    def allowed(self) -> str:
        """What the rule allows, for error messages."""
        if self.hi == math.inf:
            return f"a finite number {'≥' if self.lo_closed else '>'} {self.lo:g}"
        if self.lo == -math.inf:
            return f"a finite number {'≤' if self.hi_closed else '<'} {self.hi:g}"
        return (f"a finite {'positive ' if self.lo > 0 else ''}number x with {self.lo:g} "
                f"{'≤' if self.lo_closed else '<'} x {'≤' if self.hi_closed else '<'} {self.hi:g}")

    def __call__(self, v) -> float:
        x = _real(v)
        if x < self.lo or (x == self.lo and not self.lo_closed) or x > self.hi or (x == self.hi and not self.hi_closed):
            raise Refused
        return x


@dataclass(frozen=True)
class Magnitude:
    """0, or a finite number x with lo ≤ |x| ≤ hi."""

    lo: float
    hi: float

    @property
    def allowed(self) -> str:
        """What the rule allows, for error messages."""
        return f"0, or a finite number x with {self.lo:g} ≤ |x| ≤ {self.hi:g}"

    def __call__(self, v) -> float:
        x = _real(v)
        if x != 0 and not self.lo <= abs(x) <= self.hi:
            raise Refused
        return x


@dataclass(frozen=True)
class Choice:
    """One of the strings `values`."""

    values: tuple

    @property
    def allowed(self) -> str:
        """What the rule allows, for error messages."""
        return "one of " + ", ".join(map(repr, self.values))

    def __call__(self, v) -> str:
        if not isinstance(v, str) or v not in self.values:
            raise Refused
        return v


@dataclass(frozen=True)
class Lengths:
    """Two lengths [lo, hi] with shortest ≤ lo < hi ≤ longest, as a tuple."""

    shortest: float
    longest: float

    @property
    def allowed(self) -> str:
        """What the rule allows, for error messages."""
        return f"two finite numbers [lo, hi] with {self.shortest:g} ≤ lo < hi ≤ {self.longest:g}"

    def __call__(self, v) -> tuple:
        if isinstance(v, (str, bytes, dict)) or not hasattr(v, "__len__") or len(v) != 2:
            raise Refused
        lo, hi = _real(v[0]), _real(v[1])
        if not self.shortest <= lo < hi <= self.longest:
            raise Refused
        return lo, hi


class Channels:
    """"pairs", "all" or a non-empty list of coordinate-set names."""

    allowed = ("'pairs', 'all' or a non-empty list of coordinate-set names "
               "('jacobi:0-1-2', 'hpc:0', 'cmc:2', ...)")

    def __call__(self, v):
        if v in ("pairs", "all"):
            return v
        if isinstance(v, (list, tuple)) and v and all(isinstance(c, str) for c in v):
            return list(v)
        raise Refused


@dataclass(frozen=True)
class Automatic:
    """A value of `rule`, or None: absent, chosen by prebo for the system (prebo.optimise.defaults)."""

    rule: object

    @property
    def allowed(self) -> str:
        """What the rule allows, for error messages."""
        return f"{self.rule.allowed}, or absent (chosen for the system)"

    def __call__(self, v):
        return None if v is None else self.rule(v)


def strict_keywords(cls):
    """Class decorator: unknown keyword (or surplus positional) arguments of a dataclass raise
    InputError naming them and the known ones, instead of TypeError."""
    init = cls.__init__
    names = [f.name for f in fields(cls) if f.init]

    @functools.wraps(init)
    def __init__(self, *args, **kw):
        unknown = sorted(set(kw) - set(names))
        if unknown or len(args) > len(names):
            what = f"unknown arguments {unknown}" if unknown else f"{len(args)} positional arguments"
            raise InputError(f"{cls.__name__}: {what} (allowed: {', '.join(names)})")
        init(self, *args, **kw)

    cls.__init__ = __init__
    return cls


def number(value, label: str, positive: bool = False) -> float:
    """A finite real number (bools and strings refused), positive if asked; InputError otherwise."""
    try:
        x = _real(value)
        if positive and not x > 0:
            raise Refused
    except Refused:
        raise InputError(f"{label} = {value!r}: must be a finite{' positive' if positive else ''} number") from None
    return x


def path_name(value, label: str, what: str):
    """`value` if it is a non-empty str or os.PathLike (an empty path would be the current
    folder); InputError "`label` = value: must be `what`" otherwise."""
    if not isinstance(value, (str, os.PathLike)):
        raise InputError(f"{label} = {value!r}: must be {what}")
    if not os.fspath(value):
        raise InputError(f"{label} = {value!r}: empty; must be {what}")
    return value


def half_integer(value, label: str) -> Fraction:
    """A spin: 0, 1/2, 1, 3/2, ... (as a number); InputError otherwise."""
    try:
        x = _real(value)
        if x < 0 or abs(2 * x - round(2 * x)) > 1e-12:
            raise Refused
    except Refused:
        raise InputError(f"{label} = {value!r}: must be a spin 0, 1/2, 1, 3/2, ... (a number)") from None
    return Fraction(round(2 * x), 2)

