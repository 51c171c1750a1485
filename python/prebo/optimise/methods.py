"""The optimisation methods: small config objects, each doing one unit of work of the schedule
(cursor.Cursor; schedule.py) on a `Run` when the driver (driver.optimise) calls its `step`; the
phase of the cursor names the method (`methods`).

- `Grow`: competitive selection (Suzuki & Varga, Lect. Notes Phys. m54, ch. 4, the stochastic
  variational method): `trials` random functions, each one's row against the basis from the
  core (O(N_b) integrals) and the new lowest eigenvalue from the secular equation (O(N_b^2),
  eigen.roots_with_added_many); the best, if it lowers the energy beyond its uncertainty, is
  appended — with a `newcomer` Minimiser, refined first.
- `Replace` ("sweep"): one step of a replacement sweep: function i competes with `trials` replacements in the
  basis without it — its neighbours in the power K (Sampler.neighbours: K ± 1, K ± 2 with the
  peak of the global-vector coordinate kept; refinement cannot change K), then the function
  perturbed at its own scale, or random functions with `near` = 0 (Sampler.replacements);
  with `newcomer`, the winner is refined and kept only if it then beats the incumbent, which is
  refined otherwise (refine.regenerate_function).
- `PruneStep` ("prune", fixed schedule): growth past the size up to the cursor's target (as
  `Grow`, each grown function then refined with the functions it overlaps most, so that it joins
  the basis before the removals are weighed; without that the cheapest to remove are the
  newcomers themselves), then the removal of the function whose
  removal raises the energy least (eigen.root_without_each), one per step back to the size,
  the function that overlapped it most then refined with its partners to take over its part
  (H2 with 500 ECG-GVR functions at 1.2e-8 Eh above, 12 grown and removed: the net gain 6.3–9.5e-11
  Eh against −1.5e-11 … 7.7e-11 without; benchmarks/record/h2.md, "Pruning that refines after each
  removal"): pruning a basis grown past its size keeps the functions that matter and moves the
  basis out of the basin refinement has settled in (benchmarks/record/h2.md, "Grow and prune").
- `PrunePass` ("prune", a schedule whose pruning is one step, `whole_pruning`): a whole pruning,
  growth steps up to the cursor's target and the removals back to N_b, in one step, undone
  unless the energy fell: the schedule's size is a cap at every step and its energy never rises.
- `Refine`: one step of a refinement sweep, function i refined with all others fixed, or with the
  functions it overlaps most (`refine_group`; refine.py), as `Minimiser` says.
- A sweep's step (`Replace`, `Refine`) can take a batch of functions at once (`together`): each
  worked on from the same basis, on as many MPI ranks, and put in order, each only if it still
  gains.
- `Polish`: one joint L-BFGS step over every parameter (polish.py).
- `MomentumMove` ("momentum"): the basis moved on along its displacement since the last move
  (momentum.py; a schedule that `moves`).
Replacements and pruning reach new basins, joint refinement converges within one; the
prune-sweep-refine-polish block is repeated `cycles` times (fixed.py), or the schedule chooses
among grow, sweep, refine, polish and prune by their rates and moves the basis on (schedule.py).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import StalledError, UnsupportedError
from ..parallel import world
from .cursor import Cursor
from .expansion import SIGMA_PRICE, Expansion
from .momentum import Momentum
from .polish import polish
from .refine import partners, refine_group, refine_newcomer, regenerate_function
from .report import Reporter
from .sampler import Sampler
from .schedule import kind_of
from .settings import C_A, Optimiser

STALL_STEPS = 100  # growth steps in a row without an accepted trial before the run stops (StalledError)


@dataclass
class Run:
    """What the methods act on: the expansion, the sampler and the reporter; `stalled` counts the
    growth steps in a row that added nothing; `momentum` holds the reference of the next move."""

    expansion: Expansion
    sampler: Sampler
    report: Reporter
    stalled: int = 0
    momentum: Momentum = field(default_factory=Momentum)


@dataclass(frozen=True)
class Minimiser:
    """The local minimiser that refines one function (refine.py): at most `evaluations` energies
    by `method` ("gradient": L-BFGS on exact gradients, or "powell"); in a refinement sweep,
    together with the `group` - 1 functions it overlaps most (refine.refine_group)."""

    evaluations: int
    method: str
    group: int = 1


@dataclass(frozen=True)
class Grow:
    """Append the best of `trials` random functions (module docstring), refined first by the
    `newcomer` minimiser if given. StalledError after STALL_STEPS steps in a row whose every
    trial was rejected."""

    trials: int
    newcomer: Minimiser | None = None

    def step(self, run: Run, cursor: Cursor) -> None:
        """One unit of work on `run` at `cursor` (class docstring)."""
        ex = run.expansion
        trials = run.sampler.trials(self.trials, ex.basis)
        energies, rows, diag = ex.candidates(trials)
        best = int(np.argmin(energies))
        run.report.trials(len(trials))
        nb, gains = len(ex.basis), np.isfinite(energies[best]) and ex.gains(energies[best])
        if self.newcomer:
            grown = gains and refine_newcomer(ex, nb, trials.subset([best]), self.newcomer.evaluations,
                                              self.newcomer.method)
        else:
            grown = gains and ex.put(nb, trials.subset([best]), {k: v[best] for k, v in rows.items()}, diag[best])
        if grown:
            run.stalled = 0
            return
        run.stalled += 1
        if run.stalled == STALL_STEPS and len(ex.basis) == 0:
            raise UnsupportedError(f"optimiser: every trial of {STALL_STEPS} growth steps was refused with no function "
                                   f"in the basis: {unresolved(run.sampler, ex.basis.family.name)}")
        if run.stalled == STALL_STEPS:
            why = stalled(len(ex.basis), run.sampler.opts, ex.eig.overlap_condition, ex.sigma)
            raise StalledError(f"optimiser: {why}")


#: internal exponents this many times c_A or more (or less) leave too few digits beside it in double
#: precision: a trial's A = (internal part) + c_A μμᵀ loses its Cholesky factor or its integrals
#: their digits (settings.py, C_A). Two particles of charges ±1 and masses m at c_A = 1 (1/a² = m²/4):
#: m = 10⁴ grows, m = 3·10⁴ stalls at 4 functions, m = 10⁵ finds no function (measured at a7fcde6)
DIGITS_APART = 1e9


def unresolved(sampler, family: str) -> str:
    """Why no trial could start the basis: its pairs' exponents ~1/a² (a the tightest Bohr radius,
    sampler.pair_lengths) lie DIGITS_APART from c_A, which its bounds (settings.C_A) cannot reach
    (two particles of 10⁷ electron masses: a = 2e-7 bohr, 1/a² = 2.5e13 bohr⁻²), and a pure Coulomb
    system scales (masses by λ: energies by λ, lengths by 1/λ); else the functions cannot describe
    the state."""
    a, c_A = float(np.min(sampler.a)), sampler.opts.c_A
    if not 1 / DIGITS_APART < 1 / (a * a * c_A) < DIGITS_APART:
        return (f"its tightest pair's Bohr radius, {a:.1e} bohr, asks for exponents ~{1 / (a * a):.1e} bohr⁻², too far "
                f"from the centre-of-mass exponent c_A (now {c_A:g}; allowed {C_A.lo:g} to {C_A.hi:g}) for double "
                "precision to hold both: give the masses and charges in units that bring the Bohr radii near 1")
    return (f"{family} functions cannot describe this state (its symmetriser annihilates them, or their integrals "
            f"lose their digits); choose another [basis] type, or a smaller c_A (now {c_A:g})")


def stalled(nb: int, opts: Optimiser, condition: float = 0.0, sigma: float = 0.0) -> str:
    """Why growth stopped at `nb` functions, and the settings to change: at an overlap `condition`
    within a decade of 1/threshold a new function costs a dropped direction (eigen.solve), so no
    trial lowers the energy (He at 427 functions, benchmarks/record/schedules.md, "Cheaper steps at large N");
    otherwise every trial was refused by the linear-dependence guard or gained too little beyond
    the energy's uncertainty `sigma` (Eh; Expansion.keep_if_lower: He at 580 functions with σ =
    1.0e-13, benchmarks/record/schedules.md, "Defaults that know the numerics")."""
    if condition * opts.threshold >= 0.1:
        return (f"no trial of the last {STALL_STEPS} growth steps lowered the energy at {nb} functions: the "
                f"overlap condition, {condition:.2e}, is near 1/threshold, where a new function costs a dropped "
                f"direction; lower threshold (now {opts.threshold:g})")
    return (f"every trial of the last {STALL_STEPS} growth steps was rejected at {nb} functions (linearly "
            f"dependent on the basis, implausible, or gaining less than the energy's uncertainty σ = {sigma:.1e} Eh "
            f"and {SIGMA_PRICE:g} times what it adds to σ, at overlap condition {condition:.1e}); raise max_overlap "
            f"(now {opts.max_overlap:g}), lower min_norm (now {opts.min_norm:g}) or change length_range (now "
            f"{list(opts.length_range)})")


@dataclass(frozen=True)
class Replace:
    """Replace function `cursor.index` by the best of `trials` functions — its neighbours in K, then
    itself perturbed or random ones — if that lowers the energy; with a `newcomer` minimiser, the
    winner is refined first (module docstring); with a `batch` > 1, that many functions from
    `cursor.index` on at once (`together`), the trials of each drawn first, in order."""

    trials: int
    newcomer: Minimiser | None = None
    batch: int = 1

    def step(self, run: Run, cursor: Cursor) -> int:
        """One unit of work on `run` at `cursor` (class docstring); the number of functions visited."""
        ex = run.expansion
        batch = sweep_batch(cursor, self.batch, len(ex.basis))
        drawn = {i: run.sampler.replacements(ex.basis.subset([i]), self.trials) for i in batch}
        run.report.trials(sum(map(len, drawn.values())))
        return together(ex, batch, lambda ex, i: self.replace(ex, i, drawn[i]))

    def replace(self, ex: Expansion, i: int, trials) -> None:
        """Replace function i by the best of `trials` if that lowers the energy (class docstring)."""
        rest = ex.without(i)
        energies, rows, diag = ex.candidates(trials, exclude=i, eig=rest)
        best = int(np.argmin(energies))
        if self.newcomer and np.isfinite(energies[best]):
            regenerate_function(ex, i, trials.subset([best]), self.newcomer.evaluations, self.newcomer.method, rest)
        elif np.isfinite(energies[best]) and ex.gains(energies[best]):
            ex.put(i, trials.subset([best]), {k: v[best] for k, v in rows.items()}, diag[best])


@dataclass(frozen=True)
class PruneStep:
    """Below the cursor's `target` size a `grow` step past the size, the grown function then
    refined with its partners by `minimiser`; at or above it the removal of the function whose
    removal raises the energy least, the function it overlapped most then refined with its
    partners (module docstring)."""

    grow: Grow
    minimiser: Minimiser

    def step(self, run: Run, cursor: Cursor) -> None:
        """One unit of work on `run` at `cursor` (class docstring)."""
        if len(run.expansion.basis) < cursor.target:
            self.add(run, cursor)
        else:
            self.remove(run)

    def add(self, run: Run, cursor: Cursor) -> None:
        """A `grow` step, the grown function then refined with its partners."""
        ex = run.expansion
        nb = len(ex.basis)
        self.grow.step(run, cursor)
        if len(ex.basis) > nb:
            refine_group(ex, nb, self.minimiser.group, self.minimiser.evaluations, self.minimiser.method)

    def remove(self, run: Run) -> int:
        """Remove the function whose removal raises the energy least, then refine the function
        that overlapped it most with its partners, to take over its part (module docstring); the
        index removed."""
        ex = run.expansion
        run.report.trials(len(ex.basis))
        i = int(np.argmin(ex.objective.without_each(ex.eig.energies, ex.eig.vectors, ex.b)))
        j = partners(ex, i, 1)[0]
        ex.remove(i)
        refine_group(ex, j - (j > i), self.minimiser.group, self.minimiser.evaluations, self.minimiser.method)
        return i


@dataclass(frozen=True)
class PrunePass:
    """`prune`'s growth by the cursor's `target` − N_b steps (fewer if growth stalls) and its
    removals back to N_b as one step, kept only if the energy fell beyond its uncertainty (module
    docstring)."""

    prune: PruneStep

    def step(self, run: Run, cursor: Cursor) -> None:
        """One unit of work on `run` at `cursor` (class docstring)."""
        ex = run.expansion
        before, nb = ex.snapshot(), len(ex.basis)
        origin = list(range(nb))  # where each function was before the pruning (None: grown)
        try:
            for _ in range(cursor.target - nb):
                self.prune.add(run, cursor)
                origin += [None] * (len(ex.basis) - len(origin))
        except StalledError:
            run.stalled = 0
        while len(ex.basis) > nb:
            del origin[self.prune.remove(run)]
        if ex.keep_if_lower(before):
            run.momentum.follow(ex.basis, origin)


@dataclass(frozen=True)
class Refine:
    """Refine function `cursor.index`, with its partners if `minimiser.group` > 1, all others fixed;
    with a `batch` > 1, that many functions from `cursor.index` on at once (`together`)."""

    minimiser: Minimiser
    batch: int = 1

    def step(self, run: Run, cursor: Cursor) -> int:
        """One unit of work on `run` at `cursor` (class docstring); the number of functions visited."""
        m, batch = self.minimiser, sweep_batch(cursor, self.batch, len(run.expansion.basis))
        run.report.trials(len(batch))
        return together(run.expansion, batch, lambda ex, i: refine_group(ex, i, m.group, m.evaluations, m.method))


def sweep_batch(cursor: Cursor, batch: int, nb: int) -> range:
    """The functions of a sweep's unit of work at `cursor`: `batch` from `cursor.index` on, not past
    the basis's `nb` functions."""
    return range(cursor.index, min(cursor.index + batch, nb))


