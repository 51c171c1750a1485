"""Plain-ECG matrix elements of prebo against independent numerical integration.

What is checked
---------------
For 2- and 3-particle systems of distinguishable particles (physical p, e, mu and
made-up particles with O(1) masses and charges of both signs) and small bases of
correlated Gaussians ``phi(r) = exp(-r^T (A ⊗ I_3) r)`` with full (non-diagonal)
exponent matrices and a different ``c_A`` per function, every element (diagonal
and I != J) of

- ``S``                      overlap,
- ``T``   (laboratory)       kinetic energy ``-Σ_i ∇_i²/(2 m_i)``, CM motion included,
- ``T_ti`` (laboratory)      kinetic energy with the CM part eliminated by prebo's formula,
- ``T``   (``kinetic="internal"``)  the kinetic operator ``-∇^T (M - 1 1^T/(2 m_tot)) ∇``,
- ``V``                      Coulomb ``Σ_{i<j} q_i q_j / |r_i - r_j|``

of normalised functions is compared with numerical integration over R^{3n}.
``T_ti`` of the laboratory representation and ``T`` of the internal one are
both compared with the *quadrature* of ``-∇^T (M - 1 1^T/(2 m_tot)) ∇``.

Method (nothing below uses prebo's closed formulas -- no determinants of
``A_I + A_J`` combined with ``2^D``, no ``Tr(B A_I Λ A_J)``, no ``w^T B w``)
-----------------------------------------------------------------------------
1. Cartesian factorisation.  ``r^T (A ⊗ I_3) r = Σ_{α=x,y,z} u_α^T A u_α`` with
   ``u_α = (r_{1α}, ..., r_{nα})``, so with ``g(u) = exp(-u^T A u)`` on R^n:
   ``<I|J> = s³``, ``s = ∫ g_I g_J du``;  for ``K = -∇^T Λ ∇ = -Σ_α Σ_ij Λ_ij ∂_{iα}∂_{jα}``:
   ``<I|K|J> = 3 k s²``, ``k = ∫ g_I (-Σ_ij Λ_ij ∂_i ∂_j g_J) du``.
   (One 2-particle test does the full 6-dimensional integrals instead, as a check
   of the factorisation and of the factor 3.)
2. Each n-dimensional integral ``∫ F(u) du`` is done by tensor-product
   Gauss-Hermite quadrature after the linear change of variables
   ``u = L^{-T} y``, ``L L^T = β (A_I + A_J)`` (β = 0.8, deliberately not 1):
   ``∫ F du = |L|^{-1} Σ_k w_k e^{|y_k|²} F(u_k)``.  ``F`` is a black-box
   function evaluator (the product of the two Gaussians times the operator),
   and because β != 1 the rule has to integrate ``exp(-(1/β - 1)|y|²) × poly``
   rather than reproduce its own weight.  20 nodes per dimension converge this
   to ~1e-15.
3. Kinetic operator: ``-Σ_ij Λ_ij ∂_i∂_j g_J = -Σ_k λ_k (v_k·∇)² g_J`` with
   ``Λ = Σ_k λ_k v_k v_k^T``; each directional second derivative is an
   8th-order central finite difference (9 points) of the function evaluator
   ``g_J`` with step ``0.02 / sqrt(v_k^T A_J v_k)`` (truncation + rounding
   ~1e-12 relative).
4. Coulomb: ``1/|r_i - r_j| = (2/√π) ∫_0^∞ exp(-t² |r_i - r_j|²) dt``; for each t
   the 3n-dimensional Gaussian integral again factorises into three copies of
   ``G(t) = ∫ g_I g_J exp(-t² (w^T u)²) du``, ``w = e_i - e_j``, done by the
   Gauss-Hermite rule of step 2 with ``L L^T = β (A_I + A_J + t² w w^T)``;
   ``∫_0^∞ G(t)³ dt`` is done by adaptive scipy.integrate.quad (epsrel 1e-13).
5. Independent of 4, ``V`` of the 2- and 3-particle bases is also estimated by
   Monte Carlo: 10^6 samples drawn from the normal density ∝ φ_I φ_J (fixed
   seed), ``V_IJ = S_IJ E[Σ q_i q_j / |r_i - r_j|]``, compared at 5 standard errors.

Tolerances: quadrature results must agree to 1e-8 relative (relative to
``max(|X_IJ|, sqrt(|X_II X_JJ|))`` for T, and for V to the same with the
charge products replaced by their absolute values, so that a near-cancelling
Coulomb element is not judged on its cancelled size).  The observed agreement
is ~1e-15 for S and V, ~1e-12 for T (finite differences), ~1e-10 for the 6D check.  ``test_kinetic_is_sensitive`` shows that a 1% error in a
single mass (or in the CM term) would exceed the tolerance by many orders.
"""
from __future__ import annotations

