"""The CM elimination (paper eq. ecg-transl) against two independent evaluations:
(i) LFCC with the internal mass matrix M - 1 1^T/(2 m_tot); (ii) TICC with μ (shared c_A)."""
import numpy as np
import pytest

import prebo
from prebo import eigen
from prebo.coordinates import heavy_particle_centred, jacobi
from prebo.errors import SeparabilityError
from prebo.integrals import laboratory, translationally_invariant

from conftest import random_basis

SYSTEMS = {
    2: (["p", "e"], {}),
    3: (["p", "e", "e"], {"e": 0}),
    4: (["p", "p", "e", "e"], {"p": 0, "e": 0}),
    5: (["alpha", "e", "e", "e", "mu"], {"e": 0.5}),
}


def rel(a, b):
    return np.max(np.abs(a - b)) / np.max(np.abs(b))


@pytest.mark.parametrize("n", sorted(SYSTEMS))
def test_eliminated_kinetic_equals_internal_mass_matrix(n):
    particles, spin = SYSTEMS[n]
    system = prebo.System(particles, spin=spin)
    basis = random_basis(system, 12, np.random.default_rng(n))  # mixed channels, unequal c_A
    assert len(set(basis.channels)) > 1 and np.ptp(basis.c_A) > 0.1
    m = laboratory(system).matrices(basis)
    internal = laboratory(system, kinetic="internal").matrices(basis)
    assert rel(m["T_ti"], internal["T"]) < 1e-12
    # the CM part removed is real: the lab kinetic matrix differs
    assert rel(m["T"], internal["T"]) > 1e-6
    for k in ("S", "V"):
        assert rel(m[k], internal[k]) < 1e-14


@pytest.mark.parametrize("n", sorted(SYSTEMS))
def test_lfcc_equals_ticc_for_shared_c_A(n):
    particles, spin = SYSTEMS[n]
    system = prebo.System(particles, spin=spin)
    # few functions per coordinate keep S well conditioned, so energies compare at 1e-12
    basis = random_basis(system, 4 * (n - 1), np.random.default_rng(10 + n), c_A=0.7)
    lab = laboratory(system).matrices(basis)
    for coords in (jacobi(system.masses), heavy_particle_centred(system.masses, 0)):
        ti = translationally_invariant(system, coords).matrices(basis)
        for k_lab, k_ti in (("S", "S"), ("T_ti", "T"), ("V", "V")):
            assert rel(lab[k_lab], ti[k_ti]) < 1e-12, (coords.name, k_lab)
    sol = eigen.solve(lab["T_ti"] + lab["V"], lab["S"])
    assert sol.overlap_condition < 1e6
    e_lab = sol.energies[:3]
    e_ti = eigen.solve(ti["T"] + ti["V"], ti["S"]).energies[:3]
    assert np.max(np.abs(e_lab - e_ti) / np.abs(e_ti)) < 1e-12


def test_lab_energy_is_ti_energy_plus_cm_kinetic_energy():
    """Shared c_A: Ψ = exp(-c_A X^2) × internal, so E_lab = E_TI + 3 c_A / (2 m_tot) exactly."""
    system = prebo.System(["p", "e", "e"], spin={"e": 0})
    basis = random_basis(system, 15, np.random.default_rng(3), c_A=2.5)
    r = prebo.evaluate(basis)
    assert r["energy_lab"] - r["energy"] == pytest.approx(1.5 * 2.5 / system.m_total, rel=1e-9)


def test_ti_evaluation_refuses_unequal_c_A():
    system = prebo.System(["p", "e", "e"], spin={"e": 0})
    basis = random_basis(system, 5, np.random.default_rng(4))
    with pytest.raises(SeparabilityError, match="not separable in the CM coordinate"):
        prebo.evaluate(basis, coordinates="ti")


def test_unequal_c_A_energy_is_an_upper_bound_of_the_shared_one():
    """Different c_A per function: the eliminated energy is <Ψ|H_int|Ψ> of a state that is not a
    CM product, still variational; here it must not fall below the shared-c_A energy of the same
    internal parameters by more than rounding (both are upper bounds to the same internal problem)."""
    system = prebo.System(["p", "e"])
    rng = np.random.default_rng(5)
    shared = random_basis(system, 8, rng, c_A=1.0)
    r_shared = prebo.evaluate(shared)
    exact = -0.5 * system.masses[0] / (1 + system.masses[0])
    mixed = prebo.Basis(system, shared.A + 0.0, np.ones(8))
    cm = system.cm_vector
    for i, c in enumerate(np.random.default_rng(6).uniform(0.2, 5.0, 8)):
        mixed.A[i] += (c - 1.0) * np.outer(cm, cm)
        mixed.c_A[i] = c
    r_mixed = prebo.evaluate(mixed)
    assert r_mixed["energy"] >= exact
    assert r_shared["energy"] >= exact


def test_non_separable_gvr_and_fecg_energies_stay_upper_bounds():
    """c_U != 0 (GVR) or centres with different CM positions (FECG): the function is no CM ×
    internal product, and the eliminated energy is <H_int ⊗ 1_CM>, still above the internal
    ground state. For N > 0, c_U != 0 lets the CM carry angular momentum: the internal part may
    then be an s state, so the energy is bounded by the ground state, not by the N = 1 level
    (docs/gvr.md) — which is why the optimiser keeps c_U = 0."""
    system = prebo.System(["p", "e"])
    mu = system.masses[0] / (1 + system.masses[0])
    x = jacobi(system.masses)
    alphas = 0.02 * 2.0 ** np.arange(12)
    A = np.array([x.to_lab(np.array([[a]]), 1.0) for a in alphas])
    rng = np.random.default_rng(8)
    fecg = prebo.Basis(system, A, np.ones(12), kind="fecg", s=rng.normal(size=(12, 2, 3)))
    assert np.ptp(np.einsum("i,nij->nj", system.cm_vector, fecg.s)) > 0.1  # CM positions differ
    assert prebo.evaluate(fecg)["energy"] > -mu / 2
    p2 = prebo.System(["p", "e"], state=prebo.State(N=1, parity=-1))
    u = np.tile([-1.0, 1.0], (12, 1)) + rng.normal(size=(12, 2))  # c_U = u_1 + u_2 != 0
    gvr = prebo.Basis(p2, A, np.ones(12), kind="ecg-gvr", u=u, K=np.zeros(12, int))
    assert np.all(np.abs(u.sum(axis=1)) > 1e-3)
    e = prebo.evaluate(gvr)["energy"]
    assert -mu / 2 < e < -mu / 8  # above the 1s level, below the 2p level it no longer describes
    gvr.u -= np.outer(u.sum(axis=1), system.cm_vector)  # c_U = 0: a genuine internal N = 1 state
    assert np.allclose(gvr.u.sum(axis=1), 0)
    assert prebo.evaluate(gvr)["energy"] > -mu / 8
