"""How many damped elements eq. (38)'s quadrature in φ takes per product ⟨1/(r_w r_w')⟩, and how
far from a tight reference, for ladders of even Gauss–Legendre rules against the halved panels
(docs/properties-derivations.md §6; `drachmann::even` in the Rust core).

    python benchmarks/quadrature_rules.py [--basis benchmarks/checkpoints/h2-auto] [--seeds 11 12] [--products 200]

A transcription of ECG-GVR's damped Coulomb element (`ecg_gvr::drachmann::damped_inverse`, without the
normalisation, which every rule shares) on random products of the basis: a pair of functions
(the ket under a random one of the four permutations of H2), a pair vector w and a Coulomb pair
w', w the lighter (it damps, as `drachmann::coulomb::all` chooses). Prints, per ladder, the mean number of
damped elements per product, the largest relative distance from panels to 1e-15, and how often
it fell back to the panels; the panels alone last. About 4 minutes for 400 products.
"""
from __future__ import annotations

import argparse
import json
import random
from pathlib import Path

import numpy as np
from numpy.polynomial.legendre import leggauss

PAIRS = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
PERMUTATIONS = [[0, 1, 2, 3], [1, 0, 2, 3], [0, 1, 3, 2], [1, 0, 3, 2]]
SIZES = [4, 5, 6, 7, 8, 9, 10, 12, 13, 14, 16, 19, 20, 24, 28, 32, 42, 48]
LADDERS = {"8, 16, 32": [8, 16, 32], "6, 9, 13, 19, 28, 42 (prebo)": [6, 9, 13, 19, 28, 42],
           "8, 12, 16, 24, 32": [8, 12, 16, 24, 32], "4, 6, 9, 13, 19, 28": [4, 6, 9, 13, 19, 28],
           "8, 10, 14, 20, 28": [8, 10, 14, 20, 28]}
RULES = {n: leggauss(n) for n in range(2, 2 * max(SIZES) + 1)}


def pair_vector(i: int, j: int) -> np.ndarray:
    v = np.zeros(4)
    v[i], v[j] = 1.0, -1.0
    return v


def series(ki: int, kj: int) -> np.ndarray:
    """ĉ_k of Ω (N = 0; ecg_gvr::series::Coefficients)."""
    c, ck = [], 1.0
    for k in range(min(ki, kj) + 1):
        c.append(ck)
        ck *= (ki - k) * (kj - k) / ((k + 1) * (k + 1.5))
    return np.array(c)


