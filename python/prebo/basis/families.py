"""The registry of basis families, by their basis.json `basis_type` name."""
from __future__ import annotations

from ..errors import InputError
from . import ecg_gvr, fecg, pecg
from .family import Family

#: name -> family, in the order the settings list them
FAMILIES: dict[str, Family] = {f.name: f for f in (pecg.FAMILY, ecg_gvr.FAMILY, fecg.FAMILY)}


def family(name: str) -> Family:
    """The family of basis type `name` ("pecg", "ecg-gvr", "fecg"); InputError naming the known ones."""
    try:
        return FAMILIES[name]
    except (KeyError, TypeError):
        raise InputError(f"basis type {name!r} is not one of {', '.join(FAMILIES)}") from None
