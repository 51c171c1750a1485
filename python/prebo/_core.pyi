"""Typed interface of `prebo._core`, the PyO3 binding of the Rust core (crates/prebo-py).

Conventions (docs/conventions.md): a basis function in n coordinates has the exponent
exp(-r^T (A ⊗ I_3) r) (no factor 1/2); every function is used normalised; energies in hartree
(E_h), lengths in bohr (a_0), masses in electron masses. Arrays are float64 (K: uint32); any
array-like numpy can convert is accepted, in any memory layout. Errors: `prebo.errors`
`NotPositiveDefiniteError` (an exponent matrix without a Cholesky factor, an overlap without a
double-double LDLᵀ factorisation in `inverse_iteration`), `ShapeError` (arrays that do not fit
together) and `UnsupportedError` (more than `MAX_DIM` coordinates, an unknown family or operator,
K out of range).

Parameter tuples (`params`) per family, for k functions in n coordinates:
- "pecg" (plain ECGs): (A (k, n, n), c_A (k,))
- "ecg-gvr" (ECG with a global vector, M = N): (A (k, n, n), u (k, n), K (k,) uint32, c_A (k,))
- "fecg" (floating ECGs): (A (k, n, n), s (k, n, 3) centres in a_0, c_A (k,))
"""
from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

Params = tuple[ArrayLike, ...]
Matrices = dict[str, NDArray[np.float64]]

MAX_DIM: int
"""Largest number of coordinates compiled (laboratory frame: particles)."""

GIT_COMMIT: str
"""The git commit the module was built from ("" outside a checkout; crates/prebo-py/build.rs)."""

OPERATORS: dict[str, list[str]]
"""Per basis family ("pecg", "ecg-gvr", "fecg"), the names of the registered extra operators of
`Engine.operator` it evaluates (the others are refused: not derived for that family)."""


class Engine:
    """One basis family in one coordinate representation: symmetrised matrices, rows, row
    gradients and extra operators, all with the GIL released.

    A symmetrised element is Σ_P c_P <φ_I|O|P φ_J> over the symmetry operations
    P: φ(r) -> φ(T_P r) with Young-operator coefficients c_P.
    """

    def __init__(self, family: str, lam: ArrayLike, pair_w: ArrayLike, pair_q: ArrayLike,
                 sym_t: ArrayLike, sym_c: ArrayLike, cm_mass: float | None = None, N: int = 0) -> None:
        """family: "pecg", "ecg-gvr" or "fecg"; lam (n, n): kinetic matrix Λ of -∇^T Λ ∇
        (E_h a_0², laboratory frame diag(1/(2 m_i))); pair_w (p, n): Coulomb vectors w of
        Σ q/|w^T r|; pair_q (p,): charge products q; sym_t (o, n, n): transformations T_P;
        sym_c (o,): coefficients c_P; cm_mass: total mass (m_e) for the elimination of the CM
        kinetic energy (T_ti), None without a CM coordinate; N: total angular momentum quantum
        number (ECG-GVR only, M = N)."""

    @property
    def family(self) -> str:
        """The basis family: "pecg", "ecg-gvr" or "fecg"."""

    @property
    def n(self) -> int:
        """Number of coordinates."""

    @property
    def oriented(self) -> bool:
        """Whether `rows(..., position=i)` evaluates every element in the orientation of a full
        build, so that patching rows into the matrices reproduces `matrices` bit for bit."""

    def matrices(self, params: Params) -> Matrices:
        """Symmetrised (nb, nb) matrices of a basis: "S" overlap, "T" kinetic energy (E_h),
        "T_ti" kinetic energy with the CM part eliminated (E_h), "V" Coulomb energy (E_h)."""

    def rows(self, trials: Params, basis: Params, position: int | None = None) -> tuple[Matrices, NDArray[np.float64]]:
        """Rows (k, nb) of k trial functions against a basis (keys as `matrices`) and the
        trials' symmetrised diagonal elements (k, 4) as [S, T, T_ti, V]. `position`: the index
        a trial would take in the basis (None: appended), which orients the elements when
        `oriented`."""

    def row_gradient(self, f: Params, dA: ArrayLike, dv: ArrayLike | None, basis: Params) -> tuple[Matrices, NDArray[np.float64]]:
        """The row of one function `f` (the bra) against a basis and its diagonal, with the
        derivatives along P directions: dA (P, n, n) of A and dv of the vector part — (P, n) of
        u (ecg-gvr), (P, n, 3) of s (fecg), None for pecg. Returns (1 + P, nb) matrices (row 0
        the values, row 1 + p the derivative along direction p) and the (1 + P, 4) diagonal.
        Laboratory frame."""

    def operator(self, name: str, params: Params, w: ArrayLike) -> NDArray[np.float64]:
        """Symmetrised (p, nb, nb) matrices of the registered operator `name` (see `OPERATORS`)
        between normalised functions, one per instance of its vectors w (p, arity, n; (p, n) for
        arity 1), given in this representation like the Coulomb vectors ("r2": r_w² =
        |Σ_k w_k r_k|² in a_0², with w = e_i − e_j in the laboratory frame the squared distance
        r_ij²; "araki_sucher": the Araki–Sucher distribution P(1/r_w³) in a_0⁻³). Symmetrised
        like S, which is exact for operators that commute with the symmetry operations."""

    def between(self, name: str, bra: Params, ket: Engine, ket_params: Params, v: ArrayLike) -> NDArray[np.float64]:
        """(p, nb_bra, nb_ket) matrices of the registered two-basis operator `name` between the
        normalised functions of the basis `bra` (this engine's family and N) and those of
        `ket_params` (`ket`'s family and N, symmetrised by `ket`'s operations), one per instance
        of its vectors v (p, arity, n), given in this representation: "overlap" (no vectors;
        two bases of one N), and the electric dipole's reduced elements <L+1‖O‖L> between a bra
        of N = L (plain or ECG-GVR) and an ECG-GVR ket of N = L + 1: "dipole", O = Σ_k w_k r_k
        (w like the Coulomb vectors), "velocity", O = Σ_k w'_k ∇_k (w' momentum-like), every L,
        and "acceleration", O = Σ_k w'_k ∇_k V (V the representation's Coulomb potential), L = 0;
        and the quadrupole's <2‖Q‖0> between N = 0 and N = 2 ("quadrupole", v the n columns of
        its matrix);
        crates/prebo-core/src/families/ecg_gvr/transition.rs."""

    def between_gradient(self, name: str, bra: Params, ket: Engine, ket_params: Params, dA: ArrayLike,
                         du: ArrayLike, v: ArrayLike) -> NDArray[np.float64]:
        """`between` for a ket basis of one ECG-GVR function (`ket_params`) with the derivatives
        along P directions of its parameters, dA (P, n, n) of A and du (P, n) of u, as
        `row_gradient`'s: (p, 1 + P, nb_bra), row 0 of each instance `between`'s column (its
        bits), row 1 + k the derivative along direction k. "dipole" and "velocity" between a plain
        or ECG-GVR bra of N = L and the ket of N = L + 1; exact (dual numbers,
        crates/prebo-core/src/path.rs `between_gradient`). Laboratory frame."""

    def density(self, params: Params, w: ArrayLike, C: ArrayLike, r: ArrayLike) -> NDArray[np.float64]:
        """Spherically averaged densities <Ψ|ρ̄_w(r)|Ψ> (bohr⁻³) of the states Ψ = Σ_I c_I Yφ_I
        (C: (nb, ns), the columns) at the radii r (bohr), one per vector w (p, n) given in this
        representation like the Coulomb vectors: (p, ns, len(r)). For w = e_i − e_j the pair
        correlation function of r_ij; for w = e_i − μ (mass fractions) the density of particle i
        about the centre of mass."""


