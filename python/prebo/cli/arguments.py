"""The command line's parser (`Parser`: argparse with one-line errors) and the types of its values."""
from __future__ import annotations

import argparse
import math


class Parser(argparse.ArgumentParser):
    """argparse with the one-line errors of every other failure (exit 2)."""

    def error(self, message):
        """Exit 2 with one line naming the subcommand (if any) and its --help."""
        command = self.prog.removeprefix("prebo").strip()
        self.exit(2, f"prebo: error: {command + ': ' if command else ''}{message} (see {self.prog} --help)\n")


def finite(text: str) -> float:
    """A command line's number: finite (no NaN, no infinity)."""
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text!r} is not a finite number")
    return value


def within(text: str, lo: float, hi: float, what: str) -> float:
    """A command line's number in the open interval (lo, hi), else an error calling it not `what`."""
    try:
        value = finite(text)
    except argparse.ArgumentTypeError:
        value = lo
    if not lo < value < hi:
        raise argparse.ArgumentTypeError(f"{text!r} is not {what}")
    return value


def seconds(text: str) -> float:
    """A command line's wall time: a finite number of seconds above 0."""
    return within(text, 0.0, math.inf, "a number of seconds above 0")


def fraction(text: str) -> float:
    """A command line's threshold: a number strictly between 0 and 1."""
    return within(text, 0.0, 1.0, "a number between 0 and 1")


def distance(text: str) -> float:
    """A command line's distance: a finite number > 0."""
    value = finite(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"{text!r} is not a distance > 0")
    return value


def natural(text: str) -> int:
    """A command line's index: an integer ≥ 0."""
    if not (text.isascii() and text.isdigit()):
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer ≥ 0")
    return int(text)


def positive_integer(text: str) -> int:
    """A command line's count: an integer ≥ 1."""
    if not (text.isascii() and text.isdigit() and int(text) >= 1):
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer ≥ 1")
    return int(text)
