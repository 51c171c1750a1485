"""The standard output and error of a command: a `Stream` whose failure (closed, full, a pipe whose
reader has gone) breaks nothing else, and the exit status once both are flushed (`written`)."""
from __future__ import annotations

import errno
import io
import os
import sys

from ..errors import OutputError


class Stream:
    """A standard output or error whose failure breaks nothing else: the first error writing it
    (closed, full, a pipe whose reader has gone) is kept in `failed`, and its descriptor is
    pointed at /dev/null, where later writes — a progress display, the flush at exit — go. A run
    goes on and writes its result; `check` then ends the command."""

    def __init__(self, stream: io.TextIOBase):
        self.stream, self.failed, self.reported = stream, None, False

    def write(self, text: str) -> int:
        try:
            return self.stream.write(text)
        except OSError as exc:
            self.fail(exc)
            return len(text)

    def flush(self) -> None:
        try:
            self.stream.flush()
        except OSError as exc:
            self.fail(exc)

    def check(self) -> None:
        """Flush; OutputError saying why, once, if the stream could not be written."""
        self.flush()
        if self.failed and not self.reported:
            self.reported = True
            raise OutputError(failure(self.failed))

    def fail(self, exc: OSError) -> None:
        """Keep the first error `exc`; point the descriptor at /dev/null."""
        self.failed = self.failed or exc
        null = os.open(os.devnull, os.O_WRONLY)
        os.dup2(null, self.stream.fileno())
        os.close(null)

    def __getattr__(self, name):
        return getattr(self.stream, name)


def standard_streams() -> tuple[Stream, Stream]:
    """sys.stdout and sys.stderr as `Stream`s. A standard descriptor closed when prebo started is
    first pointed at /dev/null opened for reading: writing it fails as writing a closed one does,
    and no file prebo opens takes its number."""
    for fd in (0, 1, 2):
        try:
            os.fstat(fd)
        except OSError:
            os.open(os.devnull, os.O_RDONLY)  # the lowest free descriptor: fd
    return tuple(Stream(stream or open(fd, "w", closefd=False))
                 for stream, fd in ((sys.stdout, 1), (sys.stderr, 2)))


def failure(exc: OSError) -> str:
    """What the error `exc` writing the standard output says of it."""
    return {errno.EBADF: "standard output was closed",
            errno.EPIPE: "standard output was closed by the command reading it"}.get(
        exc.errno, f"standard output cannot be written ({exc.strerror or exc})")


def written(status: int, out: Stream, err: Stream) -> int:
    """The exit status `status` of a command whose output streams are `out` and `err`, once they
    are flushed: 2 if either failed (with one line on `err` for `out`, unless said already)."""
    try:
        out.check()
    except OutputError as exc:
        print(f"prebo: error: {exc}", file=err)
    err.flush()
    return 2 if out.failed or err.failed else status
