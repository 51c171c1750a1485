"""The adaptive schedule: which unit of work comes next, chosen by the energy each kind of pass has
been gaining per second.

A pass is the unit the schedule measures: growth by a quarter of the basis (at least GROWTH
functions, at most to `size`; every new function refined), refinement or replacement of the
next CHUNK functions (a sweep continues where the last pass of its kind stopped), one joint
L-BFGS step, or, at full size, one pruning: `pruned(size)` functions grown past the size, each
refined with its partners, as many removed again (each removal followed by a refinement of the
function that overlapped most the one removed), and the basis before it restored unless the
energy fell (methods.PrunePass; with the fixed schedule's pruning He with 500 functions gained
2.8× as much as with the adaptive schedule in 150 s, benchmarks/record/schedules.md, "Pruning in the
adaptive schedule"). After each pass the next one is of the kind whose last pass gained the most
energy per second of wall time — except at full size after every momentum.EVERY passes that move functions
(refinement, replacement, joint) since the last move or pruning, when the basis moves on along
its displacement (momentum.py; a pass of kind "momentum", seconds long); kinds not yet tried come
first. A move extrapolates the displacement of the passes before it, so its gain is theirs: it is
shared among them in proportion to their own gains (a pass whose move has not come, yet or at
all, counts with the factor its kind had from its last move). On the H2 run the moves after
refinement gained 3–10× those after replacement sweeps, which the passes' own rates do not show
(benchmarks/record/h2.md, "A stale rate, and momentum every one, two or four passes"). A kind's rate is
measured again only when it runs again, so the rate it keeps is that of an earlier, richer
state: as the running kind's rate falls below it, the other kinds are tried again, and each stays
in use as long as it pays best.
A kind not run for REVISIT times the seconds of its shortest pass of the last three is tried
again all the same: a rate measured while the machine was busy with other work, or before the
state changed (a pruning that gained nothing once, refinement before momentum), would otherwise
keep the kind out for good; the cost is about 1/REVISIT of the time per kind. (On the H2 run with
500 functions, refinement's last pass, slowed 4× by probes beside the run, kept it out for 5000 s;
with REVISIT = 20 and the last pass's seconds, the joint steps, pruning and sweeps that lost took
22 % of the time.)
Growth is a kind while the basis is smaller than `size` and growth has not stalled (`stall`:
every trial of STALL_STEPS steps linearly dependent on the basis; the basis then keeps the size
it reached).

At full size the schedule ends when the basis has converged: a whole sweep of every kind gains
less than `tolerance` Eh (default TOLERANCE |E|); with a wall-time budget, it also ends (as the
budget's end) when the best kind's last rate would gain less than that in the seconds left. Without a budget it also ends when the
basis is exhausted: the last pass of every kind gains less than RATIO of the reference rate, what
the last growth pass gained per second (a larger basis would gain faster; where growth took one
pass, which has no rate, the best rate of a pass at full size). A budget is the user's word on
how long to spend at this size, so it overrides exhaustion — also when given to a resumed run
that ended exhausted (`resume`) — which the convergence report then states as `advantage`, the
reference over the best kind's last rate. The budget stops any
schedule (driver.py).

The choices follow measured seconds, so two runs of one input take different paths and may end
apart (H2 with 300 functions and 30 trials: 1.2e-6 and 2.4e-6 Eh above after 600 s;
benchmarks/record/schedules.md, "Trials in the adaptive schedule"); a fixed schedule (any of sweeps, refine,
polish, cycles given) repeats bit for bit.

The passes (`Pass`: stored as [kind, n_b, E before, E after, seconds before, seconds after,
functions]), the start of the pass in flight (`Start`, stored as [E, seconds]), where each sweep goes on and the size
at which growth stalled (None) are kept in the checkpoint, so a resumed run goes on with what it
had learned (`check` reads them back).

A fresh start: the first functions can settle on a fragment plus a distant particle (HD+ from
seed 1 grew a D atom with the proton far away, -0.49986 Eh, and never left it), a basin growth
and refinement do not leave, since no single molecular function gains beside it. So when growth
first reaches RESTART_AT functions (or the size, if smaller) at an energy that is not below the
lowest dissociation threshold (thresholds.lowest), the run starts again from no function, the
random numbers going on, at most RESTARTS times; the number of starts is kept in the checkpoint.
The run still returns the lowest state it passed through (lowest.Lowest).
"""
from __future__ import annotations