import itertools

import numpy as np
import pytest
from scipy.integrate import quad

import prebo
from prebo.integrals import laboratory

from conftest import custom, pair_A

RTOL = 1e-8
N_GH = 20  # Gauss-Hermite nodes per dimension
BETA = 0.8  # quadrature weight exp(-BETA u^T (A_I + A_J) u): not the integrand's own
FD_ETA = 0.02  # finite-difference step in units of the Gaussian's width along the direction
# 8th-order central second difference, offsets -4..4
FD_C = np.array([-1 / 560, 8 / 315, -1 / 5, 8 / 5, -205 / 72, 8 / 5, -1 / 5, 8 / 315, -1 / 560])
FD_K = np.arange(-4, 5)


# ---------------------------------------------------------------------------
# test systems and bases
# ---------------------------------------------------------------------------
SYSTEMS = {
    "p-e": lambda: prebo.System(["p", "e"]),
    "a-b": lambda: prebo.System([custom("a", 1.7, 2.0), custom("b", 0.6, -1.0)]),
    "p-e-mu": lambda: prebo.System(["p", "e", "mu"]),
    "x-y-z": lambda: prebo.System([custom("x", 3.0, 2.0), custom("y", 1.0, -1.0), custom("z", 0.45, -1.0)]),
}


def make_basis(system, nb=3, seed=0):
    """nb exponent matrices A = Σ_{i<j} α_ij (e_i-e_j)(e_i-e_j)^T + c_A (m/m_tot)(m/m_tot)^T (conftest.pair_A)."""
    rng = np.random.default_rng(seed)
    n = system.n
    u = system.cm_vector
    As, cs = [], []
    for b in range(nb):
        scale = [0.3, 1.0, 2.5, 0.6][b % 4]  # functions of quite different size
        A = pair_A(system, {p: scale * rng.uniform(0.2, 1.5) for p in itertools.combinations(range(n), 2)}, 0.0)
        c = rng.uniform(0.3, 2.0)
        A += c * np.outer(u, u)  # the CM term last, as these bases were always summed
        As.append(A)
        cs.append(c)
    A, c = np.array(As), np.array(cs)
    assert np.allclose(A @ np.ones(n), c[:, None] * u)  # what prebo requires
    assert np.all(np.abs(A - np.transpose(A, (0, 2, 1))) == 0)
    off = np.abs(A - np.eye(n) * A).max(axis=(1, 2))
    assert np.all(off > 0.05 * np.abs(A).max(axis=(1, 2)))  # genuinely correlated (non-diagonal)
    return A, c


# ---------------------------------------------------------------------------
# quadrature machinery (independent of prebo)
# ---------------------------------------------------------------------------
_GH_CACHE: dict = {}


def gh_grid(d, n_nodes=N_GH):
    """Tensor-product Gauss-Hermite nodes (P, d) and weights × exp(|y|²) (P,)."""
    key = (d, n_nodes)
    if key not in _GH_CACHE:
        y, w = np.polynomial.hermite.hermgauss(n_nodes)
        we = w * np.exp(y * y)
        Y = np.array(list(itertools.product(y, repeat=d)))
        W = np.prod(np.array(list(itertools.product(we, repeat=d))), axis=1)
        _GH_CACHE[key] = (Y, W)
    return _GH_CACHE[key]


