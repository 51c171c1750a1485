"""The pictures: convergence plots from run checkpoints (`convergence`) and the distance
distributions of levels (`densities`).

Convergence: energy against basis size and against wall time (one line per run); for a run for
excited levels the objective it lowers, Σ w_k E_k of the targeted levels, and the axis says so.

The growth phase gives one point per basis size; refinement sweeps at the final size are
drawn as a vertical run of points there, and spread out in the wall-time panel (histories
written before wall times were recorded leave that panel out). With a reference energy the
error E - E_ref is drawn on a logarithmic axis, and with `log_time` the wall time too: runs of
minutes and of days side by side. From a given wall time on (`since`), only the time panel is
drawn, each run starting from its state at that moment: branches of one checkpoint compared from
where they parted.
"""
from __future__ import annotations

import io
from pathlib import Path

from .errors import BasisFileError, InputError

#: the image formats `convergence` writes, by the file's suffix
FORMATS = (".png", ".pdf", ".svg")


def history(folder: Path) -> tuple[list, list | None]:
    """The optimisation history of the run checkpoint folder/basis.json: rows [basis size,
    energy (Eh; the objective Σ w_k E_k of a run for excited levels), phase, wall time (s) when
    recorded], and the root indices of those levels (None: the lowest alone); BasisFileError naming
    the file (and the row: history.check_history) if there is none or a row is not one."""
    from .io.basis_json import read
    from .optimise.checkpoint import CHECKPOINT
    from .optimise.history import check_history

    path = Path(folder) / CHECKPOINT
    d = read(path)
    if not (isinstance(d, dict) and "history" in d):
        raise BasisFileError(f"{path}: no optimisation history (not written by `prebo run`)")
    try:
        return check_history(d["history"]), d.get("levels")
    except ValueError as exc:
        raise BasisFileError(f"{path}: {exc}") from None


def since(h: list, seconds: float, where: str = "run") -> list:
    """The rows of history `h` after wall time `seconds`, led by the state at that moment (the
    last row at or before it, its time set to `seconds`); BasisFileError for a history without
    wall times or with nothing at or before `seconds`."""
    if not all(len(row) > 3 for row in h):
        raise BasisFileError(f"{where}: its history has no wall times")
    before = [row for row in h if row[3] <= seconds]
    if not before:
        raise BasisFileError(f"{where}: nothing in its history at or before {seconds:g} s")
    return [before[-1][:3] + [seconds]] + [row for row in h if row[3] > seconds]


def convergence(folders: list[Path], png: Path, reference: float | None = None, start: float | None = None,
                log_time: bool = False) -> Path:
    """Plot the energies (Eh) of the runs in `folders` against basis size (and wall time, minutes)
    into the PNG file `png`; with `reference` (Eh) E - E_ref on a log axis; with `start` (s) only
    the wall time from then on (`since`: runs branched from one checkpoint); with `log_time` the
    wall time on a log axis (its rows at time zero left out). Returns `png`.
    InputError for a suffix not in FORMATS or a reference not below every energy plotted."""
    plt = pyplot(png)
    read = [history(folder) for folder in folders]
    runs = [(Path(folder).name, h) for folder, (h, _) in zip(folders, read)]
    # a run for excited levels records the objective it lowers, Σ w_k E_k, not one level's energy
    quantity = "E" if all(levels is None for _, levels in read) else "Σ w_k E_k"
    if start is not None:
        runs = [(name, since(h, start, str(folder))) for (name, h), folder in zip(runs, folders)]
    for name, h in runs:
        if reference is not None and min(row[1] for row in h) <= reference:
            raise InputError(f"--reference {reference!r} Eh is not below the energies of run {name} (lowest "
                             f"{min(row[1] for row in h)!r} Eh): {quantity} - E_ref is drawn on a logarithmic axis")
    timed = all(len(row) > 3 for _, h in runs for row in h)
    panels = [p for p, shown in (("size", start is None), ("time", timed)) if shown]
    fig, axes = plt.subplots(1, len(panels), figsize=(5.75 * len(panels) + 0.65 * (len(panels) == 1), 4.4),
                             squeeze=False)
    t0 = start or 0.0
    for name, h in runs:
        e = [row[1] - reference if reference is not None else row[1] for row in h]
        for ax, panel in zip(axes[0], panels):
            x = [row[0] for row in h] if panel == "size" else [(row[3] - t0) / 60 for row in h]
            shown = [k for k, xi in enumerate(x) if xi > 0 or not (panel == "time" and log_time)]
            ax.plot([x[k] for k in shown], [e[k] for k in shown], ".-", ms=3, lw=1, label=name)
    for ax, panel in zip(axes[0], panels):
        ax.set_xlabel("basis size" if panel == "size" else
                      "wall time / min" if start is None else f"wall time after {start:g} s / min")
        if panel == "time" and log_time:
            ax.set_xscale("log")
        if reference is not None:
            ax.set_yscale("log")
            ax.set_ylabel(f"{quantity} − E_ref  (E_ref = {reference} Eh)")
        else:
            ax.set_ylabel(f"{quantity} / Eh (translation-free)")
        ax.grid(alpha=0.3)
        ax.legend()
    return save(fig, png)


