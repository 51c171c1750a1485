"""Independent reference evaluations of floating-ECG (FECG) matrix elements for
tests/test_fecg_integrals.py.

Functions φ(r) = exp(-(r - s)^T (A ⊗ I_3) (r - s)) with an n x 3 matrix of centres s; a
function is passed as (A, s).  Nothing here uses prebo's closed formulas (no erf / Boys
series, no 6R + Q kinetic formula, no t = (A - c_A μμ^T) s angular vectors, no cm_kinetic
expression); the methods Q1 and Q2 are described in the docstring of
tests/test_fecg_integrals.py:

* Q1 ``gh_pair``: unnormalised S, -∇^T Λ ∇ (ket and gradient forms) and N_TI² (ket and
  Hermitian forms) by the exact tensor Gauss–Hermite rule over R^{3n} (``gh_tensor``);
* Q2 ``coulomb_pair``: unnormalised 1/|w^T r| by the t integral of Gaussian integrals
  (``log_gauss_integral``, Gauss–Legendre in θ with ``N_THETA`` nodes); ``blind_log_gaussian``
  checks the Gaussian integral by a quadrature without completion of the square;
* ``reference``: the normalised, Young-symmetrised S, T, T_ti, V, N² of a basis by Q1/Q2
  (images P φ = φ(Π r) from ``images``); ``coulomb_reference``: V alone by Q2.
"""
from __future__ import annotations

import functools
import itertools

import numpy as np
from scipy.special import roots_hermite

N_THETA = 64  # Gauss–Legendre nodes of the Coulomb t-integral


# ---------------------------------------------------------------------------
# Q1: exact tensor Gauss–Hermite rule over R^{3n}
# ---------------------------------------------------------------------------
@functools.lru_cache(maxsize=None)
def gh_tensor(p, dim):
    """Tensor-product Gauss–Hermite nodes (P, dim), weights (P,) for exp(-|y|²), and |y|² (P,)."""
    x, w = roots_hermite(p)
    Y = np.array(list(itertools.product(x, repeat=dim)))
    W = functools.reduce(np.multiply.outer, [w] * dim).ravel()
    return Y, W, np.sum(Y * Y, axis=1)


def log_fecg(A, s, x):
    """log φ(x) = -Σ_c (x_c - s_c)^T A (x_c - s_c) for nodes x (P, n, 3)."""
    d = x - s
    return -np.einsum("pic,ij,pjc->p", d, A, d)


E3 = np.eye(3)


