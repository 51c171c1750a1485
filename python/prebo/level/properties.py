"""The properties of the levels of a basis (issue 40).

- `properties`: one level's energy, uncertainty, virial coefficient and whether it is bound, with
  the expectation value of every registered pair operator (`expectation.OPERATORS`: ⟨r_ij⟩,
  ⟨r_ij²⟩, ⟨1/r_ij⟩, ⟨1/r_ij²⟩, ⟨δ³(r_ij)⟩, the Araki–Sucher ⟨P(1/r_ij³)⟩, ...) per class of
  equivalent pairs — what `prebo properties BASIS --root k` prints and `prebo.properties(basis, root=k)` returns. ⟨δ³(r_ij)⟩ is the direct
  expectation value, which Gaussians, lacking the cusp, reach slowly (hydrogen 1s in 80
  even-tempered Gaussians: 1.8e-4 low, against 2e-11 for ⟨r⟩). With them, the level's
  Breit–Pauli correction (relativistic.py).
- `densities`: the pictures of several levels — the distribution P(r) = 4πr²ρ̄(r) of every
  inter-particle distance and of every particle's distance from the centre of mass, ρ̄ the
  spherically averaged density (`expectation.densities`), on a grid; `csv` its text, which
  `prebo plot --densities` writes beside the picture (plot.densities).
"""
from __future__ import annotations

import csv
import io
import math

import numpy as np

from .. import eigen
from ..basis import Basis
from ..errors import InputError, NonFiniteError
from ..validation import Integer, checked
from . import drachmann
from .evaluate import evaluate, grids
from .expectation import OPERATORS
from .relativistic import NEEDS, terms


def properties(basis, root: int = 0, coordinates: str = "lab", threshold: float = eigen.THRESHOLD,
               regularised: bool | None = None) -> dict:
    """The properties of level `root` (0: the lowest of the basis's symmetry) of `basis`, with
    the regularised δ and p⁴ if `regularised` (None: where they are cheap, `reported`).

    Returns {"root", "energy", "energy_uncertainty" (Eh), "virial", "bound", "threshold_unchecked"
    (`evaluate`), "expectation":
    {operator: {class: value}}, "units": {operator: unit}, "not_derived": [operators]} (and "n2",
    ⟨N²⟩_TI in ħ², for floating ECGs): the `reported` operators of the basis family, per
    class of equivalent pairs "a-b" or particles "a", and those it has no element for; and
    the level's `corrections` ("breit_pauli", "delta_regularised", "p4_regularised") where it
    holds their operators. InputError
    for a root that is not a non-negative integer below the basis size; the errors of
    `evaluate` otherwise."""
    if not isinstance(basis, Basis) or len(basis) == 0:
        raise InputError(f"properties: basis = {basis!r}: must be a prebo.Basis with at least one function")
    root = checked(Integer(0, len(basis) - 1), root, "properties: root", f"roots of a basis of {len(basis)} functions")
    names = reported(basis.family, regularised)
    r = evaluate(basis, coordinates=coordinates, threshold=threshold, operators=names, roots=root + 1)
    level = r["levels"][root] if "levels" in r else r
    keys = ("root", "energy", "energy_uncertainty", "virial", "bound", "n2", "expectation")
    return {k: level[k] for k in keys if k in level} | corrections(basis, level) | {
        "threshold_unchecked": r["threshold_unchecked"],
        "root": root, "units": {k: OPERATORS[k].unit for k in names},
        "not_derived": [k for k, op in OPERATORS.items() if not op.evaluates(basis.family)]}


#: the points of the default grid of `densities`, and its reach in root-mean-square distances
POINTS, REACH = 400, 5.0


def reported(family, regularised: bool | None = None) -> list[str]:
    """The operators a level's properties hold for a basis of `family` (`properties`, `prebo run`'s
    result.json): every one the family evaluates, Drachmann's terms, which serve the regularised
    ⟨δ³(r_ij)⟩ and ⟨p⁴⟩ alone, only if `regularised`; None: where ⟨V/r_ij⟩ is in closed form
    (`drachmann.CLOSED_FORM`). Elsewhere ⟨V/r_ij⟩ is a quadrature of tens of damped elements per
    product (eq. 38): H2-500's properties take 55 s with them, 26 s without (benchmarks/record/relativistic.md, "Eq. (38) by even rules, and every property of H2-500 in 55 s")."""
    if regularised is None:
        regularised = family.name in drachmann.CLOSED_FORM
    return [name for name, op in OPERATORS.items()
            if op.evaluates(family) and (regularised or name not in drachmann.TERMS or name == "inv_r")]


def corrections(basis, level: dict) -> dict:
    """What the expectation values of a level of `basis` ({"energy", "expectation": {operator:
    {class: value}}}, a level of `evaluate`) give beyond themselves, where they hold the
    operators: "delta_regularised", {pair class: Drachmann's ⟨δ³(r_ij)⟩} (`drachmann.regularised`),
    "p4_regularised", {class of the lightest particles: ⟨p⁴⟩ by eq. (27')}
    (`drachmann.p4_regularised`), and "breit_pauli", the Breit–Pauli correction
    (`relativistic.terms`) — with both regularised values where there are both ("regularised":
    true), else with the direct ones (the two err together, docs/relativistic.md)."""
    out, expectation = {}, level.get("expectation", {})
    have = set(expectation)
    if set(drachmann.TERMS) <= have:
        out["delta_regularised"] = drachmann.regularised(basis.system, expectation, level["energy"])
    if set(drachmann.P4_TERMS) <= have:
        out["p4_regularised"] = drachmann.p4_regularised(basis.system, expectation, level["energy"])
    if set(NEEDS) <= have:
        both = "delta_regularised" in out and bool(out.get("p4_regularised"))
        regularised = {"delta": out["delta_regularised"], "p4": out["p4_regularised"]} if both else {}
        out["breit_pauli"] = terms(basis.system, expectation, **regularised) | {"regularised": both}
    return out


