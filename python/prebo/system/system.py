"""A Coulomb system: particles, the state sought, and the groups of identical particles."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from .particles import Particle, particle
from .symmetry import Group, Symmetriser, coupling_path, lowest_total_spin
from ..validation import MAX_PARTICLES, half_integer, strict_keywords


@strict_keywords
@dataclass(frozen=True)
class State:
    """Total orbital angular momentum `N`, `parity` (+1/-1) and the total spin of each identical group."""

    N: int = 0
    parity: int = 1
    spin: dict = field(default_factory=dict)

    def __post_init__(self):
        if isinstance(self.N, bool) or not isinstance(self.N, int) or self.N < 0:
            raise InputError(f"state: N = {self.N!r}: must be a non-negative integer")
        if isinstance(self.parity, bool) or not isinstance(self.parity, int) or self.parity not in (1, -1):
            raise InputError(f"state: parity = {self.parity!r}: must be +1 or -1")
        if not isinstance(self.spin, dict) or not all(isinstance(k, str) for k in self.spin):
            raise InputError(f"state: spin = {self.spin!r}: must map particle names to total spins, e.g. {{e = 0}}")
        for name, S in self.spin.items():
            half_integer(S, f"state: spin of {name!r}")


class System:
    """Particles (LFCC order = input order) and the state; defines M, the Coulomb pairs and the symmetry.

    The Hamiltonian is paper eq. nonrel-H: H = -∇^T M ∇ + Σ_{i<j} q_i q_j / |r_i - r_j|,
    M = diag(1/(2 m_i)).
    """

    def __init__(self, particles, state: State | None = None, symmetriser: Symmetriser | None = None,
                 **state_kw):
        if not isinstance(particles, (list, tuple)) or not 2 <= len(particles) <= MAX_PARTICLES:
            raise InputError(f"system: particles = {particles!r}: must be a list of 2 to {MAX_PARTICLES} "
                             "particle names or tables")
        self.particles: list[Particle] = [particle(p) for p in particles]
        if state is not None and not isinstance(state, State):
            raise InputError(f"system: state = {state!r}: must be a prebo.State")
        self.state = state if state is not None else State(**state_kw)
        self.groups = self._groups()
        if symmetriser is not None:
            self._check_operator(symmetriser)
        # an explicit Young operator (e.g. an ecgpack file's), else the spin state's
        self._symmetriser = symmetriser

    # --- identical particles -------------------------------------------------
    def _groups(self) -> list[Group]:
        by_name: dict[str, list[int]] = {}
        for i, p in enumerate(self.particles):
            by_name.setdefault(p.name, []).append(i)
        unknown = set(self.state.spin) - set(by_name)
        if unknown:
            raise InputError(f"state.spin names particles not in the system: {sorted(unknown)}")
        groups = []
        for name, idx in by_name.items():
            first = self.particles[idx[0]]
            if any(self.particles[i] != first for i in idx):
                raise InputError(f"particles named {name!r} differ in mass, charge or spin; give them distinct names")
            if len(idx) == 1:
                if name in self.state.spin and half_integer(self.state.spin[name], name) != first.spin:
                    raise InputError(f"a single {name!r} has spin {first.spin}, not {self.state.spin[name]}")
                continue
            if name in self.state.spin:
                S = half_integer(self.state.spin[name], name)
            else:  # lowest total spin: singlet / doublet / para
                S = lowest_total_spin(first.spin, len(idx))
            coupling_path(first.spin, len(idx), S)  # raises SpinError if impossible
            groups.append(Group(name, tuple(idx), first.spin, S))
        return groups

    @property
    def symmetriser(self) -> Symmetriser:
        if self._symmetriser is not None:
            return self._symmetriser
        return Symmetriser.from_groups(self.n, self.groups)

    def _check_operator(self, sym: Symmetriser) -> None:
        """An explicit operator may only permute identical particles and must contain the identity."""
        identity = tuple(range(self.n))
        if identity not in sym.permutations:
            raise InputError("symmetry operator: the identity permutation is missing")
        for p in sym.permutations:
            if len(p) != self.n or sorted(p) != list(identity) or any(
                    self.particles[i].name != self.particles[p[i]].name for i in range(self.n)):
                raise InputError(f"symmetry operator: {list(p)} permutes particles that are not identical")

    # --- masses and charges --------------------------------------------------
    @property
    def n(self) -> int:
        return len(self.particles)

    @property
    def masses(self) -> np.ndarray:
        return np.array([p.mass for p in self.particles])

    @property
    def charges(self) -> np.ndarray:
        return np.array([p.charge for p in self.particles])

    @property
    def m_total(self) -> float:
        return float(self.masses.sum())

    @property
    def M(self) -> np.ndarray:
        """Kinetic mass matrix M = diag(1/(2 m_i)) of paper eq. nonrel-H."""
        return np.diag(1.0 / (2.0 * self.masses))

    @property
    def M_internal(self) -> np.ndarray:
        """M - 1 1^T / (2 m_tot): the kinetic operator with the CM kinetic energy removed exactly."""
        return self.M - np.ones((self.n, self.n)) / (2.0 * self.m_total)

    @property
    def cm_vector(self) -> np.ndarray:
        """m / m_tot: the last row of every U_x (paper eq. Uconstraint2)."""
        return self.masses / self.m_total

    def coulomb_pairs(self) -> tuple[np.ndarray, np.ndarray]:
        """LFCC vectors w = e_i - e_j and charge products q_i q_j of every interacting pair."""
        w, q = [], []
        for i in range(self.n):
            for j in range(i + 1, self.n):
                qq = self.particles[i].charge * self.particles[j].charge
                if qq != 0.0:
                    e = np.zeros(self.n)
                    e[i], e[j] = 1.0, -1.0
                    w.append(e)
                    q.append(qq)
        return np.array(w).reshape(len(q), self.n), np.array(q)

    # --- I/O -----------------------------------------------------------------
    def to_dict(self) -> dict:
        return {
            "particles": [p.to_dict() for p in self.particles],
            "state": {"N": self.state.N, "parity": self.state.parity,
                      "spin": {g.name: float(g.total_spin) for g in self.groups}},
        }

    @classmethod
    def from_dict(cls, d: dict, symmetry: dict | None = None) -> "System":
        """The system of `to_dict`; `symmetry` (`Symmetriser.as_dict`) is honoured when it is not
        the spin state's own operator (an explicit Young operator, e.g. imported from ecgpack)."""
        if not isinstance(d, dict) or "particles" not in d:
            raise InputError("system: missing 'particles'")
        if not isinstance(d.get("state", {}), dict):
            raise InputError(f"state = {d['state']!r}: must be a table of N, parity and spin")
        st = dict(d.get("state", {}))
        unknown = set(st) - {"N", "parity", "spin"}
        if unknown:
            raise InputError(f"state: unknown keys {sorted(unknown)}")
        system = cls(d["particles"], State(**st))
        if symmetry is not None:
            stored = Symmetriser.from_dict(symmetry)
            if not stored.equivalent(system.symmetriser):
                system = cls(system.particles, system.state, symmetriser=stored)
        return system

    def label(self) -> str:
        return " ".join(p.name for p in self.particles)

    def __repr__(self) -> str:
        return f"System({self.label()!r}, {self.state})"