def densities(table: dict, png: Path) -> Path:
    """Draw `properties.densities`' table into `png`: one panel per inter-particle distance r_ij and
    per distance r_i − R from the centre of mass, P(r) of each level side by side in it."""
    import numpy as np

    plt = pyplot(png)
    first = table["levels"][0]
    panels = [("pairs", c, f"r({c.replace('-', ', ')})") for c in first["pairs"]] + \
             [("particles", c, f"|r({c}) − R_CM|") for c in first["particles"]]
    columns = min(3, len(panels))
    rows = -(-len(panels) // columns)
    fig, axes = plt.subplots(rows, columns, figsize=(4.6 * columns, 3.6 * rows), squeeze=False)
    for ax, (group, c, label) in zip(axes.flat, panels):
        r = table["r"][group][c]
        for level in table["levels"]:
            ax.plot(r, level[group][c], lw=1.2, label=f"root {level['root']} ({level['energy']:.8f} Eh)")
        # the axis ends where every level's P has fallen below 1e-4 of its peak (the table goes on)
        seen = [r[np.abs(level[group][c]) > 1e-4 * np.abs(level[group][c]).max()] for level in table["levels"]]
        ax.set_xlim(0.0, 1.05 * max((x.max() for x in seen if len(x)), default=r.max()) or None)
        ax.set_xlabel(f"{label} / bohr")
        ax.set_ylabel("P(r) / bohr⁻¹")
        ax.grid(alpha=0.3)
    for ax in axes.flat[len(panels):]:
        ax.set_visible(False)
    axes.flat[0].legend(fontsize="small")
    return save(fig, png)


def polarisability(omega, alpha, pole: float, png: Path) -> Path:
    """Draw α(ω) (a₀³) at the frequencies `omega` (Eh) below the first `pole` into `png`."""
    plt = pyplot(png)
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    ax.plot(omega, alpha, lw=1.4)
    ax.axvline(pole, color="grey", ls="--", lw=1.0, label=f"first pole, {pole:.8f} Eh")
    ax.set_yscale("log")
    ax.set_xlabel("ω / Eh")
    ax.set_ylabel("α(ω) / a₀³")
    ax.grid(alpha=0.3)
    ax.legend()
    return save(fig, png)


def pyplot(png: Path):
    """matplotlib.pyplot without a display; InputError for a suffix not in FORMATS."""
    if Path(png).suffix.lower() not in FORMATS:
        raise InputError(f"{png}: an image file ends in {', '.join(FORMATS)}")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save(fig, png: Path) -> Path:
    """Write `fig` into `png` at once (never half an image) and close it."""
    import matplotlib.pyplot as plt

    from .io.files import write_atomic

    fig.tight_layout()
    image = io.BytesIO()
    fig.savefig(image, format=Path(png).suffix[1:].lower(), dpi=130)
    plt.close(fig)
    write_atomic(png, image.getvalue())
    return Path(png)
