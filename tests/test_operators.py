"""The r_ij² operator of every basis family against exact quadrature, LFCC ≡ TICC, and hydrogen.

Quadrature (nothing here uses prebo's formulas): for a bra and ket of any family,
φ(r) = P(v) exp(−Σ_c (r_c − s_c)ᵀ A (r_c − s_c)) with P = |v|^{2K}(v_x + i v_y)^N, v = uᵀr for
ECG-GVR (P = 1 otherwise) and centres s for floating ECGs (s = 0 otherwise), the product
φ_I* φ_J is a polynomial times exp(−Σ_c (r_c − m_c)ᵀ B (r_c − m_c)), B = A_I + A_J,
m = B⁻¹(A_I s_I + A_J s_J). With r_c = m_c + L⁻ᵀ y_c (L Lᵀ = B) a tensor Gauss–Hermite rule in all
3n variables integrates it exactly once it has more than (degree + 1)/2 nodes per variable; the
Gaussian's constant factor is evaluated at the nodes as a black box. Elements of normalised
functions are R_IJ/(S_II S_JJ)^½ of raw quadratures of the operator (r_w² = |Σ_k w_k r_k|²) and of 1.
"""
from __future__ import annotations

import functools
import itertools

import numpy as np
import pytest
from numpy.polynomial.hermite import hermgauss

import prebo
from prebo.integrals import laboratory, translationally_invariant
from prebo.level.expectation import OPERATORS, vector

from conftest import ROOT, custom, random_centres, random_pair_A


def distinguishable(n, N=0):
    """n distinguishable particles of O(1) masses and charges of both signs (symmetriser = 1)."""
    masses, charges = [1.7, 0.6, 2.3], [1.0, -1.0, 0.5]
    parts = [custom(name, m, q) for name, m, q in zip("abc", masses[:n], charges[:n])]
    return prebo.System(parts, state=prebo.State(N=N, parity=(-1) ** N))


def family_basis(kind, system, rng, nb=3, shared_c_A=None, cm_free=False):
    """nb random functions of one family in pair form; `cm_free`: c_U = 0 (ECG-GVR) or μᵀs = 0 (FECG)."""
    c_A = np.full(nb, shared_c_A) if shared_c_A else rng.uniform(0.4, 2.0, nb)
    A = np.array([random_pair_A(system, rng, c) for c in c_A])
    extra = {}
    if kind == "ecg-gvr":
        u = rng.normal(size=(nb, system.n))
        if cm_free:
            u -= u.mean(axis=1, keepdims=True)  # 1ᵀu = c_U = 0
        extra = {"u": u, "K": rng.integers(0, 2, nb)}
    elif kind == "fecg":
        extra = {"s": random_centres(system, nb, rng, cm_free)}
    return prebo.Basis(system, A, c_A, kind=kind, **extra)


def function(basis, k):
    """(A, s (n, 3), P) of function k: exponent, centres and the polynomial prefactor of v = uᵀr."""
    n, N = basis.system.n, basis.system.state.N
    s = basis.s[k] if basis.s is not None else np.zeros((n, 3))
    if basis.u is None:
        return basis.A[k], s, lambda r: np.ones(r.shape[0])
    u, K = basis.u[k], int(basis.K[k])

    def P(r):
        v = np.einsum("k,pkc->pc", u, r)
        return np.einsum("pc,pc->p", v, v) ** K * (v[:, 0] + 1j * v[:, 1]) ** N
    return basis.A[k], s, P


def degree(basis, k) -> int:
    return 0 if basis.u is None else 2 * int(basis.K[k]) + basis.system.state.N


@functools.cache
def _rule(dim, nodes):
    x, w = hermgauss(nodes)
    Y = np.stack(np.meshgrid(*[x] * dim, indexing="ij"), axis=-1).reshape(-1, dim)
    W = functools.reduce(np.multiply.outer, [w] * dim).ravel()
    return Y, W


