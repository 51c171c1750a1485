"""Stochastic basis optimisation: competitive selection, replacement and refinement sweeps.

Growth (Suzuki & Varga, Lect. Notes Phys. m54, ch. 4, "stochastic variational
method"): draw `trials` random functions, get each one's row against the basis from
the Rust core (O(N_b) integrals), the new lowest eigenvalue from the secular
equation (O(N_b^2), eigen.lowest_with_added_many), keep the best and, with `refine`,
refine it (refine.py: L-BFGS on exact gradients, or Powell). Then `sweeps` random
replacement sweeps (each function in turn competes with `trials` random replacements in
the basis without it; with `refine`, the winner is refined and kept only if it then beats
the incumbent, which is refined otherwise: refine.regenerate_function), `refine`
refinement sweeps and `polish` steps of `polish_iterations` joint L-BFGS iterations over
all parameters (polish.py); this sweep-refine-polish block is run `cycles` times
(replacements reach new basins, joint refinement converges within one). After the first
functions of a channel, a share `learned` of the trials
is drawn from the distribution of the parameters selected so far in that channel.

Functions are drawn in a coordinate set ("channel") or in pair form:
- "pairs": A = Σ_{i<j} α_ij w_ij w_ij^T + c_A (m/m_tot)(m/m_tot)^T, α_ij = 1/b_ij^2,
  b_ij log-uniform in [lo, hi] × a_ij with a_ij = 1/(min(μ_ij, 1) max(|q_i q_j|, 1));
- a coordinate set x (coordinates.all_sets): 𝒜 = diag(1/b_k^2) in x, b_k log-uniform
  over the same range with the lengths of the particles the coordinate joins, then
  A^(r) = U_x^T blockdiag(𝒜, c_A) U_x.
With an output folder, the basis, the random-number state and the position in the
schedule are written atomically after every step: a killed run loses at most the step
in flight, and `prebo run --resume` continues it bit for bit; every start removes the
temporary files (basis.json.*.tmp) a write killed in flight left. Growth never hangs: after
`STALL_STEPS` steps in a row whose every trial was rejected, the run stops (StalledError)
naming the settings to change.
"""
from __future__ import annotations

import json
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import coordinates as coords
from . import eigen
from .basis import Basis, family
from .errors import BasisFileError, IllConditionedError, InputError, PreboError, StalledError
from .integrals import laboratory
from .io.basis_json import remove_stale_temporaries
from .polish import polish
from .refine import Parametrisation, refine_function, regenerate_function
from .system import System
from .validation import check_settings, number, strict_keywords


@strict_keywords
@dataclass
class Optimiser:
    """Settings of `optimise` (TOML table [optimiser]; `size`, `c_A`, `kind`, `K_max` come from [basis]);
    types, ranges and meanings: validation.SETTINGS."""

    size: int = 50
    trials: int = 20
    sweeps: int = 0
    seed: int = 1
    channels: str | list = "pairs"
    length_range: tuple = (0.01, 15.0)
    c_A: float = 1.0
    kind: str = "pecg"
    K_max: int = 0
    refine: int = 0
    refine_evaluations: int = 200
    refine_method: str = "gradient"
    polish: int = 0
    polish_iterations: int = 20
    cycles: int = 1
    learned: float = 0.5
    learn_after: int = 5
    min_norm: float = 1e-8
    max_overlap: float = 0.99
    threshold: float = 1e-13

    def to_dict(self) -> dict:
        return vars(self) | {"length_range": list(self.length_range)}

    @classmethod
    def from_dict(cls, d: dict) -> "Optimiser":
        if not isinstance(d, dict):
            raise InputError(f"optimiser settings must be a table, got {d!r}")
        return cls(**d)

    def __post_init__(self):
        check_settings(self, "Optimiser")


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


