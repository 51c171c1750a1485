"""ECG-GVR matrix elements of prebo against independent evaluations.

Functions (laboratory-frame Cartesian coordinates, r = (r_1..r_n), r_i ∈ R³)::

    φ(r) = |v|^{2K} (v_x + i v_y)^N exp(-r^T (A ⊗ I_3) r),   v = u^T r = Σ_i u_i r_i,

bra complex-conjugated; prebo returns elements of *normalised* functions (S, T, T_ti, V;
distinguishable particles unless stated).  Nothing below uses prebo's closed formulas
(no Ω series ĉ_k, no Stein/Price identities, no cm_kinetic expression); the reference
evaluations of items 1 and 3 (quadrature rules, the mpmath moment route) are in
tests/gvr_reference.py.

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

import mpmath
import numpy as np
import pytest

import prebo
from prebo.integrals import laboratory, translationally_invariant

from conftest import custom, pair_A, random_set_A, scaled_error
from gvr_reference import (gauss_legendre_01, gauss_moment, gh_overlap_kinetic, gh_tensor, mp_reference,
                           spherical_overlap_coulomb)

MP_DPS = 50


# ---------------------------------------------------------------------------
# helpers: systems, bases, comparison
# ---------------------------------------------------------------------------
def two_body(N, charges):
    return prebo.System([custom("a", 1.7, charges[0]), custom("b", 0.6, charges[1])],
                        state=prebo.State(N=N, parity=(-1) ** N))


def gvr_basis(system, A, c_A, u, K):
    basis = prebo.Basis(system, np.array(A), np.array(c_A, float), kind="ecg-gvr",
                        u=np.array(u, float), K=np.array(K))
    basis.validate()  # symmetric, positive definite, A 1 = c_A m/m_tot
    return basis


def normalise(raw, s_raw):
    d = np.sqrt(np.diag(s_raw).real)
    return raw / np.outer(d, d)


# ---------------------------------------------------------------------------
# item 1: exact double-precision quadrature, 2 particles
# ---------------------------------------------------------------------------
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
    A = [pair_A(s, {(0, 1): al}, c) for al, c, _, _ in TWO_BODY_FUNCS]
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
        x, a, c = random_set_A(s, rng, sets)
        A.append(a)
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
    A = [pair_A(s, {(0, 1): a}, c) for a, c in zip(al, cA)]
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
    return prebo.System([custom("x", 3.0, 2.0), custom("y", 1.0, -1.0), custom("z", 0.45, -1.0)],
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
    A = [pair_A(s, a, c) for a, c, _, _ in HIGH_K_FUNCS]
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
    "x-y-z": lambda N: prebo.System([custom("x", 3.0, 2.0), custom("y", 1.0, -1.0), custom("z", 0.45, -1.0)],
                                    state=prebo.State(N=N, parity=(-1) ** N)),
    "p-e-mu": lambda N: prebo.System(["p", "e", "mu"], state=prebo.State(N=N, parity=(-1) ** N)),
    "p-e-e": lambda N: prebo.System(["p", "e", "e"], state=prebo.State(N=N, parity=(-1) ** N, spin={"e": 0})),
    "ps2": lambda N: prebo.System(["e+", "e+", "e", "e"],
                                  state=prebo.State(N=N, parity=(-1) ** N, spin={"e+": 0, "e": 0})),
    "a-b-c-d": lambda N: prebo.System([custom("a", 2.2, 1.0), custom("b", 1.0, -1.0), custom("c", 0.7, 1.5),
                                       custom("d", 4.0, -0.5)],
                                      state=prebo.State(N=N, parity=(-1) ** N)),
}


def random_gvr_basis(system, nb, rng, shared_c_A=None, c_U_zero=False):
    sets = prebo.all_sets(system.masses)
    n = system.n
    A, cA, u, K, names = [], [], [], [], []
    for k in range(nb):
        x, a, c = random_set_A(system, rng, sets, shared_c_A)
        A.append(a)
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
