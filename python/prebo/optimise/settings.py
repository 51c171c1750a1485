"""The optimiser's settings: the `Optimiser` dataclass and `SETTINGS`, its table of types, ranges,
meanings and TOML keys, used by `Optimiser.__post_init__` (Python API and checkpoints) and by
the TOML reader. Every refusal is an InputError naming the argument or TOML key, the value and
what is allowed.
"""
from __future__ import annotations

from dataclasses import dataclass, fields

from ..basis.families import FAMILIES
from ..eigen import THRESHOLD
from ..errors import InputError
from ..validation import (MATRICES, MAX_SIZE, Automatic, Channels, Choice, Integer, Lengths, Real, checked,
                          strict_keywords)

REFINE_METHODS = ("powell", "gradient")
#: drawn lengths in units of a pair's Bohr radius: a cusp needs ~1e-3 (exponents ~1e6 a⁻²), a diffuse
#: or Rydberg state ~1e3 (⟨r⟩ ~ n² a); beyond 1e-4..1e4 the functions drawn next to c_A lose their
#: digits (He: every trial refused at 1e4..2e4, A not positive definite at 1e-9..1e-8), and far
#: beyond, their exponents overflow (sampler.py)
LENGTHS = Lengths(1e-4, 1e4)
#: c_A (bohr⁻²): the energy does not depend on it (the CM is eliminated), but far from the internal
#: exponents it costs digits: the stored H, H⁻, He and H 2p bases moved to c_A in 1e-2..1e3 keep their
#: energies within 6e-14 Eh (as any change of A's bits does), at 1e-3 He moves 2e-12, at 1e5 H 6e-13,
#: and a run for H at c_A = 1e6 went below the exact energy
C_A = Real(1e-2, 1e3, True, True)
SCHEDULES = ("adaptive", "fixed")  # the kinds of schedule (schedule.py)
FIXED = ("prune", "sweeps", "refine", "polish", "cycles")  # the fixed schedule's own settings
ADAPTIVE = ("tolerance",)  # the adaptive schedule's own settings


@dataclass(frozen=True)
class Setting:
    """One setting: its rule (type and range, with `.allowed`), meaning and TOML key."""

    rule: object
    meaning: str
    key: str  # in a TOML input


SETTINGS = {
    "schedule": Setting(Automatic(Choice(SCHEDULES)), "the schedule: one that chooses its passes by the energy "
                        "each gains per second, or the fixed one of prune, sweeps, refine, polish and cycles (not "
                        "given: fixed if any of those is given)", "[optimiser] schedule"),
    "size": Setting(Integer(1, MAX_SIZE), f"basis functions; at most {MAX_SIZE}, what {MATRICES} nb x nb "
                    "matrices in this machine's memory allow", "[basis] size"),
    "trials": Setting(Automatic(Integer(1, MAX_SIZE)), "competitive trials per step", "[optimiser] trials"),
    "prune": Setting(Automatic(Integer(0)), "functions grown past the size and pruned again at the start of each "
                     "cycle", "[optimiser] prune"),
    "sweeps": Setting(Automatic(Integer(0)), "random replacement sweeps per cycle", "[optimiser] sweeps"),
    "seed": Setting(Integer(0), "seed of the random numbers", "[optimiser] seed"),
    "channels": Setting(Automatic(Channels()), "coordinate sets the functions are drawn in", "[optimiser] channels"),
    "length_range": Setting(LENGTHS, "range of the drawn lengths in units of each pair's Bohr radius",
                            "[optimiser] length_range"),
    "c_A": Setting(C_A, "exponent of the centre-of-mass coordinate in bohr⁻²", "[basis] c_A"),
    "kind": Setting(Automatic(Choice(tuple(FAMILIES))), "basis type", "[basis] type"),
    "K_max": Setting(Automatic(Integer(0, max(f.K_limit for f in FAMILIES.values()))),
                     "largest power K of a function of a family with powers", "[basis] K_max"),
    "refine": Setting(Automatic(Integer(0)), "refinement sweeps per cycle", "[optimiser] refine"),
    "refine_evaluations": Setting(Automatic(Integer(1)), "energies per refinement of one function",
                                  "[optimiser] refine_evaluations"),
    "refine_method": Setting(Choice(REFINE_METHODS), "refinement minimiser", "[optimiser] refine_method"),
    "refine_group": Setting(Automatic(Integer(1, 8)), "functions a refinement sweep moves together: each with those it "
                            "overlaps most (L-BFGS on exact gradients)", "[optimiser] refine_group"),
    "batch": Setting(Automatic(Integer(1, MAX_SIZE)), "functions of a replacement or refinement sweep worked on at "
                     "once from one basis, shared among the MPI ranks, then put in order, each only if it still "
                     "gains", "[optimiser] batch"),
    "polish": Setting(Automatic(Integer(0)), "joint refinement steps per cycle", "[optimiser] polish"),
    "polish_iterations": Setting(Integer(1), "L-BFGS iterations per joint step", "[optimiser] polish_iterations"),
    "cycles": Setting(Automatic(Integer(1)), "repetitions of the prune-sweep-refine-polish block", "[optimiser] cycles"),
    "budget": Setting(Automatic(Real(0.0)), "wall-time budget of the run in seconds", "[optimiser] budget"),
    "tolerance": Setting(Automatic(Real(0.0)), "energy gain (Eh) below which a pass over the basis counts as "
                         "converged (adaptive schedule)", "[optimiser] tolerance"),
    "learned": Setting(Real(0.0, 1.0, True, True), "share of trials from the learned distributions",
                       "[optimiser] learned"),
    "near": Setting(Automatic(Real(0.0, 1.0, True, True)), "share of a growth step's trials drawn near the basis: "
                    "functions of it perturbed at their own scale (> 0: a sweep's trials all move the function "
                    "replaced)", "[optimiser] near"),
    "learn_after": Setting(Integer(1), "functions of a channel before its distribution is learned",
                           "[optimiser] learn_after"),
    "min_norm": Setting(Real(0.0, 1.0), "smallest part of a trial orthogonal to the basis, relative to its norm",
                        "[optimiser] min_norm"),
    "max_overlap": Setting(Real(0.0, 1.0, hi_closed=True), "largest normalised overlap of a trial with a function",
                           "[optimiser] max_overlap"),
    "threshold": Setting(Real(0.0, 1.0), "relative overlap eigenvalue below which directions are dropped",
                         "[optimiser] threshold"),
}


