"""A level's energy order by order in α, each part with its numerical uncertainty, and the lines
between levels by the same parts: the budget a comparison with experiment reads (H₂'s D₀ as α⁰,
α², α³ and α⁴ parts: J. Piszczatowski et al., J. Chem. Theory Comput. 5, 3039 (2009)).

- α⁰: the nonrelativistic energy and its first-order uncertainty (evaluate, eigen.uncertainty);
- α²: the Breit–Pauli correction (relativistic.terms) with Drachmann's regularised ⟨δ³⟩ and ⟨p⁴⟩
  where the level has them (properties.corrections); its uncertainty, their difference from the
  direct ones, which miss what the basis misses at the coalescences (docs/relativistic.md);
- α³: E⁽³⁾ (qed.of_level), its uncertainty qed.uncertainty (ln k₀'s convergence and the direct
  against the regularised ⟨δ³⟩).

Parts not computed are absent; the total is the sum of those present. The uncertainties of a sum of
parts and of a difference of levels add in quadrature, as evaluate's transitions do.
"""
from __future__ import annotations

import math

from .evaluate import HARTREE_CM
from .properties import corrections
from .qed import uncertainty
from .relativistic import terms

#: the parts, in the order reported: α⁰, α², α³ (Eh)
PARTS = ("alpha0", "alpha2", "alpha3")


def part(Eh: float, sigma: float) -> dict:
    """One part: its value in Eh and cm⁻¹ and its numerical uncertainty in both."""
    return {"Eh": Eh, "cm-1": Eh * HARTREE_CM, "uncertainty": sigma, "uncertainty_cm-1": sigma * HARTREE_CM}


def total(parts: dict) -> dict:
    """The sum of `parts`' values, their uncertainties in quadrature."""
    present = [parts[p] for p in PARTS if p in parts]
    return part(math.fsum(x["Eh"] for x in present), math.hypot(*(x["uncertainty"] for x in present)))


def of_level(basis, level: dict, qed: dict | None = None) -> dict:
    """The parts of a level of `basis` (`level`, a level of evaluate with the expectation values of
    relativistic.NEEDS and, for the regularised values, drachmann's terms; `qed`, qed.of_level's
    result for it, or None): {"alpha0", "alpha2" (where the level has NEEDS), "alpha3" (with `qed`),
    "total"}, each `part`."""
    parts = {"alpha0": part(level["energy"], level["energy_uncertainty"])}
    bp = corrections(basis, level).get("breit_pauli")
    if bp is not None:
        direct = terms(basis.system, level["expectation"])["Eh"]["total"]
        parts["alpha2"] = part(bp["Eh"]["total"], abs(bp["Eh"]["total"] - direct))
    if qed is not None:
        parts["alpha3"] = part(qed["Eh"]["total"], uncertainty(basis.system, dict(level["expectation"]["delta"]), qed))
    return parts | {"total": total(parts)}


def line(lower: dict, upper: dict) -> dict:
    """The parts of the line from the level `lower` to `upper` (each `of_level`'s): the differences
    of the parts both have, uncertainties in quadrature, and their total."""
    parts = {p: part(upper[p]["Eh"] - lower[p]["Eh"], math.hypot(upper[p]["uncertainty"], lower[p]["uncertainty"]))
             for p in PARTS if p in lower and p in upper}
    return parts | {"total": total(parts)}
