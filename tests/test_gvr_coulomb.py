"""The closed form of the ECG-GVR Coulomb τ-integral (docs/gvr.md, "Coulomb: closed form"), in mpmath.

prebo writes <φ_I| 1/|wᵀr| |φ_J> = (2/√(πc)) S_0 ∫_0^1 Ω(x − τ²γ_I², y − τ²γ_J², z − τ²γ_Iγ_J) dτ
with Ω = Σ_k ĉ_k x^{K_I−k} y^{K_J−k} z^{N+2k}.  The closed form: Ω is homogeneous of degree
M = K_I + K_J + N, so with t = τ², s = 1 − t, P = (x, y, z), P' = P − (γ_I², γ_J², γ_Iγ_J),

    Ω(sP + tP') = Σ_j e_j s^j t^{M−j},   ∫_0^1 Ω dτ = Σ_j e_j β_j,   β_j = B(j+1, M−j+1/2)/2.

``closed_form`` implements this (the e_j by direct expansion of every term of Ω, not by the
Horner scheme of crates/prebo-core/src/families/ecg_gvr/coulomb.rs) and is checked, at 50 digits, against

* the τ-integral itself, by an mpmath Gauss–Legendre rule exact for the degree-2M polynomial,
  for (K_I, K_J) up to 40 and N = 0, 1, 2, at 1e-30;
* the independent 50-digit references of tests/gvr_reference.py (``MpPair``: Gaussian moments
  of the Wigner–Eckart kernel, no Ω series) through the ratio V/S, in which the normalisation
  constants cancel: V/S = (2/√(πc)) ∫Ω dτ / Ω(x, y, z), K up to 40, at 1e-30;

and in double precision (``closed_form`` with floats) it stays within 1e-13 of the 50-digit value.
"""
from __future__ import annotations

import random
from math import comb

import mpmath
import numpy as np
import pytest

from gvr_reference import MpPair, gauss_legendre_01

MP_DPS = 50


def c_hat(KI, KJ, N):
    """ĉ_0 = 1, ĉ_{k+1} = ĉ_k (K_I−k)(K_J−k) / ((k+1)(k+N+3/2))."""
    c = [mpmath.mpf(1)]
    for k in range(min(KI, KJ)):
        c.append(c[-1] * (KI - k) * (KJ - k) / ((k + 1) * (k + N + mpmath.mpf(3) / 2)))
    return c


def omega(KI, KJ, N, x, y, z):
    return mpmath.fsum(ck * x ** (KI - k) * y ** (KJ - k) * z ** (N + 2 * k) for k, ck in enumerate(c_hat(KI, KJ, N)))


def _power(p, q, e):
    """Coefficients of (p t + q s)^e, index j = power of s."""
    return [comb(e, j) * q**j * p ** (e - j) for j in range(e + 1)]


def _times(a, b):
    out = [0] * (len(a) + len(b) - 1)
    for i, ai in enumerate(a):
        for j, bj in enumerate(b):
            out[i + j] += ai * bj
    return out


def closed_form(KI, KJ, N, inputs, num=mpmath.mpf):
    """∫_0^1 Ω(x − τ²γ_I², y − τ²γ_J², z − τ²γ_Iγ_J) dτ as Σ_j e_j β_j (in `num` arithmetic)."""
    x, y, z, gi, gj = (num(v) for v in inputs)
    P, Pp = (x, y, z), (x - gi * gi, y - gj * gj, z - gi * gj)
    M = KI + KJ + N
    e = [num(0)] * (M + 1)
    for k, ck in enumerate(c_hat(KI, KJ, N)):
        term = [num(ck)]
        for (p, q), power in zip(zip(Pp, P), (KI - k, KJ - k, N + 2 * k)):
            term = _times(term, _power(p, q, power))
        e = [a + b for a, b in zip(e, term)]
    beta, b = [], num(1) / (2 * M + 1)
    for j in range(M + 1):
        if j:
            b = b * (2 * j) / (2 * (M - j) + 1)
        beta.append(b)
    return sum(ej * bj for ej, bj in zip(e, beta))


