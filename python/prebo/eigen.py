"""The generalised eigenproblem H c = E S c and its O(N^2) update for one or a few added functions.

Solve: functions are scaled to unit self-overlap, then canonical orthogonalisation
(Löwdin): S = V s V^T, keep s_k > threshold * max(s), X = V_k s_k^{-1/2}, diagonalise
X^T H X. No explicit inverse; near-linear dependence costs the dropped directions only.

Update (Suzuki & Varga, Lect. Notes Phys. m54, sec. 4.2, the secular equation):
with S-orthonormal eigenvectors C and eigenvalues E_k of the current basis and a new
function n with rows h, s and diagonal h_nn, s_nn, let d = C^T s, b = C^T h. The part
of n orthogonal to the basis has norm^2 ν = s_nn - d·d, couplings γ_k = (b_k - E_k d_k)/√ν
and energy h' = (h_nn - 2 b·d + Σ E_k d_k^2)/ν. The new lowest eigenvalue is the root
below E_0 of f(x) = h' - x - Σ γ_k^2 / (E_k - x), strictly decreasing there; root r of the grown
basis is its root in (E_{r-1}, E_r), the roots interlacing (Hylleraas–Undheim–MacDonald), which is
how the objective of several levels (optimise/objective.py) evaluates each (`roots_with_added`,
`roots_with_block`, `root_without_each`).

Gradient (Hellmann–Feynman for the augmented problem): at the root e the eigenvector is
c = (C a, 1) with a_k = -(b_k - e d_k)/(E_k - e); when only the new function's parameters move,
de = [2 (C a)·(dh - e ds) + dh_nn - e ds_nn] / (|a|^2 + 2 a·d + s_nn).

Block update (a few functions at once, `roots_with_block`): with rows h, s (k x N) of k new
functions and their k x k blocks H_ff, S_ff, the Schur complement of the eigenbasis in H - x S is
M(x) = H_ff - x S_ff - G diag(1/(E - x)) G^T, G = (h - x s) C. Below E_0 the block E - x is
positive, so by Sylvester's law of inertia the number of eigenvalues below x is the number of
negative eigenvalues of M(x): the lowest root is the zero of λ(x), the lowest eigenvalue of M(x),
which falls strictly (λ' = v^T M' v = -c^T S c for its eigenvector v), found by Newton's method
kept inside a bracket and finished by bisection to the last bit. Its eigenvector is c = (C a, β),
β the null vector of M, a = -G^T β / (E - x); moving the parameters of function m alone,
de = [2 β_m (dh_m - e ds_m)·(C a) + 2 β_m Σ_{o≠m} β_o (dH_mo - e dS_mo) + β_m^2 (dH_mm - e dS_mm)]
/ c^T S c.

Refinement: LAPACK's eigenvalues of an ill-conditioned basis depend on the BLAS kernel (1e-8
relative at an overlap condition of 5e12), so `solve` refines the lowest root(s) in the Rust core
(`prebo_core::eigenpair`): Rayleigh quotient and residual in double-double, corrections from the
LAPACK eigenbasis (Dongarra, Moler & Wilkinson, SIAM J. Numer. Anal. 20, 23 (1983)). Where that
eigenbasis is too poor for the corrections to converge (overlap condition towards 1e15–1e16), the
lowest root is found by inverse iteration in double-double instead: H − σS factorised below the
lowest eigenvalue (Sylvester's law of inertia), x ← (H − σS)⁻¹ S x. It solves the whole stored
pencil, so it stands in only where every direction of S is kept. The result is the eigenvalue of
the stored matrices to about an ulp, the same on every machine; a root that does not converge is
refused (LinearDependenceError), never returned, and so is an overlap that is not positive
definite in double-double (NotPositiveDefiniteError).

Threads: below SERIAL_BELOW functions LAPACK and BLAS run on one thread (`lapack_threads`, in
`solve` and around a whole optimisation). prebo's own parallelism is the Rust core's (rayon);
OpenBLAS's threads spin between calls and compete with it and with any other job: on the 2-core
machine refinement steps ran 1.4–1.5× faster (He, 400 functions) with one LAPACK thread, though
a lone eigh of 500–3000 functions gains 1.1–1.8× from two (benchmarks/record/schedules.md, "LAPACK
threads"). The refined energies do not depend on the thread count.

Uncertainty: to first order an element error changes the energy by δE = cᵀ(δH − E δS)c
(cᵀSc = 1). With independent relative errors ε of the elements of S and of each term of H
(symmetric, i ≤ j), its standard deviation is σ = ε (2 Σ_ij w_ij − Σ_i w_ii)^½,
w_ij = c_i² c_j² (Σ_terms t_ij² + E² S_ij²); `energy_uncertainty` uses ε = 4 u
(docs/conventions.md: the formula against a Monte-Carlo experiment).
"""
from __future__ import annotations

