"""Numerical check of the closed forms of docs/properties-derivations.md (issue 40).

Standalone: numpy and scipy only, nothing from prebo. For random pairs of unsymmetrised,
unnormalised functions φ_I, φ_J of each family (plain ECG, floating ECG, ECG-GVR) in the
laboratory frame of n = 2 and n = 3 particles (6- and 9-dimensional integrals), it compares
each closed form with a numerical value (rows; equation numbers of the note):

  S                  the overlap (2) (for ECG-GVR only the normalisation of the ratios)
  damped a=1/q       <exp(-α r_w²)>/S at α = 1/q, (4)-(5)
  delta              <δ³(r_w)>/S, (7)-(8), against the integral over the hyperplane r_w = 0
  delta (lim)        the same against (α/π)^{3/2}<exp(-α r_w²)>/S, Richardson in 1/α, (9)
  1/r, r, 1/r2       <r_w^k>/S, (12)-(16); "[binary]" the Beta sums (17); "[damped]" rule (18)
  1F1, series        the FECG forms (16) against ₁F₁ (scipy) and the small-λ series
  1/(r r')           <1/(r_w r_w')>/S, plain ECGs, (19)
  p4 lab, p4 TI      <Δ_g φ_I|Δ_g φ_J>/S, g = e_i and g = e_i − μ_i 1, (22), (25); "c_A form" (24)
  grad.(1/r).grad    <∇φ_I|Λ/r_w|∇φ_J>/S, Λ = M − 1 1ᵀ/(2 m_tot), (28)-(29)
  grad.g.grad (30)   the identity (30) at α = 1/q

What "numerical" means per row:
- delta, 1/r, r, 1/r2, grad.(1/r).grad: the full 3n-dimensional integral in coordinates (y, ξ),
  y = r_w: the 3(n−1) coordinates ξ by Gauss–Hermite about their Gaussian for fixed y (exact for
  a polynomial prefactor), y in spherical coordinates (composite Gauss–Legendre in |y|,
  Gauss–Legendre × trapezoid over the directions). The δ row is the same integrand at y = 0.
  The last column is the change when the node counts are doubled (the quadrature's own error).
- damped, delta (lim), [damped], p4, grad.g.grad: Gauss–Hermite over all 3n coordinates (exact
  for a polynomial times the Gaussian); Δ_g φ/φ from three values of φ along g (exact: the
  exponent is quadratic along any line).
- 1/(r r'): the Gaussian marginal of (r_w, r_w') integrated in (|y|, |y'|, cos ∠(y, y')).
None of these uses the closed forms, the α-integrals (10) or the substitution u.

Run: `nice -n 19 python benchmarks/check_property_formulas.py` (about one minute of CPU).
"""
import math
import time

import numpy as np
from numpy.polynomial import Polynomial
from numpy.polynomial.hermite import hermgauss
from numpy.polynomial.legendre import leggauss
from scipy import special

RNG = np.random.default_rng(40)

# --------------------------------------------------------------------------------------------
# Test functions: CM-separable exponents A = U^T blockdiag(𝒜, c_A) U (docs/conventions.md)
# --------------------------------------------------------------------------------------------


def heavy_centred(masses):
    """U of the set x_i = r_i − r_0 (i ≥ 1), last row μ = m/m_tot."""
    n = len(masses)
    u = np.zeros((n, n))
    for i in range(1, n):
        u[i - 1, i], u[i - 1, 0] = 1.0, -1.0
    u[-1] = masses / masses.sum()
    return u


def exponent(masses, c_a):
    """A random CM-separable exponent matrix with CM exponent c_A (A 1 = c_A μ)."""
    n = len(masses)
    l = np.tril(RNG.normal(size=(n - 1, n - 1)) * 0.3) + np.eye(n - 1) * 0.8
    inner = l @ l.T
    block = np.zeros((n, n))
    block[:-1, :-1], block[-1, -1] = inner, c_a
    u = heavy_centred(masses)
    return u.T @ block @ u


class Function:
    """exp(−(r−s)^T A (r−s)) |v|^{2K} (v_x + i v_y)^N, v = u^T r (the three families)."""

    def __init__(self, a, c_a, s=None, u=None, k=0, n_ang=0):
        d = a.shape[0]
        self.a, self.c_a = a, c_a
        self.s = np.zeros((d, 3)) if s is None else s
        self.u, self.k, self.n_ang = u, k, n_ang


