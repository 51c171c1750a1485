"""Command line: `prebo run`, `energy`, `import`, `export`, `plot`. Errors print one line and exit 2, never a traceback."""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from dataclasses import replace
from pathlib import Path

from .errors import NonFiniteError, OutputError, PreboError
from .expectation import OPERATORS


def _result(basis, where, threshold: float, coordinates: str = "lab", operators=()) -> dict:
    """The JSON-ready result of `basis` (overlap directions below `threshold` dropped, with the
    expectation values of `operators`; results.evaluate); NonFiniteError naming the keys that
    are not finite numbers, and every error prefixed with `where` (the basis file)."""
    from .results import evaluate, public

    try:
        r = public(evaluate(basis, coordinates=coordinates, operators=operators, threshold=threshold))
        flat = r | {f"{name} {pair}": v for name, values in r.get("expectation", {}).items()
                    for pair, v in values.items()}
        bad = [f"{k} = {v}" for k, v in flat.items() if isinstance(v, float) and not math.isfinite(v)]
        if bad:
            raise NonFiniteError(f"the result is not finite ({', '.join(bad)}): the basis's integrals "
                                 "overflow or lost their digits")
    except PreboError as exc:
        raise type(exc)(f"{where}: {exc}") from exc
    return r


def _print_result(r: dict) -> None:
    from rich.console import Console
    from rich.table import Table

    from .optimise.convergence import STOPPED
    from .optimise.schedule import RATIO

    t = Table(show_header=False, box=None)
    t.add_row("energy (translation-free)", f"{r['energy']:.12f} Eh")
    t.add_row("numerical uncertainty", f"{r['energy_uncertainty']:.1e} Eh")
    if r.get("energy_lab") is not None:
        t.add_row("energy (laboratory frame)", f"{r['energy_lab']:.12f} Eh")
    t.add_row("virial η_TI", f"{r['virial']:.2e}")
    for fragments, energy in r["thresholds"].items():
        t.add_row("given threshold" if fragments == "given" else "dissociation threshold",
                  f"{energy:.12f} Eh" + ("" if fragments == "given" else f" ({fragments})"))
    t.add_row("binding energy", f"{r['binding_energy']:.3e} Eh ({'bound' if r['bound'] else 'not bound'})")
    t.add_row("basis", f"{r['n_basis']} {r['basis_type']} functions")
    t.add_row("particles", " ".join(p["name"] for p in r["particles"]))
    t.add_row("overlap condition", f"{r['overlap_condition']:.2e} ({r['kept']} kept)")
    if r.get("convergence"):
        c = r["convergence"]
        t.add_row("stopped", f"{STOPPED[c['stopped']]} after {c['seconds']:.1f} s")
        if c.get("advantage") is not None and c["advantage"] > 1 / RATIO and c["stopped"] != "exhausted":
            t.add_row("basis size", f"growth was gaining {c['advantage']:.0f}× faster than the last passes: "
                      "a larger basis would gain faster")
        if c["recent"]:
            rate = c["recent"]["rate"]
            t.add_row(f"last {c['recent']['steps']} steps", f"ΔE = {-c['recent']['gain']:.2e} Eh in "
                      f"{c['recent']['seconds']:.1f} s" + (f" ({rate:.1e} Eh/s)" if rate else ""))
        if c["extrapolation"]:
            t.add_row("still to gain at this size", f"~{c['extrapolation']['remaining']:.1e} Eh (Aitken's Δ² of the "
                      "gains since growth; not the error against the exact energy)")
    for name, values in r.get("expectation", {}).items():
        op = OPERATORS[name]
        for pair, value in values.items():
            t.add_row(f"{name} {pair}", f"{value:.10g} {op.unit}")
    Console().print(t)


def _warn_if_unbound(r: dict) -> None:
    """One line on stderr when the energy is not below the lowest dissociation threshold (`results`),
    after the result (a closed output pipe shows before it)."""
    sys.stdout.flush()
    if not r["bound"]:
        print(f"prebo: warning: E = {r['energy']:.12g} Eh is not below the dissociation threshold "
              f"{r['threshold']:.12g} Eh ({r['threshold_fragments']}): the state is not bound in this basis "
              "(a small virial coefficient is no evidence of binding)", file=sys.stderr)


