"""`prebo polarisability`: the dipole polarisability of a level from a basis of its first-order function."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..errors import InputError, PreboError
from .arguments import finite, natural, positive_integer
from ..validation import path_name
from ..io.load import basis_file, load_basis
from .files import output_file
from .tables import show


def add(sub) -> None:
    """The `prebo polarisability` subcommand, added to the subparsers `sub`."""
    p = sub.add_parser("polarisability", help="the dipole polarisability α(ω) of a level of N = 0 from a basis of N = 1")
    p.add_argument("ground", help="the level's basis (N = 0): basis.json, a run folder holding one, or an ecgpack file")
    p.add_argument("response", help="the basis of its first-order function (N = 1, opposite parity)")
    p.add_argument("--root", type=natural, default=0, metavar="K", help="the level: root K of the ground basis (default 0)")
    p.add_argument("--omega", type=finite, nargs="+", default=[0.0], metavar="W",
                   help="frequencies in Eh, each below the first pole (default 0: the static value)")
    p.add_argument("--plot", metavar="PNG", help="draw α(ω) from 0 to the first pole into this image file")
    p.add_argument("--points", type=positive_integer, default=200, metavar="N", help="with --plot: frequencies (default 200)")
    p.add_argument("--force", action="store_true", help="replace an existing image file")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=command)


def command(args) -> int:
    """`prebo polarisability GROUND RESPONSE [--root K] [--omega W...] [--plot PNG [--points N]] [--json]`:
    α(ω) in a₀³ by Hylleraas' functional with the sum over the response basis's pseudostates as a
    check, and the first pole (level/response.py)."""
    from ..level.response import first_order

    (ground, t0), (response, t1) = (load_basis(basis_file(p)) for p in (args.ground, args.response))
    png = None
    if args.plot is not None:
        png = Path(path_name(args.plot, "--plot", "an image file"))
        png = output_file(png if png.suffix else png.with_suffix(".png"), args.force, [args.ground, args.response])
    elif args.points != 200:
        raise InputError("--points: only with --plot")
    try:
        problem = first_order(ground, response, args.root, max(t0, t1))
        r = problem.at(args.omega)
        if png is not None:
            from ..plot import polarisability as draw

            grid = np.linspace(0.0, problem.pole, args.points + 1)[:-1]
            draw(grid, problem.at(grid)["alpha"], problem.pole, png)
    except PreboError as exc:
        raise type(exc)(f"{args.ground}, {args.response}: {exc}") from exc
    if args.json:
        print(json.dumps(r, allow_nan=False))
    else:
        from rich.table import Table

        t = Table("ω (Eh)", "α(ω) (a₀³), Hylleraas", "sum over states", title="dipole polarisability",
                  caption=f"E₀ = {r['energy']:.12f} Eh; first pole at ω = {r['pole']:.10f} Eh")
        for w, a, s in zip(r["omega"], r["alpha"], r["sum_over_states"]):
            t.add_row(f"{w:.8f}", f"{a:.12f}", f"{s:.12f}")
        show(t)
    if png is not None:
        print(f"wrote {png}")
    return 0
