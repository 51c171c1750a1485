"""The Bethe logarithm ln k₀ of a level of N = 0 from a fixed basis of N = 1, by the sum over the
basis's pseudostates and by the integral over the photon energy k with the large-k asymptotics
subtracted analytically (docs/relativistic.md, "The Bethe logarithm").

Definition (H. A. Bethe, Phys. Rev. 72, 339 (1947); C. Schwartz, Phys. Rev. 123, 1700 (1961);
G. W. F. Drake and R. A. Swainson, Phys. Rev. A 41, 1243 (1990) for hydrogen; V. I. Korobov,
arXiv:1203.1404 (2012) in the velocity gauge for a general few-body system; hartree atomic units).
Every particle is quantum and charged particles all radiate: the current is J = Σ_i (q_i/m_i) p_i.
Its part that moves the internal state is J' = Σ_i w'_i p_i = −i∇_w', w' = q/m − Q/m_tot, the
dipole's velocity-form vector (level/transitions.py `dipole_vectors`; Σ_i w'_i m_i = 0, so J' has
no CM part; J − J' = (Q/m_tot) P acts on the CM alone). With the levels n of N = 1 (energies
E_n, ΔE_n = E_n − E_0), s_n = |⟨n‖J‖0⟩|², the reduced element of Edmonds summed over M and the
three components (for a level 0 of N = 0), and R the energy unit of the logarithm,

    ln k₀ = Σ_n s_n ΔE_n ln(|ΔE_n|/R) / D,   D = Σ_n s_n ΔE_n .

Sum rules (closure over the levels of N = 1, exact eigenstates):

    A = Σ_n s_n = ⟨J'²⟩,
    D = ½⟨[J', [H, J']]⟩ = −2π Σ_{a<b} q_a q_b (w'_a − w'_b)² ⟨δ³(r_ab)⟩,

the latter from [H, J'] = i Σ_i w'_i ∇_i V, ∇_i·∇_j(1/r_ab) = (δ_ia − δ_ib)(δ_ja − δ_jb) ∇²(1/r_ab)
and ∇²(1/r) = −4πδ³(r): Σ_ij w'_i w'_j ∇_i·∇_j V = −4π Σ_{a<b} q_a q_b (w'_a − w'_b)² δ³(r_ab). Pairs
of one charge-to-mass ratio (two electrons) drop out. Hydrogen (μ = m_p/(1 + m_p)):
w'_e − w'_p = −1/μ, ⟨δ³⟩ = μ³/(πn³), so D = 2μ/n³; A = ⟨p²⟩/μ² = 1/n².

The unit R (`rydberg`, Eh): ln k₀ in another unit R' is ln k₀ + ln(R/R'). Hydrogen's values of
Drake & Swainson, 2.984 128 556 (1s) and 2.811 769 893 (2s), are in the reduced Rydberg μ/2 Eh of
the atom: ΔE_n and D scale as μ, s_n not at all, so in that unit ln k₀ does not depend on μ.
Helium's are quoted in R_∞ = ½ Eh at infinite nuclear mass. The default here is ½ Eh
(`R_INFINITY`, the Rydberg of the electron's mass), for any system; pass μ/2 for hydrogen-like
atoms (`reduced_rydberg`).

The pseudostates. The N = 1 basis's levels (H c = E S c, the directions its overlap resolves) and
r_J = ⟨φ_J‖∇_w'‖ψ₀⟩ (the core's two-basis "velocity" element) give s_n = (c_nᵀr)². The sum over
them, ln k₀ = Σ s_nΔE_n ln(|ΔE_n|/R)/Σ s_nΔE_n, is the basis's own value ("pseudostate"). Levels
of N = 1 at or below the level (ΔE_n ≤ 0: He 2¹P below 3¹S; hydrogen's 2p, degenerate with 2s) are
counted with ln |ΔE_n|, their term zero at ΔE_n = 0.

The integral representation (the method of Schwartz 1961, carried to the velocity gauge and a
general few-body system by Korobov 2012; of these papers only the abstracts and introductions were
read here, and every formula below is derived here). For ΔE > 0, ∫_0^∞ dk [1/(R + k) − 1/(ΔE + k)] = ln(ΔE/R), so

    Σ_{ΔE_n>0} s_n ΔE_n ln(ΔE_n/R) = ∫_0^∞ dk [D₊/(R + k) − g(k)],
    g(k) = Σ_{ΔE_n>0} s_n ΔE_n/(ΔE_n + k) = A₊ − k f(k),   f(k) = ⟨J'(H − E₀ + k)⁻¹J'⟩₊,

with D₊ = D − Σ_{ΔE_n≤0} s_nΔE_n and A₊ the sums over the levels above; the levels at or below
are added as their terms, so no pole of f lies on the path of k. f(k) is minus the minimum of Hylleraas' functional
⟨ψ₁|H − E₀ + k|ψ₁⟩ + 2⟨ψ₁|J'⟩ over the N = 1 basis with the reduced elements r (response.py
`FirstOrder.hylleraas(−k)`; −3 × the minimum with J'_z's elements r/√3): the dipole response at
ω = −k. g is evaluated from the pseudostates as the sum above, not as A₊ − k f(k), which loses
to cancellation at large k what the integrand needs (at k = 1e6 Eh in hydrogen kf agrees with A
to 2e-6 and the integrand is 1e-9).

Large k. At k → ∞ the resolvent probes short distances, r_ab ~ (2μ_ab k)^(−1/2), where ψ₀ has the
cusp of Kato's condition ψ₀ ≈ ψ₀(r_ab = 0)(1 + μ_ab q_a q_b r_ab) (μ_ab = m_a m_b/(m_a + m_b)) and
J' ⊃ (w'_a − w'_b) p_ab, p_ab the pair's relative momentum, whose kinetic energy is p²/(2μ_ab).
The cusp's |r_ab| makes the distribution of p_ab fall as 8 μ_ab² (q_a q_b)² ⟨δ³(r_ab)⟩/(π p⁸) (the
Fourier transform of r is −8π/p⁴); with the free resolvent (k + p²/2μ_ab)⁻¹ the pseudostates'
strength per unit ΔE falls as (C/π) ΔE^(−5/2) (C below, summed over the pairs), and the first
Coulomb correction of the pair's high-energy continuum multiplies it by 1 + πμ_ab q_a q_b/p
(the 1/p term of the exact hydrogen photoeffect cross section of Stobbe, σ ∝ p⁻⁷(1 − πZ/p),
recalled, not read here, and scaled to the pair's charges and reduced mass; its consequence λ below
is checked against hydrogen numerically). D/k − g(k) = Σ_n s_n ΔE_n²/(k(ΔE_n + k)) then gives

    g(k) = D₊/k − C k^(−3/2) + Σ_{a<b} λ_ab ln(k/μ_ab)/k² + b/k² + e k^(−5/2) + …,
    C = 4√2 π Σ_{a<b} √μ_ab (q_a q_b)² (w'_a − w'_b)² ⟨δ³(r_ab)⟩,
    λ_ab = −4π μ_ab (q_a q_b)³ (w'_a − w'_b)² ⟨δ³(r_ab)⟩,

i.e. k f(k) = A − D/k + C k^(−3/2) − … . Hydrogen: C = 4√2 μ^(3/2)/n³, λ = 4μ²/n³; in
even-tempered bases (tests/test_bethe.py) k^(3/2)(D/k − g) + λ ln(k/μ)/√k reaches C to 8e-4 at
k = 1e6 Eh (the rest is b/√k) and the slope of k²[g − D/k + Ck^(−3/2)] against ln k reaches λ to
7e-3 between 1e5 and 3e5 Eh (the rest is the k^(−5/2) term's). C and λ are derived pair by pair;
what three-body coalescences add, and the constant b, are not derived. b and e (the next order)
are fitted to the computed g on [K/`window`, K] ("fit"; hydrogen 1s: b ≈ −4.3).

The integral is split at K: Gauss–Legendre panels in x = ln(1 + k/k₀) (k₀ the smaller of R and the
lowest ΔE_n > 0; `PANEL` wide, `ORDER` points each, exact to ~1e-15 for each pseudostate's term,
whose poles lie π off the real x axis) on [0, K], and on [K, ∞) the expansion in closed form,

    ∫_K^∞ [D₊/(R + k) − g] dk = −D₊ ln(1 + R/K) + 2C/√K − Σ λ_ab (ln(K/μ_ab) + 1)/K
                                − b/K − (2/3) e K^(−3/2).

K must lie where the bases still resolve f (the ground basis's cusp and the N = 1 basis's
functions at r ~ (2μk)^(−1/2)) and where the expansion holds: by default (`split`) 1e-2 of the
ground basis's largest diagonal kinetic energy or 1e5 × the Coulomb scale (Zμ)², whichever is less,
and never below 1e2 × that scale (InputError). D is taken from ⟨δ³(r_ab)⟩,
Drachmann's regularised value where `regularised` (drachmann.py; the direct one misses the cusp):
its error enters ln k₀ as (ln(K/R) − ln k₀) δD/D, 9 δD/D at K = 1e5 Eh in hydrogen. With the basis's own D and A₊
(D_b = Σ s_nΔE_n) and K far above every ΔE_n, the integral is the pseudostate sum ("own": the
check of the quadrature and of the treatment of the levels below). Not included: the
relativistic and higher-order QED corrections to ln k₀, finite nuclear size, and the recoil
corrections beyond the nonrelativistic Hamiltonian of point particles that prebo solves.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import eigen
from ..basis import Basis
from ..errors import InputError
from ..integrals import laboratory
from ..system import reduced_mass
from . import drachmann
from .evaluate import evaluate
from .expectation import members
from .response import FirstOrder, problem, require
from .transitions import dipole_vectors

#: the Rydberg at infinite mass in Eh, R_∞ = α²m_ec²/2h = ½ E_h: the default unit of ln k₀
R_INFINITY = 0.5

#: the default split point K (module docstring): GROUND_REACH of the ground basis's largest diagonal
#: kinetic energy (its f(k) stops mattering below ~1e-2 of it in hydrogen) and at most TOP × the
#: Coulomb scale (1e5 Eh for hydrogen; the expansion alone errs 1.5e-6 at 1e4, 1e-7 at 3e4); refused
#: below BOTTOM × the scale, where the expansion does not hold (benchmarks/record/bethe-logarithm.md).
#: The N = 1 basis must resolve f up to K: a union of driver-optimised bases errs in g(k) 4e-5
#: relative at 1/39 of its largest ΔE_n and 3.8e-4 at 1/3.9 (the same record; optimise/current.py
#: grows its grid to 3 K)
GROUND_REACH, TOP, BOTTOM = 1e-2, 1e5, 1e2

#: the Gauss–Legendre panels of the quadrature on [0, K]: width in x = ln(1 + k/k₀), points per panel
PANEL, ORDER = 0.5, 12

#: how far above the basis's largest ΔE_n its own integral reaches (the check against the pseudostate sum)
BEYOND = 1e12


def reduced_rydberg(system) -> float:
    """μ/2 Eh, the Rydberg of a two-body system of reduced mass μ (m_e): the unit of hydrogen's ln k₀
    (Drake & Swainson 1990) in which it does not depend on the masses. InputError for other systems."""
    if system.n != 2:
        raise InputError(f"the reduced Rydberg μ/2 is that of a two-body system, not of {system.n} particles")
    return 0.5 * float(reduced_mass(*system.masses))


@dataclass(frozen=True)
class Pairs:
    """The large-k expansion of the level's g(k) from its contact densities (module docstring): the
    sum rule `D` (Eh), the k^(−3/2) coefficient `C` (Eh^(3/2)), and per pair class its ln k/k²
    coefficient `lam` (Eh²) and reduced mass `mu` (m_e)."""

    D: float
    C: float
    lam: np.ndarray
    mu: np.ndarray

    @classmethod
    def of(cls, system, delta: dict) -> "Pairs":
        """From ⟨δ³(r_ab)⟩ per pair class `delta` ({"a-b": bohr⁻³}, averaged over the class)."""
        _, wv = dipole_vectors(system)
        D = C = 0.0
        lam, mus = [], []
        for label, ms in members(system, pairs=True).items():
            a, b = ms[0]
            qq = system.particles[a].charge * system.particles[b].charge
            mu = float(reduced_mass(system.masses[a], system.masses[b]))
            weight = len(ms) * (wv[a] - wv[b]) ** 2 * delta[label]
            D += -2 * math.pi * qq * weight
            C += 4 * math.sqrt(2) * math.pi * math.sqrt(mu) * qq**2 * weight
            lam.append(-4 * math.pi * mu * qq**3 * weight)
            mus.append(mu)
        return cls(D, C, np.array(lam), np.array(mus))

    def log_term(self, k):
        """Σ λ_ab ln(k/μ_ab) at the photon energies k."""
        k = np.asarray(k, dtype=float)
        return np.sum(self.lam[:, None] * np.log(k[None, :] / self.mu[:, None]), axis=0)


@dataclass(frozen=True)
class Spectrum:
    """The current's pseudostates in the N = 1 basis: `first` the FirstOrder problem (response.py)
    with the reduced elements r_J = ⟨φ_J‖∇_w'‖ψ₀⟩, and their strengths `s` = (c_nᵀr)²."""

    first: FirstOrder
    s: np.ndarray

    @classmethod
    def of(cls, first: FirstOrder) -> "Spectrum":
        return cls(first, (first.C.T @ first.r) ** 2)

    @property
    def de(self) -> np.ndarray:
        """The excitation energies ΔE_n = E_n − E₀ (Eh)."""
        return self.first.de

    @property
    def above(self) -> np.ndarray:
        """Which pseudostates lie above the level (ΔE_n > 0): those of the integral."""
        return self.de > 0

    def f(self, k: float) -> float:
        """f(k) = Σ s_n/(ΔE_n + k), minus the minimum of Hylleraas' functional at E₀ − k."""
        return -self.first.hylleraas(-k)

    def g(self, k) -> np.ndarray:
        """g(k) = Σ_{ΔE_n>0} s_nΔE_n/(ΔE_n + k) = A₊ − k f₊(k) at the photon energies k (Eh)."""
        k = np.atleast_1d(np.asarray(k, dtype=float))
        s, de = self.s[self.above], self.de[self.above]
        return (s * de) @ (1.0 / (de[:, None] + k[None, :]))

    def lower(self, R: float) -> float:
        """Σ_{ΔE_n≤0} s_n ΔE_n ln(|ΔE_n|/R): the levels at or below, as their terms (0 at ΔE_n = 0)."""
        keep = ~self.above & (self.de != 0)
        return float(np.sum(self.s[keep] * self.de[keep] * np.log(-self.de[keep] / R)))

    def pseudostate(self, R: float) -> float:
        """The basis's own ln k₀, Σ s_nΔE_n ln(|ΔE_n|/R) / Σ s_nΔE_n."""
        s, de = self.s, self.de
        keep = de != 0
        return float(np.sum(s[keep] * de[keep] * np.log(np.abs(de[keep]) / R)) / np.sum(s * de))


