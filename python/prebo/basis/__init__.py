"""Basis sets: the container `Basis` and the basis families, one module each.

`family(name)` gives the family of a basis type ("pecg", "ecg-gvr", "fecg"): its parameters,
validation, sampling, θ ↔ function mapping and engine calls (prebo.basis.family.Family).
"""
from .basis import Basis
from .families import FAMILIES, family
from .family import Family

__all__ = ["Basis", "Family", "FAMILIES", "family"]

# the atomic writers for cli.py, inputs.py and ecgpack.py until they import prebo.io.basis_json
from ..io.basis_json import read_text, remove_stale_temporaries, write_atomic, write_json_atomic  # noqa: E402
