"""The optimisation methods: pruning, growth, replacement and refinement steps and batches,
the patched matrices, the uncertainty a change must beat, learned and perturbed trials."""
from dataclasses import replace

import numpy as np
import pytest

import prebo
from prebo.optimise import Cursor, Optimiser
from prebo.optimise.adaptive import Adaptive
from prebo.optimise.defaults import resolved
from prebo.optimise.schedule import kind_of
from conftest import ROOT


def test_pruning_removes_the_function_that_costs_least():
    """eigen.root_without_each against the basis without each function solved afresh, and a
    prune step removes the cheapest, then refines the function that overlapped it most: only that
    one moves, and the energy falls below that of the basis without the cheapest."""
    from prebo import eigen
    from prebo.integrals import laboratory
    from prebo.optimise import Expansion
    from prebo.optimise.methods import Grow, Minimiser, PruneStep, Run
    from prebo.optimise.report import Reporter
    basis = prebo.Basis.load(ROOT / "examples" / "bases" / "h2plus-gvr" / "basis.json").subset(np.arange(40))
    ex = Expansion(basis, laboratory(basis.system), 1e-13)
    without = eigen.root_without_each(ex.eig.energies, ex.eig.vectors)
    fresh = np.array([ex.without(i).energies[0] for i in range(40)])
    assert np.all(without >= ex.energy) and np.allclose(without, fresh, rtol=1e-13, atol=0)
    cheapest = int(np.argmin(fresh))
    S = ex.m.S
    overlap = np.abs(S[cheapest]) / np.sqrt(S[cheapest, cheapest] * np.diag(S))
    overlap[cheapest] = 0
    partner = int(np.argmax(overlap)) - (int(np.argmax(overlap)) > cheapest)  # its index after the removal
    kept = ex.basis.subset(np.flatnonzero(np.arange(40) != cheapest))
    opts = resolved(Optimiser(size=39, prune=1, refine=1), basis.system)
    PruneStep(Grow(5), Minimiser(5, "gradient")).step(Run(ex, None, Reporter(opts, False, 40)),
                                                       Cursor("prune", target=39))
    moved = [k for k in range(39) if not np.array_equal(ex.basis.A[k], kept.A[k])]
    assert len(ex.basis) == 39 and moved == [partner] and ex.energy < fresh[cheapest]
    rebuilt = laboratory(basis.system).matrices(ex.basis)
    assert all(np.array_equal(rebuilt[k], getattr(ex.m, k)) for k in rebuilt)


def test_each_phase_has_its_method_configured_by_the_settings():
    from prebo.optimise import Grow, Minimiser, MomentumMove, Polish, PrunePass, PruneStep, Refine, Replace
    from prebo.optimise.methods import methods
    he = prebo.System(["alpha", "e", "e"])
    plain = methods(resolved(Optimiser(trials=7, polish_iterations=9, sweeps=0), he))
    assert plain == {"grow": Grow(7), "prune": PruneStep(Grow(7), Minimiser(200, "gradient")), "sweep": Replace(7),
                     "refine": Refine(Minimiser(200, "gradient")), "polish": Polish(9)}
    refined = methods(Optimiser(trials=3, refine=1, refine_evaluations=40, refine_method="powell"))
    assert refined["grow"] == Grow(3, Minimiser(40, "powell")) and refined["sweep"].newcomer == Minimiser(40, "powell")
    grouped = methods(resolved(Optimiser(refine=1, refine_evaluations=40, refine_group=2), he))  # refinement sweeps only
    assert grouped["refine"] == Refine(Minimiser(40, "gradient", 2)) and grouped["sweep"].newcomer == Minimiser(40, "gradient")
    batched = methods(resolved(Optimiser(refine=1, batch=4), he))
    assert batched["refine"] == Refine(Minimiser(200, "gradient"), 4)
    adaptive = methods(resolved(Optimiser(trials=5), he))  # the adaptive schedule refines every new function
    assert adaptive["grow"] == Grow(5, Minimiser(30, "gradient")) and adaptive["sweep"] == Replace(5, Minimiser(30, "gradient"))
    assert adaptive["prune"] == PrunePass(PruneStep(Grow(5, Minimiser(30, "gradient")), Minimiser(30, "gradient", 3)))
    assert adaptive["momentum"] == MomentumMove() and "momentum" not in plain  # the adaptive schedule's moves


