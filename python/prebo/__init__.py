"""prebo: pre-Born–Oppenheimer variational solver with explicitly correlated Gaussians.

The pipeline, one subpackage or module per stage (docs/architecture.md):

- `prebo.system`: particles (CODATA masses), `System`, `State`, permutational symmetry;
- `prebo.coordinates`: coordinate sets x = U_x r (`CoordinateSet`, `jacobi`, `all_sets`, ...);
- `prebo.basis`: `Basis` and its families (plain ECGs, ECG-GVR, floating ECGs);
- `prebo.integrals`, `prebo.eigen`: matrices and the generalised eigenproblem;
- `prebo.optimise`: `Optimiser` settings and `optimise`, the stochastic variational driver;
- `prebo.level`: the results of a basis's levels: `evaluate`, their energies; `properties`, a
  level's energy, expectation values and their corrections; `densities`, the distance
  distributions of levels; `transitions`, the electric-dipole lines between two bases' levels; `polarisability`, a level's
  dipole polarisability α(ω) from a basis of its first-order function; `bethe_logarithm`, its
  Bethe logarithm ln k₀ from a basis of N = 1;
- `prebo.system.thresholds`: the lowest dissociation threshold, below which a state is bound;
- `prebo.io`: TOML inputs (`io.toml`) and ecgpack files (`io.ecgpack`);
- `prebo.cli`, `prebo.plot`: the command line and convergence plots;
- `prebo.parallel`: MPI ranks sharing a run's integrals (`mpiexec -n R prebo run`; docs/mpi.md).

Hartree atomic units: energies in Eh, lengths in bohr, masses in m_e. The method is that of
Muolo, Mátyus & Reiher, J. Chem. Phys. 148, 084112 (2018).
"""
from .basis import Basis
from .coordinates import CoordinateSet, all_sets, cm_centred, heavy_particle_centred, jacobi
from .errors import PreboError
from .optimise import Optimiser, optimise
from .level.evaluate import evaluate
from .level.properties import densities, properties
from .level.bethe import bethe_logarithm
from .level.response import polarisability
from .level.transitions import transitions
from .system import Particle, State, System, particle

__all__ = [
    # system building
    "Particle", "particle", "State", "System",
    # coordinates
    "CoordinateSet", "jacobi", "heavy_particle_centred", "cm_centred", "all_sets",
    # basis, solving, results
    "Basis", "Optimiser", "optimise", "evaluate", "properties", "densities", "transitions", "polarisability",
    "bethe_logarithm",
    "PreboError",
]
from .provenance import VERSION as __version__  # noqa: E402 (the package metadata's)