import math
from dataclasses import astuple, dataclass, fields

from .cursor import OLD, Cursor
from .momentum import EVERY
from .settings import Optimiser

#: a kind not run for this many times its shortest pass of the last three is tried again (module docstring)
REVISIT = 50
#: the fewest functions a growth pass adds
GROWTH = 8
#: the most functions a refinement or replacement pass visits
CHUNK = 50
#: exhausted below this share of the reference gain per second (module docstring)
RATIO = 0.02
#: the default tolerance relative to |E|, about 50 ulp of E: a whole sweep that gains less gains
#: at the level of rounding (a step is kept only if it gains more than the energy's uncertainty σ,
#: expansion.py, so where σ is larger a sweep that keeps nothing ends the run). 1e-10 stopped He
#: with 700 functions "converged" 2.2e-10 Eh above the exact energy with a third of its 300-s
#: budget left (issue 37)
TOLERANCE = 1e-14
#: the kinds of pass that improve a basis of fixed size, in the order they are first tried
IMPROVE = ("refine", "sweep", "polish", "prune")
#: the kinds of pass that move functions, whose displacement a move (momentum.py) extrapolates
MOVES = ("refine", "sweep", "polish")
#: the most functions a pruning grows past the size and removes again
PRUNE = 20
#: the size at which growth checks that the state is bound (module docstring, a fresh start)
RESTART_AT = 20
#: the most fresh starts of one run
RESTARTS = 2
#: competitive trials per step (defaults.py): a trial costs one row of N_b integrals and the winner's
#: refinement EVALUATIONS energies with gradients, (1 + P) rows each, so a wider competition is nearly
#: free and picks better functions (H2 with 300 functions after 600 s: 6.7e-7 and 7.2e-7 Eh above
#: with 100 trials against 1.2e-6 and 2.4e-6 with 30; He with 400 in 300 s: 7.5e-10 and 8.7e-10
#: against 1.3–2.1e-9 with 20; benchmarks/record/schedules.md, "Trials in the adaptive schedule")
TRIALS = 100
#: energies per refinement of one function: L-BFGS converges a function in 15–40 (benchmarks/record/refinement.md)
EVALUATIONS = 30
#: functions a refinement pass moves together: each with the GROUP − 1 it overlaps most
#: (near-duplicate partners hold a lone function in place; benchmarks/record/h2.md, "The H2
#: campaign"; benchmarks/record/schedules.md, "Groups in the adaptive schedule")
GROUP = 3
#: the share of an atom's growth trials that perturb functions of the basis at their own scale, its
#: sweeps then trying moves of the function replaced only (sampler.py): He with 700 functions in
#: 300 s, 5.1–6.0e-11 Eh above in three runs against 2.7–6.0e-10 with every trial drawn
#: (benchmarks/record/schedules.md, "Trials near the basis"); 0 for molecules (H2⁺ from defaults
#: ended at 5.5e-7 with it, 5.6e-8 without: the perturbations keep u and K)
NEAR = 0.5


@dataclass(frozen=True, slots=True)
class Pass:
    """One pass of the schedule: its `kind`, the basis `size` after it, the energy `before` it (Eh;
    None for the first, from no function) and `after` it, the run's seconds at its `start` and
    `end`, and the `functions` it visited (every one for growth and a joint step); stored as the
    list of its fields (`row`)."""

    kind: str
    size: int
    before: float | None
    after: float
    start: float
    end: float
    functions: int

    @property
    def gain(self) -> float:
        """Energy gained (inf for the first growth pass: no energy before it)."""
        return math.inf if self.before is None else self.before - self.after

    @property
    def rate(self) -> float:
        """Energy gained per second."""
        return self.gain / max(self.end - self.start, 1e-3)

    def row(self) -> list:
        """The checkpoint's row of the pass."""
        return list(astuple(self))


@dataclass(frozen=True, slots=True)
class Start:
    """Where the pass in flight started: the `energy` (Eh; None before the first function) and the
    run's `seconds`; stored as [E, seconds] (`row`)."""

    energy: float | None
    seconds: float

    def row(self) -> list:
        """The checkpoint's "start" of the schedule block."""
        return [self.energy, self.seconds]