def quadrature(basis, I, J, w):
    """Raw ∫ φ_I* φ_J dr and ∫ φ_I* r_w² φ_J dr for each row of w (laboratory frame, 3n variables,
    exact rule)."""
    n = basis.system.n
    (AI, sI, PI), (AJ, sJ, PJ) = function(basis, I), function(basis, J)
    B = AI + AJ
    m = np.linalg.solve(B, AI @ sI + AJ @ sJ)
    L = np.linalg.cholesky(B)
    nodes = (degree(basis, I) + degree(basis, J) + 2) // 2 + 1
    Y, W = _rule(3 * n, nodes)
    r = m[None] + np.einsum("ij,pjc->pic", np.linalg.inv(L).T, Y.reshape(-1, n, 3))
    d = r - m[None]
    log_gauss = (-np.einsum("pic,ij,pjc->p", r - sI, AI, r - sI) - np.einsum("pic,ij,pjc->p", r - sJ, AJ, r - sJ)
                 + np.einsum("pic,ij,pjc->p", d, B, d))  # constant: the Gaussian's prefactor, as a black box
    weight = W * np.exp(log_gauss) / np.linalg.det(L) ** 3
    f = np.conj(PI(r)) * PJ(r) * weight
    rw = np.einsum("qk,pkc->qpc", w, r)
    return np.sum(f).real, np.sum(f[None] * np.einsum("qpc,qpc->qp", rw, rw), axis=1).real


CASES = [("pecg", 2, 0), ("pecg", 3, 0), ("fecg", 2, 0), ("fecg", 3, 0),
         ("ecg-gvr", 2, 0), ("ecg-gvr", 2, 1), ("ecg-gvr", 3, 0), ("ecg-gvr", 3, 1)]


@pytest.mark.parametrize("kind,n,N", CASES)
def test_r2_elements_against_quadrature(kind, n, N):
    """Every element of ⟨r_ij²⟩ for every pair, normalised functions, to 1e-12 of the quadrature."""
    system = distinguishable(n, N)
    basis = family_basis(kind, system, np.random.default_rng(7 + n + N), nb=3)
    pairs = [p for p in itertools.combinations(range(n), 2)]
    w = np.zeros((len(pairs), n))
    for k, (i, j) in enumerate(pairs):
        w[k, i], w[k, j] = 1.0, -1.0
    got = laboratory(system).operator("r2", basis, w)
    assert got.shape == (len(pairs), 3, 3)
    raw = {(I, J): quadrature(basis, I, J, w) for I in range(3) for J in range(3)}
    for k in range(len(pairs)):
        for I, J in itertools.product(range(3), repeat=2):
            norm = np.sqrt(raw[I, I][0] * raw[J, J][0])
            ref = raw[I, J][1][k] / norm
            scale = np.sqrt(raw[I, I][1][k] * raw[J, J][1][k]) / norm
            assert abs(got[k, I, J] - ref) <= 1e-12 * scale, (kind, pairs[k], I, J, got[k, I, J], ref)


@pytest.mark.parametrize("name", sorted(OPERATORS))
@pytest.mark.parametrize("kind", ["pecg", "ecg-gvr", "fecg"])
def test_every_operator_is_the_same_in_lfcc_and_ticc(kind, name):
    """One shared c_A (and c_U = 0, μᵀs = 0): the CM Gaussian cancels, so the laboratory-frame
    matrices of every registered operator equal those in Jacobi coordinates, for three particles
    with two identical ones (pair vectors transformed like r, particle momenta like ∇). An operator
    the family has no element for is refused in one line."""
    e, p = custom("e", 1.0, -1.0), custom("p", 1836.15267343, 1.0)
    system = prebo.System([p, p, e], state=prebo.State(N=0, parity=1))
    basis = family_basis(kind, system, np.random.default_rng(3), nb=4, shared_c_A=0.9, cm_free=True)
    op = OPERATORS[name]
    w = np.concatenate(list(op.classes(system).values()))
    if not op.evaluates(basis.family):
        with pytest.raises(prebo.errors.UnsupportedError, match=f"operator {name!r}.* not derived for {kind}"):
            prebo.evaluate(basis, operators=[name])
        return
    lab = laboratory(system).operator(name, basis, w, op.momenta)
    ti = translationally_invariant(system).operator(name, basis, w, op.momenta)
    assert np.max(np.abs(lab - ti)) <= 1e-12 * np.max(np.abs(lab)), np.max(np.abs(lab - ti)) / np.max(np.abs(lab))
    assert np.max(np.abs(lab[0] - lab[0].T)) <= 1e-13 * np.max(np.abs(lab[0]))


def images(basis, sym):
    """The distinguishable-particle basis of every image Pφ_k (P with coefficient c_P), and the
    factors c_P: Pφ(r) = φ(Π r) has A → ΠᵀAΠ, u → Πᵀu, s → Πᵀs (Π the permutation matrix)."""
    n, out, factors = basis.system.n, [], []
    for perm, c_P in zip(sym.permutations, sym.coefficients):
        Pi = np.eye(n)[list(perm)]  # (Π r)_i = r_perm(i)
        extra = {}
        if basis.u is not None:
            extra = {"u": basis.u @ Pi, "K": basis.K}
        if basis.s is not None:
            extra = {"s": np.einsum("ki,bkc->bic", Pi, basis.s)}
        out.append((np.einsum("ki,bkl,lj->bij", Pi, basis.A, Pi), extra))
        factors.append(c_P)
    return out, np.array(factors)


