"""TOML input files; each table mirrors a Python object:

    [system]     particles = ["p", "e", {name = "x", mass = 3.0, charge = 1, spin = 0.5}]   -> System
    [state]      N = 0, parity = 1, spin = {e = 0}, threshold = -7.28, root = 1 (or roots = 4
                 or roots = [0, 2], weights = [1, 0.5])                                       -> State
    [basis]      type = "pecg", size = 100, c_A = 1.0, K_max = 20     -> Optimiser.kind (a prebo.basis.family), .size, .c_A, .K_max
    [optimiser]  trials = 20, sweeps = 1, seed = 1, channels = "pairs", length_range = [0.01, 15]
    [response]   ground = "he/basis.json", operator = "dipole", root = 0, omega = 0.0
                 -> optimise(..., response=Source.of(ground basis, operator, root, omega))

With [response] the run optimises the first-order function of the level `root` of the stored
basis `ground` (a basis.json, a run folder or an ecgpack file; relative to the input's folder) on
Hylleraas' functional (optimise/response.py) for the dipole, or for the current ("velocity", the
Bethe logarithm's at omega = −k): [system] and [state] may be left out, and are then
the ground basis's particles and the symmetry its dipole reaches (N + 1, the other parity, the
same spins).

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
from ..errors import InputError, PreboError
from ..optimise import Optimiser, coordinate_sets
from ..system import State, System
from ..optimise.defaults import resolved
from ..optimise.response import Source
from ..optimise.settings import SETTINGS, check
from ..validation import path_name
from .basis_json import TOO_DEEP, nested, read_text
from .load import basis_file, load_basis

#: [basis] key -> Optimiser setting; [optimiser] takes every other setting
BASIS_KEYS = {"type": "kind", "size": "size", "c_A": "c_A", "K_max": "K_max"}
OPTIMISER_KEYS = set(SETTINGS) - set(BASIS_KEYS.values())


@dataclass
class Job:
    """An input file's run: its `title` (default: the particle names), `system` and `optimiser` settings."""

    title: str
    system: System
    optimiser: Optimiser
    response: Source | None = None


def _table(d: dict, name: str, allowed: set) -> dict:
    t = d.get(name, {})
    if not isinstance(t, dict):
        raise InputError(f"[{name}] must be a table")
    unknown = set(t) - allowed
    if unknown:
        raise InputError(f"[{name}]: unknown keys {sorted(unknown)} (allowed: {sorted(allowed)})")
    return t


def from_dict(d: dict, folder: Path = Path(".")) -> Job:
    """A Job from the parsed TOML mapping (module docstring; paths relative to `folder`);
    InputError naming the key."""
    if not isinstance(d, dict):
        raise InputError("an input is a table of title, [system], [state], [basis] and [optimiser], "
                         f"got {reprlib.repr(d)}")
    unknown = set(d) - {"title", "system", "state", "basis", "optimiser", "response"}
    if unknown:
        raise InputError(f"unknown top-level keys or tables {sorted(unknown)} (allowed: title, [system], [state], "
                         "[basis], [optimiser], [response])")
    system_t = _table(d, "system", {"particles"})
    state_t = _table(d, "state", {"N", "parity", "spin", "threshold", "root", "roots", "weights"})
    basis_t = _table(d, "basis", set(BASIS_KEYS))
    opt_t = _table(d, "optimiser", OPTIMISER_KEYS)
    response_t = _table(d, "response", {"ground", "operator", "root", "omega"})
    ground = _ground(response_t, folder) if "response" in d else None
    if ground is not None:  # what is left out: the ground's particles, the symmetry the dipole reaches
        reached = _reached(ground[0].system)
        system_t, state_t = system_t or reached[0], state_t or reached[1]
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
    response = None if ground is None else _source(ground, response_t, system)
    return Job(title or system.label(), system, opts, response)


def _ground(t: dict, folder: Path) -> tuple:
    """The ground basis of a [response] table and its overlap threshold (io.load.load_basis)."""
    if "ground" not in t:
        raise InputError("[response] needs 'ground', the stored basis of the level (a basis.json, a run folder "
                         "or an ecgpack file)")
    name = t["ground"]
    if not isinstance(name, str):
        raise InputError(f"[response] ground = {reprlib.repr(name)}: must be a file or folder name")
    path = folder / name
    try:
        return load_basis(basis_file(str(path)))
    except PreboError as exc:
        raise InputError(f"[response] ground = {name!r}: {exc}") from exc


def _reached(ground: System) -> tuple[dict, dict]:
    """[system] and [state] of the symmetry a dipole reaches from a level of `ground`'s: its
    particles, N + 1, the other parity, the same spins."""
    particles = [p.to_dict() | {"mass": p.mass} for p in ground.particles]  # an infinite mass as ∞
    return {"particles": particles}, {"N": ground.state.N + 1, "parity": -ground.state.parity,
                                      "spin": ground.to_dict()["state"]["spin"]}


def _source(ground: tuple, t: dict, system: System) -> Source:
    """The response.Source of a [response] table for a run of `system`; InputError for bad settings,
    a ground basis of other particles or a symmetry its operator does not reach (Source.check)."""
    basis, threshold = ground
    settings = {k: t[k] for k in ("operator", "root", "omega") if k in t}
    if "root" in settings and (isinstance(settings["root"], bool) or not isinstance(settings["root"], int)
                               or settings["root"] < 0):
        raise InputError(f"[response] root = {settings['root']!r}: must be a level's index (0: the lowest)")
    try:
        source = Source.of(basis, threshold=threshold, **settings)
        source.check(system)
    except PreboError as exc:
        raise InputError(f"[response] {str(exc).removeprefix('response: ')}") from exc
    return source


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
        return from_dict(d, path.parent)
    except InputError as exc:
        raise InputError(f"{path}: {exc}") from exc
