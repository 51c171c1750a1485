"""Generalised eigenproblem: oracle checks against scipy, S-orthonormality, the secular update."""
import numpy as np
import pytest
import scipy.linalg

import prebo
from prebo import eigen
from prebo.errors import NotPositiveDefiniteError
from prebo.integrals import laboratory

from conftest import random_basis


@pytest.fixture(scope="module")
def problem():
    system = prebo.System(["p", "e", "e"], spin={"e": 0})
    basis = random_basis(system, 10, np.random.default_rng(7), c_A=1.0)
    rep = laboratory(system)
    m = rep.matrices(basis)
    return system, basis, rep, m


def test_matches_scipy_and_is_S_orthonormal(problem):
    _, _, _, m = problem
    H, S = m["T_ti"] + m["V"], m["S"]
    sol = eigen.solve(H, S)
    ref = scipy.linalg.eigh(H, S, eigvals_only=True)
    assert np.allclose(sol.energies, ref, rtol=1e-11, atol=1e-12)
    C = sol.vectors
    assert np.allclose(C.T @ S @ C, np.eye(len(sol.energies)), atol=1e-10)
    assert np.allclose(H @ C, S @ C * sol.energies, atol=1e-9)


def test_secular_update_equals_full_solve(problem):
    system, basis, rep, m = problem
    keep = slice(0, 9)
    H, S = m["T_ti"] + m["V"], m["S"]
    sub = eigen.solve(H[keep, keep], S[keep, keep])
    e = eigen.lowest_with_added(sub.energies, sub.vectors, H[9, :9], S[9, :9], H[9, 9], S[9, 9])
    full = eigen.solve(H, S).energies[0]
    assert e == pytest.approx(full, rel=1e-12)
    assert e <= sub.energies[0]  # adding a function never raises the lowest eigenvalue


def test_rows_from_core_agree_with_matrices(problem):
    _, basis, rep, m = problem
    rows, diag = rep.rows(basis.subset([3, 4]), basis)
    for k, name in enumerate(("S", "T", "T_ti", "V")):
        assert np.allclose(rows[name], m[name][3:5], rtol=1e-14, atol=1e-15)
        assert np.allclose(diag[:, k], np.diag(m[name])[3:5], rtol=1e-14)


def test_duplicate_function_is_handled_without_inverse(problem):
    """An exact duplicate makes S singular: Cholesky (scipy) fails, canonical orthogonalisation
    drops the direction and reproduces the energy without the duplicate."""
    _, basis, rep, m = problem
    A = np.concatenate([basis.A, basis.A[:1]])
    c = np.concatenate([basis.c_A, basis.c_A[:1]])
    md = rep.matrices(prebo.Basis(basis.system, A, c))
    with pytest.raises(np.linalg.LinAlgError):
        scipy.linalg.eigh(md["T_ti"] + md["V"], md["S"])
    sol = eigen.solve(md["T_ti"] + md["V"], md["S"])
    assert sol.kept == len(A) - 1
    ref = eigen.solve(m["T_ti"] + m["V"], m["S"]).energies[0]
    assert sol.energies[0] == pytest.approx(ref, rel=1e-9)
    # and the update refuses the duplicate as linearly dependent
    base = eigen.solve(m["T_ti"] + m["V"], m["S"])
    H, S = md["T_ti"] + md["V"], md["S"]
    assert eigen.lowest_with_added(base.energies, base.vectors, H[-1, :-1], S[-1, :-1], H[-1, -1], S[-1, -1]) == np.inf


def test_indefinite_overlap_is_refused():
    S = np.array([[1.0, 2.0], [2.0, 1.0]])
    with pytest.raises(NotPositiveDefiniteError, match="not positive definite"):
        eigen.solve(np.eye(2), S)
