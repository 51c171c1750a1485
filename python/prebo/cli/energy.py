"""`prebo energy`: re-evaluate a stored basis."""
from __future__ import annotations

import json

from ..level.expectation import OPERATORS
from .arguments import fraction, positive_integer
from ..io.load import load_basis
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
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=command)


def command(args) -> int:
    """`prebo energy BASIS [--coordinates lab|ti] [--operator NAME ...] [--threshold T] [--json]`:
    re-evaluate a stored basis (Eh), with the expectation values of registered operators; a warning
    on stderr (exit status 0) when the state is not bound in the basis."""
    basis, stored = load_basis(args.basis)
    r = result(basis, args.basis, args.threshold or stored, args.coordinates, args.operator, args.roots)
    if args.json:
        print(json.dumps(r, allow_nan=False))
    else:
        print_result(r)
    warn_if_unbound(r)
    return 0
