"""Command line: `prebo run`, `energy`, `properties`, `transitions`, `polarisability`, `import`, `export`, `plot`, a module each (its
arguments, `add`, and its body, `command`). Errors print one line and exit 2, never a traceback.

Outputs never replace inputs nor anything but a regular file (`io.files.replaceable`), and
replace earlier outputs only with `--force` (atomically; files.py); a run
owns its folder while it runs (io/lock.py). A closed or full standard output or error ends the
command with exit 2 once its work is done and its files are written (streams.py).
"""
from __future__ import annotations

import argparse
import sys

from ..errors import PreboError
from ..parallel import stop_all, world
from . import energy, export, import_, plot, polarisability, properties, run, transitions
from .arguments import Parser
from .streams import standard_streams, written

#: the subcommands, in the order `prebo --help` lists them
COMMANDS = (run, properties, energy, transitions, polarisability, import_, export, plot)


def parser() -> argparse.ArgumentParser:
    """The `prebo` argument parser with its subcommands (`COMMANDS`)."""
    from ..provenance import VERSION, commit

    p = Parser(prog="prebo", description="pre-Born–Oppenheimer ECG solver")
    p.add_argument("--version", action="version",
                   version=f"prebo {VERSION}" + (f" (commit {commit()})" if commit() else ""))
    sub = p.add_subparsers(dest="command", required=True)
    for module in COMMANDS:
        module.add(sub)
    p.commands = sub.choices  # each subcommand's parser by name
    return p


def main(argv=None) -> int:
    """The `prebo` command (`argv`: its arguments, default sys.argv[1:]). Returns the exit status:
    0, 2 for every error (one line on stderr, never a traceback) — a standard output or error
    that cannot be written too —, 130 when interrupted."""
    saved = sys.stdout, sys.stderr
    sys.stdout, sys.stderr = streams = standard_streams()
    try:
        return written(command(argv), *streams)
    except SystemExit as exc:  # argparse's --help (0) or one-line error (2)
        raise SystemExit(written(exc.code, *streams)) from None
    finally:
        sys.stdout, sys.stderr = saved


def command(argv) -> int:
    """The exit status of the command `argv` (main); SystemExit from argparse."""
    p = parser()
    args, extra = p.parse_known_args(argv)
    if extra:  # refused by the subcommand given them, which names its own --help
        p.commands[args.command].error(f"unrecognized arguments: {' '.join(extra)}")
    try:
        world()  # under MPI: the ranks' threads set before the core first runs (parallel.py)
        return args.func(args)
    except PreboError as exc:
        return stop_all(2, "prebo: error: " + " ".join(str(exc).split("\n")))  # one line, always
    except KeyboardInterrupt:
        return stop_all(130, "prebo: interrupted (the last accepted step is saved)")