def integrand(a_i, a_j, u_i, u_j, k_i, k_j, w, wp):
    """(f, φ_max, 1 − ρ², tolerance): eq. (38)'s integrand in φ, even, on [0, φ_max]."""
    b_inv = np.linalg.inv(a_i + a_j)
    gi, gj, b = b_inv @ u_i, b_inv @ u_j, b_inv @ w
    x, y, z = u_i @ gi / 2, u_j @ gj / 2, u_i @ gj / 2
    q, bi, bj = w @ b, u_i @ b, u_j @ b
    c, gwi, gwj, bw = wp @ b_inv @ wp, gi @ wp, gj @ wp, b @ wp
    m = k_i + k_j
    nodes, weights = RULES[2 * (m // 2 + 1)]
    rule = [(t, wt) for t, wt in zip(nodes, weights) if t > 0]
    coef = series(k_i, k_j)

    def damped(alpha):
        kappa = alpha / (1 + alpha * q)
        xa, ya, za = x - 0.5 * kappa * bi * bi, y - 0.5 * kappa * bj * bj, z - 0.5 * kappa * bi * bj
        ca = c - kappa * bw * bw
        sq = np.sqrt(2 * ca)
        g_i, g_j = (gwi - kappa * bi * bw) / sq, (gwj - kappa * bj * bw) / sq
        total = 0.0
        for t, wt in rule:
            xt, yt, zt = xa - g_i * g_i * t * t, ya - g_j * g_j * t * t, za - g_i * g_j * t * t
            total += wt * sum(coef[k] * (xt / x) ** (k_i - k) * (yt / y) ** (k_j - k) * (zt / np.sqrt(x * y)) ** (2 * k)
                              for k in range(len(coef)))
        return (1 + alpha * q) ** -1.5 * 2 / np.sqrt(np.pi * ca) * total

    chol = np.linalg.cholesky(a_i + a_j)
    aw, ap = np.linalg.solve(chol, w), np.linalg.solve(chol, wp)
    qw, qp = aw @ aw, ap @ ap
    rest2 = min((qw * qp - (aw @ ap) ** 2) / (qw * qp), 1.0)
    rho2 = 1 - rest2
    rho = np.sqrt(rho2)

    def f(phi):
        s = np.sin(phi)
        rest = (rho - s) * (rho + s) / rho2
        tau = s / rho
        return damped(tau * tau / (qw * rest)) / rest ** 1.5 * np.cos(phi) / rho

    return f, np.arcsin(rho), rest2, max(1e-11, 20 * np.finfo(float).eps / rest2)


def rule(f, a, b, n):
    """(∫f, ∫|f|) over [a, b] by the n-point Gauss–Legendre rule."""
    x, wt = RULES[n]
    mid, half = (a + b) / 2, (b - a) / 2
    ys = np.array([f(mid + half * t) for t in x]) * half * wt
    return ys.sum(), np.abs(ys).sum()


def panels(f, a, b, tol):
    """`drachmann::adaptive`: (∫f, evaluations)."""
    count = [0]

    def g(x):
        count[0] += 1
        return f(x)

    whole, size = rule(g, a, b, 16)
    tol = tol * size / (b - a)
    total, stack = 0.0, [(a, b, 8, whole)]
    while stack:
        lo, hi, depth, known = stack.pop()
        fine = known if known is not None else rule(g, lo, hi, 16)[0]
        coarse = rule(g, lo, hi, 8)[0]
        if depth == 0 or abs(fine - coarse) <= tol * (hi - lo):
            total += fine
        else:
            mid = (lo + hi) / 2
            stack += [(mid, hi, depth - 1, None), (lo, mid, depth - 1, None)]
    return total, count[0]


def even(f, phi_max, m):
    """(∫_0^φmax f, ∫|f|) by the 2m-point rule on [−φ_max, φ_max] (m evaluations)."""
    x, wt = RULES[2 * m]
    ys = np.array([wt[i] * f(phi_max * x[i]) for i in range(2 * m) if x[i] > 0]) * phi_max
    return ys.sum(), np.abs(ys).sum()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--basis", type=Path, default=Path("benchmarks/checkpoints/h2-auto"))
    ap.add_argument("--seeds", type=int, nargs="+", default=[11, 12])
    ap.add_argument("--products", type=int, default=200)
    args = ap.parse_args()
    functions = json.loads((args.basis / "basis.json").read_text())["functions"]
    light = lambda k: (2 in PAIRS[k] or 3 in PAIRS[k]) + (PAIRS[k] == (2, 3))
    rows = []
    for seed in args.seeds:
        rng = random.Random(seed)
        for _ in range(args.products):
            i, j = rng.randrange(len(functions)), rng.randrange(len(functions))
            p = np.eye(4)[rng.choice(PERMUTATIONS)]
            wi, wpi = rng.sample(range(6), 2)
            if light(wpi) > light(wi):
                wi, wpi = wpi, wi
            fi, fj = functions[i], functions[j]
            f, phi_max, rest2, tol = integrand(np.array(fi["A"]), p.T @ np.array(fj["A"]) @ p, np.array(fi["u"]),
                                               p.T @ np.array(fj["u"]), fi["K"], fj["K"],
                                               pair_vector(*PAIRS[wi]), pair_vector(*PAIRS[wpi]))
            rows.append({"reference": panels(f, 0, phi_max, 1e-15)[0], "tol": tol,
                         "rules": {m: even(f, phi_max, m) for m in SIZES}, "panels": panels(f, 0, phi_max, tol)})
    print(f"{len(rows)} products of {args.basis / 'basis.json'} (seeds {args.seeds})")
    for name, ladder in LADDERS.items():
        costs, errors, fallbacks = [], [], 0
        for r in rows:
            cost, value = ladder[0], None
            for a, b in zip(ladder, ladder[1:]):
                cost += b
                (coarse, _), (fine, size) = r["rules"][a], r["rules"][b]
                if abs(fine - coarse) <= r["tol"] * size:
                    value = fine
                    break
            if value is None:
                value, n = r["panels"]
                cost, fallbacks = cost + n, fallbacks + 1
            costs.append(cost)
            errors.append(abs(value - r["reference"]) / abs(r["reference"]))
        print(f"  rules m = {name:30s} {np.mean(costs):6.1f} elements per product, largest error {max(errors):.1e}, "
              f"{fallbacks} to panels")
    errors = [abs(r["panels"][0] - r["reference"]) / abs(r["reference"]) for r in rows]
    print(f"  panels alone {'':27s} {np.mean([r['panels'][1] for r in rows]):6.1f} elements per product, "
          f"largest error {max(errors):.1e}")


if __name__ == "__main__":
    main()