def panels(k0: float, K: float) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weights of ∫_0^K dk by Gauss–Legendre panels in x = ln(1 + k/k₀), PANEL wide, ORDER
    points each: ∫ h dk = ∫ h (k₀ + k) dx."""
    X = math.log1p(K / k0)
    edges = np.linspace(0.0, X, max(1, math.ceil(X / PANEL)) + 1)
    t, w = np.polynomial.legendre.leggauss(ORDER)
    half, mid = np.diff(edges)[:, None] / 2, (edges[:-1] + edges[1:])[:, None] / 2
    x = (mid + half * t).ravel()
    k = k0 * np.expm1(x)
    return k, (half * w).ravel() * (k0 + k)


def integral(sp: Spectrum, pairs: Pairs | None, R: float, K: float, window: float) -> dict:
    """Σ_{ΔE_n>0} s_nΔE_n ln(ΔE_n/R) by the integral representation split at K (module docstring):
    with `pairs` the level's D, C and λ and the fitted b, e on [K, ∞); without, the basis's own
    D₊ and no other term (K far above every ΔE_n). Returns {"numerator", "quadrature", "tail",
    "fit": {"b", "e", "share"}}, in Eh (the numerator of ln k₀)."""
    s, de = sp.s, sp.de
    up = sp.above
    D_plus = (pairs.D if pairs else float(np.sum(s * de))) - float(np.sum(s[~up] * de[~up]))
    k0 = min(R, float(np.min(de[up])))
    k, w = panels(k0, K)
    quadrature = float(w @ (D_plus / (R + k) - sp.g(k)))
    tail = -D_plus * math.log1p(R / K)
    fit = {"b": 0.0, "e": 0.0, "share": 0.0}
    if pairs is not None:
        tail += 2 * pairs.C / math.sqrt(K) - float(np.sum(pairs.lam * (np.log(K / pairs.mu) + 1))) / K
        kk = np.geomspace(K / window, K, 24)
        y = kk**2 * (sp.g(kk) - D_plus / kk + pairs.C * kk**-1.5) - pairs.log_term(kk)
        (b, e), *_ = np.linalg.lstsq(np.c_[np.ones_like(kk), kk**-0.5], y, rcond=None)
        share = -(b / K + 2 / 3 * e * K**-1.5)
        fit = {"b": float(b), "e": float(e), "share": float(share)}
        tail += share
    return {"numerator": quadrature + tail, "quadrature": quadrature, "tail": tail, "fit": fit}


def check(ground, responses, R, K, k, window) -> None:
    """InputError (UnsupportedError for a ground basis of N > 0) for bases the Bethe logarithm is
    not derived for (response.py `require`), or a unit, split point, window or k-grid that is not a
    finite positive number."""
    require(ground, responses, "bethe_logarithm", "J ψ₀")
    for name, x in (("rydberg", R), ("K", K), ("window", window)):
        if x is not None and not (isinstance(x, (int, float)) and math.isfinite(x) and x > 0):
            raise InputError(f"bethe_logarithm: {name} = {x!r}: must be a finite positive number")
    if window is not None and window <= 1:
        raise InputError(f"bethe_logarithm: window = {window!r}: must exceed 1 (the fit's range is [K/window, K])")
    if k is not None:
        grid = np.atleast_1d(np.asarray(k, dtype=float)) if np.ndim(k) <= 1 else None
        if grid is None or grid.size == 0 or not np.all(np.isfinite(grid)) or np.any(grid <= 0):
            raise InputError(f"bethe_logarithm: k = {k!r}: must be a non-empty list of finite photon energies > 0 (Eh)")


def kinetic_scale(basis: Basis) -> float:
    """The largest diagonal kinetic energy ⟨φ_I|T|φ_I⟩/⟨φ_I|φ_I⟩ of `basis` (Eh): the shortest distance
    it resolves; GROUND_REACH of it is where the ground basis's f(k) stops being trusted."""
    m = laboratory(basis.system).matrices(basis)
    return float(np.max(np.diag(m["T_ti"]) / np.diag(m["S"])))


