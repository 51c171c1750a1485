"""Random basis functions: fresh draws in pair form or in coordinate sets, and draws from the
distributions learned from the functions selected so far.

- "pairs": A = Σ_{i<j} α_ij w_ij w_ij^T + c_A (m/m_tot)(m/m_tot)^T, α_ij = 1/b_ij^2,
  b_ij log-uniform in [lo a_ij, hi ã_ij] (`length_range` = [lo, hi]; `pair_lengths`: the pair's
  Bohr radius, bare and in the screened charge, from its reduced mass and charges);
- a coordinate set x (coordinates.all_sets): 𝒜 = diag(1/b_k^2) in x, b_k drawn in the same way
  for the two particles the coordinate joins, then A^(r) = U_x^T blockdiag(𝒜, c_A) U_x.
The family draws its own parameters: its power before the exponents (Family.draw_power, which
scales the exponent of one pair or coordinate), the rest from that coordinate and a random
displacement of it (a `Carrier`, Family.drawn): ECG-GVR the power K and the coordinate's vector as
u, floating ECGs centres displaced along it. The displacement is drawn for every family, as every
recorded run drew it, so that fixed-schedule runs repeat bit for bit.
After `learn_after` functions of a channel, a share `learned` of the trials is drawn from the
normal distribution of the parameters θ (parametrisation.py) selected so far in that channel.
Trials near the basis (`perturbed`, a share `near` of them): a function perturbed at its own
scale — 𝒜 = L Lᵀ in its coordinate set becomes L T Tᵀ Lᵀ, T lower triangular with diagonal e^z
and strict lower part z, z normal with spread PERTURBATION: each direction's exponent scaled by a
factor around e^{±1} and the directions mixed, where a fresh draw samples the whole length range
(the family's u, s and K kept). Growth perturbs functions of the basis chosen at random; with
`near` > 0 a replacement sweep tries moves of the function it may replace only: its neighbours in
K (Family.neighbours, the only moves in K besides a fresh draw: refinement changes θ only), then
perturbations of it. On an optimised He basis of 700 functions, replacements by the best of 50
perturbations gained 3.0e-10 Eh in 140 s, 20× what refinement gained per second there
(benchmarks/record/schedules.md, "Trials near the basis").
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .. import coordinates as coords
from ..basis import Basis, family
from ..errors import IllConditionedError, InputError
from ..system import System, reduced_mass
from .parametrisation import Parametrisation
from .settings import Optimiser

#: the spread of the logarithmic scale factors and mixings of `Sampler.perturbed`
PERTURBATION = 1.0


def coordinate_sets(system: System, channels) -> list[coords.CoordinateSet]:
    """The coordinate sets of the `channels` setting ([] for "pairs"), checked against the system."""
    m = system.masses
    if channels == "pairs":
        return []
    if channels == "all":
        return coords.all_sets(m, [p.name for p in system.particles])
    try:
        sets = [coords.by_name(m, name) for name in channels]
        for x in sets:
            x.check(m)
    except InputError as exc:
        raise InputError(f"channels: {exc}") from exc
    return sets


def pair_lengths(system: System) -> tuple[np.ndarray, np.ndarray]:
    """(a, ã), n x n, bohr: the length scales a pair of particles moves on.

    An attractive pair (q_i q_j < 0) is a hydrogen-like system: a_ij = 1/(μ_ij |q_i q_j|) is its
    Bohr radius (μ_ij = m_i m_j/(m_i + m_j)), the innermost length, for electrons, positrons,
    muons and nuclei alike. Its outermost length ã_ij ≥ a_ij is the largest Bohr radius of either
    particle k of the pair in Z_k, the charge the rest of the system shows it from afar
    (Σ_{l≠k} q_l where that attracts k; at least 1/2, for a particle held by polarisation, as in
    H⁻): the outer electron of Li sees Z = 1, not 3. A repulsive or neutral pair moves on the lengths of its particles'
    attractive pairs: the smallest a and the largest ã of either; a pair with no attractive
    partner at all takes 1/(μ_ij max(|q_i q_j|, 1)) for both.
    """
    m, q, n = system.masses, system.charges, system.n
    mu = reduced_mass(m[:, None], m[None, :])
    a, outer = np.full((n, n), np.inf), np.zeros((n, n))
    for i, j, _ in system.pairs():
        if q[i] * q[j] < 0:
            a[i, j] = a[j, i] = 1.0 / (mu[i, j] * abs(q[i] * q[j]))
            Z = [max(-np.sign(q[k]) * (q.sum() - q[k]), 0.5) for k in (i, j)]  # the rest, seen from k
            outer[i, j] = outer[j, i] = max(a[i, j], *(1.0 / (mu[i, j] * abs(q[k]) * z) for k, z in zip((i, j), Z)))
    inner, outermost = a.min(axis=1), outer.max(axis=1)  # per particle, over its attractive pairs
    for i, j, _ in system.pairs():
        if not q[i] * q[j] < 0:
            lo, hi = min(inner[i], inner[j]), max(outermost[i], outermost[j])
            if not np.isfinite(lo):
                lo = hi = 1.0 / (mu[i, j] * max(abs(q[i] * q[j]), 1.0))
            a[i, j] = a[j, i] = lo
            outer[i, j] = outer[j, i] = hi
    return a, outer


@dataclass(frozen=True, slots=True)
class Learned:
    """A channel's learned distribution (Sampler.learn): the parametrisation `p` of one of its
    functions, the mean and spread of θ, the powers K (None for a family without), and the
    `count` of its functions (its share of the draws)."""

    p: Parametrisation
    mean: np.ndarray
    std: np.ndarray
    Ks: np.ndarray | None
    count: int


@dataclass(frozen=True)
class Carrier:
    """The coordinate v = u^T r a fresh draw singled out (its exponent carries the family's power)
    and a random displacement of it of its drawn length: u (n, laboratory frame) and the particles'
    centres (n x 3, bohr; pairs: particle j displaced from particle i; a coordinate set: that
    coordinate displaced, the others and the CM at 0)."""

    u: np.ndarray
    centres: np.ndarray


@dataclass
class Sampler:
    """Random functions of `system` with the settings `opts`, drawn with `rng` (module docstring)."""

    system: System
    opts: Optimiser
    rng: np.random.Generator
    sets: list = field(default_factory=list)
    # θ of the functions at the last `learn`, by channel and parameters (a sweep step changes one)
    _thetas: dict = field(default_factory=dict, repr=False)

    def __post_init__(self):
        n = self.system.n
        self.a, self.a_outer = pair_lengths(self.system)
        self.sets = coordinate_sets(self.system, self.opts.channels)
        self.pairs = [(i, j) for i in range(n) for j in range(i + 1, n)]

    def _b(self, i: int, j: int) -> float:
        """A length of pair (i, j), log-uniform in [lo a_ij, hi ã_ij] (bohr)."""
        lo, hi = self.opts.length_range
        return float(np.exp(self.rng.uniform(np.log(lo * self.a[i, j]), np.log(hi * self.a_outer[i, j]))))

    def _pair_vector(self, i, j):
        w = np.zeros(self.system.n)
        w[i], w[j] = 1.0, -1.0
        return w

    def learn(self, basis: Basis) -> None:
        """Per channel: the mean and spread of the parameters θ (Parametrisation) and the
        powers K of the functions selected so far, for `draw`."""
        self.learned = {}
        if len(basis) == 0:
            return
        groups: dict[str, list[int]] = {}
        for i, ch in enumerate(basis.channels):
            groups.setdefault(ch, []).append(i)
        seen, known = {}, self._thetas
        for ch, idx in groups.items():
            if len(idx) < self.opts.learn_after:
                continue
            thetas = []
            for i in idx:  # θ of a function is remembered while it stays in the basis (a sweep step changes one)
                key = (ch, basis.c_A[i], *(v[i].tobytes() for v in (basis.A, *basis.parameters.values())))
                if key not in seen:
                    seen[key] = known[key] if key in known else Parametrisation.of(basis.subset([i])).theta()
                thetas.append(seen[key])
            thetas = np.array(thetas)
            Ks = basis.family.powers(basis, idx)
            self.learned[ch] = Learned(Parametrisation.of(basis.subset(idx[:1])), thetas.mean(axis=0),
                                       thetas.std(axis=0), Ks, len(idx))
        self._thetas = seen

    def neighbours(self, f: Basis) -> list:
        """The one-function basis f moved in its power, within 0..K_max (Family.neighbours)."""
        return f.family.neighbours(f, self.opts.K_max)

    def perturbed(self, f: Basis, k: int) -> list:
        """`k` functions near f, its exponent matrix perturbed at its own scale (module docstring);
        the family's parameters (u, s, K) are f's. A perturbation that leaves the valid region
        (Parametrisation) is replaced by a fresh draw."""
        if k == 0:
            return []
        p = Parametrisation.of(f)
        theta, d = p.theta(), self.system.n - 1
        out = []
        for _ in range(k):
            z = PERTURBATION * self.rng.normal(size=(d, d))
            try:
                out.append(p.function(p.transformed(theta, np.tril(z, -1) + np.diag(np.exp(np.diag(z))))))
            except IllConditionedError:
                out.append(self.fresh())
        return out

    def replacements(self, f: Basis, k: int) -> Basis:
        """`k` trials to replace f in a sweep: its `neighbours` in K, then, with `opts.near` > 0, f
        `perturbed` (moves of f: a fresh function enters by growth and pruning), else drawn ones."""
        near = self.neighbours(f)[:k]
        rest = self.perturbed(f, k - len(near)) if self.opts.near else [self.draw() for _ in range(k - len(near))]
        return Basis.concat(near + rest)

    def trials(self, k: int, basis: Basis | None = None) -> Basis:
        """`k` functions to grow `basis` by, as one basis: a share `opts.near` of them functions of
        the basis (chosen at random) `perturbed`, the others drawn."""
        near = []
        if basis is not None and len(basis) and self.opts.near:
            near = [g for i in self.rng.integers(len(basis), size=round(self.opts.near * k))
                    for g in self.perturbed(basis.subset([int(i)]), 1)]
        return Basis.concat(near + [self.draw() for _ in range(k - len(near))])

    def draw(self) -> Basis:
        """One function: with probability `opts.learned` from the learned per-channel
        distributions (normal in θ, K from the selected ones ± 2), otherwise `fresh`."""
        learned = getattr(self, "learned", {})
        if learned and self.rng.random() < self.opts.learned:
            names = list(learned)
            weights = np.array([learned[c].count for c in names], float)
            one = learned[names[self.rng.choice(len(names), p=weights / weights.sum())]]
            theta = one.mean + self.rng.normal(size=one.mean.shape) * np.maximum(one.std, 0.05)
            K = None if one.Ks is None else family(self.opts.kind).draw_learned_power(self.rng, one.Ks, self.opts.K_max)
            try:
                return one.p.function(theta, K)
            except IllConditionedError:
                return self.fresh()
        return self.fresh()

    def fresh(self) -> Basis:
        """One random function as a one-function Basis (module docstring)."""
        s, c_A = self.system, self.opts.c_A
        n = s.n
        cm = s.cm_vector
        fam = family(self.opts.kind)
        # |v|^{2K+N} exp(-α v²) peaks at |v| = sqrt((K + N/2)/α): for the coordinate that carries
        # the power, the drawn length b is that peak, α = (K + N/2)/b² (K + N/2 > 0)
        K, power = fam.draw_power(self.rng, self.opts.K_max, s.state.N)
        if not self.sets:
            i0, j0 = self.pairs[self.rng.integers(len(self.pairs))]
            A = c_A * np.outer(cm, cm)
            for i, j in self.pairs:
                w = self._pair_vector(i, j)
                b = self._b(i, j)
                A += np.outer(w, w) * (max(power, 1.0) if (i, j) == (i0, j0) else 1.0) / b**2
            centres = np.zeros((n, 3))
            centres[j0] = self.rng.normal(size=3) / np.sqrt(3) * self._b(i0, j0)
            carrier = Carrier(self._pair_vector(i0, j0), centres)
            channel = "pairs"
        else:
            x = self.sets[self.rng.integers(len(self.sets))]
            # the length of coordinate k: that of the two particles its row weighs most
            joined = [np.argsort(-np.abs(x.U[k]))[:2] for k in range(n - 1)]
            b = np.array([self._b(i, j) for i, j in joined])
            alpha = 1.0 / b**2
            k0 = int(self.rng.integers(n - 1))
            alpha[k0] *= max(power, 1.0)
            A = x.to_lab(np.diag(alpha), c_A)
            ux = np.zeros(n)
            ux[k0] = 1.0  # one internal coordinate, c_U = 0
            sx = np.zeros((n, 3))
            sx[k0] = self.rng.normal(size=3) / np.sqrt(3) * self._b(*joined[k0])
            carrier = Carrier(x.U.T @ ux, x.U_inv @ sx)
            channel = x.name
        return Basis.single(s, A, c_A, channel, fam.name, fam.drawn(self.rng, s, carrier, K))
