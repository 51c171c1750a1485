"""Command line: `prebo run`, `energy`, `import`, `export`, `plot`. Errors print one line and exit 2, never a traceback.

Outputs never replace inputs nor anything but a regular file (`io.files.replaceable`), and
replace earlier outputs only with `--force` (atomically); a run
owns its folder while it runs (io/lock.py). A closed or full standard output or error ends the
command with exit 2 once its work is done and its files are written (`Stream`).
"""
from __future__ import annotations

import argparse
import errno
import io
import json
import math
import os
import sys
import time
from contextlib import nullcontext
from dataclasses import replace
from pathlib import Path

from .errors import NonFiniteError, OutputError, PreboError
from .expectation import OPERATORS
from .parallel import stop_all, world
from .validation import path_name

RESULT = "result.json"


def _result(basis, where, threshold: float, coordinates: str = "lab", operators=(), roots: int | None = None) -> dict:
    """The JSON-ready result of `basis` (overlap directions below `threshold` dropped, with the
    expectation values of `operators` and the lowest `roots` levels; results.evaluate);
    NonFiniteError naming the keys that are not finite numbers, and every error prefixed with
    `where` (the basis file)."""
    from .results import evaluate, public

    try:
        r = public(evaluate(basis, coordinates=coordinates, operators=operators, threshold=threshold, roots=roots))
        flat = {}
        for prefix, part in [("", r)] + [(f"level {v['root']} ", v) for v in r.get("levels", [])]:
            flat |= {prefix + k: v for k, v in part.items()}
            flat |= {f"{prefix}{name} {pair}": v for name, values in part.get("expectation", {}).items()
                     for pair, v in values.items()}
        bad = [f"{k} = {v}" for k, v in flat.items() if isinstance(v, float) and not math.isfinite(v)]
        if bad:
            raise NonFiniteError(f"the result is not finite ({', '.join(bad)}): the basis's integrals "
                                 "overflow or lost their digits")
    except PreboError as exc:
        raise type(exc)(f"{where}: {exc}") from exc
    return r


def _print_result(r: dict) -> None:
    from rich.table import Table

    from .optimise.convergence import STOPPED
    from .optimise.adaptive import RATIO

    t = Table(show_header=False, box=None)
    # the head is root 0's (results.evaluate); a basis optimised for other levels says so
    of = "" if r.get("targets", [0]) == [0] else " of root 0"
    t.add_row(f"energy{of} (translation-free)", f"{r['energy']:.12f} Eh")
    t.add_row("numerical uncertainty", f"{r['energy_uncertainty']:.1e} Eh")
    if r.get("energy_lab") is not None:
        t.add_row("energy (laboratory frame)", f"{r['energy_lab']:.12f} Eh")
    t.add_row("virial η_TI", f"{r['virial']:.2e}")
    if "n2" in r:  # floating ECGs: not angular-momentum eigenfunctions
        t.add_row(f"⟨N²⟩_TI{of}", f"{r['n2']:.3e} ħ²")
    for fragments, energy in r["thresholds"].items():
        t.add_row("given threshold" if fragments == "given" else "dissociation threshold",
                  f"{energy:.12f} Eh" + ("" if fragments == "given" else f" ({fragments})"))
    t.add_row(f"binding energy{of}", f"{r['binding_energy']:.3e} Eh ({_bound(r)})")
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
    show(t)
    if "levels" in r:
        _print_levels(r)


#: what rich puts where it shortens a cell that does not fit the console (`show`)
ELLIPSIS = "…"


def show(table) -> None:
    """Print the rich `table` on standard output with every cell whole: framed if it fits the
    console's width (rich's, the terminal's or COLUMNS; 80 in a pipe or a log), else without its
    frame, else as plain lines (`lines`) — never a number shortened to "-0.597139061…", rich's
    way with a column the width cannot hold."""
    from rich.console import Console

    console = Console()
    for form in (table, replace_box(table)):
        with console.capture() as captured:
            console.print(form)
        if ELLIPSIS not in captured.get():
            console.print(form)
            return
    print("\n".join(lines(table)))


def replace_box(table):
    """`table` without its frame (a copy)."""
    from copy import copy

    frameless = copy(table)
    frameless.box, frameless.show_edge = None, False
    return frameless


