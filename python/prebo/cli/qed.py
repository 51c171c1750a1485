"""The command line's leading QED correction: the --qed options of `prebo properties` and `prebo
energy`, a level's E⁽³⁾ from them (level/qed.py), and its table."""
from __future__ import annotations

from pathlib import Path

from ..errors import InputError
from ..io.load import basis_file, load_basis
from .arguments import distance, positive_integer, seconds
from .tables import show

#: the options that shape the bases the optimiser builds (--qed without files)
BUILDING = ("qed_out", "qed_k", "qed_size", "qed_budget")


def add_arguments(p) -> None:
    """--qed [RESPONSE...], --qed-out, --qed-k, --qed-size on the parser `p`."""
    p.add_argument("--qed", nargs="*", metavar="RESPONSE",
                   help="the leading QED correction E⁽³⁾ (level/qed.py) with the Bethe logarithm from these bases of the "
                        "current's first-order functions (N = 1, the other parity; each a row of its convergence "
                        "table, the last the value), or, with none, from bases the optimiser builds on a grid of "
                        "photon energies (minutes; kept in --qed-out and reused)")
    p.add_argument("--qed-out", metavar="DIR",
                   help="with --qed and no RESPONSE: the folder of the first-order bases, DIR/rootK/k=<k> for root K "
                        "(default: BASIS's folder/qed)")
    p.add_argument("--qed-k", type=distance, nargs="+", metavar="K",
                   help="with --qed and no RESPONSE: the photon energies in Eh (default: one per decade from 0.3 × the "
                        "Coulomb scale to 3 × the Bethe logarithm's split point; optimise/current.py grid)")
    p.add_argument("--qed-size", type=positive_integer, metavar="N",
                   help="with --qed and no RESPONSE: functions per photon energy (default: optimise/current.py SIZE)")
    p.add_argument("--qed-budget", type=seconds, metavar="S",
                   help="with --qed and no RESPONSE: seconds of each photon energy's run (default: until it converges; "
                        "a run stopped by its budget is resumed with a larger one)")


def check(args) -> None:
    """InputError for an option of BUILDING without --qed, or with --qed's files."""
    for flag in BUILDING:
        if getattr(args, flag) is not None and not (args.qed is not None and not args.qed):
            raise InputError(f"--{flag.replace('_', '-')}: only with --qed and no RESPONSE (the bases it builds)")


def qed(basis, args, threshold: float, root: int) -> dict:
    """E⁽³⁾ of level `root` of `basis` (level/qed.py `of_level`) with its Bethe logarithm from the --qed
    bases (split at bethe.py's default K), or from those optimise/current.py builds and keeps in
    --qed-out/rootK, or qed/rootK beside BASIS (current.responses: their unions as they join, each a
    row of the convergence table, and its split point)."""
    from ..level.qed import of_level

    if args.qed:
        responses, K = [load_basis(basis_file(name))[0] for name in args.qed], None
    else:
        from ..optimise import Optimiser
        from ..optimise.current import SIZE, responses as built

        out = Path(args.qed_out or Path(args.basis).parent / "qed") / f"root{root}"
        responses, K = built(basis, root, args.qed_k, args.qed_size or SIZE, out, threshold,
                             Optimiser(budget=args.qed_budget), progress=not args.json)
    return of_level(basis, responses, root, threshold=threshold, K=K)


def print_qed(q: dict) -> None:
    """The E⁽³⁾ block of `prebo properties --qed` (`print_properties`)."""
    from rich.table import Table

    from ..level.evaluate import HARTREE_CM

    b = q["bethe"]
    table = Table("response functions", "ln k₀ (pseudostates)", "ln k₀ (integral)",
                  title="Bethe logarithm, in R_∞ = ½ Eh (level/bethe.py)")
    for row in b["convergence"]:
        table.add_row(str(row["n_basis"]), f"{row['pseudostate']:.8f}", f"{row['ln_k0']:.8f}")
    show(table)
    table = Table("term (class)", "Eh", "cm⁻¹", title=f"leading QED correction E⁽³⁾ (α = {q['alpha']}; "
                                                      f"ln k₀ = {q['ln_k0']:.8f})")
    for term, e in q["Eh"].items():
        table.add_row(term.replace("_", "–"), f"{e:.6e}", f"{q['cm-1'][term]:.6f}")
        for c, v in q["classes"].get(term, {}).items():
            table.add_row(f"  {c}", f"{v:.6e}", f"{v * HARTREE_CM:.6f}")
    show(table)
    for c, why in q["omitted"].items():
        print(f"E⁽³⁾ leaves out the pairs {c}: {why}")
