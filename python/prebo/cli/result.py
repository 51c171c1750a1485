"""The result of a basis that `prebo run` writes (result.json) and `prebo energy` prints: `result`,
its tables (`print_result`, `print_levels`) and the warning of a state not bound in the basis."""
from __future__ import annotations

import math
import sys

from ..errors import NonFiniteError, PreboError
from ..level.expectation import OPERATORS
from .tables import show


def result(basis, where, threshold: float, coordinates: str = "lab", operators=(), roots: int | None = None,
           targets=None) -> dict:
    """The JSON-ready result of `basis` (overlap directions below `threshold` dropped, with the
    expectation values of `operators` and the lowest `roots` levels, the levels optimised standing
    at the roots `targets`; level.evaluate);
    NonFiniteError naming the keys that are not finite numbers, and every error prefixed with
    `where` (the basis file)."""
    from ..level.evaluate import evaluate, public

    try:
        r = public(evaluate(basis, coordinates=coordinates, operators=operators, threshold=threshold, roots=roots,
                            targets=targets))
        flat = {}
        for prefix, part in [("", r)] + [(f"level {v['root']} ", v) for v in r.get("levels", [])]:
            flat |= {prefix + k: v for k, v in part.items()}
            flat |= {f"{prefix}{name} {pair}": v for name, values in part.get("expectation", {}).items()
                     for pair, v in values.items()}
        bad = [f"{k} = {v}" for k, v in flat.items() if isinstance(v, float) and not math.isfinite(v)]
        if bad:
            raise NonFiniteError(f"the result is not finite ({', '.join(bad)}): the basis's integrals "
                                 "overflow or lost their digits")
    except PreboError as exc:
        raise type(exc)(f"{where}: {exc}") from exc
    return r


def print_result(r: dict) -> None:
    from rich.table import Table

    from ..optimise.convergence import STOPPED
    from ..optimise.schedule import GROWTH_FASTER

    t = Table(show_header=False, box=None)
    # the head is the lowest targeted root's (level.evaluate); a basis optimised for other levels than
    # the lowest says which
    of = "" if r.get("targets", [0]) == [0] else f" of root {r['root']}"
    t.add_row(f"energy{of} (translation-free)", f"{r['energy']:.12f} Eh")
    t.add_row("numerical uncertainty", f"{r['energy_uncertainty']:.1e} Eh")
    if r.get("energy_lab") is not None:
        t.add_row("energy (laboratory frame)", f"{r['energy_lab']:.12f} Eh")
    t.add_row("virial η_TI", f"{r['virial']:.2e}")
    if "n2" in r:  # floating ECGs: not angular-momentum eigenfunctions
        t.add_row(f"⟨N²⟩_TI{of}", f"{r['n2']:.3e} ħ²")
    for fragments, energy in r["thresholds"].items():
        t.add_row("given threshold" if fragments == "given" else "dissociation threshold",
                  f"{energy:.12f} Eh" + ("" if fragments == "given" else f" ({fragments})"))
    t.add_row(f"binding energy{of}", f"{r['binding_energy']:.3e} Eh ({bound(r)})")
    t.add_row("basis", f"{r['n_basis']} {r['basis_type']} functions")
    t.add_row("particles", " ".join(p["name"] for p in r["particles"]))
    t.add_row("overlap condition", f"{r['overlap_condition']:.2e} ({r['kept']} kept)")
    if "response" in r:  # a first-order function's run (optimise/response.py)
        x = r["response"]
        t.add_row("Hylleraas functional J", f"{x['objective']:.12f} a.u. ({x['operator']} on root {x['root']}, "
                  f"E₀ = {x['energy']:.12f} Eh)")
        name, value, unit = (f"polarisability α(ω = {x['omega'][0]:g} Eh)", x["alpha"][0], "a₀³") if "alpha" in x \
            else (f"⟨J'(H − E₀ − ω)⁻¹J'⟩ at ω = {x['omega'][0]:g} Eh", x["f"][0], "a.u.")
        t.add_row(name, f"{value:.12f} {unit} (sum over states {x['sum_over_states'][0]:.12f}; first pole "
                  f"{x['pole']:.6f} Eh)")
    if r.get("convergence"):
        c = r["convergence"]
        t.add_row("stopped", f"{STOPPED[c['stopped']]} after {c['seconds']:.1f} s")
        if c.get("advantage") is not None and c["advantage"] > GROWTH_FASTER and c["stopped"] != "exhausted":
            t.add_row("basis size", f"growth was gaining {c['advantage']:.0f}× faster than the last passes: "
                      "a larger basis would gain faster")
        if c["recent"]:
            rate = c["recent"]["rate"]
            t.add_row(f"last {c['recent']['steps']} steps", f"ΔE = {-c['recent']['gain']:.2e} Eh in "
                      f"{c['recent']['seconds']:.1f} s" + (f" ({rate:.1e} Eh/s)" if rate else ""))
        if c["extrapolation"]:
            t.add_row("still to gain at this size", f"~{c['extrapolation']['remaining']:.1e} Eh (Aitken's Δ² of the "
                      "gains since growth; not the error against the exact energy)")
    for name, values in r.get("expectation", {}).items():
        op = OPERATORS[name]
        for pair, value in values.items():
            t.add_row(f"{name} {pair}", f"{value:.10g} {op.unit}")
    show(t)
    if "levels" in r:
        print_levels(r)