class Pair:
    """The product φ_I* φ_J = P(r) exp(−r^T B r + 2 r·v − κ0) (v, κ0 from the centres)."""

    def __init__(self, fi, fj):
        self.fi, self.fj = fi, fj
        self.b = fi.a + fj.a
        self.binv = np.linalg.inv(self.b)
        self.v = fi.a @ fi.s + fj.a @ fj.s
        self.kappa0 = np.sum(fi.s * (fi.a @ fi.s)) + np.sum(fj.s * (fj.a @ fj.s))
        self.rbar = self.binv @ self.v
        self.gvr = fi.u is not None
        self.degree = 2 * (fi.k + fj.k + fi.n_ang) if self.gvr else 0

    def prefactor(self, r):
        """P(r) for points r (..., D, 3): 1, or the ECG-GVR product of the bra* and ket."""
        if not self.gvr:
            return np.ones(r.shape[:-2])
        a = np.einsum("k,...kc->...c", self.fi.u, r)
        b = np.einsum("k,...kc->...c", self.fj.u, r)
        n = self.fi.n_ang
        pa = np.sum(a * a, -1) ** self.fi.k * (a[..., 0] - 1j * a[..., 1]) ** n
        pb = np.sum(b * b, -1) ** self.fj.k * (b[..., 0] + 1j * b[..., 1]) ** n
        return pa * pb


# --------------------------------------------------------------------------------------------
# Closed forms (docs/properties-derivations.md)
# --------------------------------------------------------------------------------------------


def overlap_closed(p):
    """Eq. (2): (π^D/|B|)^{3/2} exp(−κ0 + v·B⁻¹v) (plain ECG: κ0 = v = 0)."""
    d = p.b.shape[0]
    return (math.pi**d / np.linalg.det(p.b)) ** 1.5 * math.exp(-p.kappa0 + np.sum(p.v * p.rbar))


def profile(p, w):
    """q = wᵀB⁻¹w and F(u) (eq. (5)): 1, exp(−λu) or Ω(P − uG)/Ω(P) as a Polynomial in u."""
    q = w @ p.binv @ w
    if p.gvr:
        fi, fj = p.fi, p.fj
        c = p.binv / 2
        x, y, z = fi.u @ c @ fi.u, fj.u @ c @ fj.u, fi.u @ c @ fj.u
        gi, gj = (p.binv @ fi.u) @ w / math.sqrt(2 * q), (p.binv @ fj.u) @ w / math.sqrt(2 * q)
        xs, ys, zs = Polynomial([x, -gi * gi]), Polynomial([y, -gj * gj]), Polynomial([z, -gi * gj])
        om = omega(fi.k, fj.k, fi.n_ang, xs, ys, zs)
        # F(1) = Ω(P')/Ω(P) from the conditioned covariances P' (positive series, no cancellation)
        f1 = omega(fi.k, fj.k, fi.n_ang, x - gi * gi, y - gj * gj, z - gi * gj) / om(0.0)
        return q, (om / om(0.0), f1)
    m = w @ p.rbar
    lam = m @ m / q
    return q, lam


def omega(ki, kj, n, x, y, z):
    """Ω = Σ_k ĉ_k x^{K_I−k} y^{K_J−k} z^{N+2k} (docs/gvr.md; the ratio of families/ecg_gvr/series.rs)."""
    total, ck = 0.0 * x, 1.0
    for k in range(min(ki, kj) + 1):
        total = total + ck * x ** (ki - k) * y ** (kj - k) * z ** (n + 2 * k)
        ck *= (ki - k) * (kj - k) / ((k + 1) * (k + n + 1.5))
    return total


def closed_ratios(p, w, alpha):
    """<O>/S for O = exp(−α r_w²), δ³(r_w), 1/r_w, r_w, 1/r_w² (eqs. (4)-(17))."""
    q, f = profile(p, w)
    u = alpha * q / (1 + alpha * q)
    if p.gvr:  # F a polynomial Σ f_k u^k: every u-integral a sum of Beta functions
        f, f1 = f
        h = Polynomial([1.5, -1.5]) * f - Polynomial([1.0, -2.0, 1.0]) * f.deriv()
        fk, hk = f.coef, h.coef
        return {
            "damped": (1 - u) ** 1.5 * f(u),
            "delta": (math.pi * q) ** -1.5 * f1,
            "1/r": 2 / math.sqrt(math.pi * q) * sum(c / (2 * k + 1) for k, c in enumerate(fk)),
            "r": math.sqrt(q / math.pi) * sum(c / (k + 0.5) for k, c in enumerate(hk)),
            "1/r2": sum(c * special.beta(k + 1, 0.5) for k, c in enumerate(fk)) / q,
        }
    lam = f  # plain ECG: λ = 0
    sl = math.sqrt(lam)
    if lam < 1e-8:
        return {"damped": (1 - u) ** 1.5, "delta": (math.pi * q) ** -1.5,
                "1/r": 2 / math.sqrt(math.pi * q), "r": 2 * math.sqrt(q / math.pi), "1/r2": 2 / q}
    return {
        "damped": (1 - u) ** 1.5 * math.exp(-lam * u),
        "delta": (math.pi * q) ** -1.5 * math.exp(-lam),
        "1/r": math.erf(sl) / (sl * math.sqrt(q)),
        "r": math.sqrt(q) * (math.exp(-lam) / math.sqrt(math.pi) + (sl + 0.5 / sl) * math.erf(sl)),
        "1/r2": 2 * special.dawsn(sl) / (sl * q),
    }