def cmd_run(args) -> int:
    """`prebo run INPUT [--out DIR]` or `prebo run --resume DIR`, either with `--budget SECONDS` (the
    wall time of the whole run, resumed parts included, in place of the input's or checkpoint's):
    optimise, then write DIR/result.json (`_result`, energies in Eh) of the lowest state at the
    size the run passed through, beside the checkpoint DIR/basis.json (and DIR/lowest.json if
    the run stands above that state); warn when the state is not bound in the basis. A new run
    refuses a DIR that holds a checkpoint (OutputError). Returns the exit status 0."""
    from .io.basis_json import write_json_atomic
    from .errors import InputError, StalledError
    from .io import toml
    from .optimise import optimise, resume_from
    from .optimise.checkpoint import CHECKPOINT, LOWEST, checkpoint_in

    t0 = time.perf_counter()
    if args.resume and (args.input is not None or args.out is not None):
        raise InputError(f"--resume {args.resume}: give no input file or --out with it (a resumed run keeps its "
                         "checkpoint's system, settings and folder; --budget changes its budget)")
    if args.resume:
        out = Path(args.resume)
        title, source = None, str(out / "basis.json")
    else:
        if args.input is None:
            raise InputError("give an input file, or --resume DIR")
        job = toml.load(args.input)
        out = Path(args.out or Path("runs") / Path(args.input).stem)
        title, source = job.title, str(args.input)
        held = checkpoint_in(out)
        if held:
            raise OutputError(f"{out}: the output folder holds a run's checkpoint ({held.name}): continue that run "
                              f"with `prebo run --resume {out}`, or give another --out")
        try:
            out.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise OutputError(f"--out {out}: cannot create the output folder ({exc.strerror})") from exc
    try:
        if args.resume:
            basis, opts = resume_from(out, progress=not args.quiet, budget=args.budget)
        else:
            opts = job.optimiser if args.budget is None else replace(job.optimiser, budget=args.budget)
            basis = optimise(job.system, opts, out=out, progress=not args.quiet)
    except StalledError as exc:  # the settings to change are in the input (or the checkpoint)
        raise StalledError(f"{source}: {exc}") from exc
    title = title or basis.system.label()
    where = out / LOWEST if (out / LOWEST).exists() else out / CHECKPOINT  # the file of the state returned
    r = _result(basis, where, opts.threshold)  # the energy the run optimised
    r |= {"title": title, "wall_seconds": time.perf_counter() - t0, "input": source,
          "convergence": basis.convergence}
    write_json_atomic(out / "result.json", r)
    if not args.quiet:
        _print_result(r)
        print(f"wrote {out / 'result.json'} ({where.name}: the lowest state at the size; "
              f"{CHECKPOINT}: where the run stands)" if where.name == LOWEST else
              f"wrote {out / 'result.json'} and {out / CHECKPOINT}")
    _warn_if_unbound(r)
    if basis.convergence["stalled"]:
        print(f"prebo: warning: growth stalled short of the basis size: {basis.convergence['stalled']['why']}",
              file=sys.stderr)
    return 0


def cmd_import(args) -> int:
    """`prebo import FILE.inout.txt [--out X.json] [--c-A C]`: an ecgpack basis as basis.json."""
    from .eigen import RESOLVED
    from .io.ecgpack import read_inout
    from .optimise.settings import check

    basis = read_inout(args.file, c_A=check("c_A", args.c_A, "--c-A"))
    out = Path(args.out or str(args.file).removesuffix(".txt").removesuffix(".inout") + ".json")
    basis.save(out, {"optimiser": {"threshold": RESOLVED}})  # evaluated as ecgpack solves it (load_basis)
    print(f"wrote {out} ({len(basis)} {basis.family.name} functions, {basis.system.label()})")
    return 0


def cmd_export(args) -> int:
    """`prebo export BASIS.json --format ecgpack [--out FILE]`: a plain-ECG basis as an ecgpack file."""
    from .io.ecgpack import write_inout

    basis, _ = load_basis(args.basis)
    out = Path(args.out or str(args.basis).removesuffix(".json") + ".inout.txt")
    write_inout(basis, out)
    print(f"wrote {out}")
    return 0


def cmd_plot(args) -> int:
    """`prebo plot RUN... [--reference E] [--since S] [--log-time] [--out PNG]`: convergence plot of run
    checkpoints."""
    from .plot import convergence

    png = args.out or Path(args.runs[0]) / "convergence.png"
    png = png if png.suffix else png.with_suffix(".png")
    try:
        convergence(args.runs, png, args.reference, args.since, args.log_time)
    except OSError as exc:
        raise OutputError(f"{png}: cannot write ({exc.strerror})") from exc
    print(f"wrote {png}")
    return 0


def load_basis(path) -> tuple:
    """A basis.json, or an ecgpack ``*.inout.txt`` (recognised by its name), and the overlap
    threshold of the code that wrote it: a run's (its "optimiser" block), eigen.RESOLVED for an
    ecgpack file or its import (ecgpack keeps every direction), eigen.THRESHOLD for a basis saved
    without settings."""
    from .eigen import RESOLVED, THRESHOLD
    from .errors import InputError
    from .io import basis_json

    if str(path).endswith(".inout.txt"):
        from .io.ecgpack import read_inout
        return read_inout(path), RESOLVED
    if str(path).endswith(".toml"):
        raise InputError(f"{path}: a TOML input, not a basis; optimise it with `prebo run {path}`")
    d = basis_json.read(path)
    basis = basis_json.from_dict(d, str(path))  # d is a checked mapping from here on
    block = d.get("optimiser")
    threshold = block.get("threshold") if isinstance(block, dict) else None
    return basis, threshold if isinstance(threshold, float) and 0.0 < threshold < 1.0 else THRESHOLD


