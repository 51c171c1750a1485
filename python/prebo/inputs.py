"""TOML input files; each table mirrors a Python object:

    [system]     particles = ["p", "e", {name = "x", mass = 3.0, charge = 1, spin = 0.5}]   -> System
    [state]      N = 0, parity = 1, spin = {e = 0}                                          -> State
    [basis]      type = "pecg" | "ecg-gvr" | "fecg", size = 100, c_A = 1.0, K_max = 20               -> Optimiser.kind, .size, .c_A, .K_max
    [optimiser]  trials = 20, sweeps = 1, seed = 1, channels = "pairs", length_range = [0.01, 15]
"""
from __future__ import annotations

import tomllib
from dataclasses import dataclass, fields
from pathlib import Path

from .basis import read_text
from .errors import InputError
from .optimise import Optimiser
from .system import State, System

BASIS_TYPES = ("pecg", "ecg-gvr", "fecg")
#: every Optimiser setting but those [basis] gives
OPTIMISER_KEYS = {f.name for f in fields(Optimiser)} - {"size", "c_A", "kind", "K_max"}


@dataclass
class Job:
    title: str
    system: System
    optimiser: Optimiser
    basis_type: str = "pecg"


def _table(d: dict, name: str, allowed: set) -> dict:
    t = d.get(name, {})
    if not isinstance(t, dict):
        raise InputError(f"[{name}] must be a table")
    unknown = set(t) - allowed
    if unknown:
        raise InputError(f"[{name}]: unknown keys {sorted(unknown)} (allowed: {sorted(allowed)})")
    return t


def from_dict(d: dict) -> Job:
    """A Job from the parsed TOML mapping (see module docstring)."""
    unknown = set(d) - {"title", "system", "state", "basis", "optimiser"}
    if unknown:
        raise InputError(f"unknown tables {sorted(unknown)}")
    system_t = _table(d, "system", {"particles"})
    state_t = _table(d, "state", {"N", "parity", "spin"})
    basis_t = _table(d, "basis", {"type", "size", "c_A", "K_max"})
    opt_t = _table(d, "optimiser", OPTIMISER_KEYS)
    if "particles" not in system_t:
        raise InputError("[system] needs 'particles'")
    system = System(system_t["particles"], State(**state_t))
    kind = basis_t.get("type", "pecg")
    if kind not in BASIS_TYPES:
        raise InputError(f"[basis] type {kind!r} is not available (available: {', '.join(BASIS_TYPES)})")
    if kind == "pecg" and (system.state.N != 0 or system.state.parity != 1):
        raise InputError("plain ECGs describe N = 0, parity +1 states only")
    if kind == "ecg-gvr" and system.state.parity != (-1) ** system.state.N:
        raise InputError(f"ECG-GVR functions have natural parity (-1)^N = {(-1) ** system.state.N:+d}, "
                         f"not {system.state.parity:+d}")
    kw = {k: basis_t[k] for k in ("size", "c_A", "K_max") if k in basis_t} | opt_t | {"kind": kind}
    opts = Optimiser.from_dict(kw)
    return Job(str(d.get("title", system.label())), system, opts, kind)


def load(path) -> Job:
    path = Path(path)
    text = read_text(path, InputError)
    try:
        d = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{path}: not valid TOML ({exc})") from exc
    try:
        return from_dict(d)
    except InputError as exc:
        raise InputError(f"{path}: {exc}") from exc