def bound(r: dict) -> str:
    """'bound' or 'not bound' below the threshold, qualified where a break-up was not computed."""
    if not r["bound"]:
        return "not bound"
    unchecked = r.get("threshold_unchecked")
    return "bound" if unchecked is None else (f"bound below the thresholds computed; break-ups with a fragment of three "
                                              f"or more particles, e.g. {unchecked}, were not: give \\[state] threshold")


def print_levels(r: dict) -> None:
    """The levels of a result with several roots, and the transitions from the lowest and between
    neighbours (level.evaluate; every pair is in the JSON)."""
    from rich.table import Table

    from ..level.evaluate import HARTREE_CM

    levels = Table("root", "energy (Eh)", "σ (Eh)", "η_TI", "E − E_0 (cm⁻¹)", "bound", "optimised", title="levels",
                   caption="bound: below the lowest dissociation threshold by more than σ; optimised: a level the "
                           "basis was optimised for")
    gaps = {(d["lower"], d["upper"]): d for d in r["transitions"]}
    targets = r.get("targets", [0])
    for v in r["levels"]:
        gap = gaps[(0, v["root"])]["cm-1"] if v["root"] else 0.0
        levels.add_row(str(v["root"]), f"{v['energy']:.12f}", f"{v['energy_uncertainty']:.1e}", f"{v['virial']:.1e}",
                       f"{gap:.6f}", "yes" if v["bound"] else "no", "yes" if v["root"] in targets else "")
    show(levels)
    unbound = {v["root"] for v in r["levels"] if not v["bound"]}
    steps = Table("transition", "ΔE (Eh)", "ΔE (cm⁻¹)", "uncertainty (cm⁻¹)", title="between neighbouring levels",
                  caption="*: to or from a level not bound in this basis (a discretised continuum state)"
                  if unbound else None)
    for v in r["levels"][1:]:
        d = gaps[(v["root"] - 1, v["root"])]
        mark = "*" if {d["lower"], d["upper"]} & unbound else ""
        steps.add_row(f"{d['lower']} → {d['upper']}{mark}", f"{d['Eh']:.10f}", f"{d['cm-1']:.6f}",
                      f"{d['uncertainty'] * HARTREE_CM:.1e}")
    show(steps)


def warn_if_unbound(r: dict) -> None:
    """One line on stderr when the energy is not below the lowest dissociation threshold (level.evaluate),
    after the result (a standard output that could not take it ends the command first: `streams.Stream.check`)."""
    sys.stdout.check()
    if not r["bound"]:
        print(f"prebo: warning: E = {r['energy']:.12g} Eh is not below the dissociation threshold "
              f"{r['threshold']:.12g} Eh ({r['threshold_fragments']}): the state is not bound in this basis "
              "(a small virial coefficient is no evidence of binding)", file=sys.stderr)
    above = [v["root"] for v in r.get("levels", []) if v["root"] != r["root"] and not v["bound"]]
    if above and r["bound"]:
        which = f"level {above[0]}" if len(above) == 1 else f"{len(above)} levels ({above[0]}, ..., {above[-1]})"
        print(f"prebo: warning: {which} not below the dissociation threshold {r['threshold']:.12g} Eh "
              f"({r['threshold_fragments']}): not bound in this basis (discretised continuum)", file=sys.stderr)