import contextlib
import os
from dataclasses import dataclass

import numpy as np
import scipy.linalg
from threadpoolctl import ThreadpoolController

from . import _core
from .errors import LinearDependenceError, NonFiniteError, NotPositiveDefiniteError
from .parallel import world

#: relative error assumed for every stored matrix element: 4 unit roundoffs (a few ulp)
ELEMENT_ERROR = 4 * 2.0**-53
#: the default relative overlap eigenvalue below which `solve` drops directions: ELEMENT_ERROR, the
#: relative error of the elements themselves, so every direction the elements resolve is kept, as
#: ecgpack's solver keeps them (its He-490 file: 2 of 490 directions lie below 1e-13 and carry
#: 1.7e-10 Eh, tests/test_ecgpack.py), and rounding is not: an exact duplicate's overlap eigenvalue
#: comes out at 0.5-2 unit roundoffs, kept or not by the BLAS kernel at 2^-53 (tests/test_eigen.py).
#: The lowest root is refined in extended precision (`refine`) and the energy's uncertainty says
#: what the elements' rounding leaves (`uncertainty`); the optimiser keeps a change only if it gains
#: more than σ and 100 times what it adds to σ (optimise/expansion.py). The former default, 1e-13,
#: stopped He's growth at 598 functions (overlap condition 2.3e13, where a new function costs a
#: dropped direction); H2+'s main job never comes near either (condition ≤ 2.5e8)
THRESHOLD = ELEMENT_ERROR
#: the largest ELEMENT_ERROR × overlap condition at which the first-order uncertainty holds: the
#: spread of perturbed energies over the estimate was 1.09–1.15 at 0.35, 1.4–2.0 at 0.75 and 3000–5600
#: at 1.2 (He with near-duplicate functions, tests/test_eigen.py); beyond it `uncertainty` perturbs.
#: The optimiser's bases stay far below (He with 700 functions: 0.08)
FIRST_ORDER = 0.3
#: the perturbed solves of `uncertainty` beyond FIRST_ORDER (the spread to ~15 %)
DRAWS = 24
#: bases below this many functions are solved with LAPACK on one thread (module docstring)
SERIAL_BELOW = 2000


_POOLS = ThreadpoolController()  # the loaded BLAS libraries, found once (a limit then costs ~10 µs)


def lapack_threads(nb: int):
    """A context in which LAPACK and BLAS use one thread if `nb` < SERIAL_BELOW, their own count
    otherwise (under MPI the rank's share of the node, parallel.py)."""
    if nb < SERIAL_BELOW:
        return _POOLS.limit(limits=1, user_api="blas")
    share = os.environ.get("RAYON_NUM_THREADS", "") if world().size > 1 else ""
    return _POOLS.limit(limits=int(share), user_api="blas") if share.isdigit() else contextlib.nullcontext()


