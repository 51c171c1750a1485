"""Convergence plots from run checkpoints: energy against basis size and against wall time
(one line per run).

The growth phase gives one point per basis size; refinement sweeps at the final size are
drawn as a vertical run of points there, and spread out in the wall-time panel (histories
written before wall times were recorded leave that panel out). With a reference energy the
error E - E_ref is drawn on a logarithmic axis.
"""
from __future__ import annotations

import json
from pathlib import Path

from .errors import BasisFileError


def history(folder: Path) -> list:
    """The optimisation history of the run checkpoint folder/basis.json: rows [basis size,
    energy (Eh), ..., wall time (s) when recorded]; BasisFileError if there is none."""
    path = Path(folder) / "basis.json"
    try:
        d = json.loads(path.read_text())
    except (OSError, json.JSONDecodeError) as exc:
        raise BasisFileError(f"{path}: cannot read a run checkpoint ({exc})") from exc
    if "history" not in d:
        raise BasisFileError(f"{path}: no optimisation history (not written by `prebo run`)")
    return d["history"]


def convergence(folders: list[Path], png: Path, reference: float | None = None) -> Path:
    """Plot the energies (Eh) of the runs in `folders` against basis size (and wall time, minutes)
    into the PNG file `png`; with `reference` (Eh) E - E_ref on a log axis. Returns `png`."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    runs = [(Path(folder).name, history(folder)) for folder in folders]
    timed = all(len(row) > 3 for _, h in runs for row in h)
    fig, axes = plt.subplots(1, 2 if timed else 1, figsize=(11.5 if timed else 6.4, 4.4), squeeze=False)
    for name, h in runs:
        e = [row[1] - reference if reference is not None else row[1] for row in h]
        axes[0, 0].plot([row[0] for row in h], e, ".-", ms=3, lw=1, label=name)
        if timed:
            axes[0, 1].plot([row[3] / 60 for row in h], e, ".-", ms=3, lw=1, label=name)
    axes[0, 0].set_xlabel("basis size")
    if timed:
        axes[0, 1].set_xlabel("wall time / min")
    for ax in axes[0]:
        if reference is not None:
            ax.set_yscale("log")
            ax.set_ylabel(f"E − E_ref  (E_ref = {reference} Eh)")
        else:
            ax.set_ylabel("E / Eh (translation-free)")
        ax.grid(alpha=0.3)
        ax.legend()
    fig.tight_layout()
    fig.savefig(png, dpi=130)
    plt.close(fig)
    return Path(png)
