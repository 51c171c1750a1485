"""TOML input files; each table mirrors a Python object:

    [system]     particles = ["p", "e", {name = "x", mass = 3.0, charge = 1, spin = 0.5}]   -> System
    [state]      N = 0, parity = 1, spin = {e = 0}, threshold = -7.28, root = 1 (or roots = 4
                 or roots = [0, 2], weights = [1, 0.5])                                       -> State
    [basis]      type = "pecg", size = 100, c_A = 1.0, K_max = 20     -> Optimiser.kind (a prebo.basis.family), .size, .c_A, .K_max
    [optimiser]  trials = 20, sweeps = 1, seed = 1, channels = "pairs", length_range = [0.01, 15]

Every value is checked against optimise.settings.SETTINGS, the settings left out are chosen for the
system (optimise.defaults), the basis family is checked against the state and the coordinate
sets against the particles before anything runs; errors name the file and the key.
"""
from __future__ import annotations

import reprlib
import sys
from dataclasses import dataclass
from pathlib import Path

if sys.version_info >= (3, 11):
    import tomllib
else:  # Python 3.10: the same parser as a package
    import tomli as tomllib

from ..basis import family
from ..errors import InputError
from ..optimise import Optimiser, coordinate_sets
from ..system import State, System
from ..optimise.defaults import resolved
from ..optimise.settings import SETTINGS, check
from ..validation import path_name
from .basis_json import TOO_DEEP, nested, read_text

#: [basis] key -> Optimiser setting; [optimiser] takes every other setting
BASIS_KEYS = {"type": "kind", "size": "size", "c_A": "c_A", "K_max": "K_max"}
OPTIMISER_KEYS = set(SETTINGS) - set(BASIS_KEYS.values())


@dataclass
class Job:
    """An input file's run: its `title` (default: the particle names), `system` and `optimiser` settings."""

    title: str
    system: System
    optimiser: Optimiser


def _table(d: dict, name: str, allowed: set) -> dict:
    t = d.get(name, {})
    if not isinstance(t, dict):
        raise InputError(f"[{name}] must be a table")
    unknown = set(t) - allowed
    if unknown:
        raise InputError(f"[{name}]: unknown keys {sorted(unknown)} (allowed: {sorted(allowed)})")
    return t


def from_dict(d: dict) -> Job:
    """A Job from the parsed TOML mapping (module docstring); InputError naming the key."""
    if not isinstance(d, dict):
        raise InputError("an input is a table of title, [system], [state], [basis] and [optimiser], "
                         f"got {reprlib.repr(d)}")
    unknown = set(d) - {"title", "system", "state", "basis", "optimiser"}
    if unknown:
        raise InputError(f"unknown top-level keys or tables {sorted(unknown)} (allowed: title, [system], [state], "
                         "[basis], [optimiser])")
    system_t = _table(d, "system", {"particles"})
    state_t = _table(d, "state", {"N", "parity", "spin", "threshold", "root", "roots", "weights"})
    basis_t = _table(d, "basis", set(BASIS_KEYS))
    opt_t = _table(d, "optimiser", OPTIMISER_KEYS)
    if "particles" not in system_t:
        raise InputError("[system] needs 'particles'")
    title = d.get("title")
    if title is not None and not isinstance(title, str):
        raise InputError(f"title = {title!r}: must be a string")
    system = System(system_t["particles"], State(**state_t))
    if "size" not in basis_t:
        raise InputError("[basis] needs 'size', the number of basis functions (e.g. size = 100)")
    settings = {BASIS_KEYS[k]: v for k, v in basis_t.items()} | opt_t
    opts = resolved(Optimiser(**{name: check(name, v, SETTINGS[name].key) for name, v in settings.items()}), system)
    family(opts.kind).check_state(system.state)
    if "K_max" in basis_t and not family(opts.kind).K_limit:
        raise InputError(f"[basis] K_max: {opts.kind} functions have no power K (K_max is a setting of ecg-gvr)")
    coordinate_sets(system, opts.channels)
    return Job(title or system.label(), system, opts)


def load(path) -> Job:
    """The Job of a TOML input file; InputError naming the file (and the key) for anything wrong."""
    path = Path(path_name(path, "toml.load: path", "a file name (a str or path)"))
    text = read_text(path, InputError)
    try:
        d = tomllib.loads(text)
    except RecursionError:
        raise InputError(f"{path}: TOML {TOO_DEEP}") from None
    except ValueError as exc:  # TOMLDecodeError, or an integer of more digits than Python converts
        raise InputError(f"{path}: not valid TOML ({exc})") from exc
    nested(d, f"{path}: TOML", InputError)
    try:
        return from_dict(d)
    except InputError as exc:
        raise InputError(f"{path}: {exc}") from exc
