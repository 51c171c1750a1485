"""Momentum over refinement (optimise.momentum): the basis moved on along its displacement since a
reference, functions that were replaced left in place, the reference kept in the checkpoint."""
import json
from pathlib import Path

import numpy as np
import pytest

import prebo
from prebo.basis import Basis
from prebo.errors import BasisFileError
from prebo.integrals import laboratory
from prebo.optimise import Optimiser, resume_from
from prebo.optimise.expansion import Expansion
from prebo.optimise.momentum import MAX_STEP, Momentum
from prebo.optimise.parametrisation import Parametrisation

BASES = Path(__file__).resolve().parents[1] / "examples" / "bases"


def shifted(basis: Basis, d: list, t: float) -> Basis:
    """`basis` with function i at θ_i + t d_i (Parametrisation)."""
    ps = [Parametrisation.of(basis.subset([i])) for i in range(len(basis))]
    return Basis.concat([p.function(p.theta() + t * s) for p, s in zip(ps, d)])


@pytest.fixture(scope="module")
def optimised():
    """An optimised H2+ basis of 150 ECG-GVR functions, its representation and a direction in θ
    (1e-3 long for each function)."""
    basis = Basis.load(BASES / "h2plus-150" / "basis.json")
    rng = np.random.default_rng(3)
    d = [rng.normal(size=len(Parametrisation.of(basis.subset([i])).theta())) for i in range(len(basis))]
    return basis, laboratory(basis.system), [1e-3 * x / np.linalg.norm(x) for x in d]


def expansion(basis, rep):
    return Expansion(basis, rep, 1e-13)


def test_a_basis_pushed_off_its_optimum_moves_back_along_its_displacement(optimised):
    basis, rep, d = optimised
    E_opt = expansion(basis, rep).energy
    ex = expansion(shifted(basis, d, -1.0), rep)  # θ* − d, the reference θ* − 2d: the displacement points home
    E_off = ex.energy
    assert E_off > E_opt + 1e-12
    m = Momentum(shifted(basis, d, -2.0))
    before = ex.basis.subset(slice(None))
    assert m.move(ex)
    assert ex.energy < E_off - 0.5 * (E_off - E_opt)  # most of the way back
    assert np.array_equal(m.reference.A, before.A)  # the next move's reference: the basis before this one


def test_the_first_move_only_takes_the_reference_and_a_zero_displacement_moves_nothing(optimised):
    basis, rep, _ = optimised
    ex = expansion(basis.subset(slice(None)), rep)
    E = ex.energy
    m = Momentum()
    assert not m.move(ex) and ex.energy == E and np.array_equal(m.reference.A, basis.A)
    assert not m.move(ex) and ex.energy == E  # against itself: d = 0
    assert Momentum().to_dict() is None


def test_after_a_pruning_survivors_keep_their_reference_and_grown_functions_take_their_own(optimised):
    basis, rep, d = optimised
    reference, current = shifted(basis, d, -2.0), shifted(basis, d, -1.0)
    pruned = Basis.concat([current.subset(np.arange(3, 150)), basis.subset([0, 1, 2])])  # 0-2 removed, three grown
    m = Momentum(reference)
    m.follow(pruned, list(range(3, 150)) + [None] * 3)
    assert np.array_equal(m.reference.A[:147], reference.A[3:]) and np.array_equal(m.reference.A[147:], basis.A[:3])
    ex = expansion(pruned, rep)
    E = ex.energy
    assert m.move(ex) and ex.energy < E and np.array_equal(ex.basis.A[147:], basis.A[:3])  # grown: in place


def test_a_function_replaced_since_the_reference_stays_where_it_is(optimised):
    basis, rep, d = optimised
    current = shifted(basis, d, -1.0)
    reference = shifted(basis, d, -2.0)
    far = [np.zeros_like(x) for x in d]
    far[7] = d[7] * (2 * MAX_STEP / np.linalg.norm(d[7]))  # function 7 moved far: a replacement
    reference = shifted(reference, far, -1.0)
    ex = expansion(current, rep)
    assert Momentum(reference).move(ex)
    assert np.array_equal(ex.basis.A[7], current.A[7]) and not np.array_equal(ex.basis.A[8], current.A[8])


def test_the_reference_round_trips_through_the_checkpoint_and_another_run_s_is_refused(optimised):
    basis, _, _ = optimised
    m = Momentum(basis.subset(slice(None)))
    back = Momentum.from_dict(m.to_dict(), basis, "checkpoint")
    assert np.array_equal(back.reference.A, basis.A) and np.array_equal(back.reference.u, basis.u)
    assert Momentum.from_dict(None, basis, "checkpoint").reference is None  # checkpoints before 671d9a1
    for bad in (5, "x", [], {"functions": 3}):
        with pytest.raises(BasisFileError, match="checkpoint: momentum"):
            Momentum.from_dict(bad, basis, "checkpoint")
    other = Basis.load(BASES / "auto-h2" / "basis.json")
    with pytest.raises(BasisFileError, match="momentum"):
        Momentum.from_dict(Momentum(other).to_dict(), basis, "checkpoint")


def test_a_resumed_run_reads_the_reference_from_its_checkpoint_and_writes_it_back(tmp_path):
    he = prebo.System(["alpha", "e", "e"], spin={"e": 0})
    prebo.optimise(he, Optimiser(size=6, budget=0.5), out=tmp_path, progress=False)
    d = json.loads((tmp_path / "basis.json").read_text())
    reference = Basis.from_dict(d, "checkpoint")
    d["momentum"] = Momentum(reference).to_dict()
    d["optimiser"]["budget"] = d["elapsed"]  # resumed, it stops at once and writes its checkpoint again
    (tmp_path / "basis.json").write_text(json.dumps(d))
    resume_from(tmp_path, progress=False)
    again = json.loads((tmp_path / "basis.json").read_text())
    assert again["momentum"]["functions"] == d["momentum"]["functions"]
    again["momentum"]["system"]["particles"][0] = "p"  # a reference of another system
    (tmp_path / "basis.json").write_text(json.dumps(again))
    with pytest.raises(BasisFileError, match="momentum"):
        resume_from(tmp_path, progress=False)