@dataclass
class Sampler:
    """Random functions of a system in pair form or in coordinate sets (module docstring)."""

    system: System
    opts: Optimiser
    rng: np.random.Generator
    sets: list = field(default_factory=list)
    # θ of the functions at the last `learn`, by channel and parameters (a sweep step changes one)
    _thetas: dict = field(default_factory=dict, repr=False)

    def __post_init__(self):
        s, m, q = self.system, self.system.masses, self.system.charges
        n = s.n
        self.length = np.ones((n, n))
        for i in range(n):
            for j in range(n):
                if i != j:
                    mu = m[i] * m[j] / (m[i] + m[j])
                    self.length[i, j] = 1.0 / (min(mu, 1.0) * max(abs(q[i] * q[j]), 1.0))
        self.sets = coordinate_sets(s, self.opts.channels)
        self.pairs = [(i, j) for i in range(n) for j in range(i + 1, n)]

    def _b(self, a, size=None):
        lo, hi = self.opts.length_range
        return a * np.exp(self.rng.uniform(np.log(lo), np.log(hi), size))

    def _pair_vector(self, i, j):
        w = np.zeros(self.system.n)
        w[i], w[j] = 1.0, -1.0
        return w

    def learn(self, basis: Basis) -> None:
        """Per channel: the mean and spread of the parameters θ (refine.Parametrisation) and the
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
            self.learned[ch] = (Parametrisation.of(basis.subset(idx[:1])), thetas.mean(axis=0), thetas.std(axis=0),
                                Ks, len(idx))
        self._thetas = seen

    def draw(self) -> Basis:
        """One function: with probability `opts.learned` from the learned per-channel
        distributions (normal in θ, K from the selected ones ± 2), otherwise `fresh`."""
        learned = getattr(self, "learned", {})
        if learned and self.rng.random() < self.opts.learned:
            names = list(learned)
            weights = np.array([learned[c][4] for c in names], float)
            p, mean, std, Ks, _ = learned[names[self.rng.choice(len(names), p=weights / weights.sum())]]
            theta = mean + self.rng.normal(size=mean.shape) * np.maximum(std, 0.05)
            K = None if Ks is None else family(self.opts.kind).draw_learned_power(self.rng, Ks, self.opts.K_max)
            try:
                return p.function(theta, K)
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
        # the global vector, the drawn length b is that peak, α = (K + N/2)/b² (K + N/2 > 0)
        K, power = fam.draw_power(self.rng, self.opts.K_max, s.state.N)
        if not self.sets:
            i0, j0 = self.pairs[self.rng.integers(len(self.pairs))]
            A = c_A * np.outer(cm, cm)
            for i, j in self.pairs:
                w = self._pair_vector(i, j)
                b = self._b(self.length[i, j])
                A += np.outer(w, w) * (max(power, 1.0) if (i, j) == (i0, j0) else 1.0) / b**2
            u = self._pair_vector(i0, j0)
            # centres: particle j displaced from particle i by a random vector of its pair length
            centres = np.zeros((n, 3))
            centres[j0] = self.rng.normal(size=3) / np.sqrt(3) * self._b(self.length[i0, j0])
            channel = "pairs"
        else:
            x = self.sets[self.rng.integers(len(self.sets))]
            # the length of coordinate k: that of the two particles its row weighs most
            lengths = []
            for k in range(n - 1):
                i, j = np.argsort(-np.abs(x.U[k]))[:2]
                lengths.append(self.length[i, j])
            b = self._b(np.array(lengths))
            alpha = 1.0 / b**2
            k0 = int(self.rng.integers(n - 1))
            alpha[k0] *= max(power, 1.0)
            A = x.to_lab(np.diag(alpha), c_A)
            ux = np.zeros(n)
            ux[k0] = 1.0  # one internal coordinate, c_U = 0
            u = x.U.T @ ux
            # centres in x: coordinate k0 displaced by a random vector of its drawn length, CM at rest
            sx = np.zeros((n, 3))
            sx[k0] = self.rng.normal(size=3) / np.sqrt(3) * self._b(lengths[k0])
            centres = x.U_inv @ sx
            channel = x.name
        return Basis.single(s, A, c_A, channel, fam.name, fam.drawn(s, u, centres, K))


class State:
    """Current basis with its matrices (S, T, T_ti, V), eigen-solution, energy and `sigma`, the
    energy's numerical uncertainty (eigen.energy_uncertainty). A change is kept only if it lowers
    the energy by more than the uncertainty of the energies before and after it (`put`,
    `replace_basis`): a gain rounding can fake is refused, never accepted."""

    def __init__(self, basis: Basis, rep, threshold: float, min_norm: float = 1e-8, max_overlap: float = 0.99):
        self.basis, self.rep, self.threshold = basis, rep, threshold
        self.min_norm, self.max_overlap = min_norm, max_overlap
        if len(basis):
            self.m = rep.matrices(basis)
        else:
            self.m = {k: np.zeros((0, 0)) for k in ("S", "T", "T_ti", "V")}
        self.solve()

    def solve(self):
        if len(self.basis) == 0:
            self.eig, self.energy, self.sigma = None, np.inf, 0.0
            return
        self.eig = eigen.solve(self.m["T_ti"] + self.m["V"], self.m["S"], self.threshold)
        self.energy = float(self.eig.energies[0])
        self.sigma = eigen.energy_uncertainty(self.eig.vectors[:, 0], self.energy, self.m["S"], self.m["T_ti"],
                                              self.m["V"])

    def gains(self, energy: float) -> bool:
        """Whether `energy` lies below the current energy by more than its uncertainty."""
        return energy < self.energy - self.sigma

    def _snapshot(self) -> tuple:
        return (self.basis.subset(slice(None)), {k: v.copy() for k, v in self.m.items()}, self.eig, self.energy,
                self.sigma)

    def _keep_if_lower(self, before: tuple) -> bool:
        """After a change: keep it if the energy fell by more than the uncertainty before and after
        it; otherwise restore the state `before` (`_snapshot`). True if kept."""
        if before[3] == np.inf or self.energy < before[3] - max(self.sigma, before[4]):
            return True
        self.basis, self.m, self.eig, self.energy, self.sigma = before
        return False

    def replace_basis(self, basis: Basis) -> bool:
        """Take a whole new basis (matrices rebuilt) if it lowers the energy beyond the uncertainty."""
        before = self._snapshot()
        self.basis = basis
        self.m = self.rep.matrices(basis)
        self.solve()
        return self._keep_if_lower(before)

    def without(self, i: int):
        """The eigen-solution of the basis without function i (None if that leaves nothing)."""
        keep = np.arange(len(self.basis)) != i
        if not keep.any():
            return None
        H = self.m["T_ti"] + self.m["V"]
        return eigen.solve(H[np.ix_(keep, keep)], self.m["S"][np.ix_(keep, keep)], self.threshold)

    def virial(self) -> float:
        c = self.eig.vectors[:, 0]
        return abs(1.0 + (c @ self.m["V"] @ c) / (2.0 * (c @ self.m["T_ti"] @ c)))

    def candidates(self, trials: Basis, exclude: int | None = None, eig=None):
        """Lowest energy with each trial added (to the basis without `exclude`, where the trial
        would replace it), with the rows and diagonals for `put`. The linear-dependence guard
        gives +inf to a trial whose normalised overlap with a function exceeds `max_overlap`
        or whose part orthogonal to the basis is below `min_norm` of its norm, and so does a
        trial whose elements fail `Representation.plausible`."""
        position = len(self.basis) if exclude is None else exclude
        rows, diag = self.rep.rows(trials, self.basis, position)
        H = rows["T_ti"] + rows["V"]
        S = rows["S"]
        keep = np.ones(len(self.basis), bool)
        if exclude is not None:
            keep[exclude] = False
        if eig is None:
            eig = self.eig if exclude is None else self.without(exclude)
        E, C = (eig.energies, eig.vectors) if eig is not None else (np.zeros(0), np.zeros((0, 0)))
        energies = eigen.lowest_with_added_many(E, C, H[:, keep], S[:, keep], diag[:, 2] + diag[:, 3],
                                                diag[:, 0], self.min_norm)
        if keep.any():
            overlap = np.abs(S[:, keep]) / np.sqrt(np.outer(diag[:, 0], np.diag(self.m["S"])[keep]))
            energies[overlap.max(axis=1) > self.max_overlap] = np.inf
        energies[~self.rep.plausible({"S": S[:, keep]}, diag, np.diag(self.m["S"])[keep])] = np.inf
        return energies, rows, diag

    def put(self, i: int, f: Basis, row: dict | None = None, d=None) -> bool:
        """Append (i == len) or replace function i by `f` if that lowers the energy beyond the
        uncertainty (class docstring); True if it did. The matrices are patched from the
        function's oriented row (`Representation.rows` with position i) or else rebuilt, so that
        the state is a function of the basis alone and a resumed run continues bit for bit."""
        before = self._snapshot()
        nb = len(self.basis)
        if i == nb:
            self.basis.append(f)
        else:
            self.basis.replace(i, f)
        if row is None or not self.rep.oriented(self.basis):
            self.m = self.rep.matrices(self.basis)
        else:
            values = {"S": d[0], "T": d[1], "T_ti": d[2], "V": d[3]}
            for k in self.m:
                r = np.array(row[k], copy=True)
                if i == nb:
                    M = np.zeros((nb + 1, nb + 1))
                    M[:nb, :nb] = self.m[k]
                    M[nb, :nb] = M[:nb, nb] = r
                    M[nb, nb] = values[k]
                    self.m[k] = M
                else:
                    r[i] = values[k]
                    self.m[k][i, :] = r
                    self.m[k][:, i] = r
        self.solve()
        return self._keep_if_lower(before)


PHASES = ("grow", "sweep", "refine", "polish", "done")


@dataclass
class Cursor:
    """The next unit of work: one competitive step ("grow"), function `index` of
    replacement sweep / refinement sweep `sweep` ("sweep", "refine"), joint-refinement step
    `sweep` ("polish") of the sweep-refine-polish block `cycle`, or "done"."""

    phase: str = "grow"
    sweep: int = 0
    index: int = 0
    cycle: int = 0

    def __post_init__(self):
        counts = (self.sweep, self.index, self.cycle)
        if self.phase not in PHASES or not all(type(k) is int and k >= 0 for k in counts):
            raise InputError(f"progress {vars(self)}: phase must be one of {', '.join(PHASES)}, "
                             "sweep, index and cycle non-negative integers")

    def advance(self, nb: int, opts: Optimiser) -> "Cursor":
        if self.phase == "grow":
            if nb < opts.size:
                return self
            return Cursor("sweep").settle(opts)
        nxt = Cursor(self.phase, self.sweep, self.index + 1, self.cycle)
        if nxt.index >= nb or self.phase == "polish":
            nxt = Cursor(self.phase, self.sweep + 1, 0, self.cycle)
        return nxt.settle(opts)

    def settle(self, opts: Optimiser) -> "Cursor":
        """Skip phases whose sweeps are used up; after the last polish step, the next cycle."""
        if self.phase == "sweep" and self.sweep >= opts.sweeps:
            return Cursor("refine", cycle=self.cycle).settle(opts)
        if self.phase == "refine" and self.sweep >= opts.refine:
            return Cursor("polish", cycle=self.cycle).settle(opts)
        if self.phase == "polish" and self.sweep >= opts.polish:
            if self.cycle + 1 < opts.cycles:
                return Cursor("sweep", cycle=self.cycle + 1).settle(opts)
            return Cursor("done")
        return self


CHECKPOINT = "basis.json"
STALL_STEPS = 100  # growth steps in a row without an accepted trial before the run stops (StalledError)


def optimise(system: System, opts: Optimiser, out: Path | None = None, progress: bool = True,
             resume: dict | None = None) -> Basis:
    """Grow a basis to `opts.size` by competitive selection, then `opts.sweeps` random replacement
    sweeps, `opts.refine` refinement sweeps and `opts.polish` joint steps. With `out`, the basis, the random-number state and the
    position in this schedule are written atomically after every step (out/basis.json); `resume`
    (that file's content) continues such a run exactly where it stopped."""
    if not isinstance(system, System):
        raise InputError(f"optimise: system = {system!r}: must be a prebo.System")
    if not isinstance(opts, Optimiser):
        raise InputError(f"optimise: opts = {opts!r}: must be a prebo.Optimiser")
    rng = np.random.default_rng(opts.seed)
    sampler = Sampler(system, opts, rng)
    rep = laboratory(system)
    if resume is None:
        basis, cursor, history, elapsed = Basis.empty(system, opts.kind), Cursor().advance(0, opts), [], 0.0
    else:
        basis, cursor, history, elapsed = _resumed(resume, opts, rng, "checkpoint")
    if out is not None:
        remove_stale_temporaries(Path(out) / CHECKPOINT)
    t_start = time.perf_counter()

    def wall() -> float:
        """Seconds of optimisation so far, over all segments of a resumed run."""
        return round(elapsed + time.perf_counter() - t_start, 1)

    st = State(basis, rep, opts.threshold, opts.min_norm, opts.max_overlap)
    sampler.learn(st.basis)
    report = Reporter(opts, progress)

    def checkpoint():
        if out is not None:
            st.basis.coefficients = st.eig.vectors[:, 0] if st.eig is not None else None
            energy = st.energy if np.isfinite(st.energy) else None  # inf before the first function
            st.basis.save(Path(out) / CHECKPOINT, {
                "energy": energy, "optimiser": opts.to_dict(), "progress": vars(cursor),
                "rng": rng.bit_generator.state, "history": history, "elapsed": wall()})

    def draw(k) -> Basis:
        return Basis.concat([sampler.draw() for _ in range(k)])

    stalled = 0  # growth steps in a row that added nothing
    with report:
        while cursor.phase != "done":
            old = st.energy
            if cursor.phase == "grow":
                trials = draw(opts.trials)
                energies, rows, diag = st.candidates(trials)
                best = int(np.argmin(energies))
                report.trials(len(trials))
                if (np.isfinite(energies[best]) and st.gains(energies[best])
                        and st.put(len(st.basis), trials.subset([best]), {k: v[best] for k, v in rows.items()},
                                   diag[best])):
                    stalled = 0
                    if opts.refine:  # competitive selection, then Powell refinement of the winner
                        refine_function(st, len(st.basis) - 1, opts.refine_evaluations, opts.refine_method)
                else:
                    stalled += 1
                    if stalled == STALL_STEPS:
                        raise StalledError(
                            f"optimiser: every trial of the last {stalled} growth steps was rejected at "
                            f"{len(st.basis)} functions (linearly dependent on the basis or implausible); raise "
                            f"max_overlap (now {opts.max_overlap:g}), lower min_norm (now {opts.min_norm:g}) "
                            f"or change length_range (now {list(opts.length_range)})")
            elif cursor.phase == "sweep":
                i = cursor.index
                trials = draw(opts.trials)
                rest = st.without(i)
                energies, rows, diag = st.candidates(trials, exclude=i, eig=rest)
                report.trials(len(trials))
                best = int(np.argmin(energies))
                if opts.refine and np.isfinite(energies[best]):
                    regenerate_function(st, i, trials.subset([best]), opts.refine_evaluations, opts.refine_method,
                                        rest)
                elif np.isfinite(energies[best]) and st.gains(energies[best]):
                    st.put(i, trials.subset([best]), {k: v[best] for k, v in rows.items()}, diag[best])
            elif cursor.phase == "refine":
                report.trials(1)
                refine_function(st, cursor.index, opts.refine_evaluations, opts.refine_method)
            else:
                polish(st, opts.polish_iterations)
            if st.energy < old:
                history.append([len(st.basis), st.energy, cursor.phase, wall()])
                report.step(st, old, cursor)
                sampler.learn(st.basis)  # a function of the basis alone, so a resumed run learns the same
            cursor = cursor.advance(len(st.basis), opts)
            checkpoint()
    st.basis.coefficients = st.eig.vectors[:, 0]
    return st.basis


def _resumed(d: dict, opts: Optimiser, rng: np.random.Generator, where: str) -> tuple:
    """The basis, cursor, history and elapsed seconds of checkpoint content `d` (`rng` takes its
    state); BasisFileError naming `where` for anything that does not fit."""
    basis = Basis.from_dict(d, where, empty=True)
    if basis.kind != opts.kind:
        raise BasisFileError(f"{where}: a {basis.kind} basis, but the optimiser's kind is {opts.kind}")
    try:
        cursor = Cursor(**d["progress"])
        rng.bit_generator.state = d["rng"]
        history, elapsed = d["history"], number(d.get("elapsed", 0.0), "elapsed")
    except (KeyError, TypeError, ValueError, OverflowError) as exc:
        raise BasisFileError(f"{where}: malformed run state ({exc})") from exc
    if not (isinstance(history, list) and all(isinstance(h, list) and len(h) >= 3 for h in history)):
        raise BasisFileError(f"{where}: history must be a list of [size, energy, phase, seconds] rows")
    nb = len(basis)
    if (cursor.phase != "grow" and nb == 0) or (cursor.phase in ("sweep", "refine") and cursor.index >= nb):
        raise BasisFileError(f"{where}: progress {vars(cursor)} does not fit a basis of {nb} functions")
    return basis, cursor, history, elapsed


def load_checkpoint(folder) -> tuple[dict, System, Optimiser]:
    """The content of folder/basis.json with its system and settings, checked as a whole
    (BasisFileError naming the file)."""
    path = Path(folder) / CHECKPOINT
    try:
        text = path.read_text()
    except OSError as exc:
        raise BasisFileError(f"{path}: no checkpoint to resume ({exc.strerror})") from exc
    except UnicodeDecodeError as exc:
        raise BasisFileError(f"{path}: not a text file ({exc.reason})") from exc
    try:
        d = json.loads(text)
    except json.JSONDecodeError as exc:
        raise BasisFileError(f"{path}: corrupt checkpoint (line {exc.lineno}: {exc.msg})") from exc
    if not (isinstance(d, dict) and {"optimiser", "progress", "rng", "history"} <= set(d)):
        raise BasisFileError(f"{path}: not a run checkpoint (no optimiser state)")
    try:
        opts = Optimiser.from_dict(d["optimiser"])
    except PreboError as exc:
        raise BasisFileError(f"{path}: {exc}") from exc
    basis, *_ = _resumed(d, opts, np.random.default_rng(), str(path))
    return d, basis.system, opts


def resume_from(folder: Path, progress: bool = True) -> tuple[Basis, Optimiser]:
    """Continue the run whose checkpoint is folder/basis.json."""
    d, system, opts = load_checkpoint(folder)
    return optimise(system, opts, out=Path(folder), progress=progress, resume=d), opts


class Reporter:
    """A live line: basis size, energy, last improvement, virial, trials per second."""

    def __init__(self, opts: Optimiser, enabled: bool):
        self.opts, self.enabled = opts, enabled
        self.n_trials, self.t0 = 0, time.perf_counter()
        self.progress = None

    def __enter__(self):
        if self.enabled:
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
            self.progress = Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
                                     TimeElapsedColumn(), TextColumn("{task.fields[info]}"))
            self.progress.__enter__()
            self.task = self.progress.add_task("growing", total=self.opts.size, info="")
        return self

    def __exit__(self, *exc):
        if self.progress is not None:
            self.progress.__exit__(*exc)

    def trials(self, k):
        self.n_trials += k

    def step(self, st: State, old: float, cursor: Cursor):
        if self.progress is None:
            return
        rate = self.n_trials / max(time.perf_counter() - self.t0, 1e-9)
        gain = old - st.energy if np.isfinite(old) else float("nan")
        info = f"E = {st.energy:.12f}  ΔE = {gain:.2e}  η = {st.virial():.1e}  {rate:.1f} trials/s"
        if cursor.phase == "grow":
            self.progress.update(self.task, completed=len(st.basis), info=info)
        elif cursor.phase == "polish":
            self.progress.update(self.task, description=f"polish (cycle {cursor.cycle + 1})", completed=cursor.sweep + 1, total=self.opts.polish,
                                 info=info)
        else:
            self.progress.update(self.task, description=f"{cursor.phase} {cursor.sweep + 1} (cycle {cursor.cycle + 1})",
                                 completed=cursor.index + 1, total=len(st.basis), info=info)
