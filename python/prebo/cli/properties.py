"""`prebo properties`: a level's energy, the expectation values of every registered operator and its corrections."""
from __future__ import annotations

import json
import math
import sys

from ..errors import NonFiniteError, PreboError
from ..level.expectation import OPERATORS
from .arguments import fraction, natural
from ..io.load import load_basis
from .qed import add_arguments, check, print_qed, qed
from .result import bound
from .tables import show


def add(sub) -> None:
    """The `prebo properties` subcommand, added to the subparsers `sub`."""
    p = sub.add_parser("properties", help="a level's energy and the expectation values of every registered operator")
    p.add_argument("basis", help="basis.json, or an ecgpack FILE.inout.txt")
    p.add_argument("--root", type=natural, default=0, metavar="K", help="the level: root K of the basis's symmetry (default 0)")
    p.add_argument("--coordinates", choices=["lab", "ti"], default="lab",
                   help="lab: LFCC with CM elimination (default); ti: translationally invariant (shared c_A only)")
    p.add_argument("--threshold", type=fraction, metavar="T",
                   help="relative overlap eigenvalue below which directions are dropped (default: as for prebo energy)")
    p.add_argument("--regularised", action="store_true",
                   help="the regularised δ and p⁴ (and the Breit–Pauli correction from them) also where they are "
                        "slower (floating ECGs, ECG-GVR: H2 with 500 ECG-GVR functions 55 s against 26 s); plain ECGs always have them")
    add_arguments(p)
    p.add_argument("--json", action="store_true", help="print the properties as JSON")
    p.set_defaults(func=command)


def command(args) -> int:
    """`prebo properties BASIS [--root K] [--coordinates lab|ti] [--threshold T] [--regularised] [--qed
    [RESPONSE...]] [--json]`: the energy of level K of a stored basis, the expectation value of every
    registered operator per class of equivalent pairs (properties.py), the level's Breit–Pauli
    correction (relativistic.py) and with --qed its E⁽³⁾ (qed.py); a level not bound in the basis
    gets a warning line on stderr."""
    from ..level.properties import properties

    check(args)
    basis, stored = load_basis(args.basis)
    try:
        p = properties(basis, args.root, args.coordinates, args.threshold or stored, args.regularised or None)
        if args.qed is not None:
            p["qed"] = qed(basis, args, args.threshold or stored, args.root)
    except PreboError as exc:
        raise type(exc)(f"{args.basis}: {exc}") from exc
    values = [v for per in p["expectation"].values() for v in per.values()]
    if not all(math.isfinite(v) for v in values + [p["energy"]]):
        raise NonFiniteError(f"{args.basis}: the properties are not finite: the basis's integrals overflow or lost "
                             "their digits")
    if args.json:
        print(json.dumps(p, allow_nan=False))
    else:
        print_properties(p, basis)
    if not p["bound"]:
        sys.stdout.check()
        print(f"prebo: warning: root {p['root']} is not below the lowest dissociation threshold: not bound in this "
              "basis (its properties are those of a discretised continuum state)", file=sys.stderr)
    return 0


def print_properties(p: dict, basis) -> None:
    """`prebo properties`' tables (`command`)."""
    from rich.table import Table

    from ..level.evaluate import HARTREE_CM
    from ..level.expectation import vanishing

    head = Table(show_header=False, box=None)
    head.add_row("level", f"root {p['root']} ({bound(p)})")
    head.add_row("energy (translation-free)", f"{p['energy']:.12f} Eh ± {p['energy_uncertainty']:.1e}")
    head.add_row("virial η_TI", f"{p['virial']:.2e}")
    if "n2" in p:
        head.add_row("⟨N²⟩_TI", f"{p['n2']:.3e} ħ²")
    show(head)
    for acts_on in ("pairs", "particles"):
        names = [name for name in p["expectation"] if OPERATORS[name].acts_on == acts_on]
        if names:
            classes = list(p["expectation"][names[0]])
            table = Table("operator", *classes, "unit", title=f"expectation values per class of equivalent {acts_on}")
            for name in names:
                table.add_row(name, *(f"{p['expectation'][name][c]:.10g}" for c in classes), p["units"][name])
            if acts_on == "pairs" and "delta_regularised" in p:  # drachmann.py
                table.add_row("delta (Drachmann)", *(f"{p['delta_regularised'][c]:.10g}" if c in p["delta_regularised"]
                                                     else "" for c in classes), "bohr⁻³")
            if acts_on == "particles" and p.get("p4_regularised"):  # drachmann.py, eq. (27')
                table.add_row("p4 (regularised)", *(f"{p['p4_regularised'][c]:.10g}" if c in p["p4_regularised"]
                                                    else "" for c in classes), "ħ⁴/bohr⁴")
            show(table)
            zero = vanishing(basis.system) if acts_on == "pairs" else []
            if zero and "delta" in names:
                print(f"⟨δ³(r_ij)⟩ of {', '.join(zero)}: 0 by symmetry (the state changes sign when the two trade "
                      "places, so it vanishes where they meet)")
    if "breit_pauli" in p:  # relativistic.py: each term, per class and summed
        bp = p["breit_pauli"]
        kind = ("regularised δ and p⁴ where Drachmann's forms serve (drachmann.py)" if bp["regularised"]
                else "direct δ and p⁴")
        table = Table("term (class)", "Eh", "cm⁻¹", title=f"Breit–Pauli correction (α = {bp['alpha']}; {kind})")
        for term, e in bp["Eh"].items():
            table.add_row(term.replace("_", "–"), f"{e:.6e}", f"{bp['cm-1'][term]:.6f}")
            for c, v in bp["classes"].get(term, {}).items():
                table.add_row(f"  {c}", f"{v:.6e}", f"{v * HARTREE_CM:.6f}")
        show(table)
    if "qed" in p:  # qed.py: each term, per class and summed, and ln k₀'s convergence
        print_qed(p["qed"])
    if p["not_derived"]:
        print(f"not derived for {basis.family.name} functions: {', '.join(p['not_derived'])}"
                        + ("" if "breit_pauli" in p else " (so neither is the Breit–Pauli correction)"))

