"""The physical system: particles, the state sought and its permutational symmetry.

`particles` (names, CODATA masses), `system` (`System`, `State`), `symmetry` (spin-projected
operators, `Symmetriser`), `permutations` (the group algebra) and `young` (Young strings,
``(1+P23)(1-P24)``, as ecgpack writes symmetry operators).
"""
from .particles import KNOWN, Particle, particle, reduced_mass
from .symmetry import Group, Symmetriser
from .system import State, System

__all__ = ["KNOWN", "Particle", "particle", "reduced_mass", "Group", "Symmetriser", "State", "System"]