def coulomb_scale(system) -> float:
    """max (q_a q_b)² μ_ab over `system`'s attracting pairs (Eh; 1 for hydrogen at infinite mass,
    twice its binding energy; every charged pair if none attract): the unit of TOP and BOTTOM."""
    q, m = system.charges, system.masses
    pairs = [(q[a] * q[b], reduced_mass(m[a], m[b])) for a in range(system.n) for b in range(a) if q[a] * q[b]]
    attract = [(qq, mu) for qq, mu in pairs if qq < 0] or pairs
    return float(max(qq**2 * mu for qq, mu in attract))


def split(ground: Basis) -> float:
    """The default split point K (Eh): the lesser of GROUND_REACH × `kinetic_scale(ground)` and TOP ×
    `coulomb_scale`."""
    return min(GROUND_REACH * kinetic_scale(ground), TOP * coulomb_scale(ground.system))


def bethe_logarithm(ground: Basis, response, root: int = 0, rydberg: float = R_INFINITY, K: float | None = None,
                    k=None, window: float = 100.0, regularised: bool | None = None,
                    threshold: float = eigen.THRESHOLD) -> dict:
    """ln k₀ of the level `root` of the N = 0 basis `ground`, with its current's first-order functions
    in the N = 1 basis `response` (one, or a list of growing ones for a convergence table; the last
    gives the result), in the unit `rydberg` (Eh; module docstring), the integral split at K (Eh;
    default `split`), the O(k⁻²) terms fitted on [K/window, K]; `k`, photon
    energies (Eh) at which to tabulate f, g and the expansion; `regularised`, Drachmann's ⟨δ³⟩ in D
    (None: where cheap, `drachmann.CLOSED_FORM`).

    Returns {"ln_k0": the integral representation's value, "pseudostate": the basis's own sum,
    "own": the integral with the basis's own asymptotics (equal to "pseudostate"), "integral":
    {"K", "quadrature", "tail", "fit": {"b", "e", "share"}} (each a share of ln k₀), "D" (Eh, from
    ⟨δ³⟩), "D_response" (Σ s_nΔE_n), "J2" (⟨J'²⟩, (e ħ/(m_e a₀))²), "J2_response" (Σ s_n), "C",
    "log": {class: λ}, "delta": {class: ⟨δ³⟩ used}, "regularised", "lower": [{de, s}] of the levels
    of N = 1 at or below, "energy", "root", "rydberg", "convergence": [{n_basis, K, pseudostate,
    ln_k0, J2_response, D_response}] per response basis, and with `k` "spectrum": [{k, f, g,
    asymptotic}]}. InputError as `check` raises it, for a level that is not bound, or for a split
    point below BOTTOM × the Coulomb scale."""
    responses = list(response) if isinstance(response, (list, tuple)) else [response]
    if not responses:
        raise InputError("bethe_logarithm: response = []: give at least one basis of N = 1")
    check(ground, responses, rydberg, K, k, window)
    R = float(rydberg)
    if regularised is None:
        regularised = ground.family.name in drachmann.CLOSED_FORM
    names = ("delta",) + (drachmann.TERMS if regularised else ())
    level = evaluate(ground, threshold=threshold, roots=root + 1, targets=[root], operators=names)
    if not level["bound"]:
        raise InputError(f"bethe_logarithm: level {root} of the ground basis ({level['energy']:.10g} Eh) is not "
                         f"below its threshold {level['threshold']:.10g} Eh: not a bound level")
    E0, c0 = float(level["energy"]), level["vectors"][:, 0]
    delta = dict(level["expectation"]["delta"])
    if regularised:
        delta |= drachmann.regularised(ground.system, level["expectation"], E0)
    pairs = Pairs.of(ground.system, delta)
    rep = laboratory(ground.system)
    _, wv = dipole_vectors(ground.system)
    J2 = float(c0 @ rep.operator("p2", ground, wv[None], (True,))[0] @ c0)
    low = BOTTOM * coulomb_scale(ground.system)
    rows = []
    for basis in responses:
        sp = Spectrum.of(problem(ground, basis, E0, c0, threshold, "velocity"))
        at = K if K is not None else split(ground)
        if at < low:
            why = "give a larger K" if K is not None else (
                f"the bases do not reach far enough (ground: kinetic scale {kinetic_scale(ground):.3g} Eh; response: "
                f"largest ΔE {float(np.max(sp.de)):.3g} Eh)")
            raise InputError(f"bethe_logarithm: the split point K = {at:.4g} Eh lies below {low:.4g} Eh ({BOTTOM:g} × "
                             f"the Coulomb scale), where the large-k expansion does not hold: {why}")
        lower = sp.lower(R)
        part = integral(sp, pairs, R, at, window)
        own = integral(sp, None, R, BEYOND * max(float(np.max(sp.de)), R), window)
        D_b = float(np.sum(sp.s * sp.de))
        rows.append({"n_basis": len(basis), "pseudostate": sp.pseudostate(R),
                     "ln_k0": (part["numerator"] + lower) / pairs.D, "own": (own["numerator"] + lower) / D_b,
                     "J2_response": float(np.sum(sp.s)), "D_response": D_b, "integral": part, "K": at,
                     "spectrum": sp})
    last = rows[-1]
    part, sp = last["integral"], last["spectrum"]
    out = {
        "ln_k0": last["ln_k0"], "pseudostate": last["pseudostate"], "own": last["own"],
        "integral": {"K": last["K"], "quadrature": part["quadrature"] / pairs.D, "tail": part["tail"] / pairs.D,
                     "fit": part["fit"] | {"share": part["fit"]["share"] / pairs.D}},
        "D": pairs.D, "D_response": last["D_response"], "J2": J2, "J2_response": last["J2_response"],
        "C": pairs.C, "log": dict(zip(members(ground.system, pairs=True), pairs.lam.tolist())),
        "delta": delta, "regularised": bool(regularised),
        "lower": [{"de": float(d), "s": float(x)} for d, x in zip(sp.de[~sp.above], sp.s[~sp.above])],
        "energy": E0, "root": root, "rydberg": R,
        "convergence": [{key: r[key] for key in ("n_basis", "K", "pseudostate", "ln_k0", "J2_response", "D_response")}
                        for r in rows],
    }
    if k is not None:
        grid = np.atleast_1d(np.asarray(k, dtype=float))
        asymptotic = pairs.D / grid - pairs.C * grid**-1.5 + pairs.log_term(grid) / grid**2
        out["spectrum"] = [{"k": float(x), "f": sp.f(float(x)), "g": float(gx), "asymptotic": float(a)}
                           for x, gx, a in zip(grid, sp.g(grid), asymptotic)]
    return out