def lines(table) -> list[str]:
    """The rich `table` as plain text (`show`): its title, a line per row ("header value" per
    non-empty cell, or the cells of a table without headers), its caption."""
    columns = list(table.columns)
    rows = zip(*(column.cells for column in columns))
    text = [str(table.title)] if table.title else []
    for row in rows:
        if table.show_header:
            text.append("  " + "; ".join(f"{c.header} {v}" for c, v in zip(columns, row) if str(v).strip()))
        else:
            text.append("  ".join(str(v) for v in row))
    return text + ([f"({table.caption})"] if table.caption else [])


def _bound(r: dict) -> str:
    """'bound' or 'not bound' below the threshold, qualified where a break-up was not computed."""
    if not r["bound"]:
        return "not bound"
    unchecked = r.get("threshold_unchecked")
    return "bound" if unchecked is None else (f"bound below the thresholds computed; break-ups with a fragment of three "
                                              f"or more particles, e.g. {unchecked}, were not: give \\[state] threshold")


def _print_levels(r: dict) -> None:
    """The levels of a result with several roots, and the transitions from the lowest and between
    neighbours (results.evaluate; every pair is in the JSON)."""
    from rich.table import Table

    from .results import HARTREE_CM

    levels = Table("root", "energy (Eh)", "σ (Eh)", "η_TI", "E − E_0 (cm⁻¹)", "bound", "optimised", title="levels",
                   caption="bound: below the lowest dissociation threshold by more than σ; optimised: a level the "
                           "basis was optimised for")
    gaps = {(d["lower"], d["upper"]): d for d in r["transitions"]}
    targets = r.get("targets", [0])
    for v in r["levels"]:
        gap = gaps[(0, v["root"])]["cm-1"] if v["root"] else 0.0
        levels.add_row(str(v["root"]), f"{v['energy']:.12f}", f"{v['energy_uncertainty']:.1e}", f"{v['virial']:.1e}",
                       f"{gap:.6f}", "yes" if v["bound"] else "no", "yes" if v["root"] in targets else "")
    show(levels)
    unbound = {v["root"] for v in r["levels"] if not v["bound"]}
    steps = Table("transition", "ΔE (Eh)", "ΔE (cm⁻¹)", "uncertainty (cm⁻¹)", title="between neighbouring levels",
                  caption="*: to or from a level not bound in this basis (a discretised continuum state)"
                  if unbound else None)
    for v in r["levels"][1:]:
        d = gaps[(v["root"] - 1, v["root"])]
        mark = "*" if {d["lower"], d["upper"]} & unbound else ""
        steps.add_row(f"{d['lower']} → {d['upper']}{mark}", f"{d['Eh']:.10f}", f"{d['cm-1']:.6f}",
                      f"{d['uncertainty'] * HARTREE_CM:.1e}")
    show(steps)


def _warn_if_unbound(r: dict) -> None:
    """One line on stderr when the energy is not below the lowest dissociation threshold (`results`),
    after the result (a standard output that could not take it ends the command first: `Stream.check`)."""
    sys.stdout.check()
    if not r["bound"]:
        print(f"prebo: warning: E = {r['energy']:.12g} Eh is not below the dissociation threshold "
              f"{r['threshold']:.12g} Eh ({r['threshold_fragments']}): the state is not bound in this basis "
              "(a small virial coefficient is no evidence of binding)", file=sys.stderr)
    above = [v["root"] for v in r.get("levels", [])[1:] if not v["bound"]]
    if above and r["bound"]:
        which = f"level {above[0]}" if len(above) == 1 else f"{len(above)} levels ({above[0]}, ..., {above[-1]})"
        print(f"prebo: warning: {which} not below the dissociation threshold {r['threshold']:.12g} Eh "
              f"({r['threshold_fragments']}): not bound in this basis (discretised continuum)", file=sys.stderr)


