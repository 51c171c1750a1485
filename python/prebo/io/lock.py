"""A run folder's advisory lock: the file FOLDER/.lock, held (fcntl.flock, exclusive; on Windows
msvcrt.locking of one byte past the owner's id) by the one process whose run owns the folder and
removed when the run ends. The system drops the lock with the process however it ends (an
exception, a signal, a kill), so a stale .lock owns nothing.

`owned` creates the folder if it is missing, and removes what it created if the run left it
empty: a refused run leaves no trace. A run nested in one that owns the folder (the CLI's run
around `prebo.optimise`, `resume_from` around it) holds it already.
"""
from __future__ import annotations

import errno
import os
import stat
import threading
from contextlib import contextmanager
from pathlib import Path

from ..errors import OutputError
from .files import KINDS

try:
    import fcntl
except ImportError:  # Windows
    fcntl = None
    import msvcrt

LOCK = ".lock"
_BYTE = 1 << 20  # Windows: the locked byte, past the id a second run reads

_held = threading.local()  # the folders (device, inode) this thread owns


@contextmanager
def owned(folder):
    """Own `folder` for the duration of the block (created if missing; OutputError naming it when
    it cannot be created, or when another run, in this process or another, owns it)."""
    folder = Path(folder)
    created = _make(folder)
    st = os.stat(folder)
    key = (st.st_dev, st.st_ino)
    held = vars(_held).setdefault("folders", set())
    if key in held:
        yield
        return
    try:
        fd = _acquire(folder / LOCK)
    except BaseException:
        _remove_empty(created)
        raise
    held.add(key)
    try:
        yield
    finally:
        held.discard(key)
        if fcntl:
            (folder / LOCK).unlink(missing_ok=True)  # while held: whoever opened it before finds it gone (_acquire)
            os.close(fd)
        else:  # Windows removes no open file; one opened meanwhile by another run stays, unlocked or its own
            os.close(fd)
            try:
                (folder / LOCK).unlink(missing_ok=True)
            except PermissionError:
                pass
        _remove_empty(created)


def _make(folder: Path) -> list[Path]:
    """Create `folder` and its missing parents; those created, deepest first."""
    missing = [p for p in (folder, *folder.parents) if not p.exists()]
    if folder.exists() and not folder.is_dir():
        kind = KINDS.get(stat.S_IFMT(os.stat(folder).st_mode), "a file")
        raise OutputError(f"{folder}: {kind}, not a folder: a run writes into a folder of its own; give another --out")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"{folder}: cannot create the output folder ({exc.strerror})") from exc
    return missing


def _remove_empty(created: list[Path]) -> None:
    """Remove the folders `owned` created, deepest first, as long as they are empty."""
    for p in created:
        try:
            p.rmdir()
        except OSError:
            return


def _acquire(path: Path) -> int:
    """The descriptor of the lock file `path`, locked, with this process's id in it."""
    while True:
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o666)
        except OSError as exc:
            raise OutputError(f"{path.parent}: cannot lock the output folder ({exc.strerror})") from exc
        try:
            _lock(fd)
        except BlockingIOError:
            pid = os.read(fd, 32).decode(errors="replace").strip()
            os.close(fd)
            raise OutputError(f"{path.parent}: another prebo run{f' (pid {pid})' if pid else ''} owns this folder") \
                from None
        except OSError as exc:  # a file system without locks
            os.close(fd)
            raise OutputError(f"{path.parent}: cannot lock the output folder ({exc.strerror})") from exc
        try:
            if os.path.samestat(os.fstat(fd), os.stat(path)):
                break
        except FileNotFoundError:
            pass
        os.close(fd)  # locked a file its owner removed as it ended: lock the one there now
    try:
        os.ftruncate(fd, 0)
        os.write(fd, f"{os.getpid()}\n".encode())
    except OSError:
        pass  # the id only names the owner to a second run; a full disk stops the run at its first write
    return fd


def _lock(fd: int) -> None:
    """Lock the open file `fd` for this process, without waiting: BlockingIOError when another
    holds it, OSError when the file system has no locks."""
    if fcntl:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        return
    os.lseek(fd, _BYTE, os.SEEK_SET)
    try:
        msvcrt.locking(fd, msvcrt.LK_NBLCK, 1)
    except OSError as exc:  # a held region: EACCES, or EDEADLOCK
        if exc.errno in (errno.EACCES, errno.EDEADLOCK):
            raise BlockingIOError(exc.errno, exc.strerror) from None
        raise
    finally:
        os.lseek(fd, 0, os.SEEK_SET)