def cmd_energy(args) -> int:
    """`prebo energy BASIS [--coordinates lab|ti] [--operator NAME ...] [--threshold T] [--json]`:
    re-evaluate a stored basis (Eh), with the expectation values of registered operators; a warning
    on stderr (exit status 0) when the state is not bound in the basis."""
    basis, stored = load_basis(args.basis)
    r = _result(basis, args.basis, args.threshold or stored, args.coordinates, args.operator)
    if args.json:
        print(json.dumps(r, allow_nan=False))
    else:
        _print_result(r)
    _warn_if_unbound(r)
    return 0


class Parser(argparse.ArgumentParser):
    """argparse with the one-line errors of every other failure (exit 2)."""

    def error(self, message):
        """Exit 2 with one line naming the subcommand and its --help."""
        self.exit(2, f"prebo: error: {self.prog}: {message} (see {self.prog} --help)\n")


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


def parser() -> argparse.ArgumentParser:
    """The `prebo` argument parser with its five subcommands."""
    p = Parser(prog="prebo", description="pre-Born–Oppenheimer ECG solver")
    sub = p.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="optimise a basis for the system of a TOML input")
    run.add_argument("input", nargs="?", help="TOML input file")
    run.add_argument("--out", help="output folder (default runs/INPUT-STEM); one that holds a run's checkpoint "
                                   "is refused (--resume it)")
    run.add_argument("--resume", metavar="DIR", help="continue the run whose checkpoint is DIR/basis.json")
    run.add_argument("--budget", type=seconds, metavar="SECONDS",
                     help="wall-time budget of the whole run, resumed parts included; replaces [optimiser] "
                          "budget, or the checkpoint's with --resume (a run stopped by its budget goes on)")
    run.add_argument("--quiet", action="store_true", help="no progress display")
    run.set_defaults(func=cmd_run)
    en = sub.add_parser("energy", help="re-evaluate a stored basis")
    en.add_argument("basis", help="basis.json, or an ecgpack FILE.inout.txt")
    en.add_argument("--coordinates", choices=["lab", "ti"], default="lab",
                    help="lab: LFCC with CM elimination (default); ti: translationally invariant (shared c_A only)")
    en.add_argument("--operator", action="append", default=[], choices=list(OPERATORS),
                    help="add the expectation value of a registered operator, per class of equivalent "
                         "particle pairs (repeatable): " + "; ".join(f"{k}: {op.meaning} ({op.unit})"
                                                                     for k, op in OPERATORS.items()))
    en.add_argument("--threshold", type=fraction, metavar="T",
                    help="relative overlap eigenvalue below which directions are dropped (default: the "
                         "threshold of the run that wrote the file; 2^-53, every direction, for an ecgpack "
                         "file or its import, as ecgpack solves it; else 1e-13)")
    en.add_argument("--json", action="store_true", help="print one JSON object")
    en.set_defaults(func=cmd_energy)
    im = sub.add_parser("import", help="convert an ecgpack / ATOM-MOL-nonBO FILE.inout.txt to basis.json")
    im.add_argument("file", help="ecgpack FILE.inout.txt (RG_0S: real plain ECGs)")
    im.add_argument("--out", help="basis.json to write (default FILE.json)")
    im.add_argument("--c-A", dest="c_A", type=float, default=1.0, help="CM exponent c_A of the LFCC functions")
    im.set_defaults(func=cmd_import)
    ex = sub.add_parser("export", help="write a plain-ECG basis in another code's format")
    ex.add_argument("basis", help="basis.json")
    ex.add_argument("--format", choices=["ecgpack"], required=True)
    ex.add_argument("--out", help="file to write (default BASIS.inout.txt)")
    ex.set_defaults(func=cmd_export)
    pl = sub.add_parser("plot", help="energy against basis size of one or more runs (PNG)")
    pl.add_argument("runs", nargs="+", type=Path, help="run folders (with basis.json checkpoints)")
    pl.add_argument("--reference", type=finite, help="exact energy: plot E - E_ref on a log axis")
    pl.add_argument("--since", type=finite, metavar="SECONDS",
                    help="only the wall time from then on, against time (runs branched from one checkpoint)")
    pl.add_argument("--log-time", action="store_true", help="wall time on a logarithmic axis (runs of minutes and days)")
    pl.add_argument("--out", type=Path, help="image file, .png (the default suffix), .pdf or .svg "
                                              "(default FIRST-RUN/convergence.png)")
    pl.set_defaults(func=cmd_plot)
    return p


def main(argv=None) -> int:
    """The `prebo` command (`argv`: its arguments, default sys.argv[1:]). Returns the exit status:
    0, 2 for every error (one line on stderr, never a traceback), 130 when interrupted."""
    args = parser().parse_args(argv)
    try:
        status = args.func(args)
        sys.stdout.flush()  # a closed pipe shows here, not at exit
        return status
    except PreboError as exc:
        print("prebo: error: " + " ".join(str(exc).split("\n")), file=sys.stderr)  # one line, always
        return 2
    except BrokenPipeError:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # nothing more to flush at exit
        print("prebo: error: standard output was closed before the result was written", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("prebo: interrupted (the last accepted step is saved)", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