def test_a_batch_keeps_each_change_only_if_it_still_gains_after_the_ones_before(monkeypatch):
    """methods.Refine with a batch of three: each function's refinement is done on a copy of the
    same basis and the changes are put in order, re-checked against the basis the ones before
    changed (methods.together). Functions 0 and 3 are first moved away from where they belong.
    Unit 1 puts function 0 where ten energies of its refinement take it from there: that gains
    against the basis it started from, less than unit 0's refinement of function 0, so after
    unit 0 it is refused; unit 2's refinement of function 3 is kept; the matrices are those of a
    full build. The basis comes from a fixed schedule, which does not follow the clock."""
    from prebo.integrals import laboratory
    from prebo.optimise import Expansion, Minimiser, Refine
    from prebo.optimise import methods as m
    from prebo.optimise.refine import accept, FunctionEnergy, minimise
    from prebo.optimise.report import Reporter
    system = prebo.System(["p", "e", "e"], spin={"e": 0})
    basis = prebo.optimise(system, Optimiser(size=8, trials=5, seed=0, sweeps=0), progress=False)
    basis.A[[0, 3]] *= 2.0  # functions 0 and 3 moved far from where they belong
    rep = laboratory(system)

    def fresh():
        return Expansion(basis.subset(slice(None)), rep, 1e-13)

    def refined(ex, j, evaluations):
        obj = FunctionEnergy(ex, j)
        minimise(obj, evaluations, "gradient")
        return obj

    f_1 = refined(fresh(), 0, 10).best_f  # where unit 1 puts function 0

    def unit(ex, i, *args):  # unit i of the batch
        if i == 1:
            obj = FunctionEnergy(ex, 0, f=f_1)
        else:
            obj = refined(ex, {0: 0, 2: 3}[i], 200)
        accept(ex, obj.i, obj)

    def energy(*units):  # the units done one after the other
        ex = fresh()
        for i in units:
            unit(ex, i)
        return ex.energy

    def changes(*units):  # each unit done from the same basis, their changes put in order
        ex, out = fresh(), fresh()
        for i in units:
            draft = ex.draft()
            unit(draft, i)
            assert out.put_group(*draft.changes(ex))
        return out.energy

    ex = fresh()
    assert energy(0) < energy(1) < ex.energy and energy(0, 1) == energy(0)
    monkeypatch.setattr(m, "refine_group", unit)
    opts = resolved(Optimiser(size=8, refine=1), system)
    visited = Refine(Minimiser(200, "gradient"), batch=3).step(m.Run(ex, None, Reporter(opts, False, 8)),
                                                                Cursor("refine"))
    assert visited == 3 and ex.energy == changes(0, 2) < energy(0)
    rebuilt = rep.matrices(ex.basis)
    assert all(np.array_equal(rebuilt[k], getattr(ex.m, k)) for k in rebuilt)


def test_refinement_and_learning_lower_the_energy():
    """Same seed and size: refinement and learned sampling must beat plain selection."""
    system = prebo.System(["p", "e", "e"], spin={"e": 0})
    plain = prebo.optimise(system, Optimiser(size=8, trials=5, seed=2, learned=0.0, sweeps=0), progress=False)
    better = prebo.optimise(system, Optimiser(size=8, trials=5, seed=2, refine=1, refine_evaluations=40),
                            progress=False)
    e_plain, e_better = prebo.evaluate(plain)["energy"], prebo.evaluate(better)["energy"]
    assert -0.527445881114 < e_better < e_plain


@pytest.mark.parametrize("kind, extra", [("ecg-gvr", {"K_max": 3}), ("fecg", {})])
def test_patched_matrices_have_the_bits_of_a_full_build(kind, extra):
    """Appending and replacing through oriented rows gives exactly the matrices of a fresh build
    (what makes a resumed run continue bit for bit without rebuilding after every step)."""
    from prebo import eigen
    from prebo.integrals import laboratory
    from prebo.optimise import Expansion
    s = prebo.System(["p", "e", "e"], spin={"e": 0})
    b = prebo.optimise(s, Optimiser(size=6, trials=4, seed=3, kind=kind, channels="all", **extra), progress=False)
    rep = laboratory(s)
    poor = b.subset([1])  # function 1 made 100 times tighter: putting it back is a real gain
    poor.A *= 100.0
    poor.c_A *= 100.0
    st = Expansion(prebo.Basis.concat([b.subset([0]), poor, b.subset([2, 3])]), rep, 1e-13)
    _, rows, diag = st.candidates(b.subset([4]))
    assert st.put(4, b.subset([4]), {k: v[0] for k, v in rows.items()}, diag[0])
    keep = np.arange(5) != 1
    sub = eigen.solve((st.m.T_ti + st.m.V)[np.ix_(keep, keep)], st.m.S[np.ix_(keep, keep)])
    _, rows, diag = st.candidates(b.subset([1]), exclude=1, eig=sub)
    assert st.put(1, b.subset([1]), {k: v[0] for k, v in rows.items()}, diag[0])
    full = rep.matrices(st.basis)
    for k in full:
        assert np.array_equal(full[k], getattr(st.m, k)), k