def cmd_run(args) -> int:
    """`prebo run INPUT [--out DIR] [--force]` or `prebo run --resume DIR`, either with `--budget
    SECONDS` (the wall time of the whole run, resumed parts included, in place of the input's or
    checkpoint's): optimise, then write DIR/result.json (`_result`, energies in Eh, and per level the
    expectation values of the operators the basis family evaluates (`properties.reported`), with
    their `corrections`:
    the Breit–Pauli correction and Drachmann's δ where the family has their operators) of the lowest
    state at the size the run passed through, beside the checkpoint DIR/basis.json (and
    DIR/lowest.json if the run stands above that state); warn when the state is not bound in the
    basis. The run owns DIR from before it looks into it until it ends (io/lock.py). A new run
    refuses a DIR that holds an earlier run's outputs unless `--force` (`claim`). Returns the exit
    status 0."""
    from .io.files import write_json_atomic
    from .errors import InputError, StalledError, UnsupportedError
    from .io import toml
    from .io.lock import owned
    from .optimise import optimise, resume_from
    from .properties import corrections, reported
    from .optimise.checkpoint import CHECKPOINT, LOWEST
    from .provenance import provenance

    t0 = time.perf_counter()
    if args.resume is not None and (args.input is not None or args.out is not None or args.force):
        raise InputError(f"--resume {args.resume}: give no input file or --out with it, nor --force (a resumed run "
                         "keeps its checkpoint's system, settings and folder; --budget changes its budget)")
    if args.resume is not None:
        out = Path(path_name(args.resume, "--resume", "a run folder"))
        title, source = None, str(out / CHECKPOINT)
    else:
        if args.input is None:
            raise InputError("give an input file, or --resume DIR")
        job = toml.load(args.input)
        out = given(args.out, Path("runs") / Path(args.input).stem, "a folder")
        title, source = job.title, str(args.input)
    root = world().root  # under MPI, rank 0 alone owns and writes the folder (parallel.py)
    with owned(out) if root else nullcontext():
        try:
            if args.resume is not None:
                basis, opts = resume_from(out, progress=not args.quiet, budget=args.budget)
            else:
                if root:
                    claim(out, args.force)
                opts = job.optimiser if args.budget is None else replace(job.optimiser, budget=args.budget)
                basis = optimise(job.system, opts, out=out, progress=not args.quiet)
        # the settings to change are in the input (or the checkpoint): a state, size or settings that
        # do not fit together, or no trial that could start or grow the basis
        except (StalledError, InputError, UnsupportedError) as exc:
            raise type(exc)(f"{source}: {exc}") from exc
        title = title or basis.system.label()
        where = out / LOWEST if (out / LOWEST).exists() else out / CHECKPOINT  # the file of the state returned
        levels = basis.convergence.get("levels")  # where the targeted levels stand, if followed
        derived = reported(basis.family)  # the properties block
        roots = None if levels is None else max(levels) + 1
        try:
            r = _result(basis, where, opts.threshold, operators=derived, roots=roots)
        except NonFiniteError as exc:  # the energies stand without the properties: say so, write them
            r = _result(basis, where, opts.threshold, roots=roots)
            print(f"prebo: warning: result.json without expectation values: {exc}", file=sys.stderr)
        for level in r.get("levels", [r]):  # each level's Breit–Pauli correction and regularised δ, p⁴
            level |= corrections(basis, level)
        if levels is not None:
            r["targets"] = levels
        r |= {"title": title, "wall_seconds": time.perf_counter() - t0, "input": source,
              "convergence": basis.convergence, "provenance": provenance()}
        if root:
            write_json_atomic(out / RESULT, r)
    if not root:
        return 0
    if not args.quiet:
        _print_result(r)
        print(f"wrote {out / RESULT} ({where.name}: the lowest state at the size; "
              f"{CHECKPOINT}: where the run stands)" if where.name == LOWEST else
              f"wrote {out / RESULT} and {out / CHECKPOINT}")
    _warn_if_unbound(r)
    if basis.convergence["stalled"]:
        print(f"prebo: warning: growth stalled short of the basis size: {basis.convergence['stalled']['why']}",
              file=sys.stderr)
    if basis.convergence.get("followed"):
        seconds, before, after = basis.convergence["followed"][-1]
        print(f"prebo: note: the targeted levels were followed by overlap to other roots "
              f"{len(basis.convergence['followed'])} time(s), last from roots {before} to {after} after {seconds:.0f} s; "
              f"they end at roots {basis.convergence['levels']} (convergence.followed in {RESULT})", file=sys.stderr)
    return 0


