"""A stored basis file told by its content whatever its name: a basis.json (`basis_json`: a JSON
object, its opening brace first) or an ecgpack file (`ecgpack`: a line of its header first;
ecgpack's own name for it is inout.txt). The file is opened and read once, its first PREFIX bytes
deciding what it is before the rest is read: a FIFO is not consumed twice, and a device such as
/dev/zero is refused at once rather than read to MAX_BYTES. The loaders (prebo.io.load.load_basis:
either kind; prebo.Basis.load, ecgpack.read_inout: their own) read through `read`.
"""
from __future__ import annotations

from pathlib import Path

from ..errors import BasisFileError
from . import basis_json

#: the bytes read to tell a basis.json from an ecgpack file
PREFIX = 4096
#: the keywords of an ecgpack file's header, one of which starts it (BASIS_TYPE, as ecgpack writes it)
HEADER = (b"BASIS_TYPE", b"PARTICLES", b"MASSES", b"CHARGES", b"SYMMETRY", b"BASIS_SIZE")
#: what a basis file's name ends with, by kind (derived names replace it: `stem`)
SUFFIXES = (".json", ".inout.txt", ".txt", ".inout")


def kind(head: bytes) -> str | None:
    """"json" or "ecgpack" by the start `head` of a file (its first line that is not blank opens
    a JSON object, or is a line of an ecgpack header), else None."""
    head = head.lstrip()
    if head.startswith(b"{"):
        return "json"
    words = head.split(b"\n", 1)[0].split()
    return "ecgpack" if words and words[0].upper() in HEADER else None


def read(path) -> tuple[str, str]:
    """The kind (`kind`) and text of basis file `path`, read once (at most MAX_BYTES); BasisFileError
    naming the file if it is unreadable, too large, not text, or neither a basis.json nor an
    ecgpack file."""
    path = Path(path)
    try:
        with open(path, "rb") as f:
            head = f.read(PREFIX)
            what = kind(head)
            if what is None:
                raise BasisFileError(f"{path}: neither a basis.json (a JSON object) nor an ecgpack file (a header "
                                     "line, BASIS_TYPE, first)")
            data = head + f.read(basis_json.MAX_BYTES + 1 - len(head))
    except OSError as exc:
        raise BasisFileError(f"{path}: cannot read ({exc.strerror})") from exc
    return what, basis_json.decoded(data, path, BasisFileError)


def stem(path) -> str:
    """`path` without its basis file's suffix (SUFFIXES): the start of the names derived from it,
    inout.txt giving inout.json, inout.densities.png."""
    name = str(path)
    return next((name.removesuffix(s) for s in SUFFIXES if name.endswith(s)), name)
