"""Refinement steps on a run's basis, one BLAS thread: the time and gain of `--steps` group
refinements (refine.refine_group of functions 0, 1, ...), or with `--survey` the groups' standing
against the linear-dependence guard — per group (every `--stride`-th function with its partners)
its independence of the rest from the rest's own solve and from the whole basis's eigen-solution
(Expansion.independence), and the block update's energy at the group's own parameters less the
refined energy (the offset; min_norm ignored); or with `--polish N` the time and gain of one joint
step of at most N L-BFGS iterations over every parameter (polish.polish); or with `--near T` the
time and gain of `--steps` replacement steps (methods.Replace with `near` > 0) whose T trials all
move the function replaced: its neighbours in K, then perturbations of it (Sampler.perturbed); the
best is kept if it lowers the energy, refined first with `--refine`; or with `--converge I,J,...`
how far each group's L-BFGS gets from the basis as it stands (nothing kept): the gain of one
L-BFGS run of `--evaluations` energies, and of Newton steps on a forward-difference Hessian of
the exact gradient (one step reaches the group's local minimum when refinement is exhausted).
Variants of the group steps: `--start I` begins them at function I; `--ranked` takes instead the
groups with the largest squared energy gradient ‖∂E/∂θ‖² summed over their members (polish.Joint);
`--k-moves` also refines each group with function i moved to K ± 1 (Sampler.neighbours) and keeps
the lowest; `--extrapolate OLD` first moves the basis on along its displacement since the basis of
the checkpoint OLD (momentum.Momentum.move); `--rounds R` repeats [extrapolate, --steps group
steps], each round's displacement taken from the basis after its extrapolation, or before it with
`--momentum`.

    python benchmarks/refine_steps.py runs/he-700 --steps 100
    python benchmarks/refine_steps.py runs/he-700 --survey --stride 23
    python benchmarks/refine_steps.py runs/he-700 --polish 30
    python benchmarks/refine_steps.py runs/he-700 --near 50 --steps 700
    python benchmarks/refine_steps.py runs/h2 --group 6 --evaluations 200 --converge 59,160,104,10,300
    python benchmarks/refine_steps.py runs/h2 --group 6 --steps 200 --rounds 3 --start 418
"""
from __future__ import annotations

import argparse
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from prebo import eigen
from prebo.basis import Basis
from prebo.integrals import laboratory
from prebo.optimise.checkpoint import CHECKPOINT
from prebo.optimise.cursor import Cursor
from prebo.optimise.expansion import Expansion
from prebo.optimise.methods import Minimiser, Replace, Run
from prebo.optimise.momentum import Momentum
from prebo.optimise.parametrisation import Parametrisation
from prebo.optimise.polish import Joint, polish
from prebo.optimise.refine import GroupEnergy, lbfgs, partners, refine_group
from prebo.optimise.report import Reporter
from prebo.optimise.resume import load_checkpoint, resumed
from prebo.optimise.sampler import Sampler


def survey(ex: Expansion, group: int, stride: int) -> None:
    """Print each sampled group's independence (rest solve, eigen-solution) and offset."""
    H, S = ex.m.H, ex.m.S
    below = []
    for i in range(0, len(ex.basis), stride):
        idx = [i] + partners(ex, i, group - 1)
        keep = np.ones(len(S), bool)
        keep[idx] = False
        rest = ex.without(idx)
        D = S[np.ix_(idx, keep)] @ rest.vectors
        scale = 1.0 / np.sqrt(np.diag(S)[idx])
        solved = np.linalg.eigvalsh((S[np.ix_(idx, idx)] - D @ D.T) * np.outer(scale, scale))[0]
        e = eigen.lowest_with_block(rest.energies, rest.vectors, H[np.ix_(idx, keep)], S[np.ix_(idx, keep)],
                                    H[np.ix_(idx, idx)], S[np.ix_(idx, idx)], 0.0, near=ex.energy)[0]
        below.append(solved < ex.min_norm)
        print(f"{idx}: independence {solved:.3e} (rest solve), {ex.independence(idx):.3e} (eigen-solution); "
              f"offset {e - ex.energy:+.2e} Eh")
    print(f"{sum(below)} of {len(below)} groups below min_norm = {ex.min_norm:g}")


