"""`prebo run`: optimise a basis for the system of a TOML input, or resume a run, and write its result."""
from __future__ import annotations

import sys
import time
from contextlib import nullcontext
from dataclasses import replace
from pathlib import Path

from ..errors import NonFiniteError, PreboError
from ..parallel import world
from ..validation import path_name
from .arguments import seconds
from ..io.load import basis_file, load_basis
from .files import RESULT, claim, given
from .result import print_result, result, warn_if_unbound


def add(sub) -> None:
    """The `prebo run` subcommand, added to the subparsers `sub`."""
    p = sub.add_parser("run", help="optimise a basis for the system of a TOML input")
    p.add_argument("input", nargs="?", help="TOML input file")
    p.add_argument("--out", help="output folder (default runs/INPUT-STEM); one that holds a run's checkpoint "
                                 "or result is refused (--resume it, or --force)")
    p.add_argument("--force", action="store_true",
                   help="start over in an output folder holding an earlier run: its basis.json, lowest.json and "
                        "result.json are removed as the new run starts")
    p.add_argument("--resume", metavar="DIR", help="continue the run whose checkpoint is DIR/basis.json")
    p.add_argument("--budget", type=seconds, metavar="SECONDS",
                   help="wall-time budget of the whole run, resumed parts included; replaces [optimiser] "
                        "budget, or the checkpoint's with --resume (a run stopped by its budget goes on)")
    p.add_argument("--partner", metavar="BASIS",
                   help="a basis of another symmetry of the same particles (basis.json, a run folder or an ecgpack "
                        "file): result.json gains the electric-dipole lines between the run's levels and its "
                        "(`lines`, as `prebo transitions`)")
    p.add_argument("--quiet", action="store_true", help="no progress display")
    p.set_defaults(func=command)


def command(args) -> int:
    """`prebo run INPUT [--out DIR] [--force]` or `prebo run --resume DIR`, either with `--budget
    SECONDS` (the wall time of the whole run, resumed parts included, in place of the input's or
    checkpoint's): optimise, then write DIR/result.json (`result.result`, energies in Eh, and per level the
    expectation values of the operators the basis family evaluates (`properties.reported`), with
    their `corrections`:
    the Breit–Pauli correction and Drachmann's δ where the family has their operators) of the lowest
    state at the size the run passed through, beside the checkpoint DIR/basis.json (and
    DIR/lowest.json if the run stands above that state); warn when the state is not bound in the
    basis. The run owns DIR from before it looks into it until it ends (io/lock.py). A new run
    refuses a DIR that holds an earlier run's outputs unless `--force` (`files.claim`). Returns the exit
    status 0."""
    from ..errors import InputError, StalledError, UnsupportedError
    from ..io import toml
    from ..io.files import write_json_atomic
    from ..io.lock import owned
    from ..level.properties import corrections, reported
    from ..optimise import optimise, resume_from
    from ..optimise.checkpoint import CHECKPOINT, LOWEST
    from ..provenance import provenance

    t0 = time.perf_counter()
    partner = None if args.partner is None else load_basis(basis_file(args.partner))[0]  # refused before the run
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
        if partner is not None:
            from ..level.transitions import same_particles

            try:
                same_particles(job.system, partner.system)
            except InputError as exc:
                raise InputError(f"--partner {args.partner}: {exc}") from exc
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
                basis = optimise(job.system, opts, out=out, progress=not args.quiet, response=job.response)
        # the settings to change are in the input (or the checkpoint): a state, size or settings that
        # do not fit together, or no trial that could start or grow the basis
        except (StalledError, InputError, UnsupportedError) as exc:
            raise type(exc)(f"{source}: {exc}") from exc
        title = title or basis.system.label()
        where = out / LOWEST if (out / LOWEST).exists() else out / CHECKPOINT  # the file of the state returned
        levels = basis.convergence.get("levels")  # where the targeted levels stand, if followed
        derived = reported(basis.family)  # the properties block
        try:
            r = result(basis, where, opts.threshold, operators=derived, targets=levels)
        except NonFiniteError as exc:  # the energies stand without the properties: say so, write them
            r = result(basis, where, opts.threshold, targets=levels)
            print(f"prebo: warning: result.json without expectation values: {exc}", file=sys.stderr)
        for level in r.get("levels", [r]):  # each level's Breit–Pauli correction and regularised δ, p⁴
            level |= corrections(basis, level)
        driving = job.response if args.resume is None else checkpoint_source(out / CHECKPOINT)
        if driving is not None:  # a first-order function's run: the polarisability it gives
            r["response"] = response(basis, driving)
        if partner is not None:  # the run's result stands without them: a warning
            try:
                r["lines"] = lines(basis, partner, args.partner, len(r.get("levels", [r])), opts.threshold)
            except PreboError as exc:
                print(f"prebo: warning: result.json without the lines to --partner {args.partner}: {exc}",
                      file=sys.stderr)
        r |= {"title": title, "wall_seconds": time.perf_counter() - t0, "input": source,
              "convergence": basis.convergence, "provenance": provenance()}
        if root:
            write_json_atomic(out / RESULT, r)
    if not root:
        return 0
    if not args.quiet:
        print_result(r)
        print(f"wrote {out / RESULT} ({where.name}: the lowest state at the size; "
              f"{CHECKPOINT}: where the run stands)" if where.name == LOWEST else
              f"wrote {out / RESULT} and {out / CHECKPOINT}")
    warn_if_unbound(r)
    if basis.convergence["stalled"]:
        print(f"prebo: warning: growth stalled short of the basis size: {basis.convergence['stalled']['why']}",
              file=sys.stderr)
    if basis.convergence.get("followed"):
        seconds, before, after = basis.convergence["followed"][-1]
        print(f"prebo: note: the targeted levels were followed by overlap to other roots "
              f"{len(basis.convergence['followed'])} time(s), last from roots {before} to {after} after {seconds:.0f} s; "
              f"they end at roots {basis.convergence['levels']} (convergence.followed in {RESULT})", file=sys.stderr)
    return 0


def lines(basis, partner, where: str, roots: int, threshold: float) -> dict:
    """result.json's `lines`: the electric-dipole lines between the run's `roots` lowest levels and
    the levels the `partner` basis (the file `where`) targets (level/transitions.py)."""
    from ..level.transitions import transitions

    return {"partner": where} | transitions(basis, partner, (roots, max(partner.system.state.levels[0]) + 1), threshold)


def checkpoint_source(path: Path):
    """The response.Source of the checkpoint `path` of a response run (None for a run of levels)."""
    from ..io import basis_json
    from ..optimise.response import Source

    d = basis_json.read(path)
    return None if "response" not in d else Source.from_dict(d["response"], str(path))


def response(basis, source) -> dict:
    """result.json's `response`: the operator, the ground level (`root`, `energy`), the functional's
    minimum the run reached (`objective`, Eh) and what the run's basis gives at the source's
    frequency (level/response.FirstOrder, the Hylleraas value with the sum over its pseudostates
    and the first pole): the dipole polarisability α(ω) (a₀³, `at`), or for the current
    f(ω) = ⟨J'(H − E₀ − ω)⁻¹J'⟩ (`resolvent`)."""
    from ..level.response import first_order

    order = first_order(source.ground, basis, source.root, source.threshold, source.operator)
    value = order.at(source.omega) if source.operator == "dipole" else order.resolvent(source.omega)
    return {"operator": source.operator, "root": source.root, "objective": basis.convergence["objective"]} | value