@dataclass
class Eigen:
    """The solution of H c = E S c: `energies` (hartree, ascending) and `vectors` (columns,
    S-orthonormal, in the original basis) of the kept directions, the number `kept` of overlap
    eigenvectors kept and the overlap's condition number."""

    energies: np.ndarray  # ascending
    vectors: np.ndarray  # columns, S-orthonormal, in the original (unscaled) basis
    kept: int  # number of overlap eigenvectors kept
    overlap_condition: float  # max(s)/min(s) of the unit-diagonal overlap


def solve(H: np.ndarray, S: np.ndarray, threshold: float = THRESHOLD, roots: int = 1) -> Eigen:
    """All eigenpairs of H c = E S c by canonical orthogonalisation, the lowest `roots` of them
    refined in extended precision (module docstring).

    H, S: (nb, nb) symmetric Hamiltonian (hartree) and overlap matrices; threshold: overlap
    eigenvalues (of S scaled to unit diagonal) below threshold × the largest are dropped.
    Returns an `Eigen`. NonFiniteError for NaN or infinite elements, NotPositiveDefiniteError for
    an overlap that is not positive definite, LinearDependenceError when fewer than `roots`
    directions are kept or a refined root does not converge."""
    require_finite(H, "Hamiltonian", "H")
    require_finite(S, "overlap", "S")
    diag = np.diag(S).copy()
    if np.any(~(diag > 0)):
        bad = int(np.argmin(diag))
        raise NotPositiveDefiniteError(f"overlap matrix: diagonal element {bad} is {diag[bad]:.3g}, not positive")
    d = 1.0 / np.sqrt(diag)
    Ss = S * np.outer(d, d)
    with lapack_threads(len(S)):
        s, V = np.linalg.eigh(Ss)
    if s[0] < -1e3 * threshold * s[-1] - 1e-10:
        raise NotPositiveDefiniteError(f"overlap matrix is not positive definite (lowest eigenvalue {s[0]:.3g})")
    keep = s > threshold * s[-1]
    if not np.any(keep):
        raise LinearDependenceError("overlap matrix has no eigenvalue above the threshold")
    if roots > keep.sum():
        raise LinearDependenceError(f"{roots} roots asked for, but the basis resolves {int(keep.sum())} directions "
                                    f"of its {len(S)} (overlap condition {s[-1] / max(s[0], 1e-300):.2e})")
    X = V[:, keep] / np.sqrt(s[keep])
    Hs = H * np.outer(d, d)
    with lapack_threads(len(S)):
        E, Y = np.linalg.eigh(X.T @ Hs @ X)
    return refine(H, S, Eigen(E, d[:, None] * (X @ Y), int(keep.sum()), float(s[-1] / max(s[0], 1e-300))), roots)


def require_finite(M: np.ndarray, name: str, symbol: str) -> None:
    """Refuse a matrix with a NaN or infinite element (NonFiniteError naming the first one)."""
    bad = np.argwhere(~np.isfinite(M))
    if len(bad):
        i, j = (int(k) for k in bad[0])
        raise NonFiniteError(f"the {name} matrix is not finite: {symbol}[{i}, {j}] = {M[i, j]} ({len(bad)} of {M.size} "
                         "elements): an integral overflowed or lost every digit")