def sweep_near(ex: Expansion, run_opts, system, i: int, a, report: Reporter) -> bool:
    """One replacement step of function i (methods.Replace) whose `a.near` trials move it only
    (`near` > 0: its neighbours in K, then perturbations of it); True if the energy fell."""
    E = ex.energy
    step = Replace(a.near, Minimiser(a.evaluations, "gradient") if a.refine else None)
    step.step(Run(ex, Sampler(system, run_opts, np.random.default_rng(i)), report), Cursor("sweep", index=i))
    return ex.energy < E


def ranked(ex: Expansion, size: int, count: int) -> list[int]:
    """The `count` functions whose groups (each with its `size` - 1 partners) have the largest
    ‖∂E/∂θ‖² summed over their members (the whole basis's gradient, polish.Joint)."""
    joint = Joint(ex)
    g2 = np.add.reduceat(joint(joint.theta0)[1] ** 2, joint.cut[:-1])
    score = [g2[[i] + partners(ex, i, size - 1)].sum() for i in range(len(ex.basis))]
    return [int(i) for i in np.argsort(score)[::-1][:count]]


def k_moves(ex: Expansion, i: int, size: int, evaluations: int, sampler: Sampler) -> bool:
    """Refine function i's group as it stands and with i moved to K ± 1 (its peak kept,
    Sampler.neighbours); keep the lowest if it gains. True if the energy fell."""
    idx = [i] + partners(ex, i, size - 1)
    best_E, best_f = ex.energy, None
    for f in [None] + [g for g in sampler.neighbours(ex.basis.subset([i])) if abs(int(g.K[0]) - int(ex.basis.K[i])) == 1]:
        obj = GroupEnergy(ex, idx)
        if f is not None:
            obj.p[0] = Parametrisation.of(f)
        lbfgs(obj.energy_and_gradient, obj.theta(), evaluations)
        if obj.best_f is not None and obj.best_E < best_E:
            best_E, best_f = obj.best_E, obj.best_f
    return best_f is not None and ex.gains(best_E) and ex.put_group(idx, best_f)


def newton(obj: GroupEnergy, steps: int, h: float = 1e-4) -> list[tuple[float, int]]:
    """`steps` Newton steps on obj from its θ, each on the forward-difference Hessian of the exact
    gradient (symmetrised), shifted by the first of λ = 0, 1e-8, ..., 1e-4 that lowers the energy
    (steps longer than 1 in θ shortened); (best energy, energies evaluated) after each step."""
    count = [0]

    def f(theta):
        count[0] += 1
        return obj.energy_and_gradient(theta)

    theta = obj.theta()
    e, g = f(theta)
    out = []
    for _ in range(steps):
        H = np.empty((len(theta), len(theta)))
        for k in range(len(theta)):
            t = theta.copy()
            t[k] += h
            H[:, k] = (f(t)[1] - g) / h
        w, V = np.linalg.eigh(0.5 * (H + H.T))
        for lam in (0.0, 1e-8, 1e-7, 1e-6, 1e-5, 1e-4):
            step = -V @ ((V.T @ g) / (np.abs(w) + lam + 1e-12))
            step /= max(1.0, np.linalg.norm(step))
            e2, g2 = f(theta + step)
            if e2 < e:
                e, theta, g = e2, theta + step, g2
                break
        out.append((obj.best_E, count[0]))
    return out


