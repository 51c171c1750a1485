"""Atomic file writes: a killed writer leaves the old file or the new one, never half of one
(basis.json and its checkpoints, lowest.json, result.json, ecgpack files, plots, CSV tables).
Only a regular file is ever replaced: a device, a FIFO, a socket or a folder at an output's
path is refused (`replaceable`), since renaming a file over it would destroy it."""
from __future__ import annotations

import json
import os
import stat
import tempfile
from glob import escape as glob_escape
from pathlib import Path

from ..errors import OutputError


#: what each kind of file that is not a regular one is called in a refusal (`replaceable`)
KINDS = {stat.S_IFDIR: "a folder", stat.S_IFCHR: "a character device", stat.S_IFBLK: "a block device",
         stat.S_IFIFO: "a FIFO (named pipe)", stat.S_IFSOCK: "a socket"}


def replaceable(path) -> Path:
    """The file an output at `path` is written into: `path`, or the file a symbolic link there
    names (the link is kept). OutputError unless that is a regular file or nothing yet."""
    path = Path(path)
    target = Path(os.path.realpath(path)) if path.is_symlink() else path
    try:
        mode = os.stat(target).st_mode
    except FileNotFoundError:
        return target
    except OSError as exc:
        raise OutputError(f"{path}: cannot write ({exc.strerror})") from exc
    if not stat.S_ISREG(mode):
        kind = KINDS.get(stat.S_IFMT(mode), "not a regular file")
        raise OutputError(f"{path}: {kind}, not a regular file: prebo replaces only regular files; give another path")
    return target


def write_atomic(path, text: str | bytes) -> None:
    """Write `text` (or bytes: an image) to a temporary file in the same folder (PATH.*.tmp), fsync,
    then os.replace: a killed writer leaves the old file or the new one, never half of one.
    OutputError naming the path if it cannot be written or is not a regular file (`replaceable`)."""
    path = Path(path)
    target = replaceable(path)
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=target.parent, prefix=target.name + ".", suffix=".tmp")
    except OSError as exc:
        raise OutputError(f"{path}: cannot write ({exc.strerror})") from exc
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)  # mkstemp's 0600 would hide results from other users
    try:
        with os.fdopen(fd, "wb" if isinstance(text, bytes) else "w") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, target)
    except BaseException as exc:
        if os.path.exists(tmp):
            os.unlink(tmp)
        if isinstance(exc, OSError):
            raise OutputError(f"{path}: cannot write ({exc.strerror})") from exc
        raise


_ENCODER = json.JSONEncoder(allow_nan=False)  # the C encoder: `indent` would select the pure-Python one


def write_json_atomic(path, obj: dict) -> None:
    """`write_atomic` of the mapping `obj` as strict JSON (ValueError on NaN or infinity, which
    JSON cannot hold): a key per line and an element per line of a list of lists, tuples (as
    lists) or mappings (the functions, the history). Compact lines keep the C encoder: a checkpoint of 500
    functions is written in 6 ms instead of the 20 ms of `indent=1`, once per step of a run."""
    def value(v):
        if isinstance(v, list) and v and isinstance(v[0], (list, tuple, dict)):
            return "[\n  " + ",\n  ".join(map(_ENCODER.encode, v)) + "\n ]"
        return _ENCODER.encode(v)

    write_atomic(path, "{\n" + ",\n".join(f" {_ENCODER.encode(k)}: {value(v)}" for k, v in obj.items()) + "\n}\n")


def remove_stale_temporaries(path) -> None:
    """Delete the temporary files a killed `write_atomic` of `path` left behind."""
    path = Path(path)
    for f in path.parent.glob(glob_escape(path.name) + ".*.tmp"):
        f.unlink(missing_ok=True)
