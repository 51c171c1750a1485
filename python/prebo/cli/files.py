"""The files a command writes: an output file that replaces
no input nor anything but a regular file, and an earlier one only with `--force` (`output_file`), and
a run's folder (`claim`)."""
from __future__ import annotations

import os
from pathlib import Path

from ..errors import OutputError
from ..validation import path_name

RESULT = "result.json"


def claim(out: Path, force: bool) -> None:
    """Make the folder `out` a new run's: OutputError if it holds an earlier run's checkpoint,
    lowest state or result, unless `force`, which removes them (the new run writes its own), and
    if one of their names is anything but a regular file (`files.replaceable`)."""
    from ..io.files import replaceable
    from ..optimise.checkpoint import CHECKPOINT, LOWEST

    earlier = [out / name for name in (CHECKPOINT, LOWEST, RESULT) if os.path.lexists(out / name)]
    for path in earlier:
        replaceable(path)
    if earlier and not force:
        if earlier[0].name == RESULT:
            raise OutputError(f"{out}: the output folder holds a run's result ({RESULT}): give another --out, "
                              "or --force to replace it")
        raise OutputError(f"{out}: the output folder holds a run's checkpoint ({earlier[0].name}): continue that run "
                          f"with `prebo run --resume {out}`, or give another --out (or --force to start over)")
    for path in earlier:
        path.unlink()


def given(out: str | None, default: Path, what: str) -> Path:
    """The path of --out `out` (None: not given, `default`); InputError for an empty one."""
    return default if out is None else Path(path_name(out, "--out", what))


def output_file(path: Path, force: bool, inputs=()) -> Path:
    """`path`, the file a command is to write; OutputError for a folder, for one of the files
    `inputs` (through a symbolic or hard link too), for anything but a regular file (a device, a
    FIFO: `files.replaceable`) and, unless `force`, for an existing file."""
    from ..io.files import replaceable

    if path.is_dir():
        raise OutputError(f"{path}: cannot write (a folder, not a file)")
    if os.path.lexists(path):
        source = next((source for source in inputs if same_file(path, source)), None)
        if source is not None:
            raise OutputError(f"{path}: the input file {source} itself (an output never replaces its input): "
                              "give another --out")
        replaceable(path)
        if not force:
            raise OutputError(f"{path}: the file exists: give --force to replace it, or another --out")
    return path


def same_file(a, b) -> bool:
    """Whether the paths `a` and `b` name one file (through symbolic or hard links too)."""
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