def claim(out: Path, force: bool) -> None:
    """Make the folder `out` a new run's: OutputError if it holds an earlier run's checkpoint,
    lowest state or result, unless `force`, which removes them (the new run writes its own), and
    if one of their names is anything but a regular file (`files.replaceable`)."""
    from .io.files import replaceable
    from .optimise.checkpoint import CHECKPOINT, LOWEST

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
    from .io.files import replaceable

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


def cmd_import(args) -> int:
    """`prebo import FILE.inout.txt [--out X.json] [--force] [--c-A C]`: an ecgpack basis as basis.json."""
    from .eigen import THRESHOLD
    from .io import stored
    from .io.ecgpack import read_inout
    from .optimise.settings import check

    c_A = check("c_A", args.c_A, "--c-A")
    default = Path(stored.stem(args.file) + ".json")
    out = output_file(given(args.out, default, "a file name"), args.force, [args.file])
    basis = read_inout(args.file, c_A=c_A)
    basis.save(out, {"optimiser": {"threshold": THRESHOLD}})  # every direction kept, as ecgpack solves it
    print(f"wrote {out} ({len(basis)} {basis.family.name} functions, {basis.system.label()})")
    return 0


def cmd_export(args) -> int:
    """`prebo export BASIS.json --format ecgpack [--out FILE] [--force]`: a plain-ECG basis as an ecgpack file."""
    from .io import stored
    from .io.ecgpack import write_inout

    default = Path(stored.stem(args.basis) + ".inout.txt")
    out = output_file(given(args.out, default, "a file name"), args.force, [args.basis])
    basis, _ = load_basis(args.basis)
    write_inout(basis, out)
    print(f"wrote {out}")
    return 0


def cmd_plot(args) -> int:
    """`prebo plot RUN... [--reference E] [--since S] [--log-time] [--out PNG|DIR] [--force]`:
    convergence plot of run checkpoints (into DIR/convergence.png for an existing folder DIR);
    `prebo plot --densities BASIS [--roots K...] [--rmax R] [--points N] [--out PNG] [--force]`: the
    distance distributions of levels, the picture and its CSV table beside it."""
    if args.densities:
        return plot_densities(args)
    given_options = [o for o, v in (("--roots", args.roots), ("--rmax", args.rmax), ("--points", args.points)) if v]
    if given_options:
        from .errors import InputError
        raise InputError(f"{', '.join(given_options)}: only with --densities")
    from .optimise.checkpoint import CHECKPOINT
    from .plot import convergence

    default = Path(args.runs[0]) / "convergence.png"
    png = given(args.out, default, "an image file or a folder")
    if png.is_dir() or args.out is not None and args.out.endswith(os.sep):  # "DIR/": a folder, as in `cp`
        png = png / default.name
    png = output_file(png if png.suffix else png.with_suffix(".png"), args.force,
                      [run / CHECKPOINT for run in args.runs])
    try:
        convergence(args.runs, png, args.reference, args.since, args.log_time)
    except OSError as exc:
        raise OutputError(f"{png}: cannot write ({exc.strerror})") from exc
    print(f"wrote {png}")
    return 0


def plot_densities(args) -> int:
    """`prebo plot --densities`: properties.densities of one stored basis, drawn (plot.densities)
    into BASIS.densities.png (or --out) and tabulated into the same name with .csv."""
    import numpy as np

    from .errors import InputError
    from .io import stored
    from .io.files import write_atomic
    from .plot import densities as draw
    from .properties import POINTS, csv_text, densities

    if len(args.runs) != 1:
        raise InputError(f"--densities draws one basis, not {len(args.runs)} ({' '.join(map(str, args.runs))})")
    source = args.runs[0]
    default = Path(stored.stem(source) + ".densities.png")
    png = given(args.out, default, "an image file")
    png = output_file(png if png.suffix else png.with_suffix(".png"), args.force, [source])
    table_file = output_file(png.with_suffix(".csv"), args.force, [source])
    basis, stored = load_basis(source)
    points = args.points or POINTS
    r = None if args.rmax is None else np.linspace(0.0, args.rmax, points)
    try:
        table = densities(basis, args.roots or [0], r, points, threshold=stored)
    except PreboError as exc:
        raise type(exc)(f"{source}: {exc}") from exc
    try:
        draw(table, png)
        write_atomic(table_file, csv_text(table))
    except OSError as exc:
        raise OutputError(f"{png}: cannot write ({exc.strerror})") from exc
    print(f"wrote {png} and {table_file}")
    return 0


