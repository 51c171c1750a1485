"""Convergence plots from run checkpoints: energy against basis size (one line per run).

The growth phase gives one point per basis size; refinement sweeps at the final size are
drawn as a vertical run of points there. With a reference energy the error E - E_ref is
drawn on a logarithmic axis.
"""
from __future__ import annotations

import json
from pathlib import Path

from .errors import BasisFileError


def history(folder: Path) -> list:
    path = Path(folder) / "basis.json"
    try:
        d = json.loads(path.read_text())
    except (OSError, json.JSONDecodeError) as exc:
        raise BasisFileError(f"{path}: cannot read a run checkpoint ({exc})") from exc
    if "history" not in d:
        raise BasisFileError(f"{path}: no optimisation history (not written by `prebo run`)")
    return d["history"]


def convergence(folders: list[Path], png: Path, reference: float | None = None) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for folder in folders:
        h = history(folder)
        n = [row[0] for row in h]
        e = [row[1] - reference if reference is not None else row[1] for row in h]
        ax.plot(n, e, ".-", ms=3, lw=1, label=Path(folder).name)
    ax.set_xlabel("basis size")
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
