"""ECG-GVR matrix elements of prebo against independent evaluations.

Functions (laboratory-frame Cartesian coordinates, r = (r_1..r_n), r_i ∈ R³)::

    φ(r) = |v|^{2K} (v_x + i v_y)^N exp(-r^T (A ⊗ I_3) r),   v = u^T r = Σ_i u_i r_i,

bra complex-conjugated; prebo returns elements of *normalised* functions (S, T, T_ti, V;
distinguishable particles unless stated).  Nothing below uses prebo's closed formulas
(no Ω series ĉ_k, no Stein/Price identities, no cm_kinetic expression).

1. ``test_two_body_quadrature`` -- exact quadrature, 2 particles, N = 0, 1, 2, a basis of
   four functions with K = (0, 1, 3, 1) (so every (K_I, K_J) in {0,1,3}² for every N,
   and an off-diagonal K_I = K_J = 1 pair), three of them with c_U = Σ_i u_i != 0, a
   different c_A per function, charge products of both signs.

   * S, T (Λ = M), T_ti and T of ``kinetic="internal"`` (Λ = M - 1 1^T/(2 m_tot)):
     6-dimensional tensor-product Gauss–Hermite rule.  Per Cartesian component c the
     weight is exp(-r_c^T B r_c), B = A_I + A_J, r_c = L^{-T} y_c with B = L L^T.  The
     integrands conj(P_I) P_J and Σ_ij Λ_ij conj(∇_i φ_I)·∇_j φ_J / (G_I G_J), with
     ∇_i φ = [u_i ∇_v P(v) - 2 (A r)_i P(v)] G (chain rule, evaluated numerically), are
     polynomials of degree <= 2(K_I+K_J+N)+2, so n = K_I+K_J+N+2 nodes per dimension
     make the rule exact.
   * V: the relative coordinate x = r_1 - r_2 and the centre of mass X (Jacobian 1).
     The X integral (conditional Gaussian at fixed x) by a 3-D Gauss–Hermite rule,
     x in spherical coordinates: Gauss–Laguerre in s = β|x|² (weight 1 for 1/|x|,
     s^{1/2} for the overlap, computed the same way as a check of the grid), Gauss–
     Legendre in cos θ and the trapezoid rule in φ, each exact for the polynomial
     degree at hand.
   Expected agreement ~1e-13; tolerance 1e-10 relative to max(|X_IJ|, sqrt|X_II X_JJ|).

2. ``test_k0_n0_equals_plain_ecg`` -- p e e (singlet electrons, symmetrised): GVR with
   K = N = 0 (random u, some with c_U != 0) against the plain-ECG matrices, 1e-13.

3. High precision, K up to 40 (mpmath, 50 digits), N = 0, 1, 2:

   * ``test_two_body_radial_high_k``: 2 particles, u ∥ e_1 - e_2 (c_U = 0).  In (X, x)
     the functions are μ^{2K+N} |x|^{2K+N} Y_NN(x̂) e^{-α x²} e^{-c_A X²}, so S, T
     (= T_X + T_x with T_X = -∇_X²/(2 m_tot), T_x = -∇_x²/(2 m_red)), T_ti = T_x and V
     reduce to Γ functions (∫ρ^p e^{-βρ²}dρ = Γ((p+1)/2) / (2β^{(p+1)/2})).
   * ``test_three_body_moments_high_k``: 3 particles, u_I not parallel to u_J, c_U != 0.
     Route: by Wigner–Eckart (the operators are rotation invariant, the functions are
     M = N members of L = N multiplets) <φ_I|O|φ_J> ∝ Σ_M <..Y_NM..|O|..Y_NM..>, and
     Σ_M conj(Y_NM(â)) Y_NM(b̂) ∝ P_N(â·b̂): the bra/ket product becomes the scalar kernel
     h = |a|^{2K_I}|b|^{2K_J} |a|^N|b|^N P_N(â·b̂), a polynomial in p = a·a, q = b·b,
     s = a·b (a = u_I^T r, b = u_J^T r).  The kinetic operator is applied to the ket
     side of the kernel by the chain rule; the linear forms (A_J Λ u_J)^T r and the
     quadratic form r^T A_J Λ A_J r are replaced by their Gaussian conditional
     expectations given (a, b).  The remaining moments E[p^i q^j s^k] of the 2×3
     Gaussian (a, b) are evaluated exactly: by isotropy a = √x r ẑ (r ~ χ_3),
     b = √y (ρ a/√x + σ ξ), ξ ~ N(0, I_3), and binomial expansion with the moments of
     χ_3, N(0,1) and χ²_2 gives integer coefficients times (ρ², σ²) powers, all
     non-negative.  Coulomb: 1/|d| = (2/√π) ∫_0^∞ e^{-t²d²} dt; the t integral (mapped
     to τ = t√c/√(1+t²c) ∈ [0,1), c = w^T B^{-1} w, where the integrand is a
     polynomial of degree 2(K_I+K_J+N) in τ) by mpmath Gauss–Legendre with
     K_I+K_J+N+3 nodes; for each node the full matrix B + t² w w^T is inverted in mpmath.
     The moment formula itself is checked against the Gauss–Hermite rule of item 1.
   Tolerance 1e-10 relative to the element itself (S, T, T_ti, V separately).

4. ``test_translation_free_kinetic_*``: random 3- and 4-particle GVR bases (distinguishable
   particles, and p e e / Ps2 with spin-singlet pairs, i.e. non-trivial Young operators), each function
   drawn in a random coordinate set (prebo.all_sets, CoordinateSet.to_lab), u = U_x^T
   (u', c_U), K in 0..5, N in {0, 1}: laboratory T_ti == T of kinetic="internal"
   (1e-11 relative to max(|X_IJ|, sqrt|X_II X_JJ|)); with every c_U = 0 and one shared
   c_A also lab S, T_ti, V == TICC S, T, V of ``translationally_invariant`` (1e-11).
"""
from __future__ import annotations