def test_a_change_within_the_numerical_uncertainty_is_refused():
    """On examples/bases/h2plus-pecg (overlap condition 4.7e12, energy uncertainty ~1e-8 Eh) a function
    replaced by itself perturbed at 1e-10 relative moves the energy by far less than the uncertainty:
    the state refuses the change and keeps its bits, whichever way the energy moved; a real gain
    (the function restored after its removal) is kept."""
    from prebo.integrals import laboratory
    from prebo.optimise import Expansion
    basis = prebo.Basis.load(ROOT / "examples" / "bases" / "h2plus-pecg" / "basis.json")
    rep = laboratory(basis.system)
    st = Expansion(basis, rep, 1e-13)
    assert st.sigma > 1e-10
    A0, m0, e0 = st.basis.A.copy(), st.m.map(np.copy).to_dict(), st.energy
    for i in (0, 17, 42):
        f = st.basis.subset([i])
        f.A[0] *= 1 + 1e-10
        rows, diag = rep.rows(f, st.basis, i)
        assert not st.put(i, f, {k: v[0] for k, v in rows.items()}, diag[0])
        assert np.array_equal(st.basis.A, A0) and st.energy == e0
        assert all(np.array_equal(getattr(st.m, k), m0[k]) for k in m0)
    small = Expansion(basis.subset(np.arange(len(basis) - 1)), rep, 1e-13)
    last = basis.subset([len(basis) - 1])
    _, rows, diag = small.candidates(last)
    assert small.put(len(small.basis), last, {k: v[0] for k, v in rows.items()}, diag[0])
    assert small.energy == pytest.approx(e0, rel=1e-8, abs=0)


@pytest.mark.parametrize("K, N", [(0, 0), (1, 0), (7, 0), (30, 0), (4, 1)])
def test_a_sweep_tries_the_neighbours_in_K_with_the_peak_of_the_global_vector_coordinate_kept(K, N):
    from prebo.optimise.sampler import Sampler
    state = prebo.State(N=N, parity=(-1) ** N, spin={"p": N % 2, "e": 0})
    system = prebo.System([{"name": "p", "mass": 1836.15}, {"name": "p", "mass": 1836.15}, "e", "e"], state)
    opts = Optimiser(kind="ecg-gvr", K_max=30, channels="all")
    sampler = Sampler(system, opts, np.random.default_rng(5))
    f = sampler.fresh()
    u = f.u + 0.3 * np.random.default_rng(6).standard_normal(f.u.shape)
    f = prebo.Basis.single(system, f.A[0], f.c_A[0], f.channels[0], f.kind, {"u": u - u.mean(), "K": [K]})
    near = sampler.neighbours(f)
    assert sorted(int(g.K[0]) for g in near) == sorted(k for k in (K - 2, K - 1, K + 1, K + 2) if 0 <= k <= 30)
    u = f.u[0]

    def peak(g):  # |v|^{2K+N} exp(-α_v v²) of the marginal in v = u·r peaks at (p/α_v)^½, p = max(K + N/2, 1)
        return max(int(g.K[0]) + N / 2, 1.0) * (u @ np.linalg.solve(g.A[0], u))

    for g in near:
        assert np.allclose(g.u, f.u) and peak(g) == pytest.approx(peak(f), rel=1e-10)  # A^-1 u: cond(A) ~ 1e4
        moved = max(int(g.K[0]) + N / 2, 1.0) != max(K + N / 2, 1.0)  # p = 1 for K + N/2 ≤ 1, as in fresh draws
        assert np.linalg.matrix_rank(g.A[0] - f.A[0], tol=1e-12 * np.abs(f.A[0]).max()) == moved  # along u only
        assert np.all(np.linalg.eigvalsh(g.A[0]) > 0)
    pecg = Sampler(prebo.System(["alpha", "e", "e"]), Optimiser(kind="pecg", channels="pairs"), np.random.default_rng(1))
    assert pecg.neighbours(pecg.fresh()) == []


@pytest.mark.parametrize("kind, particles", [("pecg", ["alpha", "e", "e"]),
                                              ("ecg-gvr", [{"name": "p", "mass": 1836.15}, {"name": "p", "mass": 1836.15}, "e", "e"])])