def binary_ratios(p, w):
    """Eq. (17), ECG-GVR: the u-integrals as Beta sums over the binary form
    Ω(sP + tP') = Σ_j e_j s^j t^{M−j} (s = 1 − u, t = u; e_j from Ω(P + vP') = Σ_j e_j v^{M−j})."""
    fi, fj = p.fi, p.fj
    q = w @ p.binv @ w
    c = p.binv / 2
    x, y, z = fi.u @ c @ fi.u, fj.u @ c @ fj.u, fi.u @ c @ fj.u
    gi, gj = (p.binv @ fi.u) @ w / math.sqrt(2 * q), (p.binv @ fj.u) @ w / math.sqrt(2 * q)
    xp, yp, zp = x - gi * gi, y - gj * gj, z - gi * gj
    big_m = fi.k + fj.k + fi.n_ang
    ov = omega(fi.k, fj.k, fi.n_ang, Polynomial([x, xp]), Polynomial([y, yp]), Polynomial([z, zp]))
    e = np.zeros(big_m + 1)
    e[: len(ov.coef)] = ov.coef
    e = e[::-1] / omega(fi.k, fj.k, fi.n_ang, x, y, z)  # e_j / Ω(P), j = 0..M
    beta = special.beta
    inv_r = 2 / math.sqrt(math.pi * q) * 0.5 * sum(e[j] * beta(big_m - j + 0.5, j + 1) for j in range(big_m + 1))
    inv_r2 = sum(e[j] * beta(big_m - j + 1, j + 0.5) for j in range(big_m + 1)) / q
    r = math.sqrt(q / math.pi) * sum(
        e[j] * ((1.5 + j) * beta(big_m - j + 0.5, j + 2) - ((big_m - j) * beta(big_m - j - 0.5, j + 3) if j < big_m else 0.0))
        for j in range(big_m + 1))
    return {"1/r": inv_r, "r": r, "1/r2": inv_r2}


def pair_inverse_closed(p, w1, w2):
    """Eq. (19), plain ECG: <1/(r_w r_w')>/S = 4 arcsin(ρ)/(π ρ √(q q')), ρ = q_12/√(q q')."""
    q11, q22, q12 = w1 @ p.binv @ w1, w2 @ p.binv @ w2, w1 @ p.binv @ w2
    rho = q12 / math.sqrt(q11 * q22)
    return 4 * math.asin(rho) / (math.pi * rho * math.sqrt(q11 * q22))


def boys(j, lam):
    """F_j(λ) = ∫_0^1 τ^{2j} exp(−λτ²) dτ."""
    if lam < 1e-12:
        return 1.0 / (2 * j + 1)
    return special.gammainc(j + 0.5, lam) * special.gamma(j + 0.5) / (2 * lam ** (j + 0.5))


def grad_inverse_closed(p, w, lam_matrix):
    """Eq. (29): <∇φ_I|Λ/r_w|∇φ_J>/S = 2/√(πq) Σ_j f_j F_j(λ), F_T(u) = Σ_j f_j u^j (eq. (28))."""
    q = w @ p.binv @ w
    bw = p.binv @ w
    wm = p.fi.a @ lam_matrix @ p.fj.a
    m = w @ p.rbar
    di, dj = p.rbar - p.fi.s, p.rbar - p.fj.s
    f0 = 6 * np.trace(p.binv @ wm) + 4 * np.sum(di * (wm @ dj))
    f1 = -6 * bw @ wm @ bw / q - 4 / q * m @ (di.T @ wm @ bw + dj.T @ wm.T @ bw)
    f2 = 4 / q**2 * (m @ m) * (bw @ wm @ bw)
    lam = m @ m / q
    return 2 / math.sqrt(math.pi * q) * sum(f * boys(j, lam) for j, f in enumerate((f0, f1, f2)))