def refine(H: np.ndarray, S: np.ndarray, eig: Eigen, roots: int = 1) -> Eigen:
    """`eig` with its lowest `roots` eigenpairs refined in double-double (`prebo_core::eigenpair`):
    each energy (hartree) is the Rayleigh quotient of the stored H, S at its vector, converged to
    an ulp, the same on every machine; where the corrections do not converge and every direction
    is kept, the lowest by inverse iteration (the quotient at a double-double vector, returned
    rounded). Returns a new `Eigen`; LinearDependenceError for a root that does not converge,
    NotPositiveDefiniteError for an overlap without a double-double LDLᵀ factorisation."""
    c = np.ascontiguousarray
    H, S, E0, C0 = c(H, dtype=float), c(S, dtype=float), c(eig.energies, dtype=float), c(eig.vectors, dtype=float)
    energies, vectors, _, converged = _core.refine_eigenpairs(H, S, E0, C0, roots)
    if converged[:1] == [False] and eig.kept == len(S):  # the whole pencil, as no direction was dropped
        energies[0], vectors[:, 0], _, converged[0] = _core.inverse_iteration(H, S, E0, C0)
    if not all(converged):
        raise LinearDependenceError(
            f"eigenvalue {converged.index(False)} does not converge in extended precision: double precision "
            f"cannot resolve this basis (overlap condition {eig.overlap_condition:.2e})")
    E, C = eig.energies.copy(), eig.vectors.copy()
    E[:len(energies)], C[:, :len(energies)] = energies, vectors
    return Eigen(E, C, eig.kept, eig.overlap_condition)


def energy_uncertainty(c: np.ndarray, energy: float, S: np.ndarray, *terms: np.ndarray) -> float:
    """Standard deviation (hartree) of the energy of the S-normalised vector `c` from independent
    relative errors `ELEMENT_ERROR` of the elements of S and of each term of H = Σ terms
    (module docstring). c: (nb,) eigenvector; energy: its eigenvalue (hartree); S: (nb, nb)
    overlap; terms: (nb, nb) matrices summing to H (e.g. T_ti and V)."""
    c2 = c * c
    W = energy**2 * S**2
    for t in terms:
        W += t**2
    return ELEMENT_ERROR * float(np.sqrt(max(2.0 * c2 @ W @ c2 - c2**2 @ np.diag(W), 0.0)))


def first_order(eig: Eigen) -> bool:
    """Whether the first-order `energy_uncertainty` holds for the solution `eig` (FIRST_ORDER)."""
    return ELEMENT_ERROR * eig.overlap_condition <= FIRST_ORDER


def uncertainty(eig: Eigen, S: np.ndarray, *terms: np.ndarray, threshold: float = THRESHOLD, root: int = 0) -> float:
    """The standard deviation (hartree) of energy `root` of `eig` (0: the lowest) from independent
    relative errors ELEMENT_ERROR of the elements of S and of each term of H = Σ terms: first-order
    theory (`energy_uncertainty`) where it holds (`first_order`), else the largest move of that
    energy re-solved (`threshold`) with every element so perturbed, DRAWS times from a fixed seed —
    the experiment that measures the first-order estimate (docs/conventions.md). There the moves
    have heavy tails (a few draws fall by 1 Eh where most move 1e-4) and a drift, so their largest
    is reported, not their standard deviation: the number stays an honest bound where double
    precision runs out. LinearDependenceError where such rounding leaves no lowest root."""
    if first_order(eig):
        return energy_uncertainty(eig.vectors[:, root], float(eig.energies[root]), S, *terms)
    rng = np.random.default_rng(0)
    n = len(S)

    def perturbed(M):
        Z = np.triu(rng.normal(size=(n, n)))
        return M * (1.0 + ELEMENT_ERROR * (Z + np.triu(Z, 1).T))

    energies = []
    for _ in range(DRAWS):
        H = sum(perturbed(t) for t in terms)
        try:
            energies.append(solve(H, perturbed(S), threshold, root + 1).energies[root])
        except (LinearDependenceError, NotPositiveDefiniteError) as exc:
            raise LinearDependenceError(f"double precision cannot resolve this basis (overlap condition "
                                        f"{eig.overlap_condition:.2e}): rounding its elements by a few ulp leaves "
                                        f"no lowest root ({exc})") from None
    return float(np.max(np.abs(np.array(energies) - eig.energies[root])))


def roots_with_added(E, C, h, s, h_nn, s_nn, min_norm: float = 1e-10, roots: tuple = (0,)) -> np.ndarray:
    """Eigenvalues `roots` (0: the lowest) after adding one function (secular equation, in the Rust
    core); +inf if it is linearly dependent on the basis (orthogonal remainder below `min_norm` of
    its norm)."""
    return roots_with_added_many(E, C, np.atleast_2d(h), np.atleast_2d(s), [h_nn], [s_nn], min_norm, roots)[0]


