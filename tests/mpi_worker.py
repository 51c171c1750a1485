"""Run by tests/test_mpi.py under `mpiexec -n R python tests/mpi_worker.py MODE`.

integrals: every family's full build, rows of many trials and of one (at several positions), a
row gradient, every operator's matrices and a density, split among the ranks (parallel.py), against the same engine's calls in this one
process: equal bit for bit on every rank, or an AssertionError (and every rank stopped).
raise: the last rank raises while the others enter a build that needs it.
diverge: the ranks build matrices of different bases (as ranks whose copies of a run differ would).
"""
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))

import prebo  # noqa: E402
from prebo.level.expectation import OPERATORS  # noqa: E402
from prebo.integrals import laboratory  # noqa: E402
from prebo.parallel import world  # noqa: E402
from conftest import custom  # noqa: E402
from test_operators import family_basis  # noqa: E402


def same(a: dict, b: dict, what: str) -> None:
    for name in b:
        assert np.array_equal(a[name], b[name]), f"{what}: {name} differs on rank {world().rank}"


def integrals() -> None:
    ranks = world()
    e, p = custom("e", 1.0, -1.0), custom("p", 1836.15267343, 1.0)
    for kind, N in [("pecg", 0), ("ecg-gvr", 0), ("ecg-gvr", 1), ("fecg", 0)]:
        system = prebo.System([p, e, e], state=prebo.State(N=N, parity=(-1) ** N, spin={"e": 0}))
        rng = np.random.default_rng(11)
        basis = family_basis(kind, system, rng, nb=13)
        trials = family_basis(kind, system, rng, nb=5)
        rep = laboratory(system)
        engine, params = rep.engine(basis), rep.arrays(basis)
        same(rep.matrices(basis), engine.matrices(params), f"{kind} N={N} matrices")
        for position in (None, 0, 6, 12):
            for t in (trials, trials.subset([2])):
                got, want = rep.rows(t, basis, position), engine.rows(rep.arrays(t), params, position)
                same(got[0], want[0], f"{kind} N={N} rows of {len(t)} at {position}")
                assert np.array_equal(got[1], want[1]), f"{kind}: diagonal at {position}"
        f = trials.subset([0])
        dA = rng.normal(size=(3, system.n, system.n))
        dA = dA + dA.transpose(0, 2, 1)
        dv = {"pecg": None, "ecg-gvr": rng.normal(size=(3, system.n)), "fecg": rng.normal(size=(3, system.n, 3))}[kind]
        got = rep.row_gradient(f, dA, dv, basis)
        want = engine.row_gradient(rep.arrays(f), dA, dv, params)
        same(got[0], want[0], f"{kind} N={N} row gradient")
        assert np.array_equal(got[1], want[1])
        for name, op in OPERATORS.items():
            if op.evaluates(basis.family):
                v = np.concatenate(list(op.classes(system).values()))
                got = rep.operator(name, basis, v, op.momenta)
                want = engine.operator(name, params, np.stack([rep.vectors(v[:, k], m) for k, m in enumerate(op.momenta)], 1))
                assert np.array_equal(got, want), f"{kind} N={N} operator {name}"
        w, C, r = system.pairs()[0][2][None].repeat(3, 0), rng.normal(size=(13, 2)), np.linspace(0.1, 3.0, 7)
        assert np.array_equal(rep.density(basis, w, C, r), engine.density(params, w, C, r)), f"{kind} density"
    if ranks.root:
        print(f"integrals: {ranks.size} ranks equal one process bit for bit")


def fail() -> None:
    ranks = world()
    if ranks.rank == ranks.size - 1:
        raise RuntimeError("a deliberate failure on the last rank")
    e, p = custom("e", 1.0, -1.0), custom("p", 1836.15267343, 1.0)
    system = prebo.System([p, e, e], state=prebo.State(N=0, parity=1, spin={"e": 0}))
    basis = family_basis("pecg", system, np.random.default_rng(1), nb=40)
    laboratory(system).matrices(basis)


def diverge() -> None:
    e, p = custom("e", 1.0, -1.0), custom("p", 1836.15267343, 1.0)
    system = prebo.System([p, e, e], state=prebo.State(N=0, parity=1, spin={"e": 0}))
    basis = family_basis("pecg", system, np.random.default_rng(1), nb=20 + world().rank)
    laboratory(system).matrices(basis)


if __name__ == "__main__":
    {"integrals": integrals, "raise": fail, "diverge": diverge}[sys.argv[1]]()
