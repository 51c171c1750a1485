"""`prebo plot`: energy against basis size of runs, or the distance distributions of a basis's levels."""
from __future__ import annotations

import os
from pathlib import Path

from ..errors import OutputError, PreboError
from .arguments import distance, finite, natural, positive_integer
from ..io.load import load_basis
from .files import given, output_file


def add(sub) -> None:
    """The `prebo plot` subcommand, added to the subparsers `sub`."""
    p = sub.add_parser("plot", help="energy against basis size of one or more runs, or the distance "
                                    "distributions of a basis's levels (PNG)")
    p.add_argument("runs", nargs="+", type=Path, help="run folders (with basis.json checkpoints); with --densities "
                                                      "one basis.json or ecgpack FILE.inout.txt")
    p.add_argument("--densities", action="store_true",
                   help="draw P(r) of every inter-particle distance and every particle's distance from the centre "
                        "of mass (and write the table as CSV beside the picture)")
    p.add_argument("--roots", type=natural, nargs="+", metavar="K", help="with --densities: the levels (default 0)")
    p.add_argument("--rmax", type=distance, metavar="R",
                   help="with --densities: the grid's end in bohr (default: 5 root-mean-square distances)")
    p.add_argument("--points", type=positive_integer, metavar="N", help="with --densities: grid points (default 400)")
    p.add_argument("--reference", type=finite, help="exact energy: plot E - E_ref on a log axis")
    p.add_argument("--since", type=finite, metavar="SECONDS",
                   help="only the wall time from then on, against time (runs branched from one checkpoint)")
    p.add_argument("--log-time", action="store_true", help="wall time on a logarithmic axis (runs of minutes and days)")
    p.add_argument("--out", help="image file, .png (the default suffix), .pdf or .svg, or a folder for its "
                                  "convergence.png (default FIRST-RUN/convergence.png)")
    p.add_argument("--force", action="store_true", help="replace an existing image file")
    p.set_defaults(func=command)


def command(args) -> int:
    """`prebo plot RUN... [--reference E] [--since S] [--log-time] [--out PNG|DIR] [--force]`:
    convergence plot of run checkpoints (into DIR/convergence.png for an existing folder DIR);
    `prebo plot --densities BASIS [--roots K...] [--rmax R] [--points N] [--out PNG] [--force]`: the
    distance distributions of levels, the picture and its CSV table beside it."""
    if args.densities:
        return plot_densities(args)
    given_options = [o for o, v in (("--roots", args.roots), ("--rmax", args.rmax), ("--points", args.points)) if v]
    if given_options:
        from ..errors import InputError
        raise InputError(f"{', '.join(given_options)}: only with --densities")
    from ..optimise.checkpoint import CHECKPOINT
    from ..plot import convergence

    default = Path(args.runs[0]) / "convergence.png"
    png = given(args.out, default, "an image file or a folder")
    if png.is_dir() or args.out is not None and args.out.endswith(os.sep):  # "DIR/": a folder, as in `cp`
        png = png / default.name
    png = output_file(png if png.suffix else png.with_suffix(".png"), args.force,
                      [run / CHECKPOINT for run in args.runs])
    try:
        convergence(args.runs, png, args.reference, args.since, args.log_time)
    except OSError as exc:
        raise OutputError(f"{png}: cannot write ({exc.strerror})") from exc
    print(f"wrote {png}")
    return 0


def plot_densities(args) -> int:
    """`prebo plot --densities`: properties.densities of one stored basis, drawn (plot.densities)
    into BASIS.densities.png (or --out) and tabulated into the same name with .csv."""
    import numpy as np

    from ..errors import InputError
    from ..io import stored
    from ..io.files import write_atomic
    from ..level.properties import POINTS, csv_text, densities
    from ..plot import densities as draw

    if len(args.runs) != 1:
        raise InputError(f"--densities draws one basis, not {len(args.runs)} ({' '.join(map(str, args.runs))})")
    source = args.runs[0]
    default = Path(stored.stem(source) + ".densities.png")
    png = given(args.out, default, "an image file")
    png = output_file(png if png.suffix else png.with_suffix(".png"), args.force, [source])
    table_file = output_file(png.with_suffix(".csv"), args.force, [source])
    basis, stored = load_basis(source)
    points = args.points or POINTS
    r = None if args.rmax is None else np.linspace(0.0, args.rmax, points)
    try:
        table = densities(basis, args.roots or [0], r, points, threshold=stored)
    except PreboError as exc:
        raise type(exc)(f"{source}: {exc}") from exc
    try:
        draw(table, png)
        write_atomic(table_file, csv_text(table))
    except OSError as exc:
        raise OutputError(f"{png}: cannot write ({exc.strerror})") from exc
    print(f"wrote {png} and {table_file}")
    return 0
