"""The one driver: `optimise` runs the methods (methods.py) one unit of work at a time, where the
schedule (schedule.py: its kinds, the fixed one of the settings and the one that chooses by rates) says, tells the
schedule what each left, keeps the history (history.py), stops at the wall-time budget, writes
the checkpoint (checkpoint.py) and leaves the convergence report (convergence.py) on the basis
it returns; `resume_from` continues a run (resume.py).

With an output folder, the basis, the random-number state and the position in the schedule are
written atomically after every step: a killed run loses at most the step in flight, and
`prebo run --resume` continues it bit for bit; every start removes the temporary files
(basis.json.*.tmp, lowest.json.*.tmp) a write killed in flight left. The run returns the lowest
state it passed through (lowest.Lowest), kept in lowest.json while it stands above it.
"""
from __future__ import annotations

import time
from contextlib import nullcontext
from dataclasses import replace
from pathlib import Path

import numpy as np

from .. import eigen
from ..basis import Basis
from ..errors import InputError, OutputError, StalledError
from ..integrals import laboratory
from ..io.files import remove_stale_temporaries
from ..io.lock import owned
from ..parallel import world
from ..system import System
from ..system.thresholds import lowest as lowest_threshold
from ..validation import path_name
from .checkpoint import CHECKPOINT, LOWEST, checkpoint_in
from .convergence import convergence
from .defaults import resolved
from .expansion import Expansion
from .history import Step
from .lowest import Lowest
from .methods import Run, methods
from .objective import Levels, Objective
from .response import Hylleraas, Source, driven
from .momentum import Momentum
from .report import Reporter
from .resume import followed_roots, load_checkpoint, resumed
from .sampler import Sampler
from .schedule import schedule_of
from .settings import Optimiser


def optimise(system: System, opts: Optimiser, out: Path | None = None, progress: bool = True,
             resume: dict | None = None, response: Source | None = None) -> Basis:
    """Optimise a basis of `opts.kind` for the state of `system`, with the schedule of `opts`
    (schedule.kind_of): growth to `opts.size` and refinement, replacement and joint passes chosen by
    the energy each gains per second until the basis has converged or is exhausted; or a fixed
    one (fixed.py), growth to `opts.size` by competitive selection, then `opts.cycles` times growth
    by `opts.prune` functions and pruning back to the size, `opts.sweeps` random replacement
    sweeps, `opts.refine` refinement sweeps and `opts.polish` joint steps (methods.py). Either stops
    after `opts.budget` seconds and keeps its place in the checkpoint: resumed with a larger
    budget, it goes on (a budget that ends a run while it prunes leaves a checkpoint of up to
    `opts.prune` functions more). Settings left at None are chosen for the system first
    (defaults.resolved).

    out: folder of the checkpoint out/basis.json, written atomically after every step (None: no
    checkpoint; OutputError if a new run's folder holds one already), owned by the run while it
    runs (io/lock.py; OutputError if another run owns it); progress: show a live
    line; resume: a checkpoint's content (resume.load_checkpoint) to continue exactly where
    it stopped; response: optimise the first-order function of a level (response.Source) on
    Hylleraas' functional (response.Hylleraas) instead of the levels of `system.state`, the basis's
    symmetry (the functional's value is the checkpoint's and the convergence report's "objective").
    Returns the lowest state of at most `opts.size` functions the run passed through (with a
    fixed schedule's pruning, not always where it stopped; lowest.Lowest): its basis with the
    state's coefficients and `convergence`, the report of convergence.py; its energy (hartree)
    is prebo.evaluate(basis)["energy"]. InputError for
    arguments of the wrong type, StalledError when growth rejects every trial for STALL_STEPS
    steps in a fixed schedule (one that goes on keeps the size reached: Schedule.stall), BasisFileError for a
    `resume` that does not fit."""
    if not isinstance(system, System):
        raise InputError(f"optimise: system = {system!r}: must be a prebo.System")
    if not isinstance(opts, Optimiser):
        raise InputError(f"optimise: opts = {opts!r}: must be a prebo.Optimiser")
    if out is not None:
        path_name(out, "optimise: out", "a folder (a str or path), or None")
    if response is not None and not isinstance(response, Source):
        raise InputError(f"optimise: response = {response!r}: must be a prebo.optimise.response.Source, or None")
    if response is not None:
        response.check(system)
    ranks = world()
    if not ranks.root:  # rank 0 alone writes (parallel.py); the others run the same steps
        out, progress = None, False
    with nullcontext() if out is None else owned(out):
        return _run(system, opts, out, progress, resume, ranks, response)


