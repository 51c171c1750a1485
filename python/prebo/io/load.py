"""A stored basis of either kind for the commands and inputs that read one (`load_basis`): a
basis.json or an ecgpack file told by its content (io.stored), or a run folder's basis.json
(`basis_file`)."""
from __future__ import annotations

from pathlib import Path

from ..basis import Basis
from ..eigen import THRESHOLD
from ..errors import InputError
from . import basis_json
from .ecgpack import parse_inout
from .stored import read


def load_basis(path) -> tuple:
    """A basis.json or an ecgpack file (ecgpack's own name: inout.txt), recognised by its content
    whatever its name (io.stored), and the overlap threshold of the code that wrote it: a run's
    (its "optimiser" block), else eigen.THRESHOLD (every direction double precision resolves, as
    ecgpack keeps them)."""
    if str(path).endswith(".toml"):
        raise InputError(f"{path}: a TOML input, not a basis; optimise it with `prebo run {path}`")
    what, text = read(path)
    if what == "ecgpack":
        return parse_inout(path, text).to_basis(), THRESHOLD
    d = basis_json.parse(text, path)
    basis = Basis.from_dict(d, str(path))  # d, its settings included, is checked from here on
    return basis, (d.get("optimiser") or {}).get("threshold", THRESHOLD)


def basis_file(path: str) -> str:
    """`path`, or the basis.json of the run folder `path`."""
    p = Path(path)
    return str(p / "basis.json") if p.is_dir() else path
