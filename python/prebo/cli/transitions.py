"""`prebo transitions`: the electric-dipole or electric-quadrupole lines between the levels of two
stored bases."""
from __future__ import annotations

import json
from pathlib import Path

from ..errors import PreboError
from .arguments import fraction, positive_integer
from ..io.load import basis_file, load_basis
from .tables import show


def add(sub) -> None:
    """The `prebo transitions` subcommand, added to the subparsers `sub`."""
    p = sub.add_parser("transitions", help="electric-dipole or quadrupole lines between the levels of two bases")
    for name in ("lower", "upper"):
        p.add_argument(name, help=f"the {name} levels' basis: basis.json, a run folder holding one, "
                                  "or an ecgpack FILE.inout.txt")
    p.add_argument("--roots", type=positive_integer, nargs="+", default=[1], metavar="K",
                   help="the lowest K levels of each basis (one K for both, or K_lower K_upper; default 1)")
    p.add_argument("--coordinates", choices=["lab", "ti"], default="lab",
                   help="lab: LFCC with CM elimination (default); ti: translationally invariant (shared c_A only)")
    p.add_argument("--threshold", type=fraction, metavar="T",
                   help="relative overlap eigenvalue below which directions are dropped (default: each "
                        "basis's run's, else 4 x 2^-53)")
    p.add_argument("--corrections", action="store_true",
                   help="each level and line by order in α with its numerical uncertainty: α⁰ and α² (Breit–Pauli; "
                        "level/budget.py); α³ needs the Bethe logarithm, derived for levels of N = 0 only "
                        "(prebo energy --qed)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=command)


def command(args) -> int:
    """`prebo transitions LOWER UPPER [--roots K [K]] [--coordinates lab|ti] [--threshold T] [--json]`:
    for every pair of levels the reduced dipole moment in length, velocity and acceleration form, the line and
    oscillator strengths and the Einstein A coefficient, or the reduced quadrupole moment, its line
    strength and Einstein A coefficient; and each emitting level's lifetime (level/transitions.py)."""
    from ..level.transitions import transitions

    if len(args.roots) > 2:
        raise PreboError(f"--roots {' '.join(map(str, args.roots))}: one K for both bases, or K_lower K_upper")
    (lower, t_lower), (upper, t_upper) = (load_basis(basis_file(p)) for p in (args.lower, args.upper))
    threshold = args.threshold or max(t_lower, t_upper)
    try:
        roots = tuple(args.roots) if len(args.roots) == 2 else args.roots[0]
        r = transitions(lower, upper, roots, threshold, args.coordinates)
        if args.corrections:
            budget(r, (lower, upper), threshold, args.coordinates)
    except PreboError as exc:
        raise type(exc)(f"{args.lower}, {args.upper}: {exc}") from exc
    if args.json:
        print(json.dumps(r, allow_nan=False))
    else:
        _print(r)
    return 0


def budget(r: dict, bases: tuple, threshold: float, coordinates: str) -> None:
    """Each level's parts by order in α (α⁰, α²) into its "budget", and each line's into its own
    (level/budget.py), the levels re-evaluated with the operators the α² part needs."""
    from ..level import budget as parts
    from ..level.evaluate import evaluate
    from ..level.properties import reported

    solved = {}
    for k, basis in enumerate(bases):
        roots = 1 + max(v["root"] for v in r["levels"] if v["basis"] == k)
        e = evaluate(basis, coordinates=coordinates, threshold=threshold, roots=roots,
                     operators=reported(basis.family, True))
        solved[k] = (basis, e.get("levels", [e]))
    for v in r["levels"]:
        basis, levels = solved[v["basis"]]
        v["budget"] = parts.of_level(basis, levels[v["root"]])
    for line in r["lines"]:
        line["budget"] = parts.line(r["levels"][line["lower"]]["budget"], r["levels"][line["upper"]]["budget"])


def _print(r: dict) -> None:
    from rich.table import Table

    names = ("lower", "upper")
    label = {k: f"{names[v['basis']]} {v['root']} (N={v['N']}{'+' if v['parity'] > 0 else '−'})"
             for k, v in enumerate(r["levels"])}
    levels = Table("level", "energy (Eh)", title="levels")
    for k, v in enumerate(r["levels"]):
        levels.add_row(label[k], f"{v['energy']:.12f}")
    show(levels)
    if "budget" in r["levels"][0]:
        _budget(r, label)
    if any("quadrupole" in line for line in r["lines"]):
        _quadrupole(r, label)
    else:
        _dipole(r, label)
    if r["lifetimes"]:
        life = Table("level", "lifetime (s)", "lines", title="radiative lifetimes",
                     caption="1/Σ A over the lines to the lower levels computed")
        for v in r["lifetimes"]:
            life.add_row(label[v["level"]], f"{v['lifetime']:.6e}", str(v["lines"]))
        show(life)


def _budget(r: dict, label: dict) -> None:
    """The lines' frequencies by order in α (`budget`), in cm⁻¹ ± their numerical uncertainty."""
    from rich.table import Table

    def cell(x):
        return f"{x['cm-1']:.6f} ± {x['uncertainty_cm-1']:.1e}"

    t = Table("lower → upper", "α⁰ (cm⁻¹)", "α² (cm⁻¹)", "total (cm⁻¹)", title="line frequencies by order in α",
              caption="± the numerical uncertainty (level/budget.py)")
    for line in r["lines"]:
        b = line["budget"]
        t.add_row(f"{label[line['lower']]} → {label[line['upper']]}", cell(b["alpha0"]),
                  cell(b["alpha2"]) if "alpha2" in b else "", cell(b["total"]))
    show(t)


def _dipole(r: dict, label: dict) -> None:
    from rich.table import Table

    lines = Table("lower → upper", "ν (cm⁻¹)", "<‖d‖> length (e a₀)", "velocity/length", "acceleration/length",
                  "S (e² a₀²)", "f", "A (s⁻¹)",
                  title="electric-dipole lines",
                  caption="reduced moments <N'‖d‖N> (Edmonds), d about the centre of mass; f absorption from the "
                          "lower level; A emission from the upper")
    for line in r["lines"]:
        pair = f"{label[line['lower']]} → {label[line['upper']]}"
        if "forbidden" in line:
            lines.add_row(pair, f"{line['cm-1']:.4f}", line["forbidden"], "", "", "", "", "")
            continue
        ratios = ("" if x is None else f"{x:.8f}" for x in (line["velocity/length"], line["acceleration/length"]))
        lines.add_row(pair, f"{line['cm-1']:.4f}", f"{line['length']:.9f}", *ratios, f"{line['line_strength']:.9e}",
                      f"{line['oscillator_strength']:.9e}", f"{line['einstein_A']:.6e}")
    show(lines)


def _quadrupole(r: dict, label: dict) -> None:
    from rich.table import Table

    lines = Table("lower → upper", "ν (cm⁻¹)", "<‖Q‖> (e a₀²)", "S (e² a₀⁴)", "A (s⁻¹)", title="electric-quadrupole lines",
                  caption="reduced moments <N'‖Q‖N> (Edmonds), Q about the centre of mass; A emission from the upper")
    for line in r["lines"]:
        pair = f"{label[line['lower']]} → {label[line['upper']]}"
        lines.add_row(pair, f"{line['cm-1']:.4f}", f"{line['quadrupole']:.9f}", f"{line['line_strength']:.9e}",
                      f"{line['einstein_A']:.6e}")
    show(lines)
