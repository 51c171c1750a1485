"""The convergence report of a run (result.json's "convergence"), from its history of accepted
steps (history.Step), since the last pruning (a basis grown past its size and pruned
back starts again from a higher energy; methods.PruneStep):

- `stopped`: why the run ended, a key of STOPPED (each schedule's reasons, schedule.py) — and
  `seconds` of optimisation over every segment of the run;
- the kind of schedule and its `advantage` (the kind's `report`): where the schedule measures
  rates, at full size, how many times faster than the best kind of pass growth was gaining at the
  end (Schedule.advantage; above 1/RATIO a larger basis is the better use of time), else None;
- `stalled`: where growth stopped short of `size` in a schedule that goes on (Schedule.stall:
  every trial refused; the basis kept the size it reached), with the settings to change, or None;
- `recent`: the energy gained by the last RECENT accepted steps, the seconds they span and the
  gain rate in Eh/s;
- `extrapolation`: from the energies E₁, E₂, E₃ at three equally spaced times between the end of
  growth and the last step, gains g₁ = E₁ − E₂ and g₂ = E₂ − E₃, the gain still to be had at
  this basis size, g₂²/(g₁ − g₂), were the gains to keep falling geometrically (Aitken's Δ²
  process), and the energy E₃ less that; none while the gains are not yet falling; with the
  caveat that says what the figure is and is not.
"""
from __future__ import annotations

from .history import Step
from .methods import stalled
from .schedule import kind_of
from .settings import Optimiser

RECENT = 10
#: why a run stopped, as the result table says it (None: interrupted, or not yet stopped)
STOPPED = {"converged": "converged at this basis size (gains below the tolerance)",
           "exhausted": "basis exhausted (a larger basis would gain faster)", "budget": "wall-time budget used",
           "schedule": "schedule completed", None: "interrupted"}
CAVEAT = ("the gain still to be had at this basis size were the gains to keep falling geometrically (Aitken's "
          "delta-squared over three equal spans of time since growth ended); not the error against the exact "
          "energy, which also holds the error of the basis size; too small where the gains fall more slowly "
          "(as a power of the time), or where the run would still find a deeper basin")


def energy_at(steps: list[Step], t: float) -> float:
    """The energy of the last step taken by time `t` (seconds)."""
    return [h.energy for h in steps if h.seconds <= t][-1]


def convergence(history: list[Step], opts: Optimiser, stopped: str | None, seconds: float,
                stalled_at: int | None = None, advantage: float | None = None, condition: float = 0.0,
                sigma: float = 0.0) -> dict:
    """The report of a run with `history` (module docstring); `stalled_at`: the size at which growth
    stalled; `advantage`: the schedule's (Schedule.advantage); `condition`, `sigma`: the basis's overlap
    condition and energy uncertainty (Eh)."""
    steps = [h for h in history if h.seconds is not None]
    pruned = [k for k in range(1, len(steps)) if steps[k].size < steps[k - 1].size]
    steps = steps[pruned[-1]:] if pruned else steps
    why = None if stalled_at is None else {"size": stalled_at, "why": stalled(stalled_at, opts, condition, sigma)}
    report = ({"stopped": stopped, "seconds": seconds} | kind_of(opts).report(advantage)
              | {"recent": None, "extrapolation": None, "stalled": why})
    if len(steps) >= 2:
        last = steps[-min(RECENT + 1, len(steps)):]
        gain, span = last[0].energy - last[-1].energy, last[-1].seconds - last[0].seconds
        report["recent"] = {"steps": len(last) - 1, "gain": gain, "seconds": span,
                            "rate": gain / span if span > 0 else None}
    final = [h for h in steps if h.size == steps[-1].size] if steps else []
    if len(final) >= 3 and final[-1].seconds > final[0].seconds:
        t0, T = final[0].seconds, final[-1].seconds
        E1, E2, E3 = (energy_at(final, t0 + k * (T - t0) / 3) for k in (1, 2, 3))
        g1, g2 = E1 - E2, E2 - E3
        if g1 > g2:
            remaining = g2 * g2 / (g1 - g2)
            report["extrapolation"] = {"energy": E3 - remaining, "remaining": remaining, "gains": [g1, g2],
                                       "caveat": CAVEAT}
    return report