import functools
import itertools
from fractions import Fraction
from math import comb, factorial

import mpmath
import numpy as np
import pytest
from scipy.special import roots_genlaguerre, roots_hermite, roots_legendre

import prebo
from prebo.integrals import laboratory, translationally_invariant

MP_DPS = 50


# ---------------------------------------------------------------------------
# helpers: systems, bases, comparison
# ---------------------------------------------------------------------------
def _p(name, mass, charge):
    return {"name": name, "mass": mass, "charge": charge, "spin": 0.5}


def two_body(N, charges):
    return prebo.System([_p("a", 1.7, charges[0]), _p("b", 0.6, charges[1])],
                        state=prebo.State(N=N, parity=(-1) ** N))


def separable_A(masses, alpha, c_A):
    """Σ_{i<j} α_ij (e_i-e_j)(e_i-e_j)^T + c_A (m/m_tot)(m/m_tot)^T."""
    n = len(masses)
    w = masses / masses.sum()
    A = c_A * np.outer(w, w)
    for (i, j), a in alpha.items():
        e = np.zeros(n)
        e[i], e[j] = 1.0, -1.0
        A += a * np.outer(e, e)
    return A


def gvr_basis(system, A, c_A, u, K):
    basis = prebo.Basis(system, np.array(A), np.array(c_A, float), kind="ecg-gvr",
                        u=np.array(u, float), K=np.array(K))
    basis.validate()  # symmetric, positive definite, A 1 = c_A m/m_tot
    return basis


def scaled_error(got, ref):
    """max_IJ |got - ref| / max(|ref_IJ|, sqrt|ref_II ref_JJ|)."""
    d = np.sqrt(np.abs(np.outer(np.diag(ref), np.diag(ref))))
    return float(np.max(np.abs(got - ref) / np.maximum(np.abs(ref), d)))


