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
- trials per step: adaptive.TRIALS in the adaptive schedule — a trial costs one row of N_b integrals and
  the winner's refinement 30 energies with gradients, (1 + P) rows each, so a wider competition
  is nearly free and picks better functions (H2 with 300 functions after 600 s: 6.7e-7 and
  7.2e-7 Eh above with 100 trials against 1.2e-6 and 2.4e-6 with 30; He with 400 in 300 s:
  7.5e-10 and 8.7e-10 against 1.3–2.1e-9 with 20;
  benchmarks/README, "Trials in the adaptive schedule"); in a fixed one 20, or 30 for molecules;
- near: adaptive.NEAR of an atom's growth trials in the adaptive schedule perturb functions of the basis
  at their own scale, and its sweeps try moves of the function replaced only (sampler.py): He
  with 700 functions in 300 s, 5.1–6.0e-11 Eh above in three runs against 2.7–6.0e-10 with every
  trial drawn (benchmarks/README, "Trials near the basis"); 0 for molecules (H2⁺ from defaults
  ended at 5.5e-7 with it, 5.6e-8 without: the perturbations keep u and K) and in a fixed
  schedule, whose runs are reproduced as they were measured;
- refine_evaluations: adaptive.EVALUATIONS (30) in the adaptive schedule (L-BFGS converges a function in 15–40
  energies, benchmarks/README), 200 in a fixed one;
- refine_group: adaptive.GROUP in the adaptive schedule, whose refinement passes then move each function
  with the GROUP − 1 it overlaps most (near-duplicate partners hold a lone function in place;
  benchmarks/README, "The H2 campaign" and issue 17's rows), 1 in a fixed one;
- batch: the number of MPI ranks (parallel.py; 1 in one process), each working on one function
  of a sweep's batch; kept in the checkpoint, so a run resumed on another number of ranks goes on
  as it would have;
- the schedule's own settings: the fixed schedule's missing ones at 0, 0, 0, 0 and 1
  (fixed.SETTINGS).
Each value that depends on the kind of schedule (schedule.kind_of) is the kind's (`defaults`).
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
