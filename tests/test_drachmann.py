"""Drachmann's regularised ⟨δ³(r_ij)⟩ (prebo.level.drachmann; docs/properties-derivations.md §6, eq. 27)
on wave functions: hydrogen against the closed form, helium and H2⁺ (floating ECGs, ECG-GVR) against
the direct ⟨δ⟩. The elements are checked against quadratures in
crates/prebo-core/src/operators/drachmann/."""
import json

import numpy as np
import pytest

import prebo
from prebo import eigen
from prebo.cli import main
from prebo.integrals import laboratory, translationally_invariant
from prebo.io.ecgpack import read_inout
from prebo.level import drachmann
from prebo.level.drachmann import delta_regularised
from prebo.level.expectation import expectation

from conftest import ROOT, hydrogen_s


def states(basis, roots: int, rep=None):
    """(representation, C, energies) of the lowest `roots` states of `basis` in `rep` (default the
    laboratory frame, CM kinetic energy eliminated), as `prebo.evaluate` solves them."""
    rep = rep or laboratory(basis.system)
    m = rep.matrices(basis)
    ti = eigen.solve(m["T_ti"] + m["V"], m["S"], eigen.THRESHOLD, roots)
    return rep, ti.vectors[:, :roots], ti.energies[:roots]


def test_hydrogen_regularised_contact_density_is_much_closer_to_the_closed_form():
    """H (finite proton mass) 1s and 2s as roots 0 and 1 of 40 even-tempered s Gaussians: the direct
    ⟨δ³(r_ep)⟩ misses μ³/(πn³) by −9.8e-4 relative (both levels), the regularised one by −7.7e-7
    (measured): a factor above 1000; asserted 2e-6 and a factor 300."""
    basis, mu = hydrogen_s(3e-3 * 1.6 ** np.arange(40))
    rep, C, E = states(basis, 2)
    direct = expectation(rep, basis, C, "delta")
    regularised = delta_regularised(rep, basis, C, E)
    for n, d, r in zip((1, 2), direct, regularised):
        exact = mu**3 / (np.pi * n**3)
        assert set(r) == {"e-p"}
        err_d, err_r = abs(d["e-p"] / exact - 1), abs(r["e-p"] / exact - 1)
        assert err_r < 2e-6 and err_r < err_d / 300, (n, err_d, err_r)


def test_helium_direct_and_regularised_contact_densities_agree():
    """⁴He ground state in the 490 ecgpack functions (tests/data/ecgpack): ⟨δ³(r_αe)⟩ and ⟨δ³(r_ee)⟩
    direct and regularised agree within the direct values' basis error (measured differences 6.6e-5
    and 7.3e-5 relative; benchmarks/drachmann_convergence.py shows the direct values still moving by
    that much between 400 and 700 functions of another basis); translationally invariant coordinates
    give the same regularised values (1e-10 measured)."""
    basis = read_inout(ROOT / "tests" / "data" / "ecgpack" / "ecgpack-He4-490.inout.txt")
    rep, C, E = states(basis, 1)
    (direct,), (regularised,) = expectation(rep, basis, C, "delta"), delta_regularised(rep, basis, C, E)
    assert set(regularised) == {"alpha-e", "e-e"}
    for label in regularised:
        assert abs(regularised[label] / direct[label] - 1) < 2e-4, (label, direct[label], regularised[label])
    rep, C, E = states(basis, 1, translationally_invariant(basis.system))
    (invariant,) = delta_regularised(rep, basis, C, E)
    for label in regularised:
        assert abs(invariant[label] / regularised[label] - 1) < 1e-8, (label, invariant[label], regularised[label])


@pytest.mark.parametrize("name, size", [("h2plus-fecg", 100), ("h2plus-gvr", 60)])
def test_floating_and_global_vector_functions_regularise_too(name, size):
    """H2⁺ (p p e) in the first `size` functions of the floating-ECG (400) and ECG-GVR (180)
    examples, whose ⟨V/r_ij⟩ is the quadrature of eq. (38): the regularised ⟨δ³(r_ep)⟩ is nearer
    the direct value of the whole basis than the subset's direct value is (measured: 4.7e-4 against
    7.1e-3 for floating ECGs, 6.3e-4 against 3.4e-3 for ECG-GVR); translationally invariant
    coordinates give the same regularised values to 1e-7 (measured 2.1e-8: the quadrature's
    elements hold 1e-11, which the expansion's cancellation raises a thousandfold)."""
    whole = prebo.Basis.load(ROOT / "examples" / "bases" / name / "basis.json")
    rep, C, E = states(whole, 1)
    (reference,) = expectation(rep, whole, C, "delta")
    basis = whole.subset(range(size))
    rep, C, E = states(basis, 1)
    (direct,), (regularised,) = expectation(rep, basis, C, "delta"), delta_regularised(rep, basis, C, E)
    ref = reference["e-p"]
    assert abs(regularised["e-p"] - ref) < abs(direct["e-p"] - ref) / 4, (ref, direct, regularised)
    # the protons repel and are heavy: their contact density stays the direct one (drachmann.regularisable)
    assert set(regularised) == {"e-p"}
    rep, C, E = states(basis, 1, translationally_invariant(basis.system))
    (invariant,) = delta_regularised(rep, basis, C, E)
    assert abs(invariant["e-p"] / regularised["e-p"] - 1) < 1e-7, (invariant, regularised)