def roots_with_added_gradient(E, C, h, s, h_nn, s_nn, dh, ds, dh_nn, ds_nn, min_norm: float = 1e-10,
                              roots: tuple = (0,)):
    """`roots_with_added` and their gradients (len(roots) x P) with respect to parameters of the
    new function, given the derivatives dh, ds (P x nb) and dh_nn, ds_nn (P) of its rows and
    diagonal (module docstring; the eigenvector (C a, 1) holds at any root e of the augmented
    problem that is not an E_k; d = C^T s and b = C^T h formed once for every root)."""
    e = roots_with_added(E, C, h, s, h_nn, s_nn, min_norm, roots)
    g = np.zeros((len(e), len(dh_nn)))
    d, b = (C.T @ s, C.T @ h) if len(E) else (None, None)
    for i, e_r in enumerate(e):
        if not np.isfinite(e_r):
            continue
        if len(E) == 0:
            g[i] = (dh_nn - e_r * ds_nn) / s_nn
            continue
        a = -(b - e_r * d) / (E - e_r)
        c_old = C @ a
        norm2 = a @ a + 2.0 * a @ d + s_nn
        g[i] = (2.0 * (dh - e_r * ds) @ c_old + dh_nn - e_r * ds_nn) / norm2
    return e, g


def roots_with_block(E, C, h, s, H_ff, S_ff, min_norm: float = 1e-10, near=None, roots: tuple = (0,)) -> list[tuple]:
    """Eigenvalues `roots` after adding k functions at once, each with its eigenvector as (e, a, β,
    c^T S c), a over the eigenvectors C, β over the new functions (module docstring, block update;
    the products s C, h C formed once for every root; `_Block.root`). h, s: (k x nb) rows against
    the basis; H_ff, S_ff: (k x k) among the new functions. By interlacing root r lies at or below
    E_r: (inf, None, None, None) where it does not (the block lowers nothing), where the basis does
    not hold E_r, or where the block is linearly dependent on the basis (the smallest eigenvalue of
    its orthogonal part S_ff - D D^T, D = s C, below `min_norm` of its diagonal). `near`: per root,
    an estimate where Newton's method starts (the energies before the block changed; None: no
    estimate); the root found depends on it only where rounding blurs the sign of M's eigenvalue
    at the root, within a few ulp."""
    block = _Block.of(E, C, h, s, H_ff, S_ff, min_norm)
    near = [None] * len(roots) if near is None else near
    none = (np.inf, None, None, None)
    return [none if block is None or len(E) <= r and not (r == 0 and len(E) == 0) else block.root(r, x)
            for r, x in zip(roots, near)]


def lowest_with_block(E, C, h, s, H_ff, S_ff, min_norm: float = 1e-10, near: float | None = None):
    """The lowest eigenvalue after adding k functions at once, with its eigenvector (`roots_with_block`)."""
    return roots_with_block(E, C, h, s, H_ff, S_ff, min_norm, [near])[0]


def independent(D: np.ndarray, S_ff: np.ndarray, min_norm: float) -> bool:
    """Whether k functions of overlap S_ff and overlaps D = s C with a basis's S-orthonormal
    eigenvectors C are independent of it: the smallest eigenvalue of their orthogonal part
    S_ff − D Dᵀ, scaled to unit diagonal, is at least `min_norm` (and finite)."""
    scale = 1.0 / np.sqrt(np.diag(S_ff))
    orthogonal = (S_ff - D @ D.T) * np.outer(scale, scale)
    return bool(np.all(np.isfinite(orthogonal)) and np.linalg.eigvalsh(orthogonal)[0] >= min_norm)