def check(name: str, value, label: str | None = None):
    """`value` of setting `name`, normalised (ints, floats, a tuple for length_range); InputError
    naming `label` (default: the name), the value and what is allowed."""
    s = SETTINGS[name]
    return checked(s.rule, value, label or name, s.meaning)


@strict_keywords
@dataclass
class Optimiser:
    """Settings of `optimise` (TOML table [optimiser]; `size`, `c_A`, `kind`, `K_max` from [basis]).
    Checked on construction (InputError naming the setting, the value and what is allowed). A
    setting left at None is chosen for the system by `defaults.resolved` when the run starts.

    Basis: size — functions to grow to (≤ MAX_SIZE, what memory allows); kind — the basis
    family ("pecg", "ecg-gvr", "fecg"); c_A — exponent of the CM coordinate in bohr⁻², shared by
    every function (1e-2..1e3, `C_A`); K_max — largest power K of a function (ECG-GVR: 0..60, its K_limit).
    Sampling: trials — competitive trials per step; seed — of the random numbers; channels —
    "pairs", "all" or a list of coordinate-set names the functions are drawn in; length_range —
    [lo, hi] of the drawn lengths in units of each pair's Bohr radius (sampler.pair_lengths; within
    1e-4..1e4, `LENGTHS`);
    learned — share of trials from the learned per-channel distributions (0..1); learn_after —
    functions of a channel before its distribution is learned; near — share of a growth step's
    trials that perturb functions of the basis at their own scale; with near > 0 a replacement
    sweep's trials all move the function replaced (sampler.py; chosen by the schedule when not
    given).
    Schedule: schedule — "adaptive" chooses itself (adaptive.py: growth, refinement, replacement,
    joint and pruning passes by the energy each gains per second), stopping at `budget` seconds,
    or when every kind of pass gains less than `tolerance` Eh; "fixed" (fixed.py) runs the
    settings FIXED; not given (inputs written before it), fixed if any of FIXED is given, else
    adaptive (schedule.kind_of); given, a setting of the other kind (FIXED, ADAPTIVE) is refused.
    prune — functions grown
    past `size` and then removed, those whose removal costs least, at the start of each cycle; sweeps — replacement
    sweeps per cycle; refine — refinement sweeps per cycle (and refinement of every grown or
    replacing function when > 0); polish — joint L-BFGS steps per cycle; cycles — repetitions of
    the prune-sweep-refine-polish block; `budget` still stops it. refine_evaluations — energies per
    refinement of one function; refine_method — "gradient" (L-BFGS, exact gradients) or
    "powell"; refine_group — functions a refinement sweep moves together (1: one at a time; k: each
    with the k - 1 it overlaps most, always by L-BFGS; chosen by the schedule when not given);
    batch — functions of a replacement or refinement sweep worked on at once, each from the same
    basis, shared among the MPI ranks, then put one after the other, each only if it still lowers
    the energy (methods.together; default: the number of ranks, 1 in one process);
    polish_iterations — iterations per joint step.
    Linear dependence: min_norm — smallest part of a trial orthogonal to the basis, relative to
    its norm; max_overlap — largest normalised overlap of a trial with a function; threshold —
    relative overlap eigenvalue below which eigen.solve drops directions.
    """

    schedule: str | None = None
    size: int = 50
    trials: int | None = None
    sweeps: int | None = None
    prune: int | None = None
    seed: int = 1
    channels: str | list | None = None
    length_range: tuple = (0.01, 15.0)
    c_A: float = 1.0
    kind: str | None = None
    K_max: int | None = None
    refine: int | None = None
    refine_evaluations: int | None = None
    refine_method: str = "gradient"
    refine_group: int | None = None
    batch: int | None = None
    polish: int | None = None
    polish_iterations: int = 20
    cycles: int | None = None
    budget: float | None = None
    tolerance: float | None = None
    learned: float = 0.5
    learn_after: int = 5
    near: float | None = None
    min_norm: float = 1e-8
    max_overlap: float = 0.99
    threshold: float = THRESHOLD

    def to_dict(self) -> dict:
        """The settings as a JSON-ready mapping (a checkpoint's "optimiser")."""
        return vars(self) | {"length_range": list(self.length_range)}

    @classmethod
    def from_dict(cls, d: dict) -> "Optimiser":
        """The settings of a mapping (`to_dict`'s); InputError for anything unknown or out of range."""
        if not isinstance(d, dict):
            raise InputError(f"optimiser settings must be a table, got {d!r}")
        return cls(**d)

    def __post_init__(self):
        for f in fields(self):
            setattr(self, f.name, check(f.name, getattr(self, f.name), f"Optimiser {f.name}"))
        if self.schedule is not None:
            other, theirs = {"fixed": ("adaptive", ADAPTIVE), "adaptive": ("fixed", FIXED)}[self.schedule]
            given = next((k for k in theirs if getattr(self, k) is not None), None)
            if given is not None:
                raise InputError(f"{SETTINGS[given].key} = {getattr(self, given)!r}: a setting of the {other} "
                                 f"schedule, but schedule = {self.schedule!r}")