def gh_pair(fI, fJ, lams, mu, p):
    """Unnormalised <φ_I| X |φ_J> for X = 1, -∇^T Λ ∇ (each Λ in `lams`, ket and gradient forms)
    and N² (ket and Hermitian forms) by the tensor Gauss–Hermite rule with p nodes per dimension."""
    (AI, sI), (AJ, sJ) = fI, fJ
    n = len(AI)
    B = AI + AJ
    L = np.linalg.cholesky(B)
    LiT = np.linalg.inv(L).T
    rbar = np.linalg.solve(B, AI @ sI + AJ @ sJ)
    Y, W, Y2 = gh_tensor(p, 3 * n)
    x = rbar[None] + np.einsum("ij,pjc->pic", LiT, Y.reshape(-1, n, 3))  # (P, particle, component)
    logg = log_fecg(AI, sI, x) + log_fecg(AJ, sJ, x) + Y2
    g = np.exp(logg)
    # the weight is exactly φ_I φ_J: the ratio is one constant over the grid
    assert np.ptp(logg) < 1e-12 * max(1.0, np.max(np.abs(logg))) + 1e-12, np.ptp(logg)
    wg = W * g * np.linalg.det(B) ** -1.5  # dx = |L|^{-3} dy
    GI = np.einsum("ij,pjc->pic", AI, x - sI)  # ∇_i φ = -2 G_i φ
    GJ = np.einsum("ij,pjc->pic", AJ, x - sJ)
    out = {"S": np.sum(wg)}
    for name, lam in lams.items():
        ket = 6.0 * np.trace(lam @ AJ) - 4.0 * np.einsum("pic,ij,pjc->p", GJ, lam, GJ)
        grad = 4.0 * np.einsum("pic,ij,pjc->p", GI, lam, GJ)
        out[name] = np.sum(wg * ket)
        out[name + "/grad"] = np.sum(wg * grad)
    # N² on the ket: rigid rotations about the CM, exact θ-derivatives of Q(θ) = -log φ_J
    R = np.einsum("i,pic->pc", mu, x)
    d = x - R[:, None, :]
    n2 = np.zeros(len(W))
    for k in range(3):
        xp = np.cross(E3[k], d)  # dx/dθ
        xpp = np.cross(E3[k], xp)  # d²x/dθ²
        q1 = 2.0 * np.einsum("pic,pic->p", xp, GJ)
        q2 = 2.0 * (np.einsum("pic,ij,pjc->p", xp, AJ, xp) + np.einsum("pic,pic->p", xpp, GJ))
        n2 += q2 - q1 * q1
    out["N2"] = np.sum(wg * n2)
    hI = np.sum(np.cross(d, GI), axis=1)  # L φ = -2 h φ
    hJ = np.sum(np.cross(d, GJ), axis=1)
    out["N2/herm"] = np.sum(wg * 4.0 * np.einsum("pc,pc->p", hI, hJ))
    return out


# ---------------------------------------------------------------------------
# Q2: Coulomb by the t-integral of Gaussian integrals
# ---------------------------------------------------------------------------
def log_gauss_integral(Q, b, c0):
    """log Π_c ∫_{R^n} exp(-x^T Q x + 2 b_c^T x - c0_c) dx, b (n, 3), c0 (3,) (generic formula)."""
    n = len(Q)
    sign, logdet = np.linalg.slogdet(Q)
    assert sign > 0
    y = np.linalg.solve(Q, b)
    return 1.5 * (n * np.log(np.pi) - logdet) + np.sum(b * y) - np.sum(c0)


@functools.lru_cache(maxsize=None)
def theta_rule(nt):
    x, w = np.polynomial.legendre.leggauss(nt)
    return (x + 1) * np.pi / 4, w * np.pi / 4


def coulomb_pair(fI, fJ, w, nt=N_THETA):
    """Unnormalised <φ_I| 1/|w^T r| |φ_J> = (2/√π) ∫_0^∞ G(t) dt, and log <φ_I|φ_J> (t = 0)."""
    (AI, sI), (AJ, sJ) = fI, fJ
    B = AI + AJ
    b = AI @ sI + AJ @ sJ
    c0 = np.sum(sI * (AI @ sI), axis=0) + np.sum(sJ * (AJ @ sJ), axis=0)
    scale = np.sqrt(w @ np.linalg.solve(B, w))  # only sets the t scale of the substitution
    th, wt = theta_rule(nt)
    t = np.tan(th) / scale
    dt = wt / (np.cos(th) ** 2 * scale)
    ww = np.outer(w, w)
    G = np.array([np.exp(log_gauss_integral(B + tk * tk * ww, b, c0)) for tk in t])
    return 2.0 / np.sqrt(np.pi) * np.sum(dt * G), log_gauss_integral(B, b, c0)


# ---------------------------------------------------------------------------
# reference matrices
# ---------------------------------------------------------------------------
def images(system, A, s):
    """(c_P, Π^T A Π, Π^T s) of P φ(r) = φ(Π r) for each operation of the Young operator;
    the parameters are checked against φ(Π r) evaluated from the definition."""
    sym = system.symmetriser
    r = np.random.default_rng(5).normal(size=(7, len(A), 3))
    out = []
    for Pi, c in zip(sym.matrices, sym.coefficients):
        Ap, sp = Pi.T @ A @ Pi, Pi.T @ s
        direct = log_fecg(A, s, np.einsum("ij,pjc->pic", Pi, r))
        assert np.allclose(log_fecg(Ap, sp, r), direct, rtol=1e-14, atol=1e-14)
        out.append((c, Ap, sp))
    return out