def together(ex: Expansion, batch: range, unit) -> int:
    """`unit(ex, i)`, the unit of work of a sweep at function i, for every function of `batch` (a
    range); the number of functions visited. A batch of more than one function: each unit is done
    on a draft of `ex` of its own (Expansion.draft), the MPI ranks sharing them (parallel.py; one
    process does them in turn), and the functions each draft changed are put into `ex` in the order
    of the batch, each change only if it still lowers the energy (Expansion.put_group re-checks it
    against the basis the changes before it made). The units of a batch are thus independent, and
    a batch gives the same bits on any number of ranks."""
    if len(batch) == 1:
        unit(ex, batch[0])
        return 1
    ranks, mine = world(), []
    for i in batch[ranks.mine(len(batch))]:
        draft = ex.draft()
        unit(draft, i)
        mine.append((i, draft.changes(ex)))
    for _, change in ranks.gathered(mine, ("batch", batch.start, len(batch))):
        if change is not None:
            ex.put_group(*change)
    return len(batch)


@dataclass(frozen=True)
class Polish:
    """At most `iterations` joint L-BFGS iterations over every parameter."""

    iterations: int

    def step(self, run: Run, cursor: Cursor) -> None:
        """One unit of work on `run` at `cursor` (class docstring)."""
        polish(run.expansion, self.iterations)


@dataclass(frozen=True)
class MomentumMove:
    """Move the basis on along its displacement since the last move (momentum.py)."""

    def step(self, run: Run, cursor: Cursor) -> None:
        """One unit of work on `run` at `cursor` (class docstring)."""
        run.momentum.move(run.expansion)


def methods(opts: Optimiser) -> dict:
    """The method of each phase of the schedule, configured by `opts` (defaults.resolved) and its
    kind (schedule.kind_of): whether every grown and replacing function is refined, whether a
    pruning is one step, whether the basis moves on along its displacement (momentum.py)."""
    kind = kind_of(opts)
    minimiser = Minimiser(opts.refine_evaluations, opts.refine_method, opts.refine_group)
    newcomer = Minimiser(opts.refine_evaluations, opts.refine_method) if kind.refines_newcomers(opts) else None
    prune = PruneStep(Grow(opts.trials, newcomer), minimiser)
    return {"grow": Grow(opts.trials, newcomer), "prune": PrunePass(prune) if kind.whole_pruning else prune,
            "sweep": Replace(opts.trials, newcomer, opts.batch),
            "refine": Refine(minimiser, opts.batch), "polish": Polish(opts.polish_iterations)} | (
                {"momentum": MomentumMove()} if kind.moves else {})