def pruned(size: int) -> int:
    """The functions a pruning pass grows past `size` and removes: PRUNE, at most a tenth of the basis."""
    return max(1, min(PRUNE, size // 10))


class Adaptive:
    """The adaptive schedule of `opts` (module docstring; the interface of schedule.Schedule);
    `passes`, `start` and `next` (the function each sweep goes on with) from a checkpoint."""

    #: the schedule's name, its [optimiser] schedule value
    name = "adaptive"
    #: a pruning is one unit of work, undone unless it gains (methods.PrunePass)
    whole_pruning = True
    #: the basis moves on along its displacement (momentum.py)
    moves = True

    def __init__(self, opts: Optimiser, passes: list | None = None, start: Start | None = None,
                 next: dict | None = None, stalled: int | None = None, restarts: int = 0):
        self.opts, self.stalled, self.stopped, self.restarts = opts, stalled, None, restarts
        self.passes = list(passes or [])
        self.start = start or Start(None, 0.0)  # no energy before the first function
        self.next = dict(next or {"refine": 0, "sweep": 0})

    @staticmethod
    def defaults(opts: Optimiser, molecule: bool) -> dict:
        """The settings the schedule chooses where the input leaves them out (defaults.py): TRIALS,
        EVALUATIONS, GROUP, and NEAR for an atom (0 for a `molecule`); no fixed-schedule settings."""
        return {"trials": TRIALS, "refine_evaluations": EVALUATIONS, "refine_group": GROUP,
                "near": 0.0 if molecule else NEAR}

    @staticmethod
    def refines_newcomers(opts: Optimiser) -> bool:
        """Every grown and replacing function is refined first (methods.methods)."""
        return True

    @staticmethod
    def beyond(opts: Optimiser) -> int:
        """The functions a checkpoint may hold past the size: none, a pruning being one step
        (methods.PrunePass; resume.py)."""
        return 0

    @staticmethod
    def report(advantage: float | None) -> dict:
        """The convergence report's schedule entries (convergence.py)."""
        return {"adaptive": True, "advantage": advantage}

    @property
    def size(self) -> int:
        """The size the basis grows to: `size`, or where growth stalled."""
        return self.opts.size if self.stalled is None else min(self.opts.size, self.stalled)

    def restart(self, phase: str, nb: int, energy: float, threshold: float) -> Adaptive | None:
        """The schedule of a fresh start (module docstring) if the unit of work of `phase` left a
        basis that should start afresh: just grown to min(size, RESTART_AT) functions at `energy`
        (Eh) not below `threshold` (Eh), with starts left; else None."""
        if phase == "grow" and nb == min(self.opts.size, RESTART_AT) and self.restarts < RESTARTS \
                and not energy < threshold:
            return Adaptive(self.opts, restarts=self.restarts + 1)
        return None

    def stall(self, nb: int) -> bool:
        """Growth stalled at `nb` functions (methods.Grow): the basis keeps that size and the
        schedule goes on (True)."""
        self.stalled = nb
        return True

    def first(self) -> Cursor:
        """The cursor of a new run: growth from no function."""
        return self.begin("grow", 0, 0)

    def begin(self, kind: str, nb: int, number: int) -> Cursor:
        """The cursor at the start of pass `number` of `kind` on a basis of `nb` functions: growth
        targets a quarter more (at least GROWTH, at most the size), a pruning `pruned(nb)` functions
        more, a sweep goes on where the last pass of its kind stopped."""
        if kind == "grow":
            return Cursor("grow", target=min(self.size, nb + max(GROWTH, nb // 4)), number=number)
        if kind == "prune":
            return Cursor("prune", target=nb + pruned(nb), number=number)
        return Cursor(kind, index=self.next.get(kind, 0) % max(nb, 1), number=number)

    def cursor(self, progress, nb: int) -> Cursor:
        """The cursor of a checkpoint's "progress" block on a basis of `nb` functions (Cursor.to_dict),
        also of one written before each field had one meaning (cursor.OLD: a growth pass's target
        and a sweep pass's functions visited in `sweep`, the pass in `cycle`); TypeError or
        InputError for one that is malformed."""
        if not (isinstance(progress, dict) and set(progress) <= OLD):
            return Cursor(**progress)
        old = Cursor(**progress)
        target = {"grow": old.sweep, "prune": nb + pruned(nb)}.get(old.phase, 0)
        visited = old.sweep if old.phase in ("sweep", "refine") else 0
        return Cursor(old.phase, target=target, index=old.index, number=old.cycle, visited=visited)

    def resume(self, cursor: Cursor, stopped: str | None, nb: int, energy: float,
               now: float) -> tuple[Cursor, str | None]:
        """The cursor and stop reason of a run that starts at `cursor` with `nb` functions at
        `energy` after `now` seconds, having stopped for `stopped`: one that ended exhausted or at
        its budget's end, resumed with a budget, chooses again, the budget overriding exhaustion
        (module docstring), and is "done" only if it still ends."""
        if cursor.phase != "done" or stopped not in ("exhausted", "budget") or self.opts.budget is None:
            return cursor, stopped
        kind = self.choose(nb, energy, now)
        if kind is None:
            return Cursor("done"), self.stopped
        return self.begin(kind, nb, len(self.passes)), None

    def tolerance(self, energy: float) -> float:
        """The gain (Eh) of a whole sweep below which the basis counts as converged."""
        return self.opts.tolerance if self.opts.tolerance is not None else TOLERANCE * abs(energy)

    def advance(self, cursor: Cursor, nb: int, energy: float, now: float, functions: int = 1) -> Cursor:
        """The unit of work after the one at `cursor`, which visited `functions` functions of a
        sweep and left `nb` functions at `energy` after `now` seconds of the run; at the end of a
        pass it is recorded and the next one chosen."""
        phase, visited = cursor.phase, cursor.visited + functions
        if phase == "grow" and nb < min(cursor.target, self.size):
            return cursor
        if phase in ("sweep", "refine"):
            self.next[phase] = (cursor.index + functions) % nb
            if visited < min(CHUNK, nb):
                return Cursor(phase, index=self.next[phase], number=cursor.number, visited=visited)
        functions = visited if phase in ("sweep", "refine") else nb
        self.passes.append(Pass(phase, nb, self.start.energy, energy, self.start.seconds, now, functions))
        self.start = Start(energy, now)
        kind = self.choose(nb, energy, now)
        return Cursor("done") if kind is None else self.begin(kind, nb, cursor.number + 1)

    def rates(self) -> dict:
        """Each kind's rate (Eh/s), that of its last pass with its share of the move after it
        (module docstring): the gains of the passes at full size that moved functions since the
        last move, times 1 + the move's gain over theirs; a pass whose move has not come (yet,
        or a pruning came first) with the factor of its kind's last move."""
        rates, share, stretch = {}, {}, []
        for p in self.passes + [None]:
            if p is not None and p.kind in MOVES and p.size >= self.size:
                stretch.append(p)
                continue
            if p is not None and p.kind == "momentum":
                total = sum(q.gain for q in stretch)
                share.update((q.kind, 1.0 + p.gain / total if total > 0 else 1.0) for q in stretch)
            for q in stretch:
                rates[q.kind] = share.get(q.kind, 1.0) * q.rate
            stretch = []
            if p is not None and p.kind != "momentum":
                rates[p.kind] = p.rate
        return rates

    def best(self) -> float:
        """The best rate (`rates`) of the kinds that improve a basis."""
        return max(r for k, r in self.rates().items() if k in IMPROVE)

    def seconds(self, kind: str) -> float:
        """The seconds of the shortest of the last three passes of `kind` (a pass on a busy machine
        takes longer)."""
        return max(min([p.end - p.start for p in self.passes if p.kind == kind][-3:]), 1e-3)

    def due(self, nb: int) -> bool:
        """Whether the basis of `nb` functions moves on along its displacement (module docstring):
        at full size, EVERY passes at that size that moved functions (refinement, replacement,
        joint) since the last move or pruning."""
        count = 0
        for p in reversed(self.passes):
            if p.kind in ("momentum", "prune"):
                break
            count += p.kind in MOVES and p.size == nb
        return nb >= self.size and count >= EVERY

    def kinds(self, nb: int) -> tuple:
        """The kinds that improve a basis of `nb` functions: pruning only at full size."""
        return IMPROVE if nb >= self.size else tuple(k for k in IMPROVE if k != "prune")

    def advantage(self, nb: int) -> float | None:
        """The reference rate (module docstring) over the best last rate of a kind of pass, at full
        size `nb`; None while the basis grows, before every kind has run or when none gains."""
        last = {p.kind: p for p in self.passes}
        if nb < self.size or any(k not in last for k in IMPROVE):
            return None
        grow = last.get("grow")
        if grow is not None and math.isfinite(grow.gain):
            reference = grow.rate
        else:
            reference = max((p.rate for p in self.passes if p.kind in IMPROVE and p.size == nb), default=0.0)
        best = self.best()
        return reference / best if best > 0 else None

    def stop(self, last: dict, nb: int, energy: float, now: float) -> str | None:
        """Why the schedule ends at full size — "converged", "budget" or "exhausted" — or None (module
        docstring); `now`: seconds of the run."""
        tolerance = self.tolerance(energy)
        if all(last[k].gain * nb / last[k].functions < tolerance for k in IMPROVE):
            return "converged"
        if self.opts.budget is not None:
            left = self.opts.budget - now
            return "budget" if self.best() * left < tolerance else None  # the seconds left buy nothing
        advantage = self.advantage(nb)
        return "exhausted" if advantage is not None and advantage > 1 / RATIO else None

    def choose(self, nb: int, energy: float, now: float) -> str | None:
        """The kind of the next pass, or None when the schedule ends (`stopped` says why; module
        docstring); `now`: seconds of the run."""
        last = {p.kind: p for p in self.passes}
        growing = nb < self.size
        if growing and "grow" not in last:
            return "grow"
        untried = [k for k in self.kinds(nb) if k not in last]
        if untried:
            return untried[0]
        if not growing:
            self.stopped = self.stop(last, nb, energy, now)
            if self.stopped is not None:
                return None
            if self.due(nb):
                return "momentum"
        stale = [k for k in self.kinds(nb) if now - last[k].end > REVISIT * self.seconds(k)]
        if stale:
            return min(stale, key=lambda k: last[k].end)
        rates = self.rates()
        return max((("grow",) if growing else ()) + self.kinds(nb), key=rates.get)

    def progress(self, cursor: Cursor, nb: int) -> tuple[str, int, int]:
        """(description, done, total) of the progress line: functions grown, or functions visited
        in the pass (one step for a whole-basis pass)."""
        if cursor.phase == "grow":
            return "growing", nb, self.opts.size
        done, total = (cursor.visited + 1, min(CHUNK, nb)) if cursor.phase not in ("polish", "prune", "momentum") else (1, 1)
        return f"{cursor.phase} (pass {cursor.number + 1})", done, total

    def to_dict(self) -> dict:
        """The checkpoint's "schedule" block (a pass as the list of its fields)."""
        return {"passes": [p.row() for p in self.passes], "start": self.start.row(), "next": self.next,
                "stalled": self.stalled, "restarts": self.restarts}

    @classmethod
    def check(cls, opts: Optimiser, block) -> "Adaptive":
        """The schedule of a checkpoint's "schedule" block (`to_dict`; absent in the checkpoints of
        fixed schedules written before it); ValueError for one that is malformed."""
        if block is None:
            return cls(opts)

        def count(k):
            return type(k) is int and k >= 0

        def energy(e):
            return e is None or (isinstance(e, (int, float)) and not isinstance(e, bool) and math.isfinite(e))

        def seconds(t):
            return isinstance(t, (int, float)) and not isinstance(t, bool) and math.isfinite(t) and t >= 0

        def began(e, t):
            return energy(e) and seconds(t)

        def one(p):
            if not (isinstance(p, list) and len(p) == len(fields(Pass))):
                return False
            p = Pass(*p)
            return (p.kind in ("grow", "momentum") + IMPROVE and count(p.size) and energy(p.before)
                    and p.after is not None and energy(p.after) and seconds(p.start) and seconds(p.end)
                    and count(p.functions) and p.functions > 0)

        passes, start, nxt, stalled = ((block.get("passes"), block.get("start"), block.get("next"),
                                        block.get("stalled")) if isinstance(block, dict) else (None,) * 4)
        restarts = block.get("restarts", 0) if isinstance(block, dict) else 0  # absent before 810d62f
        if not (isinstance(passes, list) and all(map(one, passes)) and isinstance(start, list) and len(start) == 2
                and began(*start) and isinstance(nxt, dict)
                and set(nxt) == {"refine", "sweep"} and all(map(count, nxt.values()))
                and (stalled is None or count(stalled)) and count(restarts)):
            raise ValueError("schedule must be {passes: [[kind, n_b, E before, E after, t before, t after, "
                             "functions], ...], start: [E, t], next: {refine: i, sweep: j}, stalled: n_b or null, "
                             "restarts: n}")
        return cls(opts, [Pass(*p) for p in passes], Start(*start), nxt, stalled, restarts)
