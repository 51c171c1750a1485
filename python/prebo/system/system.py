"""A Coulomb system: particles, the state sought, and the groups of identical particles.

Hartree atomic units throughout: masses in m_e, charges in e, spins and N in ħ, energies in Eh.
Equation numbers refer to Muolo, Mátyus & Reiher, J. Chem. Phys. 148, 084112 (2018).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..coordinates import mass_fractions
from ..errors import InputError, SpinError
from ..validation import MAX_PARTICLES, MAX_SIZE, Integer, Real, Sign, checked, half_integer, strict_keywords
from .particles import ALIASES, INFINITE, Particle, particle
from .symmetry import Group, Symmetriser, coupling_path, lowest_total_spin

#: N: bound few-body states have far smaller ones (H₂'s last rotational level has N = 31); the
#: ECG-GVR quadrature holds 2 K + N ≤ 1021 (crates/prebo-core/src/families/ecg_gvr/)
N_RANGE = Integer(0, 1000)
#: a targeted root index: below the largest basis (validation.MAX_SIZE)
ROOT_RANGE = Integer(0, MAX_SIZE - 1)
#: a level's weight in the objective Σ w_k E_k (optimise/objective.py)
WEIGHT_RANGE = Real(0.0, 1e6, hi_closed=True)
#: a given dissociation threshold (Eh): fragments (bound: < 0) and free particles at rest (0) lie at
#: or below 0 (prebo.system.thresholds)
THRESHOLD_RANGE = Real(-math.inf, 0.0, hi_closed=True)


@strict_keywords
@dataclass(frozen=True)
class State:
    """The quantum numbers of the state sought.

    Parameters: `N`, the total orbital angular momentum quantum number (0..1000, `N_RANGE`;
    units of ħ); `parity`, +1 or -1 (N and parity Python or numpy integers, not bools); `spin`,
    {particle name: total spin S} of each group of identical particles (0, 1/2, 1, ...); a group
    not named gets its lowest total spin (singlet, doublet, para); `threshold`, a dissociation
    threshold (Eh, ≤ 0) the user knows to lie below the hydrogen-like ones `prebo.system.thresholds`
    finds (e.g. Li⁺ + e for Li), or None; the levels the optimiser targets (optimise/objective.py):
    `root`, one eigenvalue index (0, the default: the lowest of the symmetry), or `roots`, a count
    K (the K lowest) or a list of distinct indices, with `weights` (positive, one per root; default
    1 each) for the objective Σ w_k E_k. They are kept as `roots`, a tuple of ascending indices
    (None for the lowest alone), and `weights` (None for 1 each). InputError for anything else
    (unknown keywords included).
    """

    N: int = 0
    parity: int = 1
    spin: dict = field(default_factory=dict)
    threshold: float | None = None
    root: int | None = None
    roots: int | tuple | list | None = None
    weights: tuple | list | None = None

    def __post_init__(self):
        object.__setattr__(self, "N", checked(N_RANGE, self.N, "state: N", "the total orbital angular momentum"))
        object.__setattr__(self, "parity", checked(Sign(), self.parity, "state: parity"))
        if not isinstance(self.spin, dict) or not all(isinstance(k, str) for k in self.spin):
            raise InputError(f"state: spin = {self.spin!r}: must map particle names to total spins, e.g. {{e = 0}}")
        for name, S in self.spin.items():
            half_integer(S, f"state: spin of {name!r}")
        if self.threshold is not None:
            object.__setattr__(self, "threshold", checked(THRESHOLD_RANGE, self.threshold, "state: threshold",
                                                          "Eh: fragments and free particles at rest lie at or below 0"))
        roots, weights = self._levels()
        object.__setattr__(self, "root", None)
        object.__setattr__(self, "roots", None if roots == (0,) else roots)
        object.__setattr__(self, "weights", None if len(roots) == 1 or set(weights) == {1.0} else weights)

    def _levels(self) -> tuple[tuple, tuple]:
        """The targeted root indices (ascending) and their weights, from `root`, `roots`, `weights`."""
        if self.root is not None and self.roots is not None:
            raise InputError(f"state: root = {self.root!r} and roots = {self.roots!r}: give one of them")
        if self.root is not None:
            roots = [checked(ROOT_RANGE, self.root, "state: root", "an eigenvalue index, 0 for the lowest")]
        elif self.roots is None:
            roots = [0]
        elif isinstance(self.roots, (list, tuple)):
            if not self.roots:
                raise InputError("state: roots = []: must name at least one root")
            roots = [checked(ROOT_RANGE, r, "state: roots", "distinct eigenvalue indices, 0 for the lowest")
                     for r in self.roots]
            if len(set(roots)) < len(roots):
                raise InputError(f"state: roots = {list(self.roots)!r}: must be distinct eigenvalue indices")
        else:
            count = checked(Integer(1, MAX_SIZE), self.roots, "state: roots",
                            "how many of the lowest levels, or a list of eigenvalue indices")
            roots = list(range(count))
        if self.weights is not None and self.roots is None:
            raise InputError(f"state: weights = {self.weights!r} without roots: weights weigh the levels roots "
                             "names (e.g. roots = [0, 1], weights = [1, 0.5])")
        if self.weights is None:
            weights = [1.0] * len(roots)
        elif not isinstance(self.weights, (list, tuple)):
            raise InputError(f"state: weights = {self.weights!r}: must be a list of positive numbers, one per root")
        elif len(self.weights) != len(roots):
            raise InputError(f"state: weights = {list(self.weights)!r}: {_count(len(self.weights), 'number')} for "
                             f"{_count(len(roots), 'root')}")
        else:
            weights = [checked(WEIGHT_RANGE, w, "state: weights", "one per root") for w in self.weights]
        order = sorted(range(len(roots)), key=roots.__getitem__)
        return tuple(roots[i] for i in order), tuple(weights[i] for i in order)

    @property
    def levels(self) -> tuple[tuple, tuple]:
        """The targeted root indices (ascending) and their weights in the objective."""
        return self._levels()


def _count(k: int, noun: str) -> str:
    """"1 root", "2 roots"."""
    return f"{k} {noun}{'' if k == 1 else 's'}"


class System:
    """Particles in LFCC order (the input order), the state, and the symmetry operator.

    The Hamiltonian is eq. (1), H = -∇ᵀ M ∇ + Σ_{i<j} q_i q_j / |r_i - r_j| with
    M = diag(1/(2 m_i)) (Eh; r in bohr, m in m_e, q in e). One particle may have an infinite mass
    (prebo.system.particles): M_ii = 0, m_tot = ∞ and the centre of mass on it (`cm_vector`).

    Parameters: `particles`, 2 to MAX_PARTICLES names (``"p"``, ``"e"``, see
    `prebo.system.particles.KNOWN`) or tables {name, mass, charge, spin}; `state`, a
    `State`, or its keywords (`N`, `parity`, `spin`) given directly; `symmetriser`, an
    explicit symmetry operator (e.g. an ecgpack file's Young operator) that replaces the
    spin state's own — kept only when it differs from it beyond an overall factor, so a
    system carries an explicit operator exactly when its spin state does not describe its
    symmetry, and refused unless it is one of the state (`Symmetriser.check_projector`).
    InputError (SpinError for impossible spins and operators) for anything invalid.
    """

    def __init__(self, particles, state: State | None = None, symmetriser: Symmetriser | None = None,
                 **state_kw):
        if not isinstance(particles, (list, tuple)) or not 2 <= len(particles) <= MAX_PARTICLES:
            raise InputError(f"system: particles = {particles!r}: must be a list of 2 to {MAX_PARTICLES} "
                             "particle names or tables")
        self.particles: list[Particle] = [particle(p) for p in particles]
        clamped = [p.name for p in self.particles if p.mass == math.inf]
        if len(clamped) > 1:
            raise InputError(f"system: particles {', '.join(map(repr, clamped))} have infinite masses: at most one "
                             "particle may (the centre of mass sits on it)")
        if state is not None and not isinstance(state, State):
            raise InputError(f"system: state = {state!r}: must be a prebo.State")
        self.state = state if state is not None else State(**state_kw)
        self.groups = self._groups()
        self._symmetriser = None
        if symmetriser is not None:
            self._take(symmetriser)

    # --- identical particles -------------------------------------------------
    def _groups(self) -> list[Group]:
        by_name: dict[str, list[int]] = {}
        for i, p in enumerate(self.particles):
            by_name.setdefault(p.name, []).append(i)
        unknown = set(self.state.spin) - set(by_name)
        if unknown:
            aliases = [f"{k!r} is {ALIASES[k]!r}" for k in sorted(unknown) if k in ALIASES]
            raise InputError(f"state.spin names particles not in the system: {sorted(unknown)} (its particles are "
                             f"named {list(by_name)}" + "".join(f"; {a}" for a in aliases) + ")")
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

    def spins(self) -> str:
        """The total spins of the groups of identical particles, for messages ("e: S = 1/2")."""
        return ", ".join(f"{g.name}: S = {g.total_spin}" for g in self.groups) or "no identical particles"

    @property
    def symmetriser(self) -> Symmetriser:
        """The symmetry operator: the explicit one if given, else the spin state's (`prebo.system.symmetry`)."""
        if self._symmetriser is not None:
            return self._symmetriser
        return Symmetriser.from_groups(self.n, self.groups)

    def _take(self, sym: Symmetriser, what: str = "the symmetry operator") -> None:
        """Carry the operator `sym` when it is not the spin state's own (up to a factor); SpinError
        saying `what` is not that of the state unless it contains the identity, permutes only
        identical particles and projects onto functions of the state (`Symmetriser.check_projector`)."""
        try:
            identity = tuple(range(self.n))
            if identity not in sym.permutations:
                raise SpinError("the identity permutation is missing")
            for p in sym.permutations:
                if len(p) != self.n or sorted(p) != list(identity) or any(
                        self.particles[i].name != self.particles[p[i]].name for i in range(self.n)):
                    raise SpinError(f"{list(p)} permutes particles that are not identical")
            if sym.equivalent(self.symmetriser):
                return
            sym.check_projector(self.groups)
        except SpinError as exc:
            raise SpinError(f"{what} is not that of the state ({self.spins()}): {exc}") from None
        self._symmetriser = sym

    # --- masses and charges --------------------------------------------------
    @property
    def n(self) -> int:
        """The number of particles N_p."""
        return len(self.particles)

    @property
    def masses(self) -> np.ndarray:
        """Particle masses m_i in m_e, LFCC order."""
        return np.array([p.mass for p in self.particles])

    @property
    def charges(self) -> np.ndarray:
        """Particle charges q_i in e, LFCC order."""
        return np.array([p.charge for p in self.particles])

    @property
    def m_total(self) -> float:
        """The total mass m_tot in m_e (∞ with an infinite mass)."""
        return float(self.masses.sum())

    @property
    def M(self) -> np.ndarray:
        """Kinetic mass matrix M = diag(1/(2 m_i)) of eq. (1), in 1/m_e (0 for an infinite mass)."""
        return np.diag(1.0 / (2.0 * self.masses))

    @property
    def M_internal(self) -> np.ndarray:
        """M - 1 1ᵀ / (2 m_tot) (1/m_e): the kinetic operator with the CM kinetic energy removed exactly
        (M itself with an infinite mass: the CM does not move)."""
        return self.M - np.ones((self.n, self.n)) / (2.0 * self.m_total)

    @property
    def cm_vector(self) -> np.ndarray:
        """m / m_tot: the last row of every U_x (eq. (4)); e_k for an infinite mass k
        (`prebo.coordinates.mass_fractions`)."""
        return mass_fractions(self.masses)

    def pairs(self) -> list[tuple[int, int, np.ndarray]]:
        """Every pair i < j with its LFCC vector w = e_i - e_j (r_ij = r_i - r_j = Σ_k w_k r_k)."""
        out = []
        for i in range(self.n):
            for j in range(i + 1, self.n):
                w = np.zeros(self.n)
                w[i], w[j] = 1.0, -1.0
                out.append((i, j, w))
        return out

    def coulomb_pairs(self) -> tuple[np.ndarray, np.ndarray]:
        """The Coulomb terms of eq. (1): LFCC vectors w = e_i - e_j, shape (pairs, N), and charge
        products q_i q_j (e²) of every pair i < j with q_i q_j ≠ 0."""
        terms = [(w, self.particles[i].charge * self.particles[j].charge) for i, j, w in self.pairs()]
        terms = [(w, qq) for w, qq in terms if qq != 0.0]
        return np.array([w for w, _ in terms]).reshape(len(terms), self.n), np.array([qq for _, qq in terms])

    # --- I/O -----------------------------------------------------------------
    def to_dict(self) -> dict:
        """basis.json's "system" block: the particles and the state with every group's total spin
        (and its threshold, only when one is given)."""
        state = {"N": self.state.N, "parity": self.state.parity,
                 "spin": {g.name: float(g.total_spin) for g in self.groups}}
        if self.state.threshold is not None:
            state["threshold"] = self.state.threshold
        if self.state.roots is not None:
            state["roots"] = list(self.state.roots)
        if self.state.weights is not None:
            state["weights"] = list(self.state.weights)
        return {"particles": [p.to_dict() for p in self.particles], "state": state}

    @classmethod
    def from_dict(cls, d: dict, symmetry: dict | None = None) -> "System":
        """The system of `to_dict` (a mass INFINITE read as ∞), and the operator of a
        `Symmetriser.as_dict` block `symmetry` checked against its state: the state's own (up to a
        factor and rounding), or one of the state kept explicitly (`Symmetriser.check_projector`, an ecgpack import's); InputError,
        SpinError naming what is malformed, or that the stored operator is not that of the state."""
        if not isinstance(d, dict) or "particles" not in d:
            raise InputError("system: missing 'particles'")
        unknown = set(d) - {"particles", "state"}
        if unknown:
            raise InputError(f"system: unknown keys {sorted(unknown)} (allowed: particles, state)")
        if not isinstance(d.get("state", {}), dict):
            raise InputError(f"state = {d['state']!r}: must be a table of N, parity, spin, threshold, roots and weights")
        st = dict(d.get("state", {}))
        unknown = set(st) - {"N", "parity", "spin", "threshold", "roots", "weights"}
        if unknown:
            raise InputError(f"state: unknown keys {sorted(unknown)}")
        particles = d["particles"]
        if isinstance(particles, list):  # an infinite mass is stored as INFINITE (JSON has no infinity)
            particles = [p | {"mass": math.inf} if isinstance(p, dict) and p.get("mass") == INFINITE else p
                         for p in particles]
        system = cls(particles, State(**st))
        if symmetry is not None:
            system._take(Symmetriser.from_dict(symmetry), "the stored symmetry")
        return system

    def label(self) -> str:
        """The particle names, space-separated (``"p p e e"``)."""
        return " ".join(p.name for p in self.particles)

    def __repr__(self) -> str:
        explicit = ""
        if self._symmetriser is not None:
            explicit = f", symmetry {self._symmetriser.young or 'explicit'}"
        return f"System({self.label()!r}, {self.state}{explicit})"