def test_a_function_perturbed_at_its_own_scale_keeps_its_channel_and_tail(kind, particles):
    from prebo.optimise.parametrisation import Parametrisation
    from prebo.optimise.sampler import PERTURBATION, Sampler
    system = prebo.System(particles, spin={"e": 0})
    sampler = Sampler(system, Optimiser(kind=kind, K_max=30, channels="all"), np.random.default_rng(3))
    f = sampler.fresh()
    p = Parametrisation.of(f)
    A_int, _ = p.x.from_lab(f.A[0])
    L = np.linalg.cholesky(A_int)
    logs, near = [], [g for g in sampler.perturbed(f, 300) if g.channels == f.channels]
    assert len(near) > 280  # the rest left the valid region (condition of 𝒜 above 1e8): fresh draws instead
    for g in near:
        assert np.array_equal(g.c_A, f.c_A)
        assert all(np.allclose(g.parameters[k], f.parameters[k]) for k in f.parameters)  # u and K kept
        g.validate()  # CM-separable, positive definite
        B_int, _ = p.x.from_lab(g.A[0])
        T = np.linalg.cholesky(np.linalg.solve(L, np.linalg.solve(L, B_int).T))  # L^-1 𝒜' L^-T = T T^T
        logs.append(np.log(np.diag(T)))
    logs = np.array(logs)
    assert abs(logs.mean()) < 0.15 and logs.std() == pytest.approx(PERTURBATION, rel=0.15)


def test_an_adaptive_sweep_tries_moves_of_the_function_it_may_replace():
    from prebo.integrals import laboratory
    from prebo.optimise import Expansion
    from prebo.optimise.methods import Replace, Run
    from prebo.optimise.report import Reporter
    from prebo.optimise.sampler import Sampler
    basis = prebo.Basis.load(ROOT / "examples" / "bases" / "he" / "basis.json")
    ex = Expansion(basis, laboratory(basis.system), 1e-13)
    sampler = Sampler(basis.system, resolved(Optimiser(size=len(basis)), basis.system), np.random.default_rng(2))
    seen = []
    perturbed = sampler.perturbed
    sampler.perturbed = lambda f, k: seen.append((f, k)) or perturbed(f, k)
    with Reporter(Optimiser(size=len(basis)), False) as report:
        Replace(10).step(Run(ex, sampler, report), Cursor("sweep", index=4))
    (f, k), = seen
    assert k == 10 and np.array_equal(f.A, basis.subset([4]).A)  # plain ECGs: no neighbours in K


def test_a_change_must_gain_a_hundred_times_what_it_adds_to_the_uncertainty():
    from prebo.integrals import laboratory
    from prebo.optimise import Expansion
    from prebo.optimise.expansion import SIGMA_PRICE
    basis = prebo.Basis.load(ROOT / "examples" / "bases" / "he" / "basis.json")
    ex = Expansion(basis, laboratory(basis.system), 1e-13)
    E0, sigma0 = ex.energy, ex.sigma
    for gain, sigma, kept in [(1e-11, 1e-12, False),  # beats σ, not the price of raising it
                              (1e-11, 0.5e-13, True), (2 * SIGMA_PRICE * 1e-12, 1e-12, True),
                              (1e-11, sigma0, True), (1e-13, sigma0, True), (1e-16, sigma0, False)]:
        sigma = max(sigma, sigma0)  # a price on what is added
        before = ex.snapshot()
        ex.energy, ex.sigma = E0 - gain, sigma
        assert ex.keep_if_lower(before) == kept, (gain, sigma)
        ex.energy, ex.sigma = E0, sigma0
    before = replace(ex.snapshot(), sigma=1e-13)  # an uncertain basis may still grow by what pays its small additions
    ex.energy, ex.sigma = E0 - 2e-13, 1.01e-13
    assert ex.keep_if_lower(before)