def plain_kinetic(ai, aj, lam_matrix):
    """The plain-ECG kinetic element <∇φ_I|Λ|∇φ_J> = 6 Tr(B⁻¹A_IΛA_J) (π^D/|B|)^{3/2}."""
    b = ai + aj
    return 6 * np.trace(np.linalg.solve(b, ai @ lam_matrix @ aj)) * (math.pi ** len(b) / np.linalg.det(b)) ** 1.5


def grad_damped_identity(p, w, lam_matrix, alpha):
    """Eq. (30): <∇φ_I|e^{−αy²}Λ|∇φ_J> from kinetic elements of damped functions and the damped
    overlap (plain ECGs), ½[T(gφ_I, φ_J) + T(φ_I, gφ_J)] + ½ wᵀΛw <(4α²y² − 6α) g>."""
    ai, aj, m = p.fi.a, p.fj.a, alpha * np.outer(w, w)
    t_sym = 0.5 * (plain_kinetic(ai + m, aj, lam_matrix) + plain_kinetic(ai, aj + m, lam_matrix))
    b = ai + aj + m
    s_a = (math.pi ** len(b) / np.linalg.det(b)) ** 1.5
    y2 = 1.5 * (w @ np.linalg.solve(b, w)) * s_a  # <y² e^{−αy²}> (r2.rs at α)
    return t_sym + 0.5 * (w @ lam_matrix @ w) * (4 * alpha**2 * y2 - 6 * alpha * s_a)


def p4_closed(p, g):
    """Eqs. (22), (25): <Δ_g φ_I|Δ_g φ_J>/S; τ = gᵀA_I B⁻¹ A_J g, ξ̄, η̄ the centred shifts."""
    ai, aj = p.fi.a, p.fj.a
    tau = g @ ai @ p.binv @ aj @ g
    xi = (ai @ g) @ (p.rbar - p.fi.s)
    eta = (aj @ g) @ (p.rbar - p.fj.s)
    return 24 * tau**2 + 32 * tau * (xi @ eta) + (4 * xi @ xi - 6 * tau) * (4 * eta @ eta - 6 * tau)


def p4_ti_closed(p, i, mu):
    """Eq. (24), plain ECG with A 1 = c_A μ: 60 [(A_I B⁻¹ A_J)_ii − μ_i² c_I c_J/(c_I + c_J)]²."""
    ci, cj = p.fi.c_a, p.fj.c_a
    tau = (p.fi.a @ p.binv @ p.fj.a)[i, i] - mu[i] ** 2 * ci * cj / (ci + cj)
    return 60 * tau**2


# --------------------------------------------------------------------------------------------
# Direct quadrature
# --------------------------------------------------------------------------------------------


def gh_nodes(p_nodes, dims):
    """Tensor Gauss–Hermite nodes (N, dims) and weights (N,) for the weight exp(−|t|²)."""
    x, wt = hermgauss(p_nodes)
    grids = np.meshgrid(*([x] * dims), indexing="ij")
    wgrids = np.meshgrid(*([wt] * dims), indexing="ij")
    return np.stack([g.ravel() for g in grids], -1), np.prod([g.ravel() for g in wgrids], 0)


def gh_integral(b, v, kappa0, f, p_nodes):
    """∫ f(r) exp(−r^T B r + 2 r·v − κ0) dr over R^{3D} by Gauss–Hermite (f(r): r (N, D, 3))."""
    d = b.shape[0]
    rbar = np.linalg.solve(b, v)
    l = np.linalg.cholesky(b)
    t, wt = gh_nodes(p_nodes, 3 * d)
    t = t.reshape(-1, 3, d).transpose(0, 2, 1)  # (N, D, 3)
    r = rbar + np.einsum("ij,njc->nic", np.linalg.inv(l).T, t)
    const = math.exp(-kappa0 + np.sum(v * rbar)) / np.linalg.det(b) ** 1.5
    return const * np.sum(wt * f(r))


