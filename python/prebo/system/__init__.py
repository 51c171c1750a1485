"""The physical system: particles, the state sought and its permutational symmetry.

`particles` (names, CODATA masses), `system` (`System`, `State`) and `symmetry` (spin-projected
operators, `Symmetriser`).
"""
from .particles import KNOWN, Particle, particle
from .symmetry import Group, Symmetriser
from .system import State, System

__all__ = ["KNOWN", "Particle", "particle", "Group", "Symmetriser", "State", "System"]
