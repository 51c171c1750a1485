"""Stochastic basis optimisation, in the order a run uses it:

settings (Optimiser, SETTINGS) → sampler (random functions) → expansion (the basis with its
matrices and eigen-solution) → methods (grow, prune, sweep, refine, polish: small configs, each one
unit of work) run by the one driver (`optimise`) → checkpoint (cursor, basis.json run state) and
report (the live line). parametrisation, refine and polish hold the θ ↔ function mapping and the
local and joint minimisers the methods use.
"""
from .checkpoint import CHECKPOINT, Cursor, load_checkpoint
from .driver import optimise, resume_from
from .expansion import Expansion
from .methods import Grow, Polish, Prune, Refine, Refinement, Sweep
from .sampler import Sampler, coordinate_sets
from .settings import SETTINGS, Optimiser, check

__all__ = ["Optimiser", "SETTINGS", "check", "optimise", "resume_from", "load_checkpoint", "CHECKPOINT", "Cursor",
           "Expansion", "Sampler", "coordinate_sets", "Grow", "Prune", "Sweep", "Refine", "Polish",
           "Refinement"]