def densities(basis, roots=(0,), r=None, points: int = POINTS, coordinates: str = "lab",
              threshold: float = eigen.THRESHOLD) -> dict:
    """The distance distributions of the levels `roots` of `basis` at the radii `r` (bohr), or by
    default on a grid per class of `points` from 0 to REACH root-mean-square distances of that
    class (the largest over the levels; `rms`).

    Returns {"r": {"pairs": {"a-b": radii}, "particles": {"a": radii}}, "levels": [{"root",
    "energy", "pairs": {"a-b": P}, "particles": {"a": P}}]} with P(r) = 4πr²ρ̄(r) (bohr⁻¹; ∫P dr = 1
    over a grid that reaches far enough). InputError for roots that are not distinct non-negative
    integers below the basis size, or radii that are empty or not finite distances ≥ 0;
    NonFiniteError naming the class and the first radius where P is not finite (a grid that
    reaches where r² overflows against the exponents, ~1e148 bohr for He); the errors of
    `evaluate` otherwise."""
    if not isinstance(basis, Basis) or len(basis) == 0:
        raise InputError(f"densities: basis = {basis!r}: must be a prebo.Basis with at least one function")
    roots = [roots] if not isinstance(roots, (list, tuple)) else list(roots)
    if not roots or len(set(roots)) != len(roots):
        raise InputError(f"densities: roots = {roots!r}: must be distinct levels of the basis")
    for k in roots:
        checked(Integer(0, len(basis) - 1), k, "densities: roots", f"roots of a basis of {len(basis)} functions")
    if r is None:
        points = checked(Integer(2, 10**6), points, "densities: points", "grid points")
        e = evaluate(basis, coordinates=coordinates, threshold=threshold, operators=("r2",), roots=max(roots) + 1)
        levels = e.get("levels", [e])
        reach = [rms(basis.system, levels[k]["expectation"]["r2"]) for k in roots]
        r = {group: {c: np.linspace(0.0, REACH * max(x[group][c] for x in reach), points) for c in classes}
             for group, classes in reach[0].items()}
    radii = grids(basis.system, r)
    e = evaluate(basis, coordinates=coordinates, threshold=threshold, roots=max(roots) + 1, radii=radii)
    levels = e.get("levels", [e])
    with np.errstate(over="ignore", invalid="ignore"):  # a value that is not finite is refused below
        table = {"r": radii, "levels": [{"root": k, "energy": levels[k]["energy"]} | {
            group: {c: 4.0 * math.pi * radii[group][c] ** 2 * rho for c, rho in levels[k]["densities"][group].items()}
            for group in radii} for k in roots]}
    for level in table["levels"]:
        for group in radii:
            for c, p in level[group].items():
                if not np.all(np.isfinite(p)):
                    far = radii[group][c][np.argmin(np.isfinite(p))]
                    why = ("the basis's integrals overflow or lost their digits" if far == 0 else
                           "r² overflows against the basis's exponents there: end the grid nearer")
                    raise NonFiniteError(f"densities: P(r) of {c} (root {level['root']}) is not finite from "
                                         f"r = {far:.3g} bohr on: {why}")
    return table


def rms(system, r2: dict) -> dict:
    """Root-mean-square distances per class from the pair classes' ⟨r_ij²⟩ `r2`: {"pairs": {"a-b"},
    "particles": {"a": ⟨|r_i − R|²⟩^½}}, from r_i − R = Σ_j μ_j r_ij (μ the mass fractions):
    ⟨|r_i − R|²⟩ = Σ_j μ_j d_ij − ½ Σ_jk μ_j μ_k d_jk, d_ij = ⟨r_ij²⟩ (equal within a class)."""
    names = [p.name for p in system.particles]
    d = np.zeros((system.n, system.n))
    for i, j, _ in system.pairs():
        d[i, j] = d[j, i] = r2["-".join(sorted((names[i], names[j])))]
    mu = system.cm_vector
    about_cm = d @ mu - 0.5 * mu @ d @ mu
    return {"pairs": {c: math.sqrt(v) for c, v in r2.items()},
            "particles": {names[i]: math.sqrt(max(x, 0.0)) for i, x in enumerate(about_cm)}}


def csv_text(table: dict) -> str:
    """`densities`' table as CSV, one row per level, class and radius: root, group ("pair" or
    "particle"), class ("a-b" or "a"), r (bohr), P (bohr⁻¹)."""
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(["root", "group", "class", "r_bohr", "P_per_bohr"])
    for level in table["levels"]:
        for group, word in (("pairs", "pair"), ("particles", "particle")):
            for c, p in level[group].items():
                writer.writerows([level["root"], word, c, x, y] for x, y in zip(table["r"][group][c].tolist(), p.tolist()))
    return out.getvalue()
