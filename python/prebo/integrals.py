"""Symmetrised overlap, kinetic and Coulomb matrices from the Rust core, in two representations.

- `laboratory(system)`: LFCC, kinetic matrix M; the core returns T (with CM motion) and T_ti,
  the CM kinetic energy eliminated through c_A (Muolo, Mátyus & Reiher, J. Chem. Phys. 148,
  084112 (2018), Sec. IV.B-D, the translationally invariant kinetic energy of a CM-separable
  function; crates/prebo-core/src/families/pecg/kernel.rs).
- `laboratory(system, kinetic="internal")`: LFCC with M - 1 1^T/(2 m_tot), the CM
  kinetic operator removed exactly (an independent check of the elimination).
- `translationally_invariant(system, coords)`: TICC of a coordinate set x, kinetic
  matrix μ, exponents 𝒜 (possible only when every function shares one c_A).

Each representation returns dict(S, T, T_ti, V) (matrices.NAMES) of normalised functions (hartree atomic units)
from the engine of the basis's family (`Family.engine`, one per family and N); under MPI the
ranks share a build's or a row's elements (parallel.py), with the bits of one process.

Cancellation: an element is a sum over the symmetriser's images, each at most 1 for normalised
functions, and T_ti is T less the CM kinetic energy. A function the symmetriser nearly annihilates
(S_nn ≪ Σ_P |c_P|: a function symmetric in two electrons of a spin triplet) or whose internal
kinetic energy is a sliver of its CM one (T_ti,nn ≪ T_nn: two electrons drifting apart) has
elements that lost the digits of that ratio, and bases of them gave energies far below the exact
ones (He ³S at -4.3e9 Eh, e e "bound" at -106 Eh). `require_resolved` refuses a basis with a
function below MIN_SYMMETRIC or MIN_INTERNAL (every committed basis lies above 2e-5 and 1e-2);
`plausible` refuses trials below MIN_SYMMETRIC or MIN_INTERNAL_TRIAL, stricter because the
optimiser drives a trial to whatever edge it allows: two particles of 1e-3 m_e at c_A = 1 (their
CM kinetic energy 3e6 times their binding) reached T_ti,nn = 1.01e-5 T_nn and an energy below
the exact one.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from .coordinates import CoordinateSet, jacobi
from .errors import CancellationError, SeparabilityError
from .matrices import NAMES
from .parallel import Ranks, world
from .system import System

#: smallest S_nn / Σ_P |c_P| of a function (module docstring, cancellation)
MIN_SYMMETRIC = 1e-6
#: smallest T_ti,nn / T_nn of a function in the laboratory frame (module docstring, cancellation)
MIN_INTERNAL = 1e-5
#: the same for a trial: the optimiser drives a trial to whatever edge it is allowed
MIN_INTERNAL_TRIAL = 1e-3


@dataclass(frozen=True)
class Representation:
    """The operators of one coordinate representation, for the engines of every basis family.

    lam: (n, n) kinetic matrix Λ of T = -∇^T Λ ∇ (hartree bohr²); pair_w: (p, n) Coulomb vectors w
    and pair_q: (p,) charge products q of V = Σ q/|w^T r|; sym_t: (o, n, n) symmetry operations T_P
    and sym_c: (o,) their Young-operator coefficients c_P; cm_mass: total mass (electron masses)
    for the elimination of the CM kinetic energy (T_ti), None without a CM coordinate; coords:
    the coordinate set of a TICC representation (None: laboratory frame); ranks: the MPI ranks
    that share its integrals (None: every rank of the run, parallel.world())."""

    lam: np.ndarray
    pair_w: np.ndarray
    pair_q: np.ndarray
    sym_t: np.ndarray
    sym_c: np.ndarray
    cm_mass: float | None
    coords: CoordinateSet | None = None  # None: laboratory frame
    ranks: Ranks | None = field(default=None, compare=False, repr=False)

    _engines: dict = field(default_factory=dict, compare=False, repr=False)

    def shared(self) -> Ranks:
        """The MPI ranks that share this representation's integrals (parallel.py)."""
        return world() if self.ranks is None else self.ranks

    def alone(self) -> Representation:
        """This representation (its engines shared) with the integrals evaluated by this process
        alone (`Expansion.draft`)."""
        return replace(self, ranks=Ranks())

    def arrays(self, f) -> tuple:
        """The core's parameter tuple of a function set `f` (a Basis) in this representation:
        (A, c_A) for plain ECGs, (A, u, K, c_A) for ECG-GVR, (A, s, c_A) for floating ECGs."""
        return f.family.params(f, self.coords)

    def _ops(self) -> tuple:
        return self.lam, self.pair_w, self.pair_q, self.sym_t, self.sym_c, self.cm_mass

    def engine(self, f):
        """The engine of the family of `f` and its state's N, built once per representation."""
        key = (f.kind, f.N)
        if key not in self._engines:
            self._engines[key] = f.family.engine(self._ops(), f.N)
        return self._engines[key]

    def matrices(self, f) -> dict:
        """Symmetrised S, T, T_ti, V (nb x nb, hartree) of the normalised functions of the basis `f`."""
        return self.shared().matrices(self.engine(f), self.arrays(f))

    def rows(self, trials, f, position: int | None = None) -> tuple[dict, np.ndarray]:
        """Rows (k x nb) of `trials` against the basis `f`, and the trials' diagonals [S, T, T_ti, V].

        `position`: where a trial would sit in the basis (default: appended). Where the family's
        engine is `oriented`, rows are evaluated in the orientation of a full build, so patching
        them into the matrices gives the bits of `matrices`; otherwise the trial is the bra."""
        return self.shared().rows(self.engine(f), self.arrays(trials), self.arrays(f), position)

    def row_gradient(self, f, dA: np.ndarray, dv: np.ndarray | None, basis) -> tuple[dict, np.ndarray]:
        """Row of the one-function basis `f` against `basis` (f as bra) and its diagonal, with the
        derivatives along P directions: dA (P x n x n) of A and dv (P x n) of u or (P x n x 3) of s
        (None for plain ECGs). Returns dict of (1 + P) x nb arrays (row 0 the values) and the
        (1 + P) x 4 diagonal. Laboratory frame only."""
        if self.coords is not None:
            raise ValueError("row gradients are computed in the laboratory frame")
        return self.shared().row_gradient(self.engine(f), self.arrays(f), dA, dv, self.arrays(basis))

    def operator(self, name: str, f, v: np.ndarray, momenta=(False,)) -> np.ndarray:
        """Symmetrised (p, nb, nb) matrices of the core's registered operator `name` between the
        normalised functions of the basis `f` ("r2": r_w² = |Σ_k w_k r_k|², bohr²), one per
        instance of its laboratory-frame vectors v (p, arity, n; (p, n) for arity 1), the k-th
        position-like or, with `momenta[k]`, momentum-like (p_w = Σ_k w_k p_k)."""
        v = np.asarray(v, dtype=float).reshape(len(v), len(momenta), -1)
        v = np.stack([self.vectors(v[:, k], m) for k, m in enumerate(momenta)], axis=1)
        engine, params = self.engine(f), self.arrays(f)
        return self.shared().instances(lambda part: engine.operator(name, params, part), np.ascontiguousarray(v))

    def between(self, name: str, bra, ket, v: np.ndarray, momentum: bool = False) -> np.ndarray:
        """(p, nb_bra, nb_ket) matrices of the core's two-basis operator `name` ("dipole", "velocity",
        "acceleration", "quadrupole", "overlap"; crates/prebo-core/src/registry.rs) between the normalised functions
        of the basis `bra` and those of the basis `ket`, symmetrised by this representation's
        operations (the kets' images), one per laboratory-frame vector v (p, n), position-like or,
        with `momentum`, momentum-like (`vectors`); for the quadrupole v is its symmetric (n, n)
        matrix M (level/transitions.py `quadrupole_matrix`), transformed on both sides (p = 1). The
        dipole's forms (O = d, ∇_w' and ∇_w' V, the last two with a momentum-like v) join a bra of
        N = L to a ket of N = L + 1 (the acceleration form N = 0 to 1) and are reduced elements
        <L+1‖O‖L>, the quadrupole's a bra of N = 0 to a ket of N = 2, <2‖Q‖0>
        (level/transitions.py). Each element
        is that of the functions' internal parts (`centre_of_mass`)."""
        if name == "quadrupole":
            v = self.vectors(self.vectors(v).T)
        else:
            v = self.vectors(v, momentum) if len(v) else np.zeros((0, 0))
        out = self.engine(bra).between(name, self.arrays(bra), self.engine(ket), self.arrays(ket), v)
        return out / self.centre_of_mass(bra, ket)

    def centre_of_mass(self, bra, ket) -> np.ndarray | float:
        """⟨Φ_i|Φ_j⟩ = (2√(c_i c_j)/(c_i + c_j))^{3/2}, the overlap of the normalised CM Gaussians
        exp(−c_A R²) of the functions of `bra` and `ket` (nb_bra, nb_ket), which divides a two-basis
        element of the laboratory frame into its internal one: a function is its CM Gaussian times
        an internal function, and an operator of the internal coordinates (the dipole about the CM)
        leaves the CM factor, which two bases optimised at different c_A do not share (H's α fell
        by 4.6 % between c_A = 0.7 and 1). 1 without a CM coordinate (TICC, a clamped nucleus)."""
        if self.coords is not None or self.cm_mass is None:
            return 1.0
        ci, cj = np.asarray(bra.c_A, dtype=float)[:, None], np.asarray(ket.c_A, dtype=float)[None, :]
        return (2.0 * np.sqrt(ci * cj) / (ci + cj)) ** 1.5

    def between_gradient(self, name: str, bra, f, dA: np.ndarray, dv: np.ndarray, v: np.ndarray,
                         momentum: bool = False) -> np.ndarray:
        """`between(name, bra, f, v, momentum)` for the one-function ECG-GVR basis `f` (the ket), with
        the exact derivatives along P directions of its parameters as `row_gradient`'s: dA (P x n x n)
        of A, dv (P x n) of u. Returns (p, 1 + P, nb_bra): row 0 of each instance `between`'s
        column, row 1 + k its derivative along direction k (docs/transitions.md). "dipole" and
        "velocity"; laboratory frame only; internal elements as `between`'s (c_A does not move)."""
        if self.coords is not None:
            raise ValueError("two-basis gradients are computed in the laboratory frame")
        engine = self.engine(bra)
        out = engine.between_gradient(name, self.arrays(bra), self.engine(f), self.arrays(f),
                                      np.ascontiguousarray(dA, dtype=float), np.ascontiguousarray(dv, dtype=float),
                                      self.vectors(v, momentum))
        return out / self.centre_of_mass(bra, f).T[:, None, :] if self.cm_mass is not None else out

    def density(self, f, w: np.ndarray, C: np.ndarray, r: np.ndarray) -> np.ndarray:
        """The spherically averaged densities (p, states, len(r)) of r_w (bohr⁻³) at the radii `r`
        (bohr) in the states Σ_k C_ks Yφ_k of the basis `f`, one per laboratory-frame vector w (p, n)."""
        C, r = np.ascontiguousarray(C, dtype=float), np.ascontiguousarray(r, dtype=float)
        engine, params = self.engine(f), self.arrays(f)
        return self.shared().instances(lambda part: engine.density(params, part, C, r), self.vectors(w))

    def vectors(self, w: np.ndarray, momentum: bool = False) -> np.ndarray:
        """Laboratory-frame operator vectors w (p, n) in this representation: in TICC a position-like
        w as the Coulomb vectors, w' = (U^-T w)_{1..n-1} (Σ w_k r_k = Σ w'_k x_k), a momentum-like
        one as ∇, w' = (U w)_{1..n-1} (Σ w_k ∇_{r_k} = Σ w'_k ∇_{x_k}); both without the CM component,
        which vanishes for 1ᵀw = 0 and μᵀw = 0 respectively."""
        w = np.atleast_2d(np.asarray(w, dtype=float))
        if self.coords is not None:
            w = (w @ self.coords.U.T if momentum else self.coords.transform_vectors_to_x(w))[:, :-1]
        return np.ascontiguousarray(w)

    def plausible(self, rows: dict, diag: np.ndarray, S_basis: np.ndarray) -> np.ndarray:
        """Per trial, whether its elements pass the bounds exact integrals obey: 0 < S_nn ≤ Σ_P |c_P|,
        T_nn, T_ti,nn ≥ 0, |S_nj| ≤ (S_nn S_jj)^{1/2} (Cauchy–Schwarz), and whether they kept their
        digits (`resolved`). Integrals of extreme parameters that lost their digits fail them, and
        would otherwise break the variational bound."""
        S_nn = diag[:, 0]
        ok = (S_nn <= np.abs(self.sym_c).sum() * (1 + 1e-10)) & (diag[:, 1] >= 0) & (diag[:, 2] >= 0)
        ok &= self.resolved(diag, MIN_INTERNAL_TRIAL)
        if rows["S"].shape[1]:
            bound = np.sqrt(np.outer(np.maximum(S_nn, 0), S_basis)) * (1 + 1e-8)
            ok &= np.all(np.abs(rows["S"]) <= bound, axis=1)
        return ok & np.all(np.isfinite(diag), axis=1)

    def resolved(self, diag: np.ndarray, internal: float = MIN_INTERNAL) -> np.ndarray:
        """Per function, from its diagonal [S, T, T_ti, V]: whether its elements kept their digits,
        S_nn ≥ MIN_SYMMETRIC Σ_P |c_P| and (laboratory frame) T_ti,nn ≥ `internal` T_nn (module
        docstring, cancellation)."""
        ok = diag[:, 0] >= MIN_SYMMETRIC * np.abs(self.sym_c).sum()
        if self.coords is None:
            ok &= diag[:, 2] >= internal * diag[:, 1]
        return ok

    @staticmethod
    def diagonal(m: dict) -> np.ndarray:
        """The diagonal [S, T, T_ti, V] of matrices `m`, one row per function (what `resolved` reads)."""
        return np.stack([np.diag(m[k]) for k in NAMES], axis=1)

    def require_resolved(self, m: dict) -> None:
        """Refuse (CancellationError, naming the first such function) matrices `m` of a basis with a
        function whose elements lost their digits to cancellation (`resolved`)."""
        diag = self.diagonal(m)
        bad = np.flatnonzero(~self.resolved(diag) & np.isfinite(diag).all(axis=1))  # NaN: eigen.solve's error
        if len(bad):
            i, total = int(bad[0]), np.abs(self.sym_c).sum()
            if diag[i, 0] < MIN_SYMMETRIC * total:
                why = (f"the symmetriser nearly annihilates it (symmetrised norm {diag[i, 0] / total:.2e} of "
                       f"its norm, below {MIN_SYMMETRIC:g}); is the basis of this state's symmetry?")
            else:
                why = (f"its internal kinetic energy is {diag[i, 2] / diag[i, 1]:.2e} of its laboratory-frame "
                       f"one (below {MIN_INTERNAL:g}), lost to the CM elimination")
            raise CancellationError(f"basis function {i} of {len(diag)} ({len(bad)} such) lost the digits of its "
                                    f"matrix elements to cancellation: {why}")

    def oriented(self, f) -> bool:
        """Whether `rows(..., position)` reproduces full-build bits for the family of basis `f`."""
        return self.engine(f).oriented