def roots_with_added(e: ArrayLike, c: ArrayLike, h: ArrayLike, s: ArrayLike, h_nn: ArrayLike,
                     s_nn: ArrayLike, min_norm: float, roots: list[int]) -> NDArray[np.float64]:
    """Eigenvalues `roots` (E_h; 0: the lowest) after adding each of k trials to a basis (secular
    equation, C^T s and C^T h formed once per trial): e (kept,) eigenvalues, c (nb, kept)
    S-orthonormal eigenvectors, rows h, s (k, nb) of H and S, diagonals h_nn, s_nn (k,); a trial
    whose part orthogonal to the basis has norm² below `min_norm` · s_nn gets +inf, a root above
    `kept` NaN. Returns (k, len(roots))."""


def refine_eigenpairs(h: ArrayLike, s: ArrayLike, e: ArrayLike, c: ArrayLike, roots: int
                      ) -> tuple[NDArray[np.float64], NDArray[np.float64], list[int], list[bool]]:
    """The lowest `roots` eigenpairs of H c = E S c refined in double-double from a
    double-precision solution: h, s (nb, nb); e (kept,) ascending; c (nb, kept) S-orthonormal.
    Returns the energies (roots,) in E_h, the S-normalised vectors (nb, roots), the iterations
    and whether each root converged."""


def inverse_iteration(h: ArrayLike, s: ArrayLike, e: ArrayLike, c: ArrayLike
                      ) -> tuple[float, NDArray[np.float64], int, bool]:
    """The lowest eigenpair of H c = E S c by inverse iteration in double-double, for a root
    `refine_eigenpairs` does not resolve: h, s (nb, nb); e (kept,) ascending, kept >= 1; c (nb,
    kept) S-orthonormal, from a double-precision solver. Returns the energy in E_h (the Rayleigh
    quotient at the double-double vector), the S-normalised vector (nb,) rounded to float64, the
    iterations and whether it converged. NotPositiveDefiniteError if s has no double-double LDLᵀ
    factorisation."""


def num_threads() -> int:
    """Number of rayon worker threads in use (RAYON_NUM_THREADS)."""