def test_a_growth_step_refines_the_newcomer_before_it_joins_and_solves_once(monkeypatch):
    """A grown function is refined against the basis it joins, then appended: one eigen-solution
    per step (not one for the raw winner, one for the basis without it and one after refinement),
    and the appended function is the refined one, below the raw winner's energy."""
    from prebo import eigen
    from prebo.integrals import laboratory
    from prebo.optimise import Expansion
    from prebo.optimise.methods import Grow, Minimiser, Run
    from prebo.optimise.report import Reporter
    from prebo.optimise.sampler import Sampler
    system = prebo.System(["p", "e", "e"], spin={"e": 0})
    basis = prebo.optimise(system, Optimiser(size=6, trials=5, seed=4), progress=False)
    opts = resolved(Optimiser(size=7, trials=5, seed=5), system)
    ex = Expansion(basis, laboratory(system), 1e-13)
    sampler = Sampler(system, opts, np.random.default_rng(5))
    trials = Sampler(system, opts, np.random.default_rng(5)).trials(5)  # the same draws as the step's
    raw = float(np.min(ex.candidates(trials)[0]))
    solves, solve = [], eigen.solve
    monkeypatch.setattr(eigen, "solve", lambda *a, **k: solves.append(1) or solve(*a, **k))
    Grow(5, Minimiser(30, "gradient")).step(Run(ex, sampler, Reporter(opts, False, 6)), Cursor("grow", target=7))
    assert len(ex.basis) == 7 and len(solves) == 1
    assert ex.energy < raw - 1e-9


def test_a_function_grown_past_the_size_is_refined_with_its_partners(monkeypatch):
    """Before the removals are weighed, each function grown past the size is refined together with
    the functions it overlaps most (else the newcomers themselves would be the cheapest to remove)."""
    from prebo.integrals import laboratory
    from prebo.optimise import Expansion
    from prebo.optimise import methods as m
    from prebo.optimise.report import Reporter
    from prebo.optimise.sampler import Sampler
    system = prebo.System(["p", "e", "e"], spin={"e": 0})
    basis = prebo.optimise(system, Optimiser(size=6, trials=5, seed=4), progress=False)
    opts = resolved(Optimiser(size=6, prune=2, refine=1, refine_group=3, trials=5, seed=5), system)
    ex = Expansion(basis, laboratory(system), 1e-13)
    calls, group = [], m.refine_group
    monkeypatch.setattr(m, "refine_group", lambda st, i, size, *a: calls.append((i, size)) or group(st, i, size, *a))
    step = m.methods(opts)["prune"]
    step.step(m.Run(ex, Sampler(system, opts, np.random.default_rng(5)), Reporter(opts, False, 6)),
              Cursor("prune", target=8))
    assert len(ex.basis) == 7 and calls == [(6, 3)]


def test_an_adaptive_pruning_keeps_the_size_and_is_undone_unless_it_gains(monkeypatch):
    """The adaptive schedule's pruning (methods.PrunePass) grows pruned(N_b) functions past the size
    and removes as many in one step; removing the dearest function instead of the cheapest makes it
    lose, and the basis before it comes back, bit for bit."""
    from prebo.integrals import laboratory
    from prebo.optimise import Expansion
    from prebo.optimise import methods as m
    from prebo.optimise.report import Reporter
    from prebo.optimise.sampler import Sampler
    system = prebo.System(["p", "e", "e"], spin={"e": 0})
    basis = prebo.optimise(system, Optimiser(size=20, trials=5, seed=4, sweeps=0), progress=False)  # grown only
    opts = resolved(Optimiser(size=20, trials=10, seed=5), system)
    assert kind_of(opts) is Adaptive and isinstance(m.methods(opts)["prune"], m.PrunePass)
    ex = Expansion(basis, laboratory(system), 1e-13)
    run = m.Run(ex, Sampler(system, opts, np.random.default_rng(5)), Reporter(opts, False, 20),
                momentum=m.Momentum(basis))
    E0, grown, removed = ex.energy, [], []
    monkeypatch.setattr(m.Expansion, "remove", lambda st, i, f=m.Expansion.remove: grown.append(len(st.basis))
                        or removed.append(i) or f(st, i))
    m.methods(opts)["prune"].step(run, Adaptive(opts).begin("prune", 20, 0))
    assert len(ex.basis) == 20 and grown == [22, 21] and ex.energy < E0  # pruned(20) = 2
    origin = np.delete(np.delete(np.r_[np.arange(20), [-1, -1]], removed[0]), removed[1])  # -1: grown
    reference = run.momentum.reference  # the momentum's reference follows the survivors (momentum.Momentum.follow)
    assert len(reference) == 20 and all(np.array_equal(reference.A[k], basis.A[j] if j >= 0 else ex.basis.A[k])
                                        for k, j in enumerate(origin))
    before, E1 = ex.basis.subset(slice(None)), ex.energy
    monkeypatch.setattr(m.np, "argmin", np.argmax)  # the removals now cost the most
    m.methods(opts)["prune"].step(run, Adaptive(opts).begin("prune", 20, 0))
    assert len(ex.basis) == 20 and ex.energy == E1 and np.array_equal(ex.basis.A, before.A)
