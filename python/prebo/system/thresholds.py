"""The lowest dissociation threshold of a system: hydrogen-like fragments plus free particles.

A state is bound only if its energy lies below the bottom of the continuum, the lowest energy the
particles reach when they separate into fragments infinitely far apart (HVZ theorem). For a fragment
of two particles of opposite charge — a hydrogen-like ion, positronium, a muonic atom — that energy
is exact: with its centre-of-mass motion separated, the two-body Coulomb problem has the
ground-state energy −μ_ij (q_i q_j)² / 2 (Eh; μ_ij = m_i m_j / (m_i + m_j) in m_e; Bethe & Salpeter,
Quantum Mechanics of One- and Two-Electron Atoms (1957), ch. I). Fragments infinitely far apart do not
interact and free particles at rest have energy 0, so a partition of the particles into disjoint
attractive pairs (a matching) and free particles has the sum of its pairs' energies; `hydrogen_like`
takes the lowest over every matching, or 0 (all particles free) when no pair attracts and for two
particles, whose only "fragment" is the system itself. E.g. H⁻: H + e, −μ_pe/2; He: He⁺ + e, −2μ;
H₂: H + H; Ps⁻: Ps + e, −1/4; Ps₂: Ps + Ps, −1/2; Li: Li²⁺ + e + e, −9μ/2.

Caveats. Real thresholds can be lower: fragments of three or more particles are not counted (Li⁺ + e
lies far below Li²⁺ + e + e, He + e below He⁺ + e + e for He⁻), so the user may give a lower one (≤ 0:
`[state] threshold`, `State(threshold=...)`) and `lowest` takes the lower of the two. Where such a
fragment could bind (it has an attracting pair) and no threshold is given, `hydrogen_like` names one
(`Threshold.unchecked`, e.g. "alpha-e-e + e"), and the reports qualify "bound" by it. prebo builds
natural-parity states (parity (−1)^N), and a ground-state fragment plus a free particle in the partial wave l = N has that
N and parity whatever the exchange symmetry (the free particle is in no bound orbital), so such a
channel is always open. Two identical fragments and no free particle (H + H, Ps + Ps) are different:
exchange symmetry can forbid their relative partial wave l = N (H + H for ortho-H₂ with N = 0, whose
rotational levels have odd N); their threshold is then below the state's own, and a state reported
unbound may be bound.
"""
from __future__ import annotations

from dataclasses import dataclass

from .particles import Particle, reduced_mass
from .system import System


@dataclass(frozen=True)
class Threshold:
    """A dissociation threshold: its `energy` (Eh) and `fragments`, a label of the fragments and free
    particles ("p-e + e", "p-e + p-e"; "given" for the user's threshold); `unchecked` labels a
    break-up into a fragment of three or more particles that could lie lower and was not computed
    (None: every fragment that can bind was counted, or the threshold was given)."""

    energy: float
    fragments: str
    unchecked: str | None = None


def pair_energy(a: Particle, b: Particle) -> float:
    """−μ (q_a q_b)² / 2 (Eh): the ground-state energy of two attracting particles (q_a q_b < 0) with
    their centre-of-mass motion separated, μ = m_a m_b / (m_a + m_b)."""
    return -0.5 * reduced_mass(a.mass, b.mass) * (a.charge * b.charge) ** 2


def hydrogen_like(system: System) -> Threshold:
    """The lowest threshold of `system` into hydrogen-like fragments (disjoint attracting pairs in
    their ground states) and free particles: the minimum over every matching (module docstring),
    0 with every particle free for two particles or when no pair attracts."""
    ps = system.particles

    def best(left: tuple) -> tuple[float, list]:
        """The lowest energy of the particles `left` and its pairs: the first stays free or pairs."""
        if not left:
            return 0.0, []
        i, rest = left[0], left[1:]
        found = best(rest)
        for k, j in enumerate(rest):
            if ps[i].charge * ps[j].charge < 0:
                energy, pairs = best(rest[:k] + rest[k + 1:])
                if energy + pair_energy(ps[i], ps[j]) < found[0]:
                    found = energy + pair_energy(ps[i], ps[j]), [(i, j), *pairs]
        return found

    energy, pairs = best(tuple(range(system.n))) if system.n > 2 else (0.0, [])
    paired = {k for pair in pairs for k in pair}
    parts = [f"{ps[i].name}-{ps[j].name}" for i, j in pairs] + [p.name for k, p in enumerate(ps) if k not in paired]
    return Threshold(energy, " + ".join(parts), unchecked(system))


def unchecked(system: System) -> str | None:
    """A break-up `hydrogen_like` does not count: the system less one particle (the lightest that
    leaves an attracting pair behind), a fragment of three or more particles that may bind, plus that
    particle free ("alpha-e-e + e" for He⁻); None for three particles or fewer, or where no fragment of
    three or more particles has an attracting pair."""
    ps = system.particles
    if system.n < 4:
        return None
    for k in sorted(range(system.n), key=lambda k: ps[k].mass):
        rest = [p for i, p in enumerate(ps) if i != k]
        if any(a.charge * b.charge < 0 for i, a in enumerate(rest) for b in rest[i + 1:]):
            return "-".join(p.name for p in rest) + f" + {ps[k].name}"
    return None


def candidates(system: System) -> list[Threshold]:
    """`hydrogen_like(system)`, and the threshold the state gives (fragments "given") if it gives one."""
    given = system.state.threshold
    return [hydrogen_like(system)] + ([Threshold(given, "given")] if given is not None else [])


def lowest(system: System) -> Threshold:
    """The lowest of the `candidates`: the threshold below which a state of `system` is bound."""
    return min(candidates(system), key=lambda t: t.energy)