class Hyperplane:
    """∫ g(|r_w|) P(r) e^{…} dr in coordinates z = T r = (y = r_w, ξ): for fixed y the ξ-integral
    by Gauss–Hermite about its Gaussian (exact for P), then y in spherical coordinates."""

    def __init__(self, p, w, p_nodes, prefactor=None):
        d = len(w)
        self.p = p
        self.prefactor = prefactor or (p.prefactor if p.gvr else None)
        piv = int(np.argmax(np.abs(w)))
        rows = [w] + [np.eye(d)[k] for k in range(d) if k != piv]
        t = np.array(rows)
        self.tinv = np.linalg.inv(t)
        bt = self.tinv.T @ p.b @ self.tinv
        vt = self.tinv.T @ p.v
        self.byy, self.bxy, bxx = bt[0, 0], bt[1:, 0], bt[1:, 1:]
        self.vy, self.vx = vt[0], vt[1:]
        self.bxx_inv = np.linalg.inv(bxx)
        lower = np.linalg.cholesky(bxx)
        nodes, self.wt = gh_nodes(p_nodes, 3 * (d - 1))
        self.eta = np.einsum("ij,njc->nic", np.linalg.inv(lower).T,
                             nodes.reshape(-1, 3, d - 1).transpose(0, 2, 1))  # (Nt, D−1, 3)
        self.const = math.exp(-p.kappa0) / abs(np.linalg.det(t)) ** 3 / np.linalg.det(bxx) ** 1.5

    def density(self, y):
        """∫ dξ P e^{…} at the points y (n, 3): the integrand of the y-integral."""
        lin = self.bxy[None, :, None] * y[:, None, :] - self.vx[None]  # (n, D−1, 3)
        xi0 = -np.einsum("ij,njc->nic", self.bxx_inv, lin)
        rest = self.byy * np.sum(y * y, -1) - 2 * y @ self.vy - np.einsum("nic,ij,njc->n", lin, self.bxx_inv, lin)
        if self.prefactor is None:
            inner = np.full(len(y), np.sum(self.wt))
        else:
            xi = xi0[:, None] + self.eta[None]  # (n, Nt, D−1, 3)
            z = np.concatenate([np.broadcast_to(y[:, None, None, :], xi.shape[:2] + (1, 3)), xi], 2)
            r = np.einsum("ij,ntjc->ntic", self.tinv, z)
            inner = self.prefactor(r) @ self.wt
        return self.const * np.exp(-rest) * inner

    def shell(self, n_rad, n_theta, n_phi, rmax):
        """Nodes ρ_k and weights W_k with ∫ d³y g(|y|) density(y) ≈ Σ_k W_k g(ρ_k): composite
        Gauss–Legendre in |y| (8 panels), directions by Gauss–Legendre in cos θ × trapezoid in φ."""
        ct, wct = leggauss(n_theta)
        ph = 2 * math.pi * np.arange(n_phi) / n_phi
        st = np.sqrt(1 - ct**2)
        dirs = np.stack([np.outer(st, np.cos(ph)), np.outer(st, np.sin(ph)), np.outer(ct, np.ones(n_phi))], -1).reshape(-1, 3)
        wdir = np.repeat(wct, n_phi) * (2 * math.pi / n_phi)
        x, wx = leggauss(n_rad)
        edges = np.linspace(0.0, rmax, 9)
        rho = np.concatenate([0.5 * (hi - lo) * (x + 1) + lo for lo, hi in zip(edges[:-1], edges[1:])])
        wrho = np.concatenate([0.5 * (hi - lo) * wx for lo, hi in zip(edges[:-1], edges[1:])])
        return rho, np.array([wk * rk**2 * (self.density(rk * dirs) @ wdir) for rk, wk in zip(rho, wrho)])


# --------------------------------------------------------------------------------------------
# The checks
# --------------------------------------------------------------------------------------------

ROWS = []


def row(quantity, family, n, closed, numerical, quad_err=None):
    closed, numerical = complex(closed), complex(numerical)
    rel = abs(numerical - closed) / abs(closed)
    ROWS.append((quantity, family, n, closed.real, numerical.real, rel, quad_err, abs(numerical.imag)))


def richardson(values, ratio=2.0):
    """Extrapolate values at h, h/ratio, h/ratio², … to h → 0 (error a power series in h)."""
    t = list(values)
    for level in range(1, len(t)):
        t = [(ratio**level * t[k + 1] - t[k]) / (ratio**level - 1) for k in range(len(t) - 1)]
    return t[-1]