def converge(ex: Expansion, groups: list[int], size: int, evaluations: int) -> None:
    """Print, per group, the gain of one L-BFGS run of `evaluations` energies and of three Newton
    steps, each from the basis as it stands (nothing is kept)."""
    E0 = ex.energy
    for i in groups:
        idx = [i] + partners(ex, i, size - 1)
        t0 = time.perf_counter()
        obj = GroupEnergy(ex, idx)
        lbfgs(obj.energy_and_gradient, obj.theta(), evaluations)
        t1 = time.perf_counter()
        steps = newton(GroupEnergy(ex, idx), 3)
        print(f"group {idx}: L-BFGS ({evaluations} energies) {E0 - obj.best_E:.2e} Eh in {t1 - t0:.1f} s; Newton "
              + ", ".join(f"{E0 - e:.2e} ({n} energies)" for e, n in steps) + f" in {time.perf_counter() - t1:.1f} s")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("checkpoint", help="a run's folder (its basis.json)")
    ap.add_argument("--group", type=int, default=3, help="functions refined together (refine_group)")
    ap.add_argument("--evaluations", type=int, default=30, help="energies per refinement")
    ap.add_argument("--steps", type=int, default=100)
    ap.add_argument("--survey", action="store_true")
    ap.add_argument("--stride", type=int, default=23)
    ap.add_argument("--polish", type=int, metavar="N", help="one joint step of at most N iterations instead")
    ap.add_argument("--near", type=int, metavar="T", help="replacement steps of T perturbations each instead")
    ap.add_argument("--refine", action="store_true", help="with --near: refine the best trial first")
    ap.add_argument("--converge", metavar="I,J,...", help="L-BFGS against Newton on these groups (nothing kept)")
    ap.add_argument("--start", type=int, default=0, help="the first function of the group steps")
    ap.add_argument("--ranked", action="store_true", help="the groups with the largest gradient instead")
    ap.add_argument("--k-moves", action="store_true", help="each group also with function i at K ± 1")
    ap.add_argument("--extrapolate", metavar="OLD", help="first extrapolate along the displacement since OLD")
    ap.add_argument("--rounds", type=int, metavar="R", help="R rounds of [extrapolate, --steps group steps]")
    ap.add_argument("--momentum", action="store_true", help="with --rounds: displacements from before each extrapolation")
    a = ap.parse_args()
    d, system, opts = load_checkpoint(a.checkpoint)
    basis, *_ = resumed(d, opts, np.random.default_rng(0), a.checkpoint)
    with eigen.lapack_threads(len(basis)):
        ex = Expansion(basis, laboratory(system), opts.threshold, opts.min_norm, opts.max_overlap)
        print(f"{a.checkpoint}: {len(basis)} functions, E = {ex.energy!r}, overlap condition "
              f"{ex.eig.overlap_condition:.2e}")
        if a.survey:
            survey(ex, a.group, a.stride)
            return
        if a.converge:
            converge(ex, [int(i) for i in a.converge.split(",")], a.group, a.evaluations)
            return
        E0, t0 = ex.energy, time.perf_counter()
        if a.polish:
            polish(ex, a.polish)
            print(f"joint step of at most {a.polish} iterations in {time.perf_counter() - t0:.2f} s, gain "
                  f"{E0 - ex.energy:.3e} Eh, E = {ex.energy!r}")
            return
        if a.near:
            with Reporter(opts, False) as report:
                accepted = sum(sweep_near(ex, replace(opts, near=1.0), system, i % len(ex.basis), a, report)
                               for i in range(a.steps))
        else:
            accepted = group_steps(ex, a, system, opts, t0)
        print(f"{a.steps * (a.rounds or 1)} steps in {time.perf_counter() - t0:.2f} s, {accepted} accepted, gain "
              f"{E0 - ex.energy:.3e} Eh, E = {ex.energy!r}")


def group_steps(ex: Expansion, a, system, opts, t0: float) -> int:
    """The group steps of main and their variants (module docstring); the number accepted."""
    sampler = Sampler(system, opts, np.random.default_rng(0))
    momentum = Momentum(Basis.load(Path(a.extrapolate) / CHECKPOINT) if a.extrapolate else None)
    accepted, start, E0 = 0, a.start, ex.energy
    for r in range(a.rounds or 1):
        before = ex.energy
        momentum.move(ex)  # the reference is then the basis before the move
        gain = before - ex.energy
        if not a.momentum:
            momentum.reference = ex.basis.subset(slice(None))
        order = ranked(ex, a.group, a.steps) if a.ranked else [(start + k) % len(ex.basis) for k in range(a.steps)]
        for i in order:
            accepted += (k_moves(ex, i, a.group, a.evaluations, sampler) if a.k_moves
                         else refine_group(ex, i, a.group, a.evaluations))
        start += a.steps
        if a.rounds:
            print(f"round {r}: extrapolation {gain:.3e} Eh, total gain {E0 - ex.energy:.3e} Eh at "
                  f"{time.perf_counter() - t0:.1f} s", flush=True)
    return accepted


if __name__ == "__main__":
    main()
