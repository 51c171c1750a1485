"""Optimiser: checkpoints, exact resumption after a kill, learned sampling, Powell refinement."""
import json
import signal
import subprocess
import sys
import time
from dataclasses import replace

import numpy as np
import pytest

import prebo
from prebo.errors import InputError
from prebo.optimise import Cursor, Optimiser
from prebo.optimise.adaptive import Adaptive
from prebo.optimise.defaults import resolved
from prebo.optimise.fixed import Fixed
from prebo.optimise.schedule import kind_of
from conftest import ROOT

INPUT = """
[system]
particles = ["p", "e", "e"]
[state]
spin = { e = 0 }
[basis]
type = "ecg-gvr"
size = 10
K_max = 3
[optimiser]
trials = 6
sweeps = 1
refine = 1
refine_evaluations = 30
refine_group = 2
polish = 2
polish_iterations = 5
cycles = 2
seed = 7
channels = "all"
"""


def run(*args):
    return subprocess.Popen([sys.executable, "-m", "prebo", "run", *map(str, args), "--quiet"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def functions(folder):
    return json.loads((folder / "basis.json").read_text())["functions"]


def mid_schedule(folder, seconds: float = 120) -> None:
    """Wait, at most `seconds`, until the run writing folder/basis.json has left growth or holds six
    functions: a point in the middle of INPUT's schedule to kill it at."""
    deadline = time.time() + seconds
    while time.time() < deadline:
        try:
            progress = json.loads((folder / "basis.json").read_text())["progress"]
            if progress["phase"] != "grow" or len(functions(folder)) >= 6:
                return
        except (OSError, json.JSONDecodeError, KeyError):
            pass
        time.sleep(0.01)


def test_a_killed_run_resumes_to_the_same_basis(tmp_path):
    (tmp_path / "in.toml").write_text(INPUT)
    whole = run(tmp_path / "in.toml", "--out", tmp_path / "whole")
    assert whole.wait(timeout=300) == 0, whole.stderr.read()

    killed = run(tmp_path / "in.toml", "--out", tmp_path / "killed")
    mid_schedule(tmp_path / "killed")
    killed.send_signal(signal.SIGKILL)
    killed.wait()
    cut = json.loads((tmp_path / "killed" / "basis.json").read_text())["progress"]
    assert cut["phase"] != "done", "the run ended before it was killed: nothing tested"
    resumed = subprocess.run([sys.executable, "-m", "prebo", "run", "--resume", tmp_path / "killed", "--quiet"],
                             capture_output=True, text=True)
    assert resumed.returncode == 0, resumed.stderr
    assert functions(tmp_path / "killed") == functions(tmp_path / "whole")
    a = json.loads((tmp_path / "whole" / "result.json").read_text())["energy"]
    b = json.loads((tmp_path / "killed" / "result.json").read_text())["energy"]
    assert a == b


def test_resume_without_checkpoint_is_a_clear_error(tmp_path):
    r = subprocess.run([sys.executable, "-m", "prebo", "run", "--resume", tmp_path], capture_output=True, text=True)
    assert r.returncode == 2 and "no checkpoint" in r.stderr and "Traceback" not in r.stderr


def test_a_checkpoint_holding_more_functions_than_its_size_allows_is_refused(tmp_path, capsys):
    """An edited checkpoint (size 6 → 3, six functions, still growing) resumed grew past its size;
    now it is a one-line error naming the file."""
    from prebo.cli import main
    prebo.optimise(prebo.System(["p", "e"]), Optimiser(size=6, seed=1, refine=1, polish=1), out=tmp_path / "run",
                   progress=False)
    f = tmp_path / "run" / "basis.json"
    d = json.loads(f.read_text())
    d["optimiser"]["size"], d["progress"] = 3, {"phase": "grow", "sweep": 0, "index": 0, "cycle": 0}
    f.write_text(json.dumps(d))
    assert main(["run", "--resume", str(tmp_path / "run"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert f"{f}: 6 functions, more than the run's size = 3" in err and err.count("\n") == 1, err



@pytest.fixture(scope="module")
def six(tmp_path_factory):
    """Checkpoints of six functions of H: of a fixed schedule that does not prune and of an adaptive
    one run to its end."""
    d = tmp_path_factory.mktemp("six")
    system = prebo.System(["p", "e"])
    prebo.optimise(system, Optimiser(size=6, trials=2, seed=1, refine=0, polish=0), out=d / "fixed", progress=False)
    prebo.optimise(system, Optimiser(size=6, trials=2, seed=1), out=d / "adaptive", progress=False)
    return {name: json.loads((d / name / "basis.json").read_text()) for name in ("fixed", "adaptive")}


@pytest.mark.parametrize("name", ["fixed", "adaptive"])
def test_a_checkpoint_one_function_above_its_size_is_refused_where_the_schedule_does_not_prune_past_it(
        six, tmp_path, capsys, name):
    """A checkpoint of six functions whose size is edited to 5 resumed and ended with six (so did
    one of 40 edited to 37 or 39): the margin of a pruning pass (adaptive.pruned) was granted to a
    fixed schedule that does not prune and to an adaptive one, which prunes in one step and so
    never leaves a checkpoint above its size. A fixed schedule's pruning keeps its margin: that
    checkpoint with size 5 and prune = 1, between its growth and its removal, resumes to five."""
    from prebo.cli import main
    d = json.loads(json.dumps(six[name]))
    assert len(d["functions"]) == 6
    d["optimiser"]["size"] = 5
    f = tmp_path / "basis.json"
    f.write_text(json.dumps(d))
    assert main(["run", "--resume", str(tmp_path), "--quiet", "--budget", "1e9"]) == 2
    err = capsys.readouterr().err
    assert err == f"prebo: error: {f}: 6 functions, more than the run's size = 5 allows\n"
    if name == "fixed":
        d["optimiser"]["prune"], d["progress"] = 1, {"phase": "prune", "sweep": 0, "index": 1, "cycle": 0}
        f.write_text(json.dumps(d))
        assert main(["run", "--resume", str(tmp_path), "--quiet"]) == 0
        assert len(functions(tmp_path)) == 5 and json.loads((tmp_path / "result.json").read_text())["n_basis"] == 5

def test_fixed_schedule():
    opts = resolved(Optimiser(size=2, sweeps=1, refine=2, polish=2), prebo.System(["p", "e"]))
    schedule = Fixed(opts)
    c, seen = schedule.first(), []
    nb = 0
    while c.phase != "done":
        assert schedule.stopped is None
        seen.append((c.phase, c.sweep, c.index))
        nb = min(nb + 1, 2) if c.phase == "grow" else nb
        c = schedule.advance(c, nb, -0.5, 1.0)
    assert seen == [("grow", 0, 0), ("grow", 0, 0), ("sweep", 0, 0), ("sweep", 0, 1),
                    ("refine", 0, 0), ("refine", 0, 1), ("refine", 1, 0), ("refine", 1, 1),
                    ("polish", 0, 0), ("polish", 1, 0)]
    assert schedule.stopped == "schedule" and schedule.advantage(2) is None and not schedule.stall(2)
    assert schedule.restart("grow", 2, 0.0, -1.0) is None and schedule.resume(c, "budget", 2, -0.5, 1.0) == (c, "budget")


def test_a_fixed_schedule_stores_its_own_schedule_block_and_reads_the_older_ones():
    """A fixed schedule's checkpoint holds its own "schedule" block; that of the checkpoints before
    it (an adaptive schedule's before its first pass, fixed.IDLE) and none are read too; another
    kind's block is refused, not read as the adaptive one's."""
    from prebo.optimise.fixed import IDLE
    from prebo.optimise.schedule import schedule_of
    opts = resolved(Optimiser(size=2, sweeps=1), prebo.System(["p", "e"]))
    assert Fixed(opts).to_dict() == {"schedule": "fixed"} != Adaptive(opts).to_dict()
    for block in (Fixed(opts).to_dict(), IDLE, None):
        assert isinstance(schedule_of(opts, json.loads(json.dumps(block))), Fixed)
    with pytest.raises(ValueError, match="schedule"):
        schedule_of(opts, Adaptive(opts).to_dict() | {"restarts": 1})
    assert isinstance(schedule_of(resolved(Optimiser(size=2), prebo.System(["p", "e"]))), Adaptive)


def test_the_schedule_kind_is_explicit_or_implied_as_before_and_contradictions_are_refused():
    """[optimiser] schedule names the kind; without it a fixed-schedule setting implies the fixed
    one (the inputs before it); a setting of the other kind is refused in one line naming it."""
    he = prebo.System(["alpha", "e", "e"])
    assert kind_of(Optimiser()) is Adaptive and kind_of(Optimiser(polish=1)) is Fixed
    assert kind_of(Optimiser(schedule="fixed")) is Fixed and kind_of(Optimiser(schedule="adaptive", tolerance=1e-9)) is Adaptive
    explicit = resolved(Optimiser(schedule="fixed"), he)
    assert [getattr(explicit, k) for k in ("prune", "sweeps", "refine", "polish", "cycles")] == [0, 0, 0, 0, 1]
    assert resolved(Optimiser(schedule="adaptive"), he) == replace(resolved(Optimiser(), he), schedule="adaptive")
    with pytest.raises(InputError, match=r"^\[optimiser\] sweeps = 2: a setting of the fixed schedule, but "
                                               r"schedule = 'adaptive'$"):
        Optimiser(schedule="adaptive", sweeps=2)
    with pytest.raises(InputError, match=r"^\[optimiser\] tolerance = 1e-09: a setting of the adaptive"):
        Optimiser(schedule="fixed", tolerance=1e-9)
    with pytest.raises(InputError, match="schedule"):
        Optimiser(schedule="steady")


@pytest.mark.parametrize("kind", ["fixed", "adaptive"])
def test_a_progress_block_written_before_the_cursor_fields_had_one_meaning_is_read(kind):
    """Before, `sweep` held an adaptive growth pass's target and a sweep pass's count, `cycle` its
    pass number, and a fixed pruning's `index` said growth (0) or removal (1): each schedule reads
    those blocks into the fields of one meaning."""
    opts = resolved(Optimiser(size=10, prune=2, refine=1) if kind == "fixed" else Optimiser(size=10),
                    prebo.System(["p", "e"]))
    s = Fixed(opts) if kind == "fixed" else Adaptive(opts)
    new = Cursor("refine", index=4, sweep=1, cycle=2, number=3, visited=5)
    assert s.cursor(json.loads(json.dumps(new.to_dict())), 10) == new
    if kind == "fixed":
        assert s.cursor({"phase": "prune", "sweep": 0, "index": 0, "cycle": 1}, 10) == Cursor("prune", target=12, cycle=1)
        assert s.cursor({"phase": "prune", "sweep": 0, "index": 1, "cycle": 1}, 11) == Cursor("prune", target=10, cycle=1)
        assert s.cursor({"phase": "refine", "sweep": 1, "index": 4, "cycle": 2}, 10) == Cursor("refine", index=4, sweep=1,
                                                                                               cycle=2)
        assert s.cursor({"phase": "grow", "sweep": 0, "index": 0, "cycle": 0}, 3) == s.first()
    else:
        assert s.cursor({"phase": "grow", "sweep": 9, "index": 0, "cycle": 3}, 8) == Cursor("grow", target=9, number=3)
        assert s.cursor({"phase": "sweep", "sweep": 6, "index": 7, "cycle": 4}, 10) == Cursor("sweep", index=7, number=4,
                                                                                              visited=6)
        assert s.cursor({"phase": "prune", "sweep": 0, "index": 0, "cycle": 5}, 10) == s.begin("prune", 10, 5)
    with pytest.raises(TypeError):
        s.cursor({"phase": "grow", "steps": 1}, 3)


def test_a_fixed_schedule_repeats_the_block_after_growth_in_cycles():
    opts = resolved(Optimiser(size=1, sweeps=1, refine=0, polish=1, cycles=3), prebo.System(["p", "e"]))
    schedule = Fixed(opts)
    c, seen = schedule.advance(Cursor(), 1, -0.5, 0.0), []
    while c.phase != "done":
        seen.append((c.phase, c.sweep, c.index, c.cycle))
        c = schedule.advance(c, 1, -0.5, 0.0)
    assert seen == [(phase, 0, 0, cycle) for cycle in range(3) for phase in ("sweep", "polish")]
    assert Cursor(**{"phase": "polish", "sweep": 0, "index": 0}).cycle == 0  # checkpoints before cycles


def test_each_cycle_grows_past_the_size_and_prunes_back_first():
    opts = resolved(Optimiser(size=3, prune=2, refine=1, cycles=2), prebo.System(["p", "e"]))
    schedule = Fixed(opts)
    c, seen, nb = schedule.first(), [], 0
    while c.phase != "done":
        seen.append((c.phase, c.target, c.index, c.cycle, nb))
        nb += 1 if c.phase == "grow" or (c.phase == "prune" and nb < c.target) else -1 if c.phase == "prune" else 0
        c = schedule.advance(c, nb, -0.5, 0.0)
    block = [("prune", 5, 0, 3), ("prune", 5, 0, 4), ("prune", 3, 0, 5), ("prune", 3, 0, 4)] + [("refine", 0, i, 3)
                                                                                                for i in range(3)]
    assert seen == [("grow", 3, 0, 0, k) for k in range(3)] + [(p, t, i, cycle, n) for cycle in (0, 1)
                                                              for p, t, i, n in block]


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


def test_the_progress_line_starts_at_the_size_of_the_basis_a_run_resumes_from():
    from prebo.optimise.report import Reporter
    with Reporter(Optimiser(size=600), True, 600) as report:
        task = report.progress.tasks[0]
        assert (task.completed, task.total) == (600, 600)
    with Reporter(Optimiser(size=40), True) as report:  # a new run grows from nothing
        assert (report.progress.tasks[0].completed, report.progress.tasks[0].total) == (0, 40)



def test_the_progress_line_is_what_the_schedule_says():
    """The progress line's description and counts come from the schedule (Schedule.progress): a
    fixed schedule counts the functions of a sweep and the steps of a joint pass, the adaptive one
    the functions of a pass of at most CHUNK; growth counts functions to the size in both."""
    from prebo.optimise.adaptive import CHUNK
    from prebo.optimise.fixed import Fixed
    opts = Optimiser(size=80, polish=4)
    fixed, adaptive = Fixed(opts), Adaptive(opts)
    assert fixed.progress(Cursor("grow"), 30) == adaptive.progress(Cursor("grow"), 30) == ("growing", 30, 80)
    assert fixed.progress(Cursor("refine", sweep=1, index=9, cycle=2), 80) == ("refine 2 (cycle 3)", 10, 80)
    assert fixed.progress(Cursor("polish", sweep=2, cycle=0), 80) == ("polish (cycle 1)", 3, 4)
    assert fixed.progress(Cursor("prune", target=80, cycle=0), 83) == ("prune (cycle 1)", 3, opts.prune)
    assert adaptive.progress(Cursor("sweep", visited=4, number=6), 80) == ("sweep (pass 7)", 5, min(CHUNK, 80))
    assert adaptive.progress(Cursor("momentum", number=1), 80) == ("momentum (pass 2)", 1, 1)

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


def test_a_checkpoint_has_a_line_per_key_and_per_function():
    """basis.json as write_json_atomic lays it out: strict JSON, a line per top-level key and per
    element of the function list (compact lines keep json's C encoder: indent would not)."""
    import tempfile
    from pathlib import Path
    basis = prebo.Basis.load(ROOT / "examples" / "bases" / "h2plus-gvr" / "basis.json")
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "basis.json"
        basis.save(path)
        text = path.read_text()
    d = json.loads(text)
    assert d["functions"] == json.loads((ROOT / "examples" / "bases" / "h2plus-gvr" / "basis.json").read_text())["functions"]
    lines = text.splitlines()
    assert len(lines) == 2 + len(d) + 1 + len(d["functions"])  # braces, keys, the list's closing bracket


def test_history_rows_are_named_in_memory_and_stored_as_they_were(tmp_path):
    """history.Step names a row's fields; written back, a checkpoint's rows are the lists it held,
    a row per line, the three-long rows of checkpoints before wall times included."""
    from prebo.io.files import write_json_atomic
    from prebo.optimise.history import Step, check_history
    rows = [[1, -0.4, "grow"], [2, -0.45, "grow", 1.5], [2, -0.47, "refine", 3.0]]
    steps = [Step(*row) for row in check_history(json.loads(json.dumps(rows)))]
    assert [(h.size, h.energy, h.phase, h.seconds) for h in steps] == [(1, -0.4, "grow", None), (2, -0.45, "grow", 1.5),
                                                                        (2, -0.47, "refine", 3.0)]
    assert steps[1] == Step(2, -0.45, "grow", 1.5) and Step(1, -0.4, "grow").row() == [1, -0.4, "grow"]
    write_json_atomic(tmp_path / "h.json", {"history": [step.row() for step in steps]})
    written = (tmp_path / "h.json").read_text()
    write_json_atomic(tmp_path / "h.json", {"history": rows})
    assert written == (tmp_path / "h.json").read_text() and len(written.splitlines()) == 4 + len(rows)  # a row per line


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


def test_a_run_that_stops_above_its_lowest_state_returns_that_state_and_keeps_it_in_lowest_json(tmp_path, monkeypatch):
    """A fixed-schedule pruning that raises the energy (made to remove the dearest functions)
    leaves the run above the state it pruned: the run returns that state, out/lowest.json holds
    it beside the checkpoint, and a resumed run returns it too."""
    from prebo import eigen
    from prebo.optimise import optimise, resume_from

    without = eigen.root_without_each
    monkeypatch.setattr(eigen, "root_without_each", lambda E, C, root=0: -without(E, C, root))
    system = prebo.System(["p", "e"])
    basis = optimise(system, Optimiser(size=3, prune=2, cycles=1, trials=5, seed=3), out=tmp_path, progress=False)
    checkpoint = json.loads((tmp_path / "basis.json").read_text())
    lowest = json.loads((tmp_path / "lowest.json").read_text())
    grown = [h for h in checkpoint["history"] if h[2] == "grow"][-1]  # the state the pruning started from
    assert grown[0] == 3 and lowest["energy"] == grown[1] < checkpoint["energy"]
    assert len(basis) == 3 and prebo.evaluate(basis)["energy"] == pytest.approx(lowest["energy"], rel=1e-14)
    assert prebo.evaluate(prebo.Basis.load(tmp_path / "lowest.json"))["energy"] == pytest.approx(lowest["energy"],
                                                                                                 rel=1e-14)
    again, _ = resume_from(tmp_path, progress=False)
    assert prebo.evaluate(again)["energy"] == pytest.approx(lowest["energy"], rel=1e-14)


def test_optimise_refuses_an_out_of_the_wrong_type_and_one_holding_a_checkpoint(tmp_path):
    """optimise(..., out=5) raised TypeError, and a new run into a folder holding a checkpoint
    overwrote that run; resuming it is still possible."""
    from prebo.errors import InputError, OutputError
    from prebo.optimise import optimise, resume_from

    h, opts = prebo.System(["p", "e"]), Optimiser(size=2, trials=2, seed=1)
    for bad in (5, 2.5, ["runs"]):
        with pytest.raises(InputError, match=r"optimise: out = .*: must be a folder \(a str or path\), or None"):
            optimise(h, opts, out=bad, progress=False)
    optimise(h, opts, out=tmp_path, progress=False)
    before = (tmp_path / "basis.json").read_bytes()
    with pytest.raises(OutputError, match=r"out = '.*' holds a run's checkpoint \(basis.json\): continue that run "
                                          r"with resume_from\(out\)"):
        optimise(h, opts, out=str(tmp_path), progress=False)
    assert (tmp_path / "basis.json").read_bytes() == before
    assert len(resume_from(tmp_path, progress=False)[0]) == 2


def test_optimise_refuses_an_empty_out_and_resume_from_a_folder_that_is_not_a_path(tmp_path, monkeypatch):
    """optimise(..., out="") wrote its checkpoint into the current folder; resume_from(5) raised TypeError."""
    from prebo.errors import InputError
    from prebo.optimise import optimise, resume_from

    monkeypatch.chdir(tmp_path)
    with pytest.raises(InputError, match=r"optimise: out = '': empty; must be a folder \(a str or path\), or None"):
        optimise(prebo.System(["p", "e"]), Optimiser(size=2, trials=2, seed=1), out="", progress=False)
    assert not list(tmp_path.iterdir())
    for bad in (5, None, ["runs"], ""):
        with pytest.raises(InputError, match=r"resume_from: folder = .*must be a folder \(a str or path\)"):
            resume_from(bad, progress=False)


def test_lowest_json_is_written_when_the_run_leaves_its_lowest_state_and_removed_when_it_is_back(tmp_path):
    """lowest.Lowest: a state above the lowest, or of more than `size` functions, writes the
    lowest to lowest.json; a state as low at the size removes it; a fresh run's tracker removes a
    file an earlier run left, a resumed run's reads it back and refuses one of another system."""
    from types import SimpleNamespace
    from prebo.optimise.lowest import Lowest

    basis = prebo.Basis.load(ROOT / "examples/bases/h/basis.json")

    def state(n, energy):
        return SimpleNamespace(basis=basis.subset(slice(0, n)), energy=energy, coefficients=np.eye(n)[:, 0],
                               lowest_root=energy, objective=SimpleNamespace(lowest=True))

    lowest, path = Lowest(basis, 3, tmp_path, {"optimiser": {}}, resumed=False), tmp_path / "lowest.json"
    lowest.see(state(3, -0.4))
    assert not path.exists() and lowest.energy == -0.4
    lowest.see(state(4, -0.45))  # beyond the size: not a candidate, the lowest is written
    assert json.loads(path.read_text())["energy"] == -0.4 and len(lowest.basis) == 3
    assert Lowest(basis, 3, tmp_path, {}, resumed=True).energy == -0.4
    with pytest.raises(prebo.errors.BasisFileError, match="lowest.json: not a state of this run"):
        Lowest(prebo.Basis.empty(prebo.System(["alpha", "e", "e"], spin={"e": 0})), 3, tmp_path, {}, resumed=True)
    lowest.see(state(3, -0.3))
    assert lowest.energy == -0.4 and path.exists()
    lowest.see(state(2, -0.4))  # back as low: the run stands at its lowest, the file goes
    assert not path.exists() and len(lowest.basis) == 2
    lowest.see(state(3, -0.2))
    assert path.exists()
    assert Lowest(basis, 3, tmp_path, {}, resumed=False).energy == np.inf and path.exists()  # a new run's own


def test_a_whole_basis_with_a_function_the_symmetriser_annihilates_is_not_taken():
    """Expansion.replace_basis (joint steps, momentum moves) refuses a basis in which a function lost
    its digits to the symmetriser (what prebo.evaluate would refuse at the end of the run): a triplet's
    function symmetric in the two electrons to 1e-9 is annihilated to 1e-9 of its norm."""
    from conftest import pair_A
    from prebo.basis import Basis
    from prebo.integrals import laboratory
    from prebo.optimise.expansion import Expansion

    system = prebo.System(["alpha", "e", "e"], spin={"e": 1})
    A = [pair_A(system, {(0, 1): a1, (0, 2): a2, (1, 2): 0.1}, 1.0) for a1, a2 in ((1.0, 0.3), (2.0, 0.5), (0.8, 0.2))]
    basis = Basis(system, np.array(A), np.ones(3), ["pairs"] * 3)
    ex = Expansion(basis, laboratory(system), 4 * 2.0**-53)
    energy = ex.energy
    symmetric = pair_A(system, {(0, 1): 0.7, (0, 2): 0.7 * (1 + 1e-9), (1, 2): 0.1}, 1.0)
    moved = Basis(system, np.array(A[:2] + [symmetric]), np.ones(3), ["pairs"] * 3)
    assert not ex.replace_basis(moved)
    assert ex.energy == energy and np.array_equal(ex.basis.A, basis.A) and ex.resolved()
