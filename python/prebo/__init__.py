"""prebo: pre-Born–Oppenheimer variational solver with explicitly correlated Gaussians.

Pipeline: system → coordinates → basis → integrals → eigen → optimise → results.
"""
from .basis import Basis
from .coordinates import CoordinateSet, all_sets, cm_centred, heavy_particle_centred, jacobi
from .errors import PreboError
from .optimise import Optimiser, optimise
from .system import Particle, particle
from .results import evaluate
from .system import State, System

__all__ = [
    # system building
    "Particle", "particle", "State", "System",
    # coordinates
    "CoordinateSet", "jacobi", "heavy_particle_centred", "cm_centred", "all_sets",
    # basis, solving, results
    "Basis", "Optimiser", "optimise", "evaluate", "PreboError",
]
__version__ = "0.1.0"
