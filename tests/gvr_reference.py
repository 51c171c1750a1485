"""Independent reference evaluations of ECG-GVR matrix elements for tests/test_gvr_integrals.py.

Functions φ(r) = |v|^{2K} (v_x + i v_y)^N exp(-r^T (A ⊗ I_3) r), v = u^T r; a function is
passed as (A, u, K).  Nothing here uses prebo's closed formulas (no Ω series ĉ_k, no
Stein/Price identities, no cm_kinetic expression); the methods are described in the
docstring of tests/test_gvr_integrals.py:

* double precision, 2 particles (item 1): ``gh_overlap_kinetic`` -- unnormalised S and
  <∇φ_I|Λ|∇φ_J> by the exact tensor-product Gauss–Hermite rule (``gh_tensor``, with
  ``poly_P`` / ``grad_P``); ``spherical_overlap_coulomb`` -- S and 1/|r_1 - r_2| in
  (X, x) coordinates (Gauss–Hermite × Gauss–Laguerre × Gauss–Legendre × trapezoid);
* mpmath at the caller's precision (item 3; the tests use 50 digits): ``MpPair`` --
  unnormalised S, -∇^T Λ ∇ and 1/|w^T r| (up to a common factor) by the Wigner–Eckart kernel
  and the exact Gaussian moments ``gauss_moment``, the Coulomb t integral by the mpmath
  Gauss–Legendre rule ``gauss_legendre_01``; ``mp_reference`` -- the normalised S, T, T_ti, V
  of a system for given index pairs.
"""
from __future__ import annotations

import functools
import itertools
from fractions import Fraction
from math import comb, factorial

import mpmath
import numpy as np
from scipy.special import roots_genlaguerre, roots_hermite, roots_legendre


# ---------------------------------------------------------------------------
# item 1: exact double-precision quadrature, 2 particles
# ---------------------------------------------------------------------------
def poly_P(v, K, N):
    """|v|^{2K} (v_x + i v_y)^N for v (..., 3)."""
    vv = np.einsum("...c,...c->...", v, v)
    return vv**K * (v[..., 0] + 1j * v[..., 1]) ** N


def grad_P(v, K, N):
    """∇_v of |v|^{2K} (v_x + i v_y)^N."""
    vv = np.einsum("...c,...c->...", v, v)
    vp = v[..., 0] + 1j * v[..., 1]
    g = np.zeros(v.shape, complex)
    if K:
        g += (2 * K * vv ** (K - 1) * vp**N)[..., None] * v
    if N:
        g += (N * vv**K * vp ** (N - 1))[..., None] * np.array([1.0, 1j, 0.0])
    return g


@functools.lru_cache(maxsize=None)
def gh_tensor(n, dim):
    """Tensor-product Gauss–Hermite nodes (P, dim) and weights (P,) for exp(-|y|²)."""
    x, w = roots_hermite(n)
    Y = np.array(list(itertools.product(x, repeat=dim)))
    W = functools.reduce(np.multiply.outer, [w] * dim).ravel()
    return Y, W


def gh_overlap_kinetic(fI, fJ, N, lams):
    """Unnormalised <φ_I|φ_J> and <∇φ_I|Λ|∇φ_J> (for each Λ in `lams`) by the exact 6-D rule."""
    (AI, uI, KI), (AJ, uJ, KJ) = fI, fJ
    B = AI + AJ
    n = KI + KJ + N + 2  # exact for per-variable degree <= 2(KI+KJ+N)+2 <= 2n-1
    L = np.linalg.cholesky(B)
    LiT = np.linalg.inv(L).T
    Y, W = gh_tensor(n, 6)
    r = np.einsum("ik,pck->pic", LiT, Y.reshape(-1, 3, 2))  # (P, particle, component)
    jac = np.linalg.det(B) ** -1.5
    a = np.einsum("i,pic->pc", uI, r)
    b = np.einsum("i,pic->pc", uJ, r)
    PI, PJ = poly_P(a, KI, N), poly_P(b, KJ, N)
    s = jac * np.sum(W * np.conj(PI) * PJ)
    DI = uI[None, :, None] * grad_P(a, KI, N)[:, None, :] - 2 * np.einsum("ij,pjc->pic", AI, r) * PI[:, None, None]
    DJ = uJ[None, :, None] * grad_P(b, KJ, N)[:, None, :] - 2 * np.einsum("ij,pjc->pic", AJ, r) * PJ[:, None, None]
    G = np.einsum("p,pic,pjc->ij", W, np.conj(DI), DJ)
    return s, [jac * np.sum(lam * G) for lam in lams]