class _Block:
    """k functions added to a basis of eigenvalues E and S-orthonormal eigenvectors C (module
    docstring, block update): D = s C, B = h C and the blocks H_ff, S_ff among them."""

    def __init__(self, E, D, B, H_ff, S_ff):
        self.E, self.D, self.B, self.H_ff, self.S_ff = E, D, B, H_ff, S_ff

    @classmethod
    def of(cls, E, C, h, s, H_ff, S_ff, min_norm: float):
        """The block of rows h, s; None when it is linearly dependent on the basis (the smallest
        eigenvalue of its orthogonal part S_ff - D D^T below `min_norm` of its diagonal)."""
        D, B = s @ C, h @ C
        if not independent(D, S_ff, min_norm):
            return None
        return cls(E, D, B, H_ff, S_ff)

    def schur(self, x: float):
        """M(x), the Schur complement of the eigenbasis in H - x S, and G = B - x D."""
        G = self.B - x * self.D
        return self.H_ff - x * self.S_ff - (G / (self.E - x)) @ G.T, G

    def eigenvector(self, e: float, beta: np.ndarray) -> tuple:
        """(e, a, β, c^T S c) of the root e with β the null vector of M(e): c = (C a, β), a = -G^T β / (E - e)."""
        a = -(beta @ self.schur(e)[1]) / (self.E - e)
        norm2 = a @ a + 2.0 * a @ (self.D.T @ beta) + beta @ self.S_ff @ beta
        return float(e), a, beta, float(norm2)

    def count(self, x: float) -> int:
        """The number of eigenvalues of the augmented pencil below x: #{E_j < x} + the number of
        negative eigenvalues of M(x) (Sylvester's law of inertia; x moved off a pole E_j)."""
        if np.any(self.E == x):
            x = np.nextafter(x, -np.inf)
        return int(np.searchsorted(self.E, x)) + int((np.linalg.eigvalsh(self.schur(x)[0]) < 0).sum())

    def root(self, root: int, near: float | None):
        """Root `root` and its eigenvector (`roots_with_block`). Between two poles E_{j-1} < x < E_j
        M(x) falls strictly (v^T M' v = -c^T S c), so each of its ordered eigenvalues does and the
        count is j + #{λ_m(x) < 0}: the root lies in the first such interval whose count just below
        E_j exceeds `root` (the count is continuous across a pole), where λ_m, m = root - j, crosses
        zero. Newton's method on λ_m (from `near`, else the bracket's left end below E_0 or its
        middle), kept inside the bracket, finished by bisection to adjacent doubles; its eigenvector
        is M's m-th at the root. A root the search pins to the pole E_{j-1} (a basis eigenvector the
        block does not couple to) is that eigenvalue, with that eigenvector."""
        E, S_ff = self.E, self.S_ff
        if len(E) == 0:  # nothing else in the basis: the k x k problem itself (S_ff positive definite)
            w, V = scipy.linalg.eigh(self.H_ff, S_ff)
            return float(w[0]), np.zeros(0), V[:, 0], float(V[:, 0] @ S_ff @ V[:, 0])
        schur, D = self.schur, self.D
        j = root
        if self.count(np.nextafter(E[j], -np.inf)) <= root:
            return np.inf, None, None, None
        while j > 0 and self.count(np.nextafter(E[j - 1], -np.inf)) > root:
            j -= 1
        m = root - j

        def below(x):  # whether root `root` lies below x (x in the interval)
            return np.linalg.eigvalsh(schur(x)[0])[m] < 0

        def newton(x):  # λ_m of M(x) and the Newton step -λ/λ', λ' = v^T M' v = -c^T S c
            M, G = schur(x)
            w, V = np.linalg.eigh(M)
            v, r = V[:, m], 1.0 / (E - x)
            Gv, Dv = v @ G, v @ D
            return w[m], w[m] / (v @ S_ff @ v - 2.0 * (Dv * r) @ Gv + (Gv * r) @ (Gv * r))

        hi = np.nextafter(E[j], -np.inf)
        if j > 0:  # the pole itself bounds the bracket; it is never evaluated
            lo = E[j - 1]
            start = 0.5 * (lo + hi) if lo < 0.5 * (lo + hi) else hi
        else:
            lo = E[0] - 1.0
            for _ in range(64):  # a lower bound: λ_m(lo) ≥ 0
                if not below(lo):
                    break
                lo -= 2.0 * abs(lo) + 1.0
            else:
                return np.inf, None, None, None
            start = lo
        x = near if near is not None and lo < near < hi else start
        for _ in range(100):  # Newton within the bracket [lo, hi] (λ_m decreasing in x), bisection where it leaves it
            lam, step = newton(x)
            lo, hi = (lo, x) if lam < 0 else (x, hi)
            if abs(step) <= 1e-12 * abs(x):
                break
            x = x + step if lo < x + step < hi else 0.5 * (lo + hi)
            if not lo < x < hi:  # the bracket is down to adjacent doubles (lo may be a pole)
                break
        width = 4e-13 * abs(x)  # a narrow bracket about the converged x, if it holds
        if lo < x - width and not below(x - width):
            lo = x - width
        if x + width < hi and below(x + width):
            hi = x + width
        for _ in range(2100):  # bisection to adjacent doubles
            mid = 0.5 * (lo + hi)
            if mid <= lo or mid >= hi:
                break
            lo, hi = (lo, mid) if below(mid) else (mid, hi)
        if j > 0 and lo == E[j - 1]:  # the root is the pole: eigenvector j - 1, which the block does not couple to
            return float(lo), np.eye(len(E))[j - 1], np.zeros(len(S_ff)), 1.0
        return self.eigenvector(hi, np.linalg.eigh(schur(hi)[0])[1][:, m])