def laboratory(system: System, kinetic: str = "M") -> Representation:
    """The laboratory-frame representation of `system`: kinetic matrix M = diag(1/(2 m_i)) with the
    CM kinetic energy eliminated through c_A (kinetic="M"), or M - 1 1^T/(2 m_tot), the CM
    kinetic operator removed exactly (kinetic="internal", no T_ti elimination). With an infinite
    mass the CM is that particle, which has no kinetic term: T_ti = T (cm_mass None)."""
    w, q = system.coulomb_pairs()
    sym = system.symmetriser
    if kinetic == "M":  # an infinite mass: the CM does not move, no kinetic energy to eliminate (T_ti = T)
        lam, cm = system.M, system.m_total if math.isfinite(system.m_total) else None
    elif kinetic == "internal":
        lam, cm = system.M_internal, None
    else:
        raise ValueError(f"kinetic must be 'M' or 'internal', not {kinetic!r}")
    c = np.ascontiguousarray
    return Representation(c(lam), c(w), c(q), c(sym.matrices), np.array(sym.coefficients), cm)


def translationally_invariant(system: System, coords: CoordinateSet | None = None) -> Representation:
    """The translationally invariant representation of `system` in the coordinate set `coords`
    (default: Jacobi in input order): kinetic matrix μ = U M U^T without the CM row, Coulomb
    vectors w' = (U^-T w)_{1..n-1}, operations 𝒯 = (U Π U^-1)_{TI} (Muolo, Mátyus & Reiher,
    J. Chem. Phys. 148, 084112 (2018), Sec. II). Its matrices need one c_A shared by every function."""
    coords = coords or jacobi(system.masses)
    coords.check(system.masses)
    w, q = system.coulomb_pairs()
    wx = coords.transform_vectors_to_x(w)
    sym = system.symmetriser
    tx = np.array([coords.transform_operation(P) for P in sym.matrices])
    c = np.ascontiguousarray
    return Representation(
        c(coords.mu(system.M)), c(wx[:, :-1]), c(q), c(tx[:, :-1, :-1]), np.array(sym.coefficients), None, coords
    )


def require_shared_c_A(c_A: np.ndarray, rtol: float = 1e-12) -> float:
    """The common c_A of a CM-separable basis, or SeparabilityError naming the spread."""
    lo, hi = float(np.min(c_A)), float(np.max(c_A))
    if hi - lo > rtol * hi:
        raise SeparabilityError(
            f"the basis is not separable in the CM coordinate: c_A ranges from {lo:.6g} to {hi:.6g}; "
            "a translationally invariant evaluation needs one shared c_A (use --coordinates lab)"
        )
    return hi
