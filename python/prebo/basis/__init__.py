"""Basis sets: the container `Basis` and the basis families, one module each.

`family(name)` gives the family of a basis type ("pecg", "ecg-gvr", "fecg"): its parameters,
validation, sampling, θ ↔ function mapping and engine calls (prebo.basis.family.Family).
"""
from .basis import Basis
from .families import FAMILIES, family
from .family import Family

__all__ = ["Basis", "Family", "FAMILIES", "family"]
