"""Matrix elements that lose their digits to cancellation (prebo/integrals.py): refused as trials,
as a basis and as a state without positive kinetic energy — the cases a new user met: He 2³S at
-4.3e9 Eh, two electrons "bound" at -106 Eh, two triplet electrons in plain ECGs (a traceback)."""
import numpy as np
import pytest

import prebo
from conftest import ROOT, cli_error, random_basis
from prebo.errors import CancellationError, UnsupportedError
from prebo.integrals import laboratory
from prebo.optimise.expansion import Expansion

HE_FILE = ROOT / "tests" / "data" / "ecgpack" / "ecgpack-He4-490.inout.txt"


def he_triplet_with_a_symmetric_function(rng) -> tuple:
    """Five random functions of He 2³S, the fourth made symmetric in the two electrons (A and
    P A P averaged, P the exchange of particles 1 and 2: still CM-separable), which the triplet's
    symmetriser 1 - P12 annihilates."""
    he = prebo.System(["alpha", "e", "e"], spin={"e": 1})
    b = random_basis(he, 5, rng)
    P = np.eye(3)[[0, 2, 1]]
    A = b.A.copy()
    A[3] = 0.5 * (A[3] + P @ A[3] @ P)
    return he, prebo.Basis(he, A, b.c_A, b.channels)


def test_a_function_the_symmetriser_annihilates_is_refused(tmp_path):
    he, basis = he_triplet_with_a_symmetric_function(np.random.default_rng(3))
    with pytest.raises(CancellationError, match="basis function 3 of 5 .*nearly annihilates"):
        prebo.evaluate(basis)
    prebo.evaluate(basis.subset([0, 1, 2, 4]))  # the others are fine
    ex = Expansion(basis.subset([0, 1, 2]), laboratory(he), 1e-13)
    energies, _, _ = ex.candidates(basis.subset([3, 4]))
    assert energies[0] == np.inf and np.isfinite(energies[1])  # as a trial: never chosen


def test_a_file_of_the_wrong_symmetry_is_refused_not_evaluated(tmp_path, capsys):
    """The singlet He-490 file relabelled (1-P23): 18 of its functions are nearly symmetric in the
    electrons; it gave -2.836 Eh "bound", far below the lowest triplet (-2.175)."""
    f = tmp_path / "triplet.inout.txt"
    f.write_text(HE_FILE.read_text().replace("SYMMETRY (1+P23)", "SYMMETRY (1-P23)"))
    err = cli_error(capsys, "energy", f)
    assert "nearly annihilates" in err and "symmetry" in err


def test_functions_whose_internal_kinetic_energy_is_lost_are_refused():
    """Two electrons that are almost only a CM Gaussian: internal exponents 1e-7 of the CM one."""
    ee = prebo.System(["e", "e"], spin={"e": 0})
    rel = np.array([[1.0, -1.0], [-1.0, 1.0]])
    A = np.array([0.25 * np.ones((2, 2)) + a * rel for a in (1e-7, 2e-7, 3e-7)])
    with pytest.raises(CancellationError, match="internal kinetic energy"):
        prebo.evaluate(prebo.Basis(ee, A, np.ones(3), ["pairs"] * 3))


def test_two_electrons_are_not_bound(tmp_path):
    """The new user's input (adaptive schedule, seed 2): it ended at -105.9 Eh, "bound", a state of
    negative kinetic energy built from rounding (Expansion.sound)."""
    ee = prebo.System(["e", "e"], spin={"e": 0})
    basis = prebo.optimise(ee, prebo.Optimiser(size=10, seed=2, budget=20), progress=False)
    r = prebo.evaluate(basis)
    assert r["energy"] > 0 and r["kinetic"] > 0 and not r["bound"]


def test_a_state_no_function_of_the_family_can_describe_is_an_error():
    """Two triplet electrons in plain ECGs (N = 0): every function is symmetric in them."""
    ee = prebo.System(["e", "e"], spin={"e": 1})
    with pytest.raises(UnsupportedError, match="pecg functions cannot describe this state"):
        prebo.optimise(ee, prebo.Optimiser(size=5, seed=1), progress=False)


def test_light_particles_with_a_heavy_cm_gaussian_stay_above_the_exact_energy():
    """Two particles of 1e-3 m_e at c_A = 1: the CM Gaussian's kinetic energy (750 Eh) is 3e6 times
    the binding; with T_ti,nn ≥ 1e-5 T_nn allowed the run reached -7.2e-4 Eh, below the exact
    -μ/2 = -2.5e-4 (the translation-invariant evaluation of that basis: +2.0e-3)."""
    light = prebo.System([{"name": "a", "mass": 1e-3, "charge": 1, "spin": 0},
                          {"name": "b", "mass": 1e-3, "charge": -1, "spin": 0}])
    basis = prebo.optimise(light, prebo.Optimiser(size=10, seed=3, budget=10), progress=False)
    assert prebo.evaluate(basis)["energy"] > -0.25e-3


@pytest.mark.parametrize("mass, radius", [(1e7, "2.0e-07"), (1e-6, "2.0e+06")])
def test_a_pair_whose_exponents_c_a_cannot_hold_is_refused_in_one_line(tmp_path, capsys, mass, radius):
    """Two particles of charges ±1 and mass 1e7 (Bohr radius 2e-7 bohr: exponents ~2.5e13 bohr⁻², 2.5e13
    times c_A = 1) or 1e-6: the trials' A lose their Cholesky factor in the core (the run stopped at the
    first such trial, naming it as "basis function 11") or their integrals their digits. Every trial is
    refused (parallel.refusing), and the error names the Bohr radius and the way out."""
    f = tmp_path / "pair.toml"
    f.write_text(f'[system]\nparticles = [{{name = "x", mass = {mass}, charge = 1, spin = 0}}, '
                 f'{{name = "y", mass = {mass}, charge = -1, spin = 0}}]\n[basis]\nsize = 4\n')
    err = cli_error(capsys, "run", f, "--out", tmp_path / "out", "--quiet")
    assert f"Bohr radius, {radius} bohr" in err and "units that bring the Bohr radii near 1" in err
