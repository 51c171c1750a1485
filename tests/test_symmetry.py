"""Young-operator coefficients c_P = sign(P)^(2s) <chi|P chi> for the cases of the literature."""
from fractions import Fraction as F

import numpy as np
import pytest

import prebo
from prebo.errors import SpinError
from prebo.system.permutations import sign as permutation_sign
from prebo.system.symmetry import Group, clebsch_gordan


def coefficients(particles, spin):
    sym = prebo.System(particles, spin=spin).symmetriser
    return {p: round(c, 12) for p, c in zip(sym.permutations, sym.coefficients)}


def test_two_fermions_singlet_is_spatially_symmetric():
    assert coefficients(["p", "e", "e"], {"e": 0}) == {(0, 1, 2): 1.0, (0, 2, 1): 1.0}


def test_two_fermions_triplet_is_spatially_antisymmetric():
    assert coefficients(["p", "e", "e"], {"e": 1}) == {(0, 1, 2): 1.0, (0, 2, 1): -1.0}


def test_three_electrons_doublet():
    """chi = (αβ - βα)α/√2: Y = 1 + P12 - (P13 + P23 + P123 + P132)/2 (e.g. Li 1s^2 2s)."""
    c = coefficients(["alpha", "e", "e", "e"], {"e": 0.5})
    assert c == {
        (0, 1, 2, 3): 1.0, (0, 2, 1, 3): 1.0,
        (0, 1, 3, 2): -0.5, (0, 3, 2, 1): -0.5, (0, 2, 3, 1): -0.5, (0, 3, 1, 2): -0.5,
    }


def test_three_electrons_quartet_is_fully_antisymmetric():
    c = coefficients(["alpha", "e", "e", "e"], {"e": 1.5})
    assert len(c) == 6
    for p, v in c.items():
        assert v == permutation_sign(p)


@pytest.mark.parametrize("nuclear, sign", [(0, 1.0), (1, -1.0)])
def test_h2_para_ortho_with_singlet_electrons(nuclear, sign):
    c = coefficients(["p", "p", "e", "e"], {"p": nuclear, "e": 0})
    assert c == {(0, 1, 2, 3): 1.0, (1, 0, 2, 3): sign, (0, 1, 3, 2): 1.0, (1, 0, 3, 2): sign}


@pytest.mark.parametrize("S, sign", [(0, 1.0), (1, -1.0), (2, 1.0)])
def test_two_spin_one_bosons(S, sign):
    """D2 nuclei: <chi_S|P12|chi_S> = (-1)^(2s - S), no fermion sign."""
    c = coefficients(["d", "d", "e", "e"], {"d": S, "e": 0})
    assert c[(1, 0, 2, 3)] == sign and c[(0, 1, 2, 3)] == 1.0


def test_young_operator_is_idempotent_up_to_a_factor():
    """Y = Σ c_P P with c from one spin function satisfies Y Y = λ Y (projector property)."""
    g = Group("e", (0, 1, 2, 3), F(1, 2), F(0))
    c = g.coefficients()
    compose = lambda p, q: tuple(p[q[i]] for i in range(len(p)))  # noqa: E731
    prod = {}
    for p, a in c.items():
        for q, b in c.items():
            r = compose(p, q)
            prod[r] = prod.get(r, 0.0) + a * b
    lam = prod[(0, 1, 2, 3)] / c[(0, 1, 2, 3)]
    for p in set(prod) | set(c):
        assert prod.get(p, 0.0) == pytest.approx(lam * c.get(p, 0.0), abs=1e-12)


def test_impossible_spin_is_refused():
    with pytest.raises(SpinError, match="cannot couple to total spin 1"):
        prebo.System(["alpha", "e", "e", "e"], spin={"e": 1})
    with pytest.raises(SpinError):
        prebo.System(["p", "e", "e"], spin={"e": 2})


def test_clebsch_gordan_known_values():
    h = F(1, 2)
    assert clebsch_gordan(h, h, h, -h, F(0), F(0)) == pytest.approx(np.sqrt(0.5))
    assert clebsch_gordan(h, -h, h, h, F(0), F(0)) == pytest.approx(-np.sqrt(0.5))
    assert clebsch_gordan(F(1), F(1), F(1), F(-1), F(0), F(0)) == pytest.approx(np.sqrt(1 / 3))
    assert clebsch_gordan(F(1), F(0), F(1), F(0), F(2), F(0)) == pytest.approx(np.sqrt(2 / 3))


def test_an_explicit_operator_is_kept_only_when_the_spin_state_does_not_give_it():
    """One concept: System(symmetriser=S) carries S exactly when S is not the spin state's own
    operator up to a factor; basis.json's "symmetry" block brings it back; S may only permute
    identical particles."""
    from prebo.errors import InputError
    from prebo.system import Symmetriser
    from prebo.system.young import young_operator

    he = prebo.System(["alpha", "e", "e"], spin={"e": 0})
    own = he.symmetriser
    twice = Symmetriser(own.permutations, tuple(2 * c for c in own.coefficients), young="(1+P23)")
    assert prebo.System(he.particles, he.state, symmetriser=twice).symmetriser is not twice
    li = ["alpha", "e", "e", "e"]
    row = young_operator("(1+P23)(1-P24)", 4)  # another row of the doublet's representation
    s = prebo.System(li, spin={"e": 0.5}, symmetriser=row)
    assert s.symmetriser is row and "(1+P23)(1-P24)" in repr(s)
    assert not row.equivalent(prebo.System(li, spin={"e": 0.5}).symmetriser)
    back = prebo.System.from_dict(s.to_dict(), s.symmetriser.as_dict())
    assert back.symmetriser == row and back.symmetriser.young is None  # the label is not stored
    with pytest.raises(InputError, match="not identical"):
        prebo.System(["e", "alpha", "e", "e"], spin={"e": 0.5}, symmetriser=row)


@pytest.mark.parametrize("particles, spin, zero", [
    (["p", "e", "e"], {"e": 0}, []), (["p", "e", "e"], {"e": 1}, ["e-e"]),
    (["alpha", "e", "e", "e"], {"e": 0.5}, []), (["alpha", "e", "e", "e"], {"e": 1.5}, ["e-e"]),
    (["p", "p", "e", "e"], {"p": 1, "e": 0}, ["p-p"]), (["p", "p", "e", "e"], {"p": 0, "e": 1}, ["e-e"]),
    (["d", "d", "e", "e"], {"d": 1, "e": 0}, ["d-d"]), (["d", "d", "e", "e"], {"d": 2, "e": 0}, []),
    (["e", "e", "e+"], {"e": 0}, [])])
def test_the_pairs_at_whose_coalescence_every_state_vanishes(particles, spin, zero):
    """A pair class vanishes by symmetry when the operator makes each of its pairs antisymmetric
    (P_ij O = O P_ij = −O): two identical fermions with symmetric spins (triplet, quartet), spin-1
    bosons in S = 1; not the electron pairs of a doublet of three, whose operator mixes both."""
    from prebo.level.expectation import vanishing
    assert vanishing(prebo.System(particles, spin=spin)) == zero
