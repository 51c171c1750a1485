"""`prebo energy`: re-evaluate a stored basis."""
from __future__ import annotations

import json

from ..errors import InputError, PreboError
from ..level.expectation import OPERATORS
from ..level.properties import reported
from .arguments import fraction, positive_integer
from ..io.load import load_basis
from .qed import add_arguments, check, qed
from .tables import show
from .result import print_result, result, warn_if_unbound


def add(sub) -> None:
    """The `prebo energy` subcommand, added to the subparsers `sub`."""
    p = sub.add_parser("energy", help="re-evaluate a stored basis")
    p.add_argument("basis", help="basis.json, or an ecgpack FILE.inout.txt")
    p.add_argument("--coordinates", choices=["lab", "ti"], default="lab",
                   help="lab: LFCC with CM elimination (default); ti: translationally invariant (shared c_A only)")
    p.add_argument("--operator", action="append", default=[], choices=list(OPERATORS),
                   help="add the expectation value of a registered operator, per class of equivalent "
                        "particle pairs (repeatable): " + "; ".join(f"{k}: {op.meaning} ({op.unit})"
                                                                    for k, op in OPERATORS.items()))
    p.add_argument("--threshold", type=fraction, metavar="T",
                   help="relative overlap eigenvalue below which directions are dropped (default: the "
                        "threshold of the run that wrote the file; else 4 x 2^-53, every direction the "
                        "elements resolve, as ecgpack solves its files)")
    p.add_argument("--roots", type=positive_integer, default=None, metavar="K",
                   help="report the lowest K levels of the state's symmetry (each an upper bound to its exact "
                        "level) and the transition energies between them, in Eh and cm⁻¹ (default: up to the "
                        "highest root the basis was optimised for)")
    p.add_argument("--corrections", action="store_true",
                   help="each level's energy by order in α, each part with its numerical uncertainty: α⁰, α² "
                        "(Breit–Pauli) and with --qed α³; and the lines between the levels by the same parts "
                        "(level/budget.py)")
    add_arguments(p)
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=command)


def command(args) -> int:
    """`prebo energy BASIS [--coordinates lab|ti] [--operator NAME ...] [--threshold T] [--roots K]
    [--corrections] [--qed [RESPONSE...]] [--json]`: re-evaluate a stored basis (Eh), with the
    expectation values of registered operators and each level's parts by order in α; a warning on
    stderr (exit status 0) when the state is not bound in the basis."""
    check(args)
    basis, stored = load_basis(args.basis)
    threshold = args.threshold or stored
    parts = args.corrections or args.qed is not None
    operators = list(dict.fromkeys(args.operator + (reported(basis.family, True) if parts else [])))
    r = result(basis, args.basis, threshold, args.coordinates, operators, args.roots)
    if parts:
        budget(basis, r, args, threshold)
    if args.json:
        print(json.dumps(r, allow_nan=False))
    else:
        print_result(r)
        if parts:
            print_budget(r)
    warn_if_unbound(r)
    return 0


def budget(basis, r: dict, args, threshold: float) -> None:
    """Each level's parts by order in α into its "budget" (with --qed its E⁽³⁾ into "qed", for the
    bound levels), and each pair's into r["transitions"]' "budget" (level/budget.py)."""
    from ..level import budget as parts

    levels = r.get("levels", [r])
    if args.qed is not None and not any(v["bound"] for v in levels):
        raise InputError(f"{args.basis}: --qed: no level is bound in this basis (E⁽³⁾ and its Bethe logarithm are "
                         "those of bound levels)")
    for v in levels:
        q = None
        if args.qed is not None and v["bound"]:
            try:
                q = v["qed"] = qed(basis, args, threshold, v["root"])
            except PreboError as exc:
                raise type(exc)(f"{args.basis}: root {v['root']}: {exc}") from exc
        v["budget"] = parts.of_level(basis, v, q)
    by_root = {v["root"]: v["budget"] for v in levels}
    for d in r.get("transitions", []):
        d["budget"] = parts.line(by_root[d["lower"]], by_root[d["upper"]])


def print_budget(r: dict) -> None:
    """The levels' parts by order in α and those of the lines from the lowest (`budget`), in cm⁻¹."""
    from rich.table import Table

    from ..level.budget import PARTS

    names = {"alpha0": "α⁰", "alpha2": "α²", "alpha3": "α³", "total": "total"}
    levels = r.get("levels", [r])
    shown = [p for p in PARTS + ("total",) if any(p in v["budget"] for v in levels)]

    def cell(x):
        return "" if x is None else f"{x['cm-1']:.6f} ± {x['uncertainty_cm-1']:.1e}"

    table = Table("root", *(names[p] + " (cm⁻¹)" for p in shown), title="energy by order in α",
                  caption="± the numerical uncertainty (level/budget.py)" + ("; α³ of the bound levels only"
                                                                               if "alpha3" in shown else ""))
    for v in levels:
        table.add_row(str(v["root"]), *(cell(v["budget"].get(p)) for p in shown))
    show(table)
    lines = [d for d in r.get("transitions", []) if d["lower"] == levels[0]["root"]]
    if lines:
        table = Table("line", *(names[p] + " (cm⁻¹)" for p in shown), title="lines from the lowest level by order in α")
        for d in lines:
            table.add_row(f"{d['lower']} → {d['upper']}", *(cell(d["budget"].get(p)) for p in shown))
        show(table)