@pytest.mark.parametrize("kind", ["pecg", "ecg-gvr", "fecg"])
@pytest.mark.parametrize("names", [("p", "p", "e"), ("p", "p", "e", "e")])
def test_pair_class_averages_of_a_symmetrised_state(kind, names):
    """With identical particles the reported value is the average over the class of equivalent
    pairs. Check it on Ψ = Y†Y Σ_k c_k φ_k written out as a basis of all images Pφ_k of distinguishable
    particles (no symmetriser; c_k c_P as coefficients): there every pair's ⟨r_ij²⟩, ⟨p_i²p_j²⟩ and
    orbit–orbit value is an ordinary Hermitian expectation value. Their class averages must equal
    the engine's, to 1e-10."""
    rng = np.random.default_rng(11)
    masses = {"p": 1836.15267343, "e": 1.0}
    charges = {"p": 1.0, "e": -1.0}
    system = prebo.System([custom(x, masses[x], charges[x]) for x in names], state=prebo.State(N=0, parity=1))
    basis = family_basis(kind, system, rng, nb=3)
    names_checked = ("r2", "p2p2", "orbit_orbit")
    result = prebo.evaluate(basis, operators=list(names_checked))
    c = result["coefficients"]
    labels = [f"{x}{i}" for i, x in enumerate(names)]
    plain = prebo.System([custom(label, masses[x], charges[x]) for label, x in zip(labels, names)],
                         state=prebo.State(N=0, parity=1))
    parts, c_P = images(basis, system.symmetriser)
    A = np.concatenate([a for a, _ in parts])
    extra = {k: np.concatenate([e[k] for _, e in parts]) for k in parts[0][1]}
    big = prebo.Basis(plain, A, np.tile(basis.c_A, len(parts)), kind=kind, **extra)
    coefficients = np.concatenate([cp * c for cp in c_P])
    rep = laboratory(plain)
    S = rep.matrices(big)["S"]
    norm = coefficients @ S @ coefficients
    pairs = list(itertools.combinations(range(len(names)), 2))
    for name in names_checked:
        op = OPERATORS[name]
        v = np.array([[vector(plain, kind, i, j) for kind in op.vectors] for i, j in pairs])
        R = rep.operator(name, big, v, op.momenta)
        per_pair = {(i, j): coefficients @ R[k] @ coefficients / norm for k, (i, j) in enumerate(pairs)}
        for label, value in result["expectation"][name].items():
            a, b = label.split("-")
            members = [v for (i, j), v in per_pair.items() if sorted((names[i], names[j])) == [a, b]]
            assert members
            assert abs(np.mean(members) - value) <= 1e-10 * abs(value), (name, label, members, value)


def test_hydrogen_mean_square_radius():
    """The stored hydrogen basis: ⟨r²⟩ = 3/μ² bohr² for the 1s state of reduced mass μ, reported by
    evaluate. Bound on the error: for ψ with energy error δE above the ground state, ‖ψ − ψ₀‖² ≤
    δE/ΔE (ΔE = E_2s − E_1s = 3μ/8), so |⟨r²⟩ − ⟨r²⟩₀| ≲ 2‖ψ − ψ₀‖ ‖r²ψ₀‖, ‖r²ψ₀‖ = ⟨r⁴⟩₀^½ = √22.5/μ²
    (first order; a factor 1.5 for the second)."""
    basis = prebo.Basis.load(ROOT / "examples" / "bases" / "h" / "basis.json")
    m_p = max(basis.system.masses)
    mu = m_p / (m_p + 1.0)
    names_checked = ("r2", "p2p2", "orbit_orbit")
    result = prebo.evaluate(basis, operators=list(names_checked))
    (label, value), = result["expectation"]["r2"].items()
    assert label == "e-p"
    dE = result["energy"] + 0.5 * mu
    assert dE > 0
    bound = 1.5 * 2.0 * np.sqrt(dE / (0.375 * mu)) * np.sqrt(22.5) / mu**2
    assert abs(value - 3.0 / mu**2) < bound, (label, value, 3.0 / mu**2, bound)