def gauss_quad(F, W, n_nodes=N_GH):
    """∫_{R^d} F(u) du with the nodes of the weight exp(-u^T W u); F maps (P, d) -> (P,)."""
    L = np.linalg.cholesky(W)
    Y, w = gh_grid(W.shape[0], n_nodes)
    U = np.linalg.solve(L.T, Y.T).T  # u = L^{-T} y
    return float(np.sum(w * F(U)) / np.prod(np.diag(L)))


def gaussian(A, U):
    """exp(-u^T A u) for each row of U."""
    return np.exp(-np.einsum("pi,ij,pj->p", U, A, U))


def minus_lambda_laplacian(A, lam, U):
    """-Σ_ij Λ_ij ∂_i ∂_j exp(-u^T A u) by finite differences along Λ's eigenvectors."""
    ev, vecs = np.linalg.eigh(lam)
    out = np.zeros(len(U))
    for lk, v in zip(ev, vecs.T):
        h = FD_ETA / np.sqrt(v @ A @ v)
        d2 = sum(ck * gaussian(A, U + k * h * v) for ck, k in zip(FD_C, FD_K)) / h**2
        out -= lk * d2
    return out


def overlap_1(AI, AJ):
    """s = ∫_{R^n} g_I g_J du."""
    return gauss_quad(lambda U: gaussian(AI, U) * gaussian(AJ, U), BETA * (AI + AJ))


def kinetic_1(AI, AJ, lam):
    """k = ∫_{R^n} g_I (-Σ Λ_ij ∂_i∂_j g_J) du."""
    return gauss_quad(lambda U: gaussian(AI, U) * minus_lambda_laplacian(AJ, lam, U), BETA * (AI + AJ))


def coulomb_3n(AI, AJ, w):
    """<φ_I| 1/|w^T r| |φ_J> over R^{3n} = (2/√π) ∫_0^∞ G(t)³ dt."""
    C = AI + AJ
    ww = np.outer(w, w)

    def G(t):
        Ct = C + t * t * ww
        return gauss_quad(lambda U: gaussian(C, U) * np.exp(-t * t * (U @ w) ** 2), BETA * Ct)

    val, err = quad(lambda t: G(t) ** 3, 0.0, np.inf, epsabs=0.0, epsrel=1e-13, limit=200)
    assert err < 1e-11 * abs(val)
    return 2.0 / np.sqrt(np.pi) * val


def quadrature_matrices(system, A, lams):
    """S, V, V_abs and one kinetic matrix per Λ in `lams` (dict name -> Λ), by quadrature."""
    nb = len(A)
    w, q = system.coulomb_pairs()
    s1 = np.array([[overlap_1(A[i], A[j]) for j in range(nb)] for i in range(nb)])
    norm = np.sqrt(np.outer(np.diag(s1), np.diag(s1))) ** 3  # sqrt(<I|I><J|J>)
    out = {"S": s1**3 / norm}
    for name, lam in lams.items():
        k1 = np.array([[kinetic_1(A[i], A[j], lam) for j in range(nb)] for i in range(nb)])
        out[name] = 3.0 * k1 * s1**2 / norm
    V = np.zeros((nb, nb))
    Vabs = np.zeros((nb, nb))
    for i in range(nb):
        for j in range(i, nb):
            c = np.array([coulomb_3n(A[i], A[j], wp) for wp in w]) / norm[i, j]
            V[i, j] = V[j, i] = q @ c
            Vabs[i, j] = Vabs[j, i] = np.abs(q) @ c
    out["V"], out["V_abs"] = V, Vabs
    return out


def lambdas(system):
    M = np.diag(1.0 / (2.0 * system.masses))
    n = system.n
    return {"T": M, "T_int": M - np.ones((n, n)) / (2.0 * system.m_total)}