def normalise(raw, s_raw):
    d = np.sqrt(np.diag(s_raw).real)
    return raw / np.outer(d, d)


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


TWO_BODY_FUNCS = [  # (α_12, c_A, u, K)
    (0.9, 0.7, (1.0, -1.0), 0),
    (0.6, 1.3, (0.8, 0.3), 1),
    (1.4, 0.45, (-0.5, 1.1), 3),
    (1.1, 0.9, (0.35, 0.9), 1),
]
TWO_BODY_CHARGES = {0: (2.0, -1.0), 1: (1.5, 0.8), 2: (-1.0, -0.7)}


@pytest.mark.parametrize("N", [0, 1, 2])
def test_two_body_quadrature(N):
    s = two_body(N, TWO_BODY_CHARGES[N])
    m = s.masses
    A = [separable_A(m, {(0, 1): al}, c) for al, c, _, _ in TWO_BODY_FUNCS]
    cA = [f[1] for f in TWO_BODY_FUNCS]
    u = [f[2] for f in TWO_BODY_FUNCS]
    K = [f[3] for f in TWO_BODY_FUNCS]
    assert any(abs(sum(x)) > 0.5 for x in u)  # c_U != 0 present
    basis = gvr_basis(s, A, cA, u, K)
    lab = laboratory(s).matrices(basis)
    internal = laboratory(s, kinetic="internal").matrices(basis)

    nb = len(A)
    fs = [(A[i], np.array(u[i]), K[i]) for i in range(nb)]
    S, T, Tti, Ssph, V = (np.zeros((nb, nb), complex) for _ in range(5))
    q12 = s.charges[0] * s.charges[1]
    for i in range(nb):
        for j in range(i, nb):
            sv, (t, tti) = gh_overlap_kinetic(fs[i], fs[j], N, [s.M, s.M_internal])
            ss, vv = spherical_overlap_coulomb(fs[i], fs[j], N, m)
            for X, val in ((S, sv), (T, t), (Tti, tti), (Ssph, ss), (V, q12 * vv)):
                X[i, j], X[j, i] = val, np.conj(val)
    for X in (S, T, Tti, Ssph, V):  # the elements are real
        assert np.max(np.abs(X.imag)) < 1e-12 * np.max(np.abs(X))
    ref = {k: normalise(X, S).real for k, X in (("S", S), ("T", T), ("T_ti", Tti), ("V", V))}
    assert scaled_error(normalise(Ssph, Ssph).real, ref["S"]) < 1e-12  # two grids agree

    errs = {k: scaled_error(lab[k], ref[k]) for k in ("S", "T", "T_ti", "V")}
    errs["T(internal)"] = scaled_error(internal["T"], ref["T_ti"])
    for k, e in errs.items():
        assert e < 1e-10, (N, k, e, lab.get(k), ref.get(k))


# ---------------------------------------------------------------------------
# item 2: K = N = 0 GVR == plain ECG
# ---------------------------------------------------------------------------
def test_k0_n0_equals_plain_ecg():
    s = prebo.System(["p", "e", "e"], state=prebo.State(N=0, parity=1, spin={"e": 0}))
    rng = np.random.default_rng(7)
    sets = prebo.all_sets(s.masses)
    nb = 6
    A, cA, u = [], [], []
    for k in range(nb):
        x = sets[rng.integers(len(sets))]
        Lm = np.tril(rng.normal(size=(2, 2)))
        c = rng.uniform(0.3, 3.0)
        A.append(x.to_lab(Lm @ Lm.T + 0.05 * np.eye(2), c))
        cA.append(c)
        u.append(x.U.T @ np.array([*rng.normal(size=2), rng.normal() if k % 2 else 0.0]))
    gvr = laboratory(s).matrices(gvr_basis(s, A, cA, u, [0] * nb))
    pecg = laboratory(s).matrices(prebo.Basis(s, np.array(A), np.array(cA)))
    for k in ("S", "T", "T_ti", "V"):
        e = scaled_error(gvr[k], pecg[k])
        assert e < 1e-13, (k, e)


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


