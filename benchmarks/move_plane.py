"""A momentum move (optimise/momentum.py) against the best step in the plane of its two parts,
measured on a running run's own states (benchmarks/record/h2.md, "A move in two
directions").

`--watch FOLDER OUT`: copy FOLDER/basis.json into OUT each time its schedule's pass count
changes (polled every 0.5 s), as `pPASSES_ELAPSED.json`. `A B`: two such copies, A right after a
move and B right before the next one: the basis of B moved to θ_B + a d₁ + b d₂, d₁ = θ_B − θ_A
(the passes since the move), d₂ = θ_A − θ_ref (the move; θ_ref the momentum's reference of B),
its energy solved anew (one thread: set RAYON_NUM_THREADS=1). Printed: the move as the run makes
it (a = b = α, the parabola through α = 0, ½, 1) and the minimum of a quadratic fitted to the
grid a, b ∈ {0, ½, 1}, refitted to the grid of half-steps around it.

    python benchmarks/move_plane.py --watch benchmarks/checkpoints/h2-auto /tmp/snaps
    python benchmarks/move_plane.py /tmp/snaps/p891_25068.1.json /tmp/snaps/p893_25160.3.json
"""
from __future__ import annotations

import argparse
import json
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np

from prebo.basis import Basis
from prebo.errors import PreboError
from prebo.integrals import laboratory
from prebo.optimise.checkpoint import CHECKPOINT
from prebo.optimise.expansion import Expansion
from prebo.optimise.momentum import MAX_STEP
from prebo.optimise.parametrisation import Parametrisation
from prebo.optimise.resume import load_checkpoint


def watch(folder: Path, out: Path) -> None:
    """Copy the checkpoint each time its pass count changes (module docstring), until interrupted."""
    out.mkdir(parents=True, exist_ok=True)
    seen = None
    while True:
        try:
            text = (folder / CHECKPOINT).read_text()
            d = json.loads(text)
        except (OSError, ValueError):  # between two writes
            time.sleep(0.5)
            continue
        key = (len(d["schedule"]["passes"]), d["elapsed"])
        if key[0] != seen:
            (out / f"p{key[0]}_{key[1]}.json").write_text(text)
            seen = key[0]
        time.sleep(0.5)


def same_shape(f: Basis, g: Basis) -> bool:
    """Whether two one-function bases share channel and powers (a displacement in θ means something)."""
    return f.channels == g.channels and np.array_equal(f.family.powers(f, [0]), g.family.powers(g, [0]))


def compare(a_path: Path, b_path: Path) -> None:
    """Print the heavy-ball move and the best step in the plane of d₁, d₂ (module docstring)."""
    with tempfile.TemporaryDirectory() as tmp:
        shutil.copy(b_path, Path(tmp) / CHECKPOINT)
        d_b, system, opts = load_checkpoint(tmp)
    basis, after = Basis.from_dict(d_b, str(b_path)), Basis.from_dict(json.loads(a_path.read_text()), str(a_path))
    reference = Basis.from_dict(d_b["momentum"], f"{b_path}: momentum")
    rep = laboratory(system)
    fs, ps, theta, d1, d2 = [], [], [], [], []
    for i in range(len(basis)):
        f, fa, fr = basis.subset([i]), after.subset([i]), reference.subset([i])
        p = Parametrisation.of(f)
        t, ta = p.theta(), Parametrisation.of(fa).theta()
        x = t - ta if same_shape(f, fa) else np.zeros_like(t)
        y = ta - Parametrisation.of(fr).theta() if same_shape(fa, fr) else np.zeros_like(t)
        if np.linalg.norm(x + y) >= MAX_STEP or np.linalg.norm(x) >= MAX_STEP:  # replaced: stays (momentum.py)
            x = y = np.zeros_like(t)
        fs.append(f), ps.append(p), theta.append(t), d1.append(x), d2.append(y)
    n1, n2 = (np.sqrt(sum(v @ v for v in d)) for d in (d1, d2))
    print(f"|d1| {n1:.4f}  |d2| {n2:.4f}  cos {sum(x @ y for x, y in zip(d1, d2)) / (n1 * n2):+.3f}")
    energies = {}

    def energy(a: float, b: float) -> float:
        key = (round(a, 9), round(b, 9))
        if key not in energies:
            moved = Basis.concat([p.function(t + a * x + b * y) if x.any() or y.any() else f
                                  for f, p, t, x, y in zip(fs, ps, theta, d1, d2)])
            try:
                energies[key] = Expansion(moved, rep, opts.threshold, opts.min_norm, opts.max_overlap).energy
            except PreboError:
                energies[key] = np.inf
        return energies[key]

    E0 = energy(0.0, 0.0)
    line = {s: energy(s, s) for s in (0.5, 1.0)}
    curvature = 2.0 * (line[1.0] - 2.0 * line[0.5] + E0)
    if curvature > 0 and 0.0 < (vertex := 0.5 - (line[1.0] - E0) / (2.0 * curvature)) < 2.0:
        line[vertex] = energy(vertex, vertex)
    alpha = min(line, key=line.get)
    print(f"heavy ball: alpha {alpha:.3f}, gain {E0 - line[alpha]:.4e} Eh")
    centre = np.full(2, 0.5)  # the grid {0, ½, 1}², then half-steps around the model's minimum
    for _ in range(2):
        grid = [centre + 0.5 * np.array([i, j]) for i in (-1, 0, 1) for j in (-1, 0, 1)]
        X = np.array([[1.0, a, b, a * a, a * b, b * b] for a, b in grid])
        q = np.linalg.lstsq(X, [energy(a, b) - E0 for a, b in grid], rcond=None)[0]
        centre = np.linalg.solve([[2 * q[3], q[4]], [q[4], 2 * q[5]]], -q[1:3])
        print(f"plane: (a, b) = ({centre[0]:.2f}, {centre[1]:.2f}), gain {E0 - energy(*centre):.4e} Eh")
    print(f"best of {len(energies)} energies: {E0 - min(energies.values()):.4e} Eh")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("paths", nargs=2, type=Path, help="A B (two copies), or with --watch: FOLDER OUT")
    ap.add_argument("--watch", action="store_true", help="copy a running run's checkpoint at each new pass")
    a = ap.parse_args()
    if a.watch:
        watch(*a.paths)
    else:
        compare(*a.paths)


if __name__ == "__main__":
    main()