def scaled_deviation(x, ref, scale_from=None):
    """|x - ref| / max(|ref_IJ|, sqrt(|s_II s_JJ|)), s = scale_from (default ref)."""
    s = ref if scale_from is None else scale_from
    d = np.sqrt(np.abs(np.outer(np.diag(s), np.diag(s))))
    return np.abs(x - ref) / np.maximum(np.abs(ref), d)


# ---------------------------------------------------------------------------
# fixtures: prebo and quadrature, computed once per system
# ---------------------------------------------------------------------------
_CACHE: dict = {}


def computed(name):
    if name not in _CACHE:
        system = SYSTEMS[name]()
        A, c = make_basis(system, seed=sum(map(ord, name)))
        lab = laboratory(system).matrices(prebo.Basis(system, A, c))
        internal = laboratory(system, kinetic="internal").matrices(prebo.Basis(system, A, c))
        quadr = quadrature_matrices(system, A, lambdas(system))
        _CACHE[name] = (system, A, c, lab, internal, quadr)
    return _CACHE[name]


REPORT: dict = {}


def _check(name, label, x, ref, scale_from=None):
    dev = scaled_deviation(x, ref, scale_from)
    REPORT[(name, label)] = float(dev.max())
    worst = np.unravel_index(np.argmax(dev), dev.shape)
    assert dev.max() < RTOL, (
        f"{name} {label}{worst}: prebo {x[worst]!r} vs quadrature {ref[worst]!r} (rel. deviation {dev.max():.2e})"
    )


# ---------------------------------------------------------------------------
# tests
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("name", list(SYSTEMS))
def test_overlap(name):
    _, _, _, lab, internal, quadr = computed(name)
    _check(name, "S", lab["S"], quadr["S"])
    _check(name, "S (internal)", internal["S"], quadr["S"])
    assert np.all(np.abs(quadr["S"] - np.eye(len(quadr["S"]))) < 0.999)  # I != J genuinely differ


@pytest.mark.parametrize("name", list(SYSTEMS))
def test_kinetic_laboratory(name):
    _, _, _, lab, _, quadr = computed(name)
    _check(name, "T", lab["T"], quadr["T"])


@pytest.mark.parametrize("name", list(SYSTEMS))
def test_kinetic_cm_eliminated(name):
    """Lab T_ti (c_A elimination) and the internal representation's T vs -∇^T(M - 11^T/2m_tot)∇."""
    _, _, c, lab, internal, quadr = computed(name)
    assert len(set(np.round(c, 12))) == len(c)  # a different c_A for every function
    _check(name, "T_ti", lab["T_ti"], quadr["T_int"])
    _check(name, "T (internal)", internal["T"], quadr["T_int"])
    _check(name, "T_ti (internal)", internal["T_ti"], quadr["T_int"])


@pytest.mark.parametrize("name", list(SYSTEMS))
def test_coulomb(name):
    system, _, _, lab, internal, quadr = computed(name)
    q = system.coulomb_pairs()[1]
    assert q.min() < 0 < q.max() or system.n == 2
    _check(name, "V", lab["V"], quadr["V"], quadr["V_abs"])
    _check(name, "V (internal)", internal["V"], quadr["V"], quadr["V_abs"])


def test_charges_of_both_signs_covered():
    signs = set()
    for name in SYSTEMS:
        signs |= set(np.sign(SYSTEMS[name]().coulomb_pairs()[1]))
    assert signs == {-1.0, 1.0}


@pytest.mark.parametrize("name", ["a-b", "x-y-z", "p-e-mu"])
def test_kinetic_is_sensitive(name):
    """The comparison can fail: a 1% error in any one mass, or in the CM term, is far outside RTOL."""
    system, A, _, lab, _, quadr = computed(name)
    m = system.masses
    for i in range(system.n):
        mi = m.copy()
        mi[i] *= 1.01
        wrong = np.diag(1.0 / (2.0 * mi))
        k = 3.0 * kinetic_1(A[0], A[1], wrong) * overlap_1(A[0], A[1]) ** 2
        k /= (overlap_1(A[0], A[0]) * overlap_1(A[1], A[1])) ** 1.5
        assert abs(k - lab["T"][0, 1]) > 10 * RTOL * abs(lab["T"][0, 1])
    # CM term: removing 1% too much or too little CM kinetic energy
    assert np.min(0.01 * np.abs(lab["T"] - lab["T_ti"]) / np.abs(quadr["T_int"])) > 10 * RTOL