def test_moment_formula_against_gauss_hermite():
    """The exact moments E[(a·a)^i (b·b)^j (a·b)^k] used by the mpmath reference vs the GH rule."""
    rng = np.random.default_rng(3)
    x, y = 0.7, 1.3
    z = 0.6 * np.sqrt(x * y)
    Lc = np.linalg.cholesky(np.array([[x, z], [z, y]]))
    Y, W = gh_tensor(8, 6)
    ab = np.einsum("ik,pck->pic", Lc * np.sqrt(2), Y.reshape(-1, 3, 2))  # (a_c, b_c) ~ N(0, Σ)
    a, b = ab[:, 0, :], ab[:, 1, :]
    W = W / np.pi**3
    for i, j, k in [(0, 0, 0), (1, 0, 0), (0, 1, 1), (2, 1, 3), (1, 3, 2), (0, 2, 4), (3, 2, 1)] + [
        tuple(rng.integers(0, 3, size=3)) for _ in range(5)
    ]:
        gh = np.sum(W * np.sum(a * a, -1) ** i * np.sum(b * b, -1) ** j * np.sum(a * b, -1) ** k)
        with mpmath.workdps(MP_DPS):
            ex = float(gauss_moment(int(i), int(j), int(k), mpmath.mpf(x), mpmath.mpf(y), mpmath.mpf(z)))
        assert abs(gh - ex) < 1e-12 * abs(ex), (i, j, k, gh, ex)
    with mpmath.workdps(MP_DPS):  # the mpmath Gauss–Legendre rule (n nodes) is exact up to degree 2n-1
        for n in (5, 46):
            rule = gauss_legendre_01(n)
            for d in (0, 1, 2 * n - 2, 2 * n - 1):
                assert abs(mpmath.fsum(w * t**d for t, w in rule) * (d + 1) - 1) < mpmath.mpf(10) ** (-40)


def _rel(got, ref):
    return abs(got - float(ref)) / abs(float(ref))


@pytest.mark.parametrize("N", [0, 1, 2])
def test_two_body_radial_high_k(N):
    """u ∥ e_1 - e_2: S, T, T_ti, V from Γ functions in (X, x)."""
    s = two_body(N, (2.0, -1.0))
    m1, m2 = s.masses
    mt = m1 + m2
    mred = m1 * m2 / mt
    Ks = [0, 17, 40, 25, 3, 40]
    al = [0.9, 1.3, 2.1, 0.7, 1.6, 2.6]
    cA = [0.7, 1.3, 0.45, 2.0, 0.9, 0.6]
    mu = [1.0, -0.8, 1.3, 0.6, -1.1, 1.1]
    A = [separable_A(s.masses, {(0, 1): a}, c) for a, c in zip(al, cA)]
    u = [(k, -k) for k in mu]
    basis = gvr_basis(s, A, cA, u, Ks)
    lab = laboratory(s).matrices(basis)
    q12 = s.charges[0] * s.charges[1]
    with mpmath.workdps(MP_DPS):
        mpf = mpmath.mpf

        def R(p, beta):  # ∫_0^∞ ρ^p e^{-βρ²} dρ
            return mpmath.gamma(mpf(p + 1) / 2) / (2 * beta ** (mpf(p + 1) / 2))

        def raw(i, j):
            ni, nj = 2 * Ks[i] + N, 2 * Ks[j] + N
            beta = mpf(al[i]) + mpf(al[j])
            sc = mpf(cA[i]) + mpf(cA[j])
            ox = (mpmath.pi / sc) ** mpf(1.5)
            sgn = mpf(mu[i]) ** ni * mpf(mu[j]) ** nj
            L2 = ni + nj
            S = sgn * ox * R(L2 + 2, beta)
            aj, kj = mpf(al[j]), Ks[j]
            # -∇²(ρ^n e^{-αρ²} Y_N) = -[2K(2K+2N+1)ρ^{n-2} - 2α(2n+3)ρ^n + 4α²ρ^{n+2}] e^{-αρ²} Y_N
            lap = 2 * kj * (2 * kj + 2 * N + 1) * R(L2, beta) - 2 * aj * (2 * nj + 3) * R(L2 + 2, beta) \
                + 4 * aj**2 * R(L2 + 4, beta)
            Tx = -sgn * ox * lap / (2 * mpf(mred))
            TX = 3 * mpf(cA[i]) * mpf(cA[j]) / (mpf(mt) * sc) * S
            V = q12 * sgn * ox * R(L2 + 1, beta)
            return {"S": S, "T": Tx + TX, "T_ti": Tx, "V": V}

        nb = len(Ks)
        raws = {(i, j): raw(i, j) for i in range(nb) for j in range(nb)}
        for (i, j), r in raws.items():
            nrm = mpmath.sqrt(raws[(i, i)]["S"] * raws[(j, j)]["S"])
            for k, v in r.items():
                e = _rel(lab[k][i, j], v / nrm)
                assert e < 1e-10, (N, Ks[i], Ks[j], k, lab[k][i, j], float(v / nrm))