def load_basis(path) -> tuple:
    """A basis.json or an ecgpack file (ecgpack's own name: inout.txt), recognised by its content
    whatever its name (io.stored), and the overlap threshold of the code that wrote it: a run's
    (its "optimiser" block), else eigen.THRESHOLD (every direction double precision resolves, as
    ecgpack keeps them)."""
    from .basis import Basis
    from .eigen import THRESHOLD
    from .errors import InputError
    from .io import basis_json, stored
    from .io.ecgpack import parse_inout

    if str(path).endswith(".toml"):
        raise InputError(f"{path}: a TOML input, not a basis; optimise it with `prebo run {path}`")
    what, text = stored.read(path)
    if what == "ecgpack":
        return parse_inout(path, text).to_basis(), THRESHOLD
    d = basis_json.parse(text, path)
    basis = Basis.from_dict(d, str(path))  # d, its settings included, is checked from here on
    return basis, (d.get("optimiser") or {}).get("threshold", THRESHOLD)


def cmd_energy(args) -> int:
    """`prebo energy BASIS [--coordinates lab|ti] [--operator NAME ...] [--threshold T] [--json]`:
    re-evaluate a stored basis (Eh), with the expectation values of registered operators; a warning
    on stderr (exit status 0) when the state is not bound in the basis."""
    basis, stored = load_basis(args.basis)
    r = _result(basis, args.basis, args.threshold or stored, args.coordinates, args.operator, args.roots)
    if args.json:
        print(json.dumps(r, allow_nan=False))
    else:
        _print_result(r)
    _warn_if_unbound(r)
    return 0


def cmd_properties(args) -> int:
    """`prebo properties BASIS [--root K] [--coordinates lab|ti] [--threshold T] [--regularised] [--json]`: the
    energy of level K of a stored basis, the expectation value of every registered operator per
    class of equivalent pairs (properties.py) and the level's Breit–Pauli correction (relativistic.py);
    a level not bound in the basis gets a warning line on stderr."""
    from .properties import properties

    basis, stored = load_basis(args.basis)
    try:
        p = properties(basis, args.root, args.coordinates, args.threshold or stored, args.regularised or None)
    except PreboError as exc:
        raise type(exc)(f"{args.basis}: {exc}") from exc
    values = [v for per in p["expectation"].values() for v in per.values()]
    if not all(math.isfinite(v) for v in values + [p["energy"]]):
        raise NonFiniteError(f"{args.basis}: the properties are not finite: the basis's integrals overflow or lost "
                             "their digits")
    if args.json:
        print(json.dumps(p, allow_nan=False))
    else:
        _print_properties(p, basis)
    if not p["bound"]:
        sys.stdout.check()
        print(f"prebo: warning: root {p['root']} is not below the lowest dissociation threshold: not bound in this "
              "basis (its properties are those of a discretised continuum state)", file=sys.stderr)
    return 0


