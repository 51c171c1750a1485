"""What a run chooses for its system when the input leaves a setting out (an `Optimiser` field at
None), from the physics of the particles:

- the basis family: ECG-GVR functions for N > 0 (plain ECGs describe N = 0 only) and for
  molecules — two or more nuclei of one charge sign, whose relative motion is a vibration about a
  bond length that the powers |v|^{2K} of ECG-GVR functions describe and plain ECGs, centred at
  r = 0, do not (Muolo, Mátyus & Reiher, J. Chem. Phys. 148, 084112 (2018), Sec. III.C);
  plain ECGs otherwise;
- K_max: |v|^{2K} exp(−α v²) peaks at v₀ = (K/α)^½ with relative width ~(4K)^−½, and the
  vibrational width of a bond falls as (μ ω)^−½ ∝ μ^−¼, so K_max grows as (μ_nn/m)^½, μ_nn the
  reduced mass of the nuclei and m the lightest particle's mass: 31 for H2 and H2+, the value
  the paper's tables were computed with (30); 0 for atoms;
- channels: every coordinate set for molecules (functions drawn in Jacobi and heavy-particle
  coordinates reach the vibrating nuclei), the particle pairs otherwise;
- trials per step, refinement energies and groups, trials near the basis: the kind of
  schedule's (schedule.kind_of, its `defaults`), with their reasons beside them (fixed.py and
  the other kind's module), each depending on whether the system is a molecule;
- batch: the number of MPI ranks (parallel.py; 1 in one process), each working on one function
  of a sweep's batch; kept in the checkpoint, so a run resumed on another number of ranks goes on
  as it would have;
- the fixed schedule's own settings, when it is the kind: the missing ones at 0, 0, 0, 0 and 1
  (fixed.SETTINGS).
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ..basis import family
from ..parallel import world
from ..system import System, reduced_mass
from .schedule import kind_of
from .settings import Optimiser

#: a particle this many times heavier than the lightest one moves as a nucleus
HEAVY = 100.0


def nuclei(system: System) -> list[int]:
    """The particles at least HEAVY times as heavy as the lightest one."""
    m = system.masses
    return [i for i in range(system.n) if m[i] >= HEAVY * m.min()]


def molecular_pair(system: System) -> tuple[int, int] | None:
    """The heaviest pair of nuclei of one charge sign (a molecule's bond), or None (an atom)."""
    m, q = system.masses, system.charges
    like = [(i, j) for i in nuclei(system) for j in nuclei(system) if i < j and q[i] * q[j] > 0]
    return max(like, key=lambda pair: reduced_mass(*m[list(pair)]), default=None)


def resolved(opts: Optimiser, system: System) -> Optimiser:
    """`opts` with every setting left at None chosen for `system` (module docstring); the fixed
    schedule's settings stay None in another. Idempotent: a checkpoint's settings are returned
    unchanged."""
    bond = molecular_pair(system)
    kind = opts.kind or ("ecg-gvr" if bond is not None or system.state.N > 0 else "pecg")
    K_max = opts.K_max
    if K_max is None:
        K_max = 0
        limit = family(kind).K_limit  # 0: a family without powers K
        if limit and bond is not None:
            m = system.masses
            K_max = min(limit, math.ceil(np.sqrt(reduced_mass(*m[list(bond)]) / m.min())))
    channels = opts.channels or ("all" if bond is not None else "pairs")
    chosen = kind_of(opts).defaults(opts, bond is not None)
    batch = opts.batch or world().size
    return replace(opts, kind=kind, K_max=K_max, channels=channels, batch=batch,
                   **{k: v if (v := getattr(opts, k)) is not None else d for k, d in chosen.items()})