def three_body_system(N):
    return prebo.System([_p("x", 3.0, 2.0), _p("y", 1.0, -1.0), _p("z", 0.45, -1.0)],
                        state=prebo.State(N=N, parity=(-1) ** N))


HIGH_K_FUNCS = [  # (α_ij, c_A, u, K); S of the (17, 40), (40, 40) pairs 1-2, 1-5, 2-5 is 0.47-0.61 (N = 1)
    ({(0, 1): 0.8, (0, 2): 0.5, (1, 2): 0.3}, 0.7, (1.0, -0.4, -0.6), 0),
    ({(0, 1): 0.4, (0, 2): 1.1, (1, 2): 0.6}, 1.3, (0.9, -0.7, 0.2), 17),
    ({(0, 1): 1.0, (0, 2): 1.9, (1, 2): 1.1}, 0.6, (0.85, -0.75, 0.0), 40),
    ({(0, 1): 0.5, (0, 2): 0.6, (1, 2): 1.4}, 2.0, (0.3, 0.8, -1.0), 25),
    ({(0, 1): 0.9, (0, 2): 0.3, (1, 2): 0.5}, 0.9, (-0.2, 1.0, 0.4), 3),
    ({(0, 1): 1.1, (0, 2): 2.0, (1, 2): 1.2}, 0.8, (0.8, -0.8, 0.05), 40),
]


@pytest.mark.parametrize("N", [0, 1, 2])
def test_three_body_moments_high_k(N):
    """Non-parallel u_I, u_J (c_U != 0 for most), K up to 40: every element against the mpmath moment route."""
    s = three_body_system(N)
    A = [separable_A(s.masses, a, c) for a, c, _, _ in HIGH_K_FUNCS]
    cA = [f[1] for f in HIGH_K_FUNCS]
    u = [f[2] for f in HIGH_K_FUNCS]
    Ks = [f[3] for f in HIGH_K_FUNCS]
    assert sum(abs(sum(x)) > 0.1 for x in u) >= 3
    basis = gvr_basis(s, A, cA, u, Ks)
    lab = laboratory(s).matrices(basis)
    nb = len(Ks)
    pairs = [(i, j) for i in range(nb) for j in range(i, nb)]
    assert {(Ks[i], Ks[j]) for i, j in pairs} >= {(0, 40), (17, 40), (40, 40), (25, 3)}
    fs = [(A[i], np.array(u[i]), Ks[i]) for i in range(nb)]
    with mpmath.workdps(MP_DPS):
        ref = mp_reference(s, fs, N, pairs)
        for (i, j), r in ref.items():
            for k, v in r.items():
                for a, b in ((i, j), (j, i)):
                    e = _rel(lab[k][a, b], v)
                    assert e < 1e-10, (N, Ks[i], Ks[j], k, lab[k][a, b], float(v))


