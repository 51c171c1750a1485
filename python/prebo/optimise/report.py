"""The live progress line of a run: basis size, energy (each targeted level's), last improvement, virial,
trials per second."""
from __future__ import annotations

import time

import numpy as np

from .adaptive import CHUNK
from .cursor import Cursor
from .expansion import Expansion
from .settings import Optimiser


class Reporter:
    """A live line (rich) while `enabled`: basis size, energy, last improvement, virial, trials per second;
    it starts at `nb`, the size of the basis the run starts from (a resumed run's)."""

    def __init__(self, opts: Optimiser, enabled: bool, nb: int = 0):
        self.opts, self.enabled, self.nb = opts, enabled, nb
        self.n_trials, self.t0 = 0, time.perf_counter()
        self.progress = None

    def __enter__(self):
        if self.enabled:
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
            self.progress = Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
                                     TimeElapsedColumn(), TextColumn("{task.fields[info]}"))
            self.progress.__enter__()
            self.task = self.progress.add_task("growing", total=max(self.opts.size, self.nb), completed=self.nb,
                                               info="")
        return self

    def __exit__(self, *exc):
        if self.progress is not None:
            self.progress.__exit__(*exc)

    def trials(self, k: int) -> None:
        """Count `k` more trial functions (or refinements) for the rate."""
        self.n_trials += k

    def followed(self, before: tuple, after: tuple) -> None:
        """Say that the targeted levels moved from the roots `before` to `after` (objective.py, following)."""
        if self.progress is not None:
            self.progress.console.print(f"levels followed by overlap: roots {list(before)} → {list(after)}")

    def step(self, st: Expansion, old: float, cursor: Cursor) -> None:
        """Show the expansion after a step that lowered the energy from `old`."""
        if self.progress is None:
            return
        rate = self.n_trials / max(time.perf_counter() - self.t0, 1e-9)
        gain = old - st.energy if np.isfinite(old) else float("nan")
        if st.objective.lowest:
            energy = f"E = {st.energy:.12f}"
        else:  # each targeted level, then the change of the objective Σ w_k E_k
            energy = "  ".join(f"E_{lv.root} = {lv.E:.12f}" for lv in st.objective.levels(st.eig))
        info = f"{energy}  ΔE = {gain:.2e}  η = {st.virial():.1e}  {rate:.1f} trials/s"
        if cursor.phase == "grow":
            self.progress.update(self.task, description="growing", completed=len(st.basis), total=self.opts.size,
                                 info=info)
        elif self.opts.adaptive:
            done, total = (cursor.sweep + 1, min(CHUNK, len(st.basis))) if cursor.phase not in ("polish", "prune", "momentum") \
                else (1, 1)
            self.progress.update(self.task, description=f"{cursor.phase} (pass {cursor.cycle + 1})", completed=done,
                                 total=total, info=info)
        elif cursor.phase == "prune":  # growth past the size: the functions to be pruned again
            self.progress.update(self.task, description=f"prune (cycle {cursor.cycle + 1})",
                                 completed=len(st.basis) - self.opts.size, total=self.opts.prune, info=info)
        elif cursor.phase == "polish":
            self.progress.update(self.task, description=f"polish (cycle {cursor.cycle + 1})", completed=cursor.sweep + 1, total=self.opts.polish,
                                 info=info)
        else:
            self.progress.update(self.task, description=f"{cursor.phase} {cursor.sweep + 1} (cycle {cursor.cycle + 1})",
                                 completed=cursor.index + 1, total=len(st.basis), info=info)