def _run(system: System, opts: Optimiser, out: Path | None, progress: bool, resume: dict | None, ranks,
         response: Source | None) -> Basis:
    """The run of `optimise`, in the folder `out` it owns (if any), on the MPI `ranks`."""
    held = None if out is None or resume is not None else checkpoint_in(out)
    if held:
        raise OutputError(f"optimise: out = {str(out)!r} holds a run's checkpoint ({held.name}): continue that run "
                          "with resume_from(out) (from prebo.optimise import resume_from), or give another folder")
    opts = resolved(opts, system)
    targets, weights = system.state.levels
    if max(targets) >= opts.size:
        raise InputError(f"state: root {max(targets)} asked for, but a basis of size = {opts.size} holds roots "
                         f"0..{opts.size - 1} only")
    rng = np.random.default_rng(opts.seed)
    sampler = Sampler(system, opts, rng)
    rep = laboratory(system)
    threshold = lowest_threshold(system).energy
    start, followed = Levels(targets, weights, threshold=threshold), []  # the levels at their targets
    if response is not None:  # a first-order function: its basis need hold no bound level
        rep, start, threshold = driven(rep, response), Hylleraas(response.E0, response.omega), np.inf
    objective = start
    if resume is None:
        basis, history, elapsed, schedule, stopped = Basis.empty(system, opts.kind), [], 0.0, schedule_of(opts), None
        cursor = schedule.first()
    else:
        basis, cursor, history, elapsed, schedule, stopped = resumed(resume, opts, rng, "checkpoint")
        roots, followed = followed_roots(resume, targets, "checkpoint")
        objective = start.to(roots)
    if out is not None:
        remove_stale_temporaries(Path(out) / CHECKPOINT)
        remove_stale_temporaries(Path(out) / LOWEST)
    t_start = time.perf_counter()

    def wall() -> float:
        """Seconds of optimisation so far, over all segments of a resumed run: rank 0's clock, so
        that every rank decides alike by time."""
        return ranks.agreed(round(elapsed + time.perf_counter() - t_start, 1), "clock")

    def expansion(b: Basis, objective: Objective) -> Expansion:
        """The expansion of basis `b` with the run's representation and linear-dependence settings."""
        return Expansion(b, rep, opts.threshold, opts.min_norm, opts.max_overlap, objective)

    ex = expansion(basis, objective)
    cursor, stopped = schedule.resume(cursor, stopped, len(ex.basis), ex.energy, elapsed)
    lowest = Lowest(basis, opts.size, out, {"optimiser": opts.to_dict()}, resumed=resume is not None)
    lowest.see(ex)
    sampler.learn(ex.basis)
    momentum = Momentum() if resume is None else Momentum.from_dict(resume.get("momentum"), basis, "checkpoint")
    run = Run(ex, sampler, Reporter(opts, progress, len(ex.basis)), momentum=momentum)
    steps = methods(opts)

    def checkpoint():
        ex.basis.coefficients = ex.coefficients if ex.eig is not None else None
        seconds = wall()  # on every rank: the clock is agreed among the ranks
        if out is not None:
            objective = ex.energy if np.isfinite(ex.energy) else None  # inf before the first function
            ex.basis.save(Path(out) / CHECKPOINT, {
                "energy": ex.lowest_root, "optimiser": opts.to_dict(), "progress": cursor.to_dict(),
                "rng": rng.bit_generator.state, "history": [step.row() for step in history], "elapsed": seconds,
                "schedule": schedule.to_dict(), "stopped": stopped, "momentum": run.momentum.to_dict()}
                | ({"objective": objective} if ex.objective.recorded else {})
                | ({} if ex.objective.lowest else {"levels": list(ex.objective.roots),
                                                   "followed": [f.row() for f in followed]})
                | ({} if response is None else {"response": response.to_dict()}))

    with run.report, eigen.lapack_threads(opts.size):
        while cursor.phase != "done":
            if opts.budget is not None and wall() >= opts.budget:
                stopped = "budget"  # the cursor is kept: resumed with a larger budget, the run goes on
                checkpoint()
                break
            stopped, old, phase, visited = None, ex.energy, cursor.phase, None
            try:
                visited = steps[cursor.phase].step(run, cursor)  # a sweep's batch visits several functions
            except StalledError:
                if not schedule.stall(len(ex.basis)):
                    raise
                run.stalled = 0
            if ex.followed is not None:  # a targeted level moved to another root (objective.py, following)
                followed.append(replace(ex.followed, seconds=wall()))
                run.report.followed(ex.followed.before, ex.followed.after)
                ex.followed = None
            if ex.energy < old:
                history.append(Step(len(ex.basis), ex.energy, cursor.phase, wall()))
                run.report.step(ex, old, cursor, schedule)
                sampler.learn(ex.basis)  # a function of the basis alone, so a resumed run learns the same
            cursor = schedule.advance(cursor, len(ex.basis), ex.energy, wall(), visited or 1)
            if cursor.phase == "done":
                stopped = schedule.stopped
            ground = ex.eig.energies[0] if ex.eig is not None else np.inf  # the lowest root: bound or not
            fresh = schedule.restart(phase, len(ex.basis), ground, threshold - ex.sigma)
            if fresh is not None:  # a fresh start (Schedule.restart)
                schedule, cursor, stopped = fresh, fresh.first(), None
                ex = run.expansion = expansion(Basis.empty(system, opts.kind), start)
                run.momentum = Momentum()
                sampler.learn(ex.basis)
            lowest.see(ex)  # first: a run killed between the two writes keeps its lowest state
            checkpoint()
    best = lowest.basis
    if best is None:  # never at or below the size (a run resumed mid-pruning and stopped there)
        best = ex.basis
        best.coefficients = ex.coefficients
    best.convergence = convergence(history, opts, stopped, wall(), schedule.stalled, schedule.advantage(len(ex.basis)),
                                   ex.eig.overlap_condition, ex.sigma)
    if not ex.objective.lowest:
        best.convergence |= {"levels": list(ex.objective.roots), "followed": [f.row() for f in followed]}
    if response is not None:
        best.convergence |= {"objective": lowest.energy}
    return best


def resume_from(folder: Path, progress: bool = True, budget: float | None = None) -> tuple[Basis, Optimiser]:
    """Continue the run whose checkpoint is folder/basis.json, with `budget` (seconds of the whole
    run) in place of the checkpoint's if given; the finished basis and its settings. A response
    run's source is rebuilt from the checkpoint's "response" block (response.Source.from_dict)."""
    folder, ranks = path_name(folder, "resume_from: folder", "a folder (a str or path)"), world()
    with owned(folder) if ranks.root else nullcontext():  # before it is read
        d, system, opts = ranks.agreed(load_checkpoint(folder) if ranks.root else None)  # rank 0 reads
        if budget is not None:
            opts = replace(opts, budget=budget)
        response = None if "response" not in d else Source.from_dict(d["response"], str(Path(folder) / CHECKPOINT))
        return optimise(system, opts, out=Path(folder), progress=progress, resume=d, response=response), opts