def root_without_each(E: np.ndarray, C: np.ndarray, root: int = 0) -> np.ndarray:
    """Eigenvalue `root` (0: the lowest) of the basis without function i, for every i, from the
    eigen-solution (E, C) of the whole basis: the eigenproblem restricted to c_i = 0 is, in the
    eigenbasis, the diagonal E restricted to the plane orthogonal to r = C[i] (Golub, SIAM Rev.
    15, 318 (1973)), whose eigenvalue `root` is the root of Σ_k r_k² / (E_k − μ) = 0 in
    [E_root, E_root+1), increasing there (interlacing); found by bisection, all i at once
    (O(N_b^2) per step). Without eigenvalue root + 1, the basis without i has no eigenvalue
    `root`: +inf."""
    if len(E) < root + 2:
        return np.full(len(C), np.inf)
    w = C * C
    lo, hi = np.full(len(C), E[root]), np.full(len(C), E[root + 1])
    with np.errstate(divide="ignore", invalid="ignore"):  # mid reaches E_0 only within an ulp of the root
        for _ in range(64):
            mid = 0.5 * (lo + hi)
            below = (w / (E - mid[:, None])).sum(axis=1) < 0
            lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
    return hi


def roots_with_added_many(E, C, H, S, h_nn, s_nn, min_norm: float = 1e-10, roots: tuple = (0,)) -> np.ndarray:
    """`roots_with_added` for k trials at once: rows H, S (k x nb), diagonals h_nn, s_nn (k);
    k x len(roots) (module docstring: the roots interlace)."""
    c = np.ascontiguousarray
    E = c(E, dtype=float)
    C = c(np.asarray(C, dtype=float).reshape(-1, len(E)) if len(E) else np.zeros((0, 0)))
    out = _core.roots_with_added(E, C, c(H, dtype=float), c(S, dtype=float), c(h_nn, dtype=float),
                                 c(s_nn, dtype=float), float(min_norm), [int(r) for r in roots])
    out[~np.isfinite(out)] = np.inf  # NaN elements (a near-singular trial) never win
    return out