def tau_integral(KI, KJ, N, inputs):
    """The τ-integral by the (M+1)-point Gauss–Legendre rule on [0, 1], exact for degree 2M + 1."""
    x, y, z, gi, gj = (mpmath.mpf(v) for v in inputs)
    rule = gauss_legendre_01(KI + KJ + N + 1)
    return mpmath.fsum(w * omega(KI, KJ, N, x - t * t * gi * gi, y - t * t * gj * gj, z - t * t * gi * gj) for t, w in rule)


def random_inputs(rng):
    """x = |p|², y = |q|², z = p·q, γ_I = p·e, γ_J = q·e, |e| = 1: a valid covariance structure."""
    p, q, e = (np.array([rng.uniform(-1, 1) for _ in range(3)]) for _ in range(3))
    e /= np.linalg.norm(e)
    return [float(p @ p), float(q @ q), float(p @ q), float(p @ e), float(q @ e)]


K_PAIRS = [(0, 0), (1, 0), (0, 1), (1, 1), (2, 5), (7, 3), (19, 8), (8, 19), (19, 19), (40, 0), (0, 40), (40, 13), (25, 40), (40, 40)]


@pytest.mark.parametrize("N", [0, 1, 2])
def test_closed_form_equals_the_tau_integral(N):
    rng = random.Random(15 + N)
    with mpmath.workdps(MP_DPS):
        for KI, KJ in K_PAIRS:
            inputs = random_inputs(rng)
            want = tau_integral(KI, KJ, N, inputs)
            got = closed_form(KI, KJ, N, inputs)
            assert abs(got - want) < mpmath.mpf(10) ** -30 * abs(want), (KI, KJ, N, got, want)


@pytest.mark.parametrize("N", [0, 1, 2])
def test_closed_form_matches_the_moment_references(N):
    """V/S of MpPair (3 particles, non-parallel u, w = e_1 − e_3) against the closed form."""
    rng = np.random.default_rng(40 + N)
    with mpmath.workdps(MP_DPS):
        for KI, KJ in [(0, 0), (3, 5), (19, 8), (40, 13), (40, 40)]:
            fs = []
            for K in (KI, KJ):
                L = np.tril(rng.normal(size=(3, 3)))
                fs.append((L @ L.T + 0.3 * np.eye(3), rng.normal(size=3), K))
            w = np.array([1.0, 0.0, -1.0])
            pair = MpPair(fs[0], fs[1], N, diagonal=False)
            ratio = pair.coulomb(w.reshape(3, 1)) / pair.overlap()
            B = mpmath.matrix(fs[0][0].tolist()) + mpmath.matrix(fs[1][0].tolist())  # as MpPair: summed in mpmath
            Binv = mpmath.inverse(B)
            uI, uJ, wm = (mpmath.matrix(v.tolist()) for v in (fs[0][1], fs[1][1], w))
            dot = lambda a, b: (a.T * b)[0, 0]  # noqa: E731
            c = dot(wm, Binv * wm)
            x, y, z = dot(uI, Binv * uI) / 2, dot(uJ, Binv * uJ) / 2, dot(uI, Binv * uJ) / 2
            gi, gj = dot(Binv * uI, wm) / mpmath.sqrt(2 * c), dot(Binv * uJ, wm) / mpmath.sqrt(2 * c)
            want = 2 / mpmath.sqrt(mpmath.pi * c) * closed_form(KI, KJ, N, (x, y, z, gi, gj)) / omega(KI, KJ, N, x, y, z)
            assert abs(ratio - want) < mpmath.mpf(10) ** -30 * abs(want), (KI, KJ, N, ratio, want)


@pytest.mark.parametrize("N", [0, 1, 2])
def test_closed_form_is_stable_in_double_precision(N):
    """All e_j β_j terms are summed in floats; relative to the 50-digit value (K up to 40)."""
    rng = random.Random(99 + N)
    with mpmath.workdps(MP_DPS):
        for KI, KJ in K_PAIRS:
            inputs = random_inputs(rng)
            want = closed_form(KI, KJ, N, inputs)
            got = closed_form(KI, KJ, N, inputs, num=float)
            assert abs(got - float(want)) < 1e-13 * abs(float(want)), (KI, KJ, N, got, float(want))