def singular_rows(p, family, w):
    """δ, 1/r, r, 1/r² and the damped overlap for one pair: closed forms against quadrature."""
    n = len(w)
    q, _ = profile(p, w)
    gh = p.degree // 2 + 1  # Gauss–Hermite nodes per coordinate, exact for P
    polynomial = p.gvr or family == "plain"
    spread = math.sqrt(q) * 12 + (np.linalg.norm(w @ p.rbar) if not p.gvr else 0.0)
    closed = closed_ratios(p, w, 1.0 / q)

    hyp = Hyperplane(p, w, gh)
    # the directions' rule is exact for a polynomial prefactor: refined only for FECG
    nt, nph = (8, 16) if polynomial else (16, 32)
    coarse = hyp.shell(12, nt, nph, spread)
    fine = hyp.shell(24, nt if polynomial else 2 * nt, nph if polynomial else 2 * nph, spread)
    (s_num, s_fine) = (np.sum(wk) for _, wk in (coarse, fine))
    if not p.gvr:
        row("S", family, n, overlap_closed(p), s_num, abs(s_fine - s_num) / abs(s_num))
    # the δ-function: the integrand of the y-integral at y = 0
    row("delta", family, n, closed["delta"], hyp.density(np.zeros((1, 3)))[0] / s_num)
    binary = binary_ratios(p, w) if p.gvr else {}
    for name, g in (("1/r", lambda r: 1 / r), ("r", lambda r: r), ("1/r2", lambda r: 1 / r**2)):
        c_val, f_val = (np.sum(wk * g(rk)) / np.sum(wk) for rk, wk in (coarse, fine))
        row(name, family, n, closed[name], c_val, abs(f_val - c_val) / abs(c_val))
        if p.gvr:
            row(name + " [binary]", family, n, binary[name], c_val, abs(f_val - c_val) / abs(c_val))
    # the damped overlap and the δ-limit by Gauss–Hermite over all coordinates (exact)
    def damped(alpha):
        bb = p.b + alpha * np.outer(w, w)
        return gh_integral(bb, p.v, p.kappa0, p.prefactor, gh)

    s_gh = damped(0.0)
    row("damped a=1/q", family, n, closed["damped"], damped(1.0 / q) / s_gh)
    alphas = [64.0 / q * 2**k for k in range(9)]
    limit = richardson([(a / math.pi) ** 1.5 * damped(a) / s_gh for a in alphas])
    row("delta (lim)", family, n, closed["delta"], limit)


