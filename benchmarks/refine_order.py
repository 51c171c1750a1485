"""Which functions a refinement sweep should visit: in turn (cyclic) or largest gradient first.

From one optimised basis, `--count` functions are refined (refine.refine_function, L-BFGS on
exact gradients, the run's refine_evaluations), chosen either
- cyclic: functions start, start + 1, ... (what a refinement sweep does), or
- gradient: the functions with the largest |∂E/∂θ_i| (the Gauss–Southwell rule), screened
  once at the start by `energy_gradients`; the screening time is counted.
Both arms start from the same basis.

    python benchmarks/refine_order.py benchmarks/checkpoints/h2-cycles/basis.json --count 60 --start 0
"""
from __future__ import annotations

import argparse
import json
import time

import numpy as np

from prebo.basis import Basis
from prebo.integrals import laboratory
from prebo.optimise import Expansion, Optimiser
from prebo.optimise.parametrisation import Parametrisation
from prebo.optimise.refine import FunctionEnergy, refine_function


def energy_gradients(state) -> list[np.ndarray]:
    """∂E/∂θ_i of the lowest energy for every function i, by Hellmann–Feynman with one S-normalised
    eigenvector c: ∂E = 2 c_i Σ_{j≠i} c_j (∂H_ij − E ∂S_ij) + c_i² (∂H_ii − E ∂S_ii), H = T_ti + V
    (θ_i as in refine.Parametrisation; the kernel normalises functions, so |u| drops out)."""
    c, E, nb = state.eig.vectors[:, 0], state.energy, len(state.basis)
    out = []
    for i in range(nb):
        keep = np.arange(nb) != i
        p = Parametrisation.of(state.basis.subset([i]))
        theta = p.theta()
        rows, diag = state.rep.row_gradient(p.function(theta), *p.directions(theta),
                                            state.basis.subset(np.flatnonzero(keep)))
        dH, dS = rows["T_ti"][1:] + rows["V"][1:], rows["S"][1:]
        out.append(2.0 * c[i] * ((dH - E * dS) @ c[keep]) + c[i] ** 2 * (diag[1:, 2] + diag[1:, 3] - E * diag[1:, 0]))
    return out


def run(basis: Basis, opts: Optimiser, order: str, count: int, start: int):
    st = Expansion(basis.subset(np.arange(len(basis))), laboratory(basis.system), opts.threshold, opts.min_norm,
               opts.max_overlap)
    e0, t0 = st.energy, time.perf_counter()
    if order == "gradient":
        g = energy_gradients(st)
        visit = np.argsort([-np.linalg.norm(gi) for gi in g])[:count]
    else:
        visit = (start + np.arange(count)) % len(basis)
    screened = time.perf_counter() - t0
    if order == "gradient":  # untimed check against the secular-equation gradient of the first function
        obj = FunctionEnergy(st, int(visit[0]))
        g_obj = obj.energy_and_gradient(obj.p.theta())[1]
        print(f"function {visit[0]}: |∂E/∂θ| {np.linalg.norm(g_obj):.3e}; Hellmann–Feynman differs by "
              f"{np.linalg.norm(g[visit[0]] - g_obj) / np.linalg.norm(g_obj):.1e} (relative)")
    t1 = time.perf_counter()
    for i in visit:
        refine_function(st, int(i), opts.refine_evaluations, opts.refine_method)
    return e0, st.energy, screened, screened + time.perf_counter() - t1


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("basis", help="a run's basis.json (its [optimiser] settings are used)")
    ap.add_argument("--count", type=int, default=60, help="functions refined per arm")
    ap.add_argument("--start", type=int, default=0, help="first function of the cyclic arm")
    ap.add_argument("--orders", default="cyclic,gradient")
    args = ap.parse_args()
    d = json.loads(open(args.basis).read())
    basis, opts = Basis.from_dict(d, args.basis), Optimiser.from_dict(d["optimiser"])
    print(f"{args.basis}: {len(basis)} functions, {args.count} refined per arm, cyclic from {args.start}")
    rows = []
    for order in args.orders.split(","):
        e0, e1, screened, t = run(basis, opts, order, args.count, args.start)
        rows.append(f"| {order} | {args.count} | {e0:.12f} | {e1:.12f} | {e0 - e1:.3e} | {screened:.1f} | {t:.1f} "
                    f"| {(e0 - e1) / t:.2e} |")
    print("| order | functions | E before | E after | gain | screening (s) | wall time (s) | gain per s |")
    print("|---|---|---|---|---|---|---|---|")
    print("\n".join(rows))


if __name__ == "__main__":
    main()
