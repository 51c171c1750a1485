"""The live progress line of a run: basis size, energy (each targeted level's), last improvement, virial,
trials per second."""
from __future__ import annotations

import time

import numpy as np

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

    def step(self, st: Expansion, old: float, cursor: Cursor, schedule) -> None:
        """Show the expansion after a step at `cursor` of `schedule` (schedule.Schedule) that lowered
        the energy from `old`."""
        if self.progress is None:
            return
        rate = self.n_trials / max(time.perf_counter() - self.t0, 1e-9)
        gain = old - st.energy if np.isfinite(old) else float("nan")
        if st.objective.lowest:  # the lowest root E, or a response functional J
            energy = f"{st.objective.symbol} = {st.energy:.12f}"
        else:  # each targeted level, then the change of the objective Σ w_k E_k
            energy = "  ".join(f"E_{lv.root} = {lv.E:.12f}" for lv in st.objective.levels(st.eig, st.b))
        info = f"{energy}  ΔE = {gain:.2e}  η = {st.virial():.1e}  {rate:.1f} trials/s"
        description, done, total = schedule.progress(cursor, len(st.basis))
        self.progress.update(self.task, description=description, completed=done, total=total, info=info)