# ---------------------------------------------------------------------------
# item 4: translation-free kinetic energy and TICC
# ---------------------------------------------------------------------------
FOUR_SYSTEMS = {
    "x-y-z": lambda N: prebo.System([_p("x", 3.0, 2.0), _p("y", 1.0, -1.0), _p("z", 0.45, -1.0)],
                                    state=prebo.State(N=N, parity=(-1) ** N)),
    "p-e-mu": lambda N: prebo.System(["p", "e", "mu"], state=prebo.State(N=N, parity=(-1) ** N)),
    "p-e-e": lambda N: prebo.System(["p", "e", "e"], state=prebo.State(N=N, parity=(-1) ** N, spin={"e": 0})),
    "ps2": lambda N: prebo.System(["e+", "e+", "e", "e"],
                                  state=prebo.State(N=N, parity=(-1) ** N, spin={"e+": 0, "e": 0})),
    "a-b-c-d": lambda N: prebo.System([_p("a", 2.2, 1.0), _p("b", 1.0, -1.0), _p("c", 0.7, 1.5), _p("d", 4.0, -0.5)],
                                      state=prebo.State(N=N, parity=(-1) ** N)),
}


def random_gvr_basis(system, nb, rng, shared_c_A=None, c_U_zero=False):
    sets = prebo.all_sets(system.masses)
    n = system.n
    A, cA, u, K, names = [], [], [], [], []
    for k in range(nb):
        x = sets[rng.integers(len(sets))]
        Lm = np.tril(rng.normal(size=(n - 1, n - 1)))
        c = shared_c_A if shared_c_A is not None else rng.uniform(0.3, 3.0)
        A.append(x.to_lab(Lm @ Lm.T + 0.05 * np.eye(n - 1), c))
        cA.append(c)
        cU = 0.0 if (c_U_zero or k % 3 == 0) else rng.uniform(0.2, 1.5) * rng.choice([-1, 1])
        u.append(x.U.T @ np.array([*rng.normal(size=n - 1), cU]))
        K.append(int(rng.integers(0, 6)))
        names.append(x.name)
    basis = gvr_basis(system, A, cA, u, K)
    basis.channels = names
    return basis


@pytest.mark.parametrize("N", [0, 1])
@pytest.mark.parametrize("name", list(FOUR_SYSTEMS))
def test_translation_free_kinetic_equals_internal(name, N):
    s = FOUR_SYSTEMS[name](N)
    rng = np.random.default_rng(11 + 3 * N + len(name))
    basis = random_gvr_basis(s, 8, rng)
    assert np.any(np.abs(basis.u.sum(axis=1)) > 0.1)
    lab = laboratory(s).matrices(basis)
    internal = laboratory(s, kinetic="internal").matrices(basis)
    e = scaled_error(lab["T_ti"], internal["T"])
    assert e < 1e-11, e
    for k in ("S", "V"):
        assert scaled_error(lab[k], internal[k]) < 1e-14


@pytest.mark.parametrize("N", [0, 1])
@pytest.mark.parametrize("name", list(FOUR_SYSTEMS))
def test_translation_free_kinetic_equals_ticc(name, N):
    s = FOUR_SYSTEMS[name](N)
    rng = np.random.default_rng(101 + 3 * N + len(name))
    basis = random_gvr_basis(s, 8, rng, shared_c_A=1.1, c_U_zero=True)
    lab = laboratory(s).matrices(basis)
    ticc = translationally_invariant(s).matrices(basis)
    internal = laboratory(s, kinetic="internal").matrices(basis)
    pairs = {"S": (lab["S"], ticc["S"]), "T_ti": (lab["T_ti"], ticc["T"]), "V": (lab["V"], ticc["V"]),
             "T(internal)": (internal["T"], ticc["T"])}
    for k, (got, ref) in pairs.items():
        e = scaled_error(got, ref)
        assert e < 1e-11, (k, e)