def damped_route_rows(p, family, w):
    """Eq. (18): 1/r, r, 1/r² from the damped overlap D(α) and R(α) = −∂D/∂α alone, at
    Gauss–Legendre nodes in τ or σ (D, R by Gauss–Hermite), against the closed forms."""
    n = len(w)
    q = w @ p.binv @ w
    gh = p.degree // 2 + 2

    def d_of(alpha):
        return gh_integral(p.b + alpha * np.outer(w, w), p.v, p.kappa0, p.prefactor, gh)

    def r_of(alpha):
        y2 = lambda r: np.sum(np.einsum("k,nkc->nc", w, r) ** 2, -1) * p.prefactor(r)
        return gh_integral(p.b + alpha * np.outer(w, w), p.v, p.kappa0, y2, gh)

    def half_rule(count):
        x, wx = leggauss(2 * count)
        return x[x > 0], wx[x > 0]

    m_deg = p.degree // 2
    n_inv, n_r = (m_deg // 2 + 1, (m_deg + 1) // 2 + 1) if p.gvr else (24, 24)
    s0 = d_of(0.0)
    closed = closed_ratios(p, w, 1.0 / q)
    tau, wt = half_rule(n_inv)
    inv_r = 2 / math.sqrt(math.pi * q) * sum(
        wk * (1 - t * t) ** -1.5 * d_of(t * t / (q * (1 - t * t))) for t, wk in zip(tau, wt)) / s0
    inv_r2 = 2 / q * sum(wk * t**-3 * d_of((1 - t * t) / (q * t * t)) for t, wk in zip(tau, wt)) / s0
    tau, wt = half_rule(n_r)
    r = 2 / math.sqrt(math.pi * q) * sum(
        wk * (1 - t * t) ** -1.5 * r_of(t * t / (q * (1 - t * t))) for t, wk in zip(tau, wt)) / s0
    for name, val in (("1/r", inv_r), ("r", r), ("1/r2", inv_r2)):
        row(name + " [damped]", family, n, closed[name], val)


def p4_rows(p, family, masses, i):
    """⟨Δ_g φ_I|Δ_g φ_J⟩/S for g = e_i and g = e_i − μ_i 1 by Gauss–Hermite."""
    n = len(masses)
    mu = masses / masses.sum()

    def laplacian_ratio(f, g, r):
        """Δ_g φ/φ = Σ_c (q1² − 2 q2), q(t) = q0 + q1 t + q2 t² the exponent along g ⊗ e_c."""
        def expo(x):
            d = x - f.s
            return np.einsum("...ic,ij,...jc->...", d, f.a, d)
        q0, total = expo(r), 0.0
        for c in range(3):
            step = np.zeros((n, 3))
            step[:, c] = g
            qp, qm = expo(r + step), expo(r - step)
            q1, q2 = (qp - qm) / 2, (qp + qm - 2 * q0) / 2
            total = total + q1**2 - 2 * q2
        return total

    s = gh_integral(p.b, p.v, p.kappa0, lambda r: np.ones(len(r)), 3)
    for label, g in (("p4 lab", np.eye(n)[i]), ("p4 TI", np.eye(n)[i] - mu[i])):
        num = gh_integral(p.b, p.v, p.kappa0,
                          lambda r: laplacian_ratio(p.fi, g, r) * laplacian_ratio(p.fj, g, r), 3) / s
        row(label, family, n, p4_closed(p, g), num)
        if label == "p4 TI" and family == "plain":
            row("p4 TI (c_A form)", family, n, p4_ti_closed(p, i, mu), num)


def gradient_rows(p, family, w, lam_matrix):
    """<∇φ_I|Λ/r_w|∇φ_J>/S by the hyperplane quadrature; for plain ECGs also the identity (30)
    at α = 1/q against Gauss–Hermite."""
    n = len(w)

    def grad_product(r):
        """∇φ_I·Λ∇φ_J/(φ_I φ_J) = 4 Σ_c (A_I(r−s_I))_c^T Λ (A_J(r−s_J))_c."""
        gi = np.einsum("ij,...jc->...ic", p.fi.a, r - p.fi.s)
        gj = np.einsum("ij,...jc->...ic", p.fj.a, r - p.fj.s)
        return 4 * np.einsum("...ic,ij,...jc->...", gi, lam_matrix, gj)

    hyp = Hyperplane(p, w, 2, grad_product)
    plain_hyp = Hyperplane(p, w, 1)
    polynomial = family == "plain"
    nt, nph = (8, 16) if polynomial else (16, 32)
    q = w @ p.binv @ w
    spread = math.sqrt(q) * 12 + np.linalg.norm(w @ p.rbar)
    vals = []
    for k in (1, 2):
        ka = 1 if polynomial else k
        rho, wk = hyp.shell(12 * k, nt * ka, nph * ka, spread)
        _, w0 = plain_hyp.shell(12 * k, nt * ka, nph * ka, spread)
        vals.append(np.sum(wk / rho) / np.sum(w0))
    row("grad.(1/r).grad", family, n, grad_inverse_closed(p, w, lam_matrix), vals[0],
        abs(vals[1] - vals[0]) / abs(vals[0]))
    if polynomial:
        alpha = 1.0 / q
        num = gh_integral(p.b + alpha * np.outer(w, w), p.v, p.kappa0, grad_product, 2)
        row("grad.g.grad (30)", family, n, grad_damped_identity(p, w, lam_matrix, alpha), num)


def confluent_rows():
    """Eq. (16) against its ₁F₁ form S q^{k/2} Γ((k+3)/2)/Γ(3/2) ₁F₁(−k/2; 3/2; −λ) (scipy's hyp1f1),
    and the small-λ series (four terms) at λ = 10⁻³; q = 1, S = 1."""
    for lam in (1.3, 1e-3):
        sl = math.sqrt(lam)
        closed = {"1/r": math.erf(sl) / sl, "r": math.exp(-lam) / math.sqrt(math.pi) + (sl + 0.5 / sl) * math.erf(sl),
                  "1/r2": 2 * special.dawsn(sl) / sl}
        for name, k in (("1/r", -1), ("r", 1), ("1/r2", -2)):
            hyper = special.gamma((k + 3) / 2) / special.gamma(1.5) * special.hyp1f1(-k / 2, 1.5, -lam)
            row(f"{name} 1F1 l={lam:g}", "FECG", 0, closed[name], hyper)
    lam = 1e-3
    series = {"r": 2 / math.sqrt(math.pi) * (1 + lam / 3 - lam**2 / 30 + lam**3 / 210),
              "1/r2": 2 * (1 - 2 * lam / 3 + 4 * lam**2 / 15 - 8 * lam**3 / 105)}
    sl = math.sqrt(lam)
    exact = {"r": math.exp(-lam) / math.sqrt(math.pi) + (sl + 0.5 / sl) * math.erf(sl), "1/r2": 2 * special.dawsn(sl) / sl}
    for name in series:
        row(f"{name} series l=1e-3", "FECG", 0, exact[name], series[name])


def pair_inverse_row(p, w1, w2):
    """Eq. (19) against the marginal of (y, y') integrated in (|y|, |y'|, cos∠)."""
    n = len(w1)
    sig = 0.5 * np.array([[w1 @ p.binv @ w1, w1 @ p.binv @ w2], [w1 @ p.binv @ w2, w2 @ p.binv @ w2]])
    prec = np.linalg.inv(sig)
    ra, wra = leggauss(120)
    rmax = 12 * math.sqrt(max(sig[0, 0], sig[1, 1]))
    ra, wra = 0.5 * rmax * (ra + 1), 0.5 * rmax * wra
    c, wc = leggauss(80)
    r1, r2, cc = np.meshgrid(ra, ra, c, indexing="ij")
    wt = np.einsum("i,j,k->ijk", wra, wra, wc)
    expo = 0.5 * (prec[0, 0] * r1**2 + 2 * prec[0, 1] * r1 * r2 * cc + prec[1, 1] * r2**2)
    # ∫d³y d³y' = 8π² ∫ r1² r2² dr1 dr2 dcos; the integrand 1/(r1 r2) × density
    dens = np.exp(-expo) / ((2 * math.pi) ** 3 * np.linalg.det(sig) ** 1.5)
    num = 8 * math.pi**2 * np.sum(wt * r1 * r2 * dens)
    row("1/(r r')", "plain", n, pair_inverse_closed(p, w1, w2), num)


def main():
    start = time.process_time()
    mp = 1836.15267343
    systems = {2: np.array([1.0, mp]), 3: np.array([mp, mp, 1.0])}
    for n, masses in systems.items():
        w = np.zeros(n)
        w[0], w[-1] = 1.0, -1.0  # r_w = r_1 − r_n, a nucleus–electron distance
        w2 = np.eye(n)[0] if n == 2 else np.eye(n)[1] - np.eye(n)[2]  # |r_1|; r_2 − r_3
        ai, aj = exponent(masses, 0.7), exponent(masses, 1.3)
        plain = Pair(Function(ai, 0.7), Function(aj, 1.3))
        lam_matrix = np.diag(0.5 / masses) - 0.5 / masses.sum()  # Λ = M − 1 1ᵀ/(2 m_tot)
        singular_rows(plain, "plain", w)
        gradient_rows(plain, "plain", w, lam_matrix)
        pair_inverse_row(plain, w, w2)
        p4_rows(plain, "plain", masses, n - 1)
        si, sj = RNG.normal(size=(n, 3)) * 0.6, RNG.normal(size=(n, 3)) * 0.6
        fecg = Pair(Function(ai, 0.7, s=si), Function(aj, 1.3, s=sj))
        singular_rows(fecg, "FECG", w)
        damped_route_rows(fecg, "FECG", w)
        gradient_rows(fecg, "FECG", w, lam_matrix)
        p4_rows(fecg, "FECG", masses, n - 1)
        ki, kj, nn = ((2, 1, 2) if n == 2 else (1, 0, 1))
        ui, uj = RNG.normal(size=n), RNG.normal(size=n)
        gvr = Pair(Function(ai, 0.7, u=ui, k=ki, n_ang=nn), Function(aj, 1.3, u=uj, k=kj, n_ang=nn))
        singular_rows(gvr, f"GVR K={ki},{kj} N={nn}", w)
        damped_route_rows(gvr, f"GVR K={ki},{kj} N={nn}", w)

    confluent_rows()
    print(f"{'quantity':<17} {'family':<16} {'n':>2} {'closed form':>23} {'numerical':>23} "
          f"{'rel. diff.':>10} {'quad. est.':>10}")
    for q, fam, n, c, v, rel, est, imag in ROWS:
        est_s = f"{est:10.1e}" if est is not None else f"{'':>10}"
        print(f"{q:<17} {fam:<16} {n:>2} {c:23.15e} {v:23.15e} {rel:10.1e} {est_s}")
    worst = max(r[5] for r in ROWS)
    imag = max(r[7] / abs(r[4]) for r in ROWS)
    print(f"\nlargest relative difference {worst:.1e}; largest |imaginary part|/value {imag:.1e}; "
          f"CPU {time.process_time() - start:.1f} s")


if __name__ == "__main__":
    main()