def _print_properties(p: dict, basis) -> None:
    """`prebo properties`' tables (cmd_properties)."""
    from rich.table import Table

    from .expectation import vanishing
    from .results import HARTREE_CM

    head = Table(show_header=False, box=None)
    head.add_row("level", f"root {p['root']} ({_bound(p)})")
    head.add_row("energy (translation-free)", f"{p['energy']:.12f} Eh ± {p['energy_uncertainty']:.1e}")
    head.add_row("virial η_TI", f"{p['virial']:.2e}")
    if "n2" in p:
        head.add_row("⟨N²⟩_TI", f"{p['n2']:.3e} ħ²")
    show(head)
    for acts_on in ("pairs", "particles"):
        names = [name for name in p["expectation"] if OPERATORS[name].acts_on == acts_on]
        if names:
            classes = list(p["expectation"][names[0]])
            table = Table("operator", *classes, "unit", title=f"expectation values per class of equivalent {acts_on}")
            for name in names:
                table.add_row(name, *(f"{p['expectation'][name][c]:.10g}" for c in classes), p["units"][name])
            if acts_on == "pairs" and "delta_regularised" in p:  # drachmann.py
                table.add_row("delta (Drachmann)", *(f"{p['delta_regularised'][c]:.10g}" if c in p["delta_regularised"]
                                                     else "" for c in classes), "bohr⁻³")
            if acts_on == "particles" and p.get("p4_regularised"):  # drachmann.py, eq. (27')
                table.add_row("p4 (regularised)", *(f"{p['p4_regularised'][c]:.10g}" if c in p["p4_regularised"]
                                                    else "" for c in classes), "ħ⁴/bohr⁴")
            show(table)
            zero = vanishing(basis.system) if acts_on == "pairs" else []
            if zero and "delta" in names:
                print(f"⟨δ³(r_ij)⟩ of {', '.join(zero)}: 0 by symmetry (the state changes sign when the two trade "
                      "places, so it vanishes where they meet)")
    if "breit_pauli" in p:  # relativistic.py: each term, per class and summed
        bp = p["breit_pauli"]
        kind = ("regularised δ and p⁴ where Drachmann's forms serve (drachmann.py)" if bp["regularised"]
                else "direct δ and p⁴")
        table = Table("term (class)", "Eh", "cm⁻¹", title=f"Breit–Pauli correction (α = {bp['alpha']}; {kind})")
        for term, e in bp["Eh"].items():
            table.add_row(term.replace("_", "–"), f"{e:.6e}", f"{bp['cm-1'][term]:.6f}")
            for c, v in bp["classes"].get(term, {}).items():
                table.add_row(f"  {c}", f"{v:.6e}", f"{v * HARTREE_CM:.6f}")
        show(table)
    if p["not_derived"]:
        print(f"not derived for {basis.family.name} functions: {', '.join(p['not_derived'])}"
                        + ("" if "breit_pauli" in p else " (so neither is the Breit–Pauli correction)"))


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


