"""Stochastic basis optimisation, in the order a run uses it:

settings (Optimiser, SETTINGS) → sampler (random functions) → expansion (the basis with its
matrices and eigen-solution; objective: the roots the methods lower, and their following) → methods (grow, replace,
refine, prune, polish, momentum: small configs, each one unit of work) run by the one driver
(`optimise`) where the schedule says (schedule: the interface and its kinds, a module each;
cursor: the next unit of work) → history and convergence (the report), checkpoint (the
run's files), resume (a run read back), lowest (the lowest state passed through) and report
(the live line). parametrisation, refine and polish hold the θ ↔ function mapping and the local
and joint minimisers the methods use; momentum the move along the basis's displacement.
"""
from .checkpoint import CHECKPOINT
from .cursor import Cursor
from .driver import optimise, resume_from
from .expansion import Expansion
from .methods import Grow, Minimiser, MomentumMove, Polish, PrunePass, PruneStep, Refine, Replace
from .resume import load_checkpoint
from .sampler import Sampler, coordinate_sets
from .settings import SETTINGS, Optimiser, check

__all__ = ["Optimiser", "SETTINGS", "check", "optimise", "resume_from", "load_checkpoint", "CHECKPOINT", "Cursor",
           "Expansion", "Sampler", "coordinate_sets", "Grow", "Replace", "Refine", "PruneStep", "PrunePass",
           "Polish", "MomentumMove", "Minimiser"]