def test_properties_report_the_regularised_contact_density_of_each_level(tmp_path, capsys):
    """`prebo.properties` gives, beside the direct ⟨δ⟩, Drachmann's from the level's own expectation
    values and energy: the value `delta_regularised` computes from the states (to rounding), for
    roots 0 and 1 of hydrogen; for floating ECGs, whose ⟨V/r_ij⟩ is slow, only when asked."""
    basis, mu = hydrogen_s(3e-3 * 1.6 ** np.arange(40))
    rep, C, E = states(basis, 2)
    for root, want in enumerate(delta_regularised(rep, basis, C, E)):
        got = prebo.properties(basis, root=root)["delta_regularised"]
        assert abs(got["e-p"] / want["e-p"] - 1) < 1e-9, (root, got, want)
    fecg = prebo.Basis.load(ROOT / "examples" / "bases" / "h2plus-fecg" / "basis.json").subset(range(20))
    assert "delta_regularised" not in prebo.properties(fecg)
    rep, C, E = states(fecg, 1)
    (want,) = delta_regularised(rep, fecg, C, E)
    got = prebo.properties(fecg, regularised=True)["delta_regularised"]
    assert got.keys() == want.keys() and all(abs(got[k] - want[k]) <= 1e-9 * abs(want["e-p"]) for k in got), (got, want)
    fecg.save(tmp_path / "basis.json")
    assert main(["properties", str(tmp_path / "basis.json"), "--regularised", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["delta_regularised"] == got


def test_a_heavy_repelling_pair_keeps_the_direct_contact_density(capsys):
    """H₂ in 80 plain ECGs (examples/bases/h2-pecg): Drachmann's form for p-p multiplies its bracket's
    basis error by μ_pp/π ≈ 292 and gives −6.40 bohr⁻³ (measured) where the direct value is 4.4e-3 and
    the exact one is positive; so p-p is not regularised and the Breit–Pauli report takes its
    direct value, while e-p and e-e are regularised."""
    basis = prebo.Basis.load(ROOT / "examples" / "bases" / "h2-pecg" / "basis.json")
    p = prebo.properties(basis)
    assert set(p["delta_regularised"]) == {"e-p", "e-e"} and p["breit_pauli"]["regularised"]
    direct, m = p["expectation"]["delta"]["p-p"], basis.system.particles[0].mass
    assert direct > 0
    # the Darwin term of the one p-p pair of two Dirac protons (q_p² = 1) with the direct value
    darwin = -np.pi * prebo.level.relativistic.ALPHA**2 / 2 * (2 / m**2) * direct
    assert p["breit_pauli"]["classes"]["darwin"]["p-p"] == pytest.approx(darwin, rel=1e-12)
    # what the form would give for p-p: below zero
    inv_r, potential, gradient = (p["expectation"][name]["p-p"] for name in drachmann.TERMS)
    assert m / 2 / np.pi * (p["energy"] * inv_r - potential - gradient) < -1
    # the table prints the regularised row with the p-p cell empty
    assert main(["properties", str(ROOT / "examples" / "bases" / "h2-pecg" / "basis.json")]) == 0
    out = capsys.readouterr().out
    assert all(f"{p['delta_regularised'][c]:.10g}" in out for c in ("e-p", "e-e"))


def raw_delta(rep, basis, C, monkeypatch) -> list[dict]:
    """⟨δ³(r_ij)⟩ from its elements alone, whatever the symmetry says (`Operator.contact` off)."""
    from dataclasses import replace

    from prebo.level import expectation as module
    with monkeypatch.context() as m:
        m.setitem(module.OPERATORS, "delta", replace(module.OPERATORS["delta"], contact=False))
        return expectation(rep, basis, C, "delta")


@pytest.mark.parametrize("particles, spin", [(["alpha", "e", "e", "e"], {"e": 1.5}),
                                             (["p", "p", "e", "e"], {"p": 1, "e": 1})])
def test_a_contact_density_zero_by_symmetry_is_zero_and_its_elements_agree(particles, spin, monkeypatch):
    """For random bases of states whose symmetry makes a pair class antisymmetric (`vanishing`), the
    elements alone give ⟨δ³⟩ of that class at the rounding level (|value| < 1e-12 of the other
    classes'), and the reported value is 0.0 exactly, as is Drachmann's."""
    from conftest import random_basis
    from prebo.level.expectation import vanishing

    system = prebo.System(particles, spin=spin)
    basis = random_basis(system, 12, np.random.default_rng(5))
    rep, C, E = states(basis, 2)
    zero = vanishing(system)
    assert zero
    for raw, reported, regularised in zip(raw_delta(rep, basis, C, monkeypatch), expectation(rep, basis, C, "delta"),
                                          delta_regularised(rep, basis, C, E)):
        scale = max(abs(v) for k, v in raw.items() if k not in zero)
        for label in zero:
            assert abs(raw[label]) < 1e-12 * scale, (label, raw[label], scale)
            assert reported[label] == 0.0 and regularised.get(label, 0.0) == 0.0
        assert all(reported[k] == raw[k] for k in raw if k not in zero)


def test_the_triplet_contact_density_is_reported_as_zero(capsys):
    """He 2³S (examples/bases/he-inf-2-3s): ⟨δ³(r_ee)⟩ printed −1.16e-15 and Drachmann's
    −1.57e-8, seven orders larger; both are 0 (positive zero), as are the contact terms of the
    Breit–Pauli correction they give, and the α-e values are untouched."""
    import math
    assert main(["properties", str(ROOT / "examples" / "bases" / "he-inf-2-3s" / "basis.json"), "--json"]) == 0
    p = json.loads(capsys.readouterr().out)
    assert p["expectation"]["delta"]["e-e"] == 0.0 and p["delta_regularised"]["e-e"] == 0.0
    assert p["expectation"]["delta"]["He-e"] > 1.3 and p["delta_regularised"]["He-e"] > 1.3
    for term in ("darwin", "spin_spin"):
        v = p["breit_pauli"]["classes"][term]["e-e"]
        assert v == 0.0 and math.copysign(1.0, v) == 1.0
