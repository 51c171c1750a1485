"""Atomic file writes: a killed writer leaves the old file or the new one, never half of one
(basis.json and its checkpoints, lowest.json, result.json, ecgpack files, plots)."""
from __future__ import annotations

import json
import os
import tempfile
from glob import escape as glob_escape
from pathlib import Path

from ..errors import OutputError


def write_atomic(path, text: str | bytes) -> None:
    """Write `text` (or bytes: an image) to a temporary file in the same folder (PATH.*.tmp), fsync,
    then os.replace: a killed writer leaves the old file or the new one, never half of one.
    OutputError naming the path if it cannot be written."""
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name + ".", suffix=".tmp")
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
        os.replace(tmp, path)
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