def test_full_six_dimensional_two_particles():
    """No Cartesian factorisation: φ(r) = exp(-Σ_ij A_ij r_i·r_j) integrated over R^6 directly."""
    system = prebo.System([custom("a", 1.3, 1.0), custom("b", 0.8, -1.0)])
    A, c = make_basis(system, nb=2, seed=7)
    lab = laboratory(system).matrices(prebo.Basis(system, A, c))
    I3 = np.eye(3)
    A6 = [np.kron(a, I3) for a in A]  # r = (x1, y1, z1, x2, y2, z2)
    lam6 = np.kron(np.diag(1.0 / (2.0 * system.masses)), I3)
    n6 = 10  # 10^6 nodes; exp(-(1/β-1)|y|²)·poly with β = 0.9 is exact to ~1e-11 per dimension

    def q6(F, W):
        return gauss_quad(F, W, n_nodes=n6)

    ov = {}
    for i in range(2):
        for j in range(2):
            ov[i, j] = q6(lambda U: gaussian(A6[i], U) * gaussian(A6[j], U), 0.9 * (A6[i] + A6[j]))
    t01 = q6(lambda U: gaussian(A6[0], U) * minus_lambda_laplacian(A6[1], lam6, U), 0.9 * (A6[0] + A6[1]))
    norm = np.sqrt(ov[0, 0] * ov[1, 1])
    S, T = ov[0, 1] / norm, t01 / norm
    for label, x, ref in (("S6", lab["S"][0, 1], S), ("T6", lab["T"][0, 1], T)):
        REPORT[("a-b 6D", label)] = abs(x / ref - 1)
        assert abs(x / ref - 1) < RTOL, f"{label}: prebo {x!r} vs 6D quadrature {ref!r}"


@pytest.mark.parametrize("name", ["a-b", "x-y-z"])
def test_coulomb_monte_carlo(name):
    """V by Monte Carlo (no 1/r representation at all), 10^6 samples, 5 standard errors."""
    system, A, _, lab, _, quadr = computed(name)
    w, q = system.coulomb_pairs()
    rng = np.random.default_rng(2024)
    n_samples = 1_000_000
    for i, j in ((0, 1), (1, 2), (2, 2)):
        C = A[i] + A[j]
        # density ∝ exp(-Σ_α u_α^T C u_α): each Cartesian component u_α ~ N(0, (2C)^{-1})
        L = np.linalg.cholesky(2.0 * C)
        z = rng.standard_normal((3, n_samples, system.n))
        u = np.linalg.solve(L.T, z.reshape(-1, system.n).T).T.reshape(3, n_samples, system.n)
        rij = u @ w.T  # (3, samples, pairs): components of r_i - r_j
        f = (q / np.sqrt(np.sum(rij**2, axis=0))).sum(axis=1)
        mean, sem = f.mean(), f.std(ddof=1) / np.sqrt(n_samples)
        est, err = lab["S"][i, j] * mean, abs(lab["S"][i, j]) * sem
        REPORT[(name, f"V MC ({i},{j}) sigmas")] = abs(lab["V"][i, j] - est) / err
        assert abs(lab["V"][i, j] - est) < 5.0 * err, (
            f"{name} V[{i},{j}]: prebo {lab['V'][i, j]!r} vs Monte Carlo {est!r} ± {err:.2e}"
        )
        assert err < 2e-3 * abs(est)  # the Monte Carlo check has teeth at the 1% level


def test_report():
    """Print the largest scaled deviations seen by the tests above (shown with pytest -s)."""
    for name in SYSTEMS:
        computed(name)
    for key, val in sorted(REPORT.items()):
        print(f"  {key[0]:8s} {key[1]:22s} {val:.2e}")