def parser() -> argparse.ArgumentParser:
    """The `prebo` argument parser with its five subcommands."""
    from .provenance import VERSION, commit

    p = Parser(prog="prebo", description="pre-Born–Oppenheimer ECG solver")
    p.add_argument("--version", action="version",
                   version=f"prebo {VERSION}" + (f" (commit {commit()})" if commit() else ""))
    sub = p.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="optimise a basis for the system of a TOML input")
    run.add_argument("input", nargs="?", help="TOML input file")
    run.add_argument("--out", help="output folder (default runs/INPUT-STEM); one that holds a run's checkpoint "
                                   "or result is refused (--resume it, or --force)")
    run.add_argument("--force", action="store_true",
                     help="start over in an output folder holding an earlier run: its basis.json, lowest.json and "
                          "result.json are removed as the new run starts")
    run.add_argument("--resume", metavar="DIR", help="continue the run whose checkpoint is DIR/basis.json")
    run.add_argument("--budget", type=seconds, metavar="SECONDS",
                     help="wall-time budget of the whole run, resumed parts included; replaces [optimiser] "
                          "budget, or the checkpoint's with --resume (a run stopped by its budget goes on)")
    run.add_argument("--quiet", action="store_true", help="no progress display")
    run.set_defaults(func=cmd_run)
    pr = sub.add_parser("properties", help="a level's energy and the expectation values of every registered operator")
    pr.add_argument("basis", help="basis.json, or an ecgpack FILE.inout.txt")
    pr.add_argument("--root", type=natural, default=0, metavar="K", help="the level: root K of the basis's symmetry (default 0)")
    pr.add_argument("--coordinates", choices=["lab", "ti"], default="lab",
                    help="lab: LFCC with CM elimination (default); ti: translationally invariant (shared c_A only)")
    pr.add_argument("--threshold", type=fraction, metavar="T",
                    help="relative overlap eigenvalue below which directions are dropped (default: as for prebo energy)")
    pr.add_argument("--regularised", action="store_true",
                    help="the regularised δ and p⁴ (and the Breit–Pauli correction from them) also where they are "
                         "slower (floating ECGs, ECG-GVR: H2 with 500 ECG-GVR functions 55 s against 26 s); plain ECGs always have them")
    pr.add_argument("--json", action="store_true", help="print the properties as JSON")
    pr.set_defaults(func=cmd_properties)
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
                         "threshold of the run that wrote the file; else 4 x 2^-53, every direction the "
                         "elements resolve, as ecgpack solves its files)")
    en.add_argument("--roots", type=positive_integer, default=None, metavar="K",
                    help="report the lowest K levels of the state's symmetry (each an upper bound to its exact "
                         "level) and the transition energies between them, in Eh and cm⁻¹ (default: up to the "
                         "highest root the basis was optimised for)")
    en.add_argument("--json", action="store_true", help="print one JSON object")
    en.set_defaults(func=cmd_energy)
    im = sub.add_parser("import", help="convert an ecgpack / ATOM-MOL-nonBO FILE.inout.txt to basis.json")
    im.add_argument("file", help="ecgpack FILE.inout.txt (RG_0S: real plain ECGs)")
    im.add_argument("--out", help="basis.json to write (default FILE.json)")
    im.add_argument("--force", action="store_true", help="replace an existing --out file")
    im.add_argument("--c-A", dest="c_A", type=float, default=1.0, help="CM exponent c_A of the LFCC functions")
    im.set_defaults(func=cmd_import)
    ex = sub.add_parser("export", help="write a plain-ECG basis in another code's format")
    ex.add_argument("basis", help="basis.json")
    ex.add_argument("--format", choices=["ecgpack"], required=True)
    ex.add_argument("--out", help="file to write (default BASIS.inout.txt)")
    ex.add_argument("--force", action="store_true", help="replace an existing --out file")
    ex.set_defaults(func=cmd_export)
    pl = sub.add_parser("plot", help="energy against basis size of one or more runs, or the distance "
                                     "distributions of a basis's levels (PNG)")
    pl.add_argument("runs", nargs="+", type=Path, help="run folders (with basis.json checkpoints); with --densities "
                                                       "one basis.json or ecgpack FILE.inout.txt")
    pl.add_argument("--densities", action="store_true",
                    help="draw P(r) of every inter-particle distance and every particle's distance from the centre "
                         "of mass (and write the table as CSV beside the picture)")
    pl.add_argument("--roots", type=natural, nargs="+", metavar="K", help="with --densities: the levels (default 0)")
    pl.add_argument("--rmax", type=distance, metavar="R",
                    help="with --densities: the grid's end in bohr (default: 5 root-mean-square distances)")
    pl.add_argument("--points", type=positive_integer, metavar="N", help="with --densities: grid points (default 400)")
    pl.add_argument("--reference", type=finite, help="exact energy: plot E - E_ref on a log axis")
    pl.add_argument("--since", type=finite, metavar="SECONDS",
                    help="only the wall time from then on, against time (runs branched from one checkpoint)")
    pl.add_argument("--log-time", action="store_true", help="wall time on a logarithmic axis (runs of minutes and days)")
    pl.add_argument("--out", help="image file, .png (the default suffix), .pdf or .svg, or a folder for its "
                                   "convergence.png (default FIRST-RUN/convergence.png)")
    pl.add_argument("--force", action="store_true", help="replace an existing image file")
    pl.set_defaults(func=cmd_plot)
    return p


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


def written(status: int, out: Stream, err: Stream) -> int:
    """The exit status `status` of a command whose output streams are `out` and `err`, once they
    are flushed: 2 if either failed (with one line on `err` for `out`, unless said already)."""
    try:
        out.check()
    except OutputError as exc:
        print(f"prebo: error: {exc}", file=err)
    err.flush()
    return 2 if out.failed or err.failed else status


def command(argv) -> int:
    """The exit status of the command `argv` (main); SystemExit from argparse."""
    args = parser().parse_args(argv)
    try:
        world()  # under MPI: the ranks' threads set before the core first runs (parallel.py)
        return args.func(args)
    except PreboError as exc:
        return stop_all(2, "prebo: error: " + " ".join(str(exc).split("\n")))  # one line, always
    except KeyboardInterrupt:
        return stop_all(130, "prebo: interrupted (the last accepted step is saved)")


if __name__ == "__main__":
    sys.exit(main())