def reference(system, A, s, p, coulomb=True):
    """Normalised, symmetrised S, T, T_ti, V, N² (and the cross-check forms) by Q1/Q2."""
    nb = len(A)
    lams = {"T": system.M, "T_ti": system.M_internal}
    mu = system.cm_vector
    wv, qv = system.coulomb_pairs()
    norm = [gh_pair((A[i], s[i]), (A[i], s[i]), lams, mu, p)["S"] for i in range(nb)]
    out: dict = {}
    for i in range(nb):
        for j in range(i, nb):
            acc: dict = {}
            for c, Aj, sj in images(system, A[j], s[j]):
                e = gh_pair((A[i], s[i]), (Aj, sj), lams, mu, p)
                if coulomb:
                    e["V"], e["V_abs"] = 0.0, 0.0
                    for w, q in zip(wv, qv):
                        val, logs = coulomb_pair((A[i], s[i]), (Aj, sj), w)
                        assert abs(np.exp(logs) / e["S"] - 1) < 1e-13  # Q2's Gaussian at t = 0 == Q1
                        e["V"] += q * val
                        e["V_abs"] += abs(q) * val
                for k, v in e.items():
                    acc[k] = acc.get(k, 0.0) + c * v
            nrm = np.sqrt(norm[i] * norm[j])
            for k, v in acc.items():
                out.setdefault(k, np.zeros((nb, nb)))
                out[k][i, j] = out[k][j, i] = v / nrm
    return out


def blind_log_gaussian(fI, fJ, w, t, p=24, beta=0.8):
    """log ∫ φ_I φ_J exp(-t² |w^T r|²) dr by a Gauss–Hermite rule (p nodes per dimension,
    per Cartesian component) whose weight exp(-β x^T (B + t² w w^T) x) is centred at 0 and
    deliberately too wide: no completion of the square, a genuine quadrature."""
    (AI, sI), (AJ, sJ) = fI, fJ
    Q = AI + AJ + t * t * np.outer(w, w)
    L = np.linalg.cholesky(beta * Q)
    Y, W, Y2 = gh_tensor(p, len(Q))
    x = Y @ np.linalg.inv(L)  # rows x = L^{-T} y
    total = 0.0
    for c in range(3):
        dI, dJ = x - sI[:, c], x - sJ[:, c]
        f = np.exp(-np.einsum("pi,ij,pj->p", dI, AI, dI) - np.einsum("pi,ij,pj->p", dJ, AJ, dJ)
                   - t * t * (x @ w) ** 2 + Y2)
        total += np.log(np.sum(W * f) / np.prod(np.diag(L)))
    return total


def coulomb_reference(system, A, s):
    """Normalised V and V_abs (|q| in place of q) by Q2 alone (distinguishable particles)."""
    nb = len(A)
    wv, qv = system.coulomb_pairs()
    logn = [log_gauss_integral(2 * A[i], 2 * A[i] @ s[i], 2 * np.sum(s[i] * (A[i] @ s[i]), axis=0))
            for i in range(nb)]
    V, Vabs = np.zeros((nb, nb)), np.zeros((nb, nb))
    for i in range(nb):
        for j in range(i, nb):
            vals = np.array([coulomb_pair((A[i], s[i]), (A[j], s[j]), w)[0] for w in wv])
            nrm = np.exp(0.5 * (logn[i] + logn[j]))
            V[i, j] = V[j, i] = qv @ vals / nrm
            Vabs[i, j] = Vabs[j, i] = np.abs(qv) @ vals / nrm
    return V, Vabs