def spherical_overlap_coulomb(fI, fJ, N, masses):
    """Unnormalised <φ_I|φ_J> and <φ_I|1/|r_1-r_2||φ_J> in (X, x) coordinates."""
    (AI, uI, KI), (AJ, uJ, KJ) = fI, fJ
    m1, m2 = masses
    mt = m1 + m2
    Tm = np.array([[1.0, m2 / mt], [1.0, -m1 / mt]])  # (r1, r2) = Tm (X, x), |det Tm| = 1
    Bp = Tm.T @ (AI + AJ) @ Tm
    bXX, bXx, bxx = Bp[0, 0], Bp[0, 1], Bp[1, 1]
    beta = bxx - bXx**2 / bXX
    D = 2 * (KI + KJ + N)  # polynomial degree of conj(P_I) P_J
    Y, WY = gh_tensor(D // 2 + 1, 3)
    ct, wt = roots_legendre(D // 2 + 1)
    nph = D + 1
    ph = 2 * np.pi * np.arange(nph) / nph
    st = np.sqrt(1 - ct**2)
    om = np.stack([np.outer(st, np.cos(ph)), np.outer(st, np.sin(ph)), np.outer(ct, np.ones(nph))], -1).reshape(-1, 3)
    w_om = np.outer(wt, np.full(nph, 2 * np.pi / nph)).ravel()
    out = []
    for alpha, pref in ((0.5, 1 / (2 * beta**1.5)), (0.0, 1 / (2 * beta))):  # overlap, 1/|x|
        sn, ws = roots_genlaguerre(D // 4 + 1, alpha)
        x = (np.sqrt(sn / beta)[:, None, None] * om[None]).reshape(-1, 3)
        wx = pref * np.outer(ws, w_om).ravel()
        X = Y[:, None, :] / np.sqrt(bXX) - (bXx / bXX) * x[None]
        r1 = X + (m2 / mt) * x[None]
        r2 = X - (m1 / mt) * x[None]
        a = uI[0] * r1 + uI[1] * r2
        b = uJ[0] * r1 + uJ[1] * r2
        f = np.conj(poly_P(a, KI, N)) * poly_P(b, KJ, N)
        out.append(bXX**-1.5 * np.einsum("p,q,pq->", WY, wx, f))
    return out


# ---------------------------------------------------------------------------
# item 3: high precision (mpmath)
# ---------------------------------------------------------------------------
def _dfact(n):
    r = 1
    while n > 1:
        r *= n
        n -= 2
    return r


@functools.lru_cache(maxsize=None)
def _moment_coeffs(i, j, k):
    """Integers c_a with E[(α·α)^i (β·β)^j (α·β)^k] = ρ^{k mod 2} Σ_a c_a (ρ²)^a (σ²)^{D-a},
    D = j + k//2, for α ~ N(0, I_3), β = ρ α + σ ξ, ξ ~ N(0, I_3), σ² = 1 - ρ².

    α = r ẑ (isotropy, r ~ χ_3, E[r^{2m}] = (2m+1)!!): α·α = r², α·β = r(ρr + σξ_z),
    β·β = (ρr + σξ_z)² + σ² η, η = ξ_x² + ξ_y² ~ χ²_2 (E[η^l] = 2^l l!)."""
    D = j + k // 2
    c = [0] * (D + 1)
    for l in range(j + 1):
        M = 2 * (j - l) + k
        pre = comb(j, l) * 2**l * factorial(l)
        for t in range(k % 2, M + 1, 2):  # ξ_z^{M-t}: only even powers survive
            c[(t - k % 2) // 2] += pre * comb(M, t) * _dfact(2 * i + k + t + 1) * _dfact(M - t - 1)
    return tuple(c)


def gauss_moment(i, j, k, x, y, z):
    """E[(a·a)^i (b·b)^j (a·b)^k] for a, b ∈ R³, each Cartesian component (a_c, b_c) ~ N(0, [[x,z],[z,y]])."""
    c = _moment_coeffs(i, j, k)
    D = len(c) - 1
    xy = x * y
    r2 = z * z / xy
    s2 = (xy - z * z) / xy
    if s2 < 0:
        s2 = mpmath.mpf(0)
    rp = [mpmath.mpf(1)]
    sp = [mpmath.mpf(1)]
    for _ in range(D):
        rp.append(rp[-1] * r2)
        sp.append(sp[-1] * s2)
    acc = mpmath.fsum(ca * rp[a] * sp[D - a] for a, ca in enumerate(c) if ca)
    return x**i * y**j * xy ** (k // 2) * (z if k % 2 else 1) * acc


def kernel(KI, KJ, N):
    """|a|^{2K_I}|b|^{2K_J} |a|^N |b|^N P_N(â·b̂) as {(i, j, k): coefficient of p^i q^j s^k}."""
    out = {}
    for m in range(N // 2 + 1):
        c = Fraction((-1) ** m * factorial(2 * N - 2 * m), 2**N * factorial(m) * factorial(N - m) * factorial(N - 2 * m))
        out[(KI + m, KJ + m, N - 2 * m)] = mpmath.mpf(c.numerator) / c.denominator
    return out


def _expect(poly, x, y, z):
    return mpmath.fsum(c * gauss_moment(i, j, k, x, y, z) for (i, j, k), c in poly.items() if c)


def _add(poly, key, val):
    if min(key) >= 0:
        poly[key] = poly.get(key, 0) + val


def _mp(a):
    return mpmath.matrix(np.asarray(a, float).tolist())


def _dot(a, b):
    return (a.T * b)[0, 0]


def _tr(X):
    return mpmath.fsum(X[i, i] for i in range(X.rows))


class MpPair:
    """Unnormalised <φ_I| 1, -∇^T Λ ∇, 1/|w^T r| |φ_J> up to a common factor c_N²/(4π)."""

    def __init__(self, fI, fJ, N, diagonal):
        (self.AI, self.uI, self.KI), (self.AJ, self.uJ, self.KJ) = [(_mp(A), _mp(u), K) for A, u, K in (fI, fJ)]
        self.N, self.diagonal = N, diagonal
        self.n = self.AI.rows
        self.B = self.AI + self.AJ
        self.h = kernel(self.KI, self.KJ, N)

    def _xyz(self, B):
        C = mpmath.inverse(B) / 2
        CI, CJ = C * self.uI, C * self.uJ
        return C, CI, CJ, _dot(self.uI, CI), _dot(self.uJ, CJ), _dot(self.uI, CJ)

    def _s0(self, B):
        return (mpmath.pi**self.n / mpmath.det(B)) ** mpmath.mpf(1.5)

    def overlap(self):
        _, _, _, x, y, z = self._xyz(self.B)
        return self._s0(self.B) * _expect(self.h, x, y, z)

    def kinetic(self, lam):
        lam = _mp(lam)
        C, CI, CJ, x, y, z = self._xyz(self.B)
        sig = mpmath.matrix([[x, z], [z, y]])
        # (pseudo-)inverse of the covariance of (a_c, b_c); rank 1 when u_I = u_J
        sig_p = sig / (x + y) ** 2 if self.diagonal else mpmath.inverse(sig)
        AJ, uJ = self.AJ, self.uJ
        g = AJ * lam * uJ  # Σ_j (Λ u_J)_j (A_J r)_j = g^T r
        W = AJ * lam * AJ
        kap = sig_p * mpmath.matrix([_dot(g, CI), _dot(g, CJ)])  # E[g^T r | a, b] = κ_a a + κ_b b
        CU = mpmath.matrix(self.n, 2)
        for r in range(self.n):
            CU[r, 0], CU[r, 1] = CI[r], CJ[r]
        H = sig_p * (CU.T * W * CU) * sig_p  # E[r_c|a_c,b_c]^T W E[r_c|..] = (a_c,b_c) H (a_c,b_c)^T
        var = C - CU * sig_p * CU.T
        trwv, trla = _tr(W * var), _tr(lam * AJ)
        lj = _dot(uJ, lam * uJ)
        ka, kb = kap[0], kap[1]
        poly: dict = {}
        for (al, be, ga), c in self.h.items():
            # λ Δ_b h:  Δ_b(q^β s^γ) = 2β(2β+1+2γ) q^{β-1}s^γ + γ(γ-1) p q^β s^{γ-2}
            _add(poly, (al, be - 1, ga), lj * c * 2 * be * (2 * be + 1 + 2 * ga))
            _add(poly, (al + 1, be, ga - 2), lj * c * ga * (ga - 1))
            # -4 ∇_b h · w:  ∇_b(q^β s^γ) = 2β q^{β-1}s^γ b + γ q^β s^{γ-1} a;  b·w -> κ_a s + κ_b q, a·w -> κ_a p + κ_b s
            _add(poly, (al, be - 1, ga + 1), -8 * c * be * ka)
            _add(poly, (al, be, ga), -8 * c * be * kb - 4 * c * ga * kb)
            _add(poly, (al + 1, be, ga - 1), -4 * c * ga * ka)
            # h (-6 Tr(Λ A_J) + 4 Σ_c r_c^T W r_c)
            _add(poly, (al, be, ga), c * (-6 * trla + 12 * trwv))
            _add(poly, (al + 1, be, ga), 4 * c * H[0, 0])
            _add(poly, (al, be, ga + 1), 8 * c * H[0, 1])
            _add(poly, (al, be + 1, ga), 4 * c * H[1, 1])
        return -self._s0(self.B) * _expect(poly, x, y, z)

    def coulomb(self, w):
        w = _mp(w)
        c = _dot(w, mpmath.inverse(self.B) * w)
        total = mpmath.mpf(0)
        for tau, wt in gauss_legendre_01(self.KI + self.KJ + self.N + 3):
            om = 1 - tau * tau
            t2 = tau * tau / (c * om)
            Bt = self.B + t2 * (w * w.T)
            _, _, _, x, y, z = self._xyz(Bt)
            total += wt * self._s0(Bt) * _expect(self.h, x, y, z) / (mpmath.sqrt(c) * om**mpmath.mpf(1.5))
        return 2 / mpmath.sqrt(mpmath.pi) * total


@functools.lru_cache(maxsize=None)
def _gl_cached(n, dps):
    nodes = []
    x0, _ = np.polynomial.legendre.leggauss(n)
    for x in x0:
        x = mpmath.mpf(x)
        for _ in range(4):  # Newton from a double-precision root: 1e-16 -> 1e-32 -> 1e-64
            p0, p1 = mpmath.mpf(1), x
            for k in range(2, n + 1):
                p0, p1 = p1, ((2 * k - 1) * x * p1 - (k - 1) * p0) / k
            dp = n * (x * p1 - p0) / (x * x - 1)
            x -= p1 / dp
        wgt = 2 / ((1 - x * x) * dp * dp)
        nodes.append(((1 + x) / 2, wgt / 2))  # on [0, 1]
    return tuple(nodes)


def gauss_legendre_01(n):
    return _gl_cached(n, mpmath.mp.dps)


def mp_reference(system, fs, N, pairs, with_ti=True):
    """Normalised S, T, T_ti, V for index pairs `pairs`, in mpmath."""
    wv, qv = system.coulomb_pairs()
    need = sorted({i for p in pairs for i in p})
    cache = {}

    def get(i, j):
        if (i, j) not in cache:
            pr = MpPair(fs[i], fs[j], N, diagonal=(i == j))
            out = {"S": pr.overlap(), "T": pr.kinetic(system.M),
                   "V": mpmath.fsum(q * pr.coulomb(w) for w, q in zip(wv, qv))}
            if with_ti:
                out["T_ti"] = pr.kinetic(system.M_internal)
            cache[(i, j)] = out
        return cache[(i, j)]

    norms = {i: mpmath.sqrt(get(i, i)["S"]) for i in need}
    return {(i, j): {k: v / (norms[i] * norms[j]) for k, v in get(i, j).items()} for i, j in pairs}
