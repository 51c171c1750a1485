"""The schedule that chooses itself (issue 17): settings chosen from the physics (optimise.defaults),
sampling lengths from each pair's Bohr radius (sampler.pair_lengths), the adaptive schedule
(optimise.adaptive), the wall-time budget and the convergence report (optimise.convergence)."""
import json
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest

import prebo
from prebo import eigen
from prebo.basis import Basis
from prebo.optimise import Cursor, Optimiser, resume_from
from prebo.optimise.convergence import convergence
from prebo.optimise.defaults import resolved
from prebo.optimise.schedule import kind_of
from prebo.optimise.sampler import pair_lengths
from prebo.optimise.momentum import EVERY
from prebo.optimise.adaptive import CHUNK, GROUP, PRUNE, RATIO, REVISIT, TRIALS, Adaptive, Pass, pruned
from prebo.optimise.fixed import Fixed
from prebo.optimise.history import Step

from conftest import ROOT

LI7 = {"name": "li7", "mass": 12786.39227775, "charge": 3, "spin": 1.5}


# --- settings chosen for the system ---------------------------------------------------------
def test_a_molecule_gets_ecg_gvr_functions_with_powers_from_its_nuclear_mass():
    for particles in (["p", "p", "e"], ["p", "p", "e", "e"], ["d", "d", "e"]):
        opts = resolved(Optimiser(), prebo.System(particles))
        m = prebo.System(particles).masses
        mu = m[0] * m[1] / (m[0] + m[1])
        assert (opts.kind, opts.channels, opts.trials) == ("ecg-gvr", "all", TRIALS)
        assert resolved(Optimiser(refine=1), prebo.System(particles)).trials == 30  # a fixed schedule
        assert opts.K_max == int(np.ceil(np.sqrt(mu)))  # 31 for H2, as the paper's 30; 43 for D2+
    assert resolved(Optimiser(), prebo.System(["p", "p", "e"])).K_max == 31


def test_the_default_threshold_keeps_every_direction_a_run_grows_into():
    """Issue 37, case 14: the He basis of 700 functions the adaptive schedule grew (overlap condition
    6.1e13, past 1/1e-13, the former default) is evaluated with every direction by default, to the
    energy the run optimised (to the ulp the refinement stops at: Haswell's kernel gives one ulp
    more); 1e-13 dropped two directions worth 7.2e-11 Eh and stopped growth."""
    folder = ROOT / "examples" / "bases" / "auto-he-700"
    basis = Basis.load(folder / "basis.json")
    assert Optimiser().threshold == eigen.THRESHOLD
    r = prebo.evaluate(basis)
    assert r["overlap_condition"] > 1e13 and r["kept"] == len(basis) == 700
    stored = json.loads((folder / "basis.json").read_text())["energy"]
    assert abs(r["energy"] - stored) <= 2 * np.spacing(abs(stored))  # the refinement's stop: an ulp on any BLAS kernel


def test_an_atom_gets_plain_ecgs_and_a_p_state_ecg_gvr_functions_without_powers():
    for particles in (["alpha", "e", "e"], [LI7, "e", "e", "e"], ["e+", "e", "e"], ["p", "mu", "e"]):
        opts = resolved(Optimiser(), prebo.System(particles))
        assert (opts.kind, opts.K_max, opts.channels, opts.trials) == ("pecg", 0, "pairs", TRIALS), particles
        assert resolved(Optimiser(refine=1), prebo.System(particles)).trials == 20  # a fixed schedule
    opts = resolved(Optimiser(), prebo.System(["p", "e"], N=1, parity=-1))
    assert (opts.kind, opts.K_max) == ("ecg-gvr", 0)


def test_explicit_settings_override_and_any_schedule_setting_fixes_the_schedule():
    h2 = prebo.System(["p", "p", "e", "e"])
    opts = resolved(Optimiser(kind="pecg", channels="pairs", trials=7, K_max=2), h2)
    assert (opts.kind, opts.channels, opts.trials, opts.K_max) == ("pecg", "pairs", 7, 2)
    assert kind_of(opts) is Adaptive and opts.refine_evaluations == 30 and opts.sweeps is None
    assert opts.refine_group == GROUP > 1  # the adaptive refinement passes move groups
    fixed = resolved(Optimiser(refine=2), h2)
    assert kind_of(fixed) is Fixed and (fixed.sweeps, fixed.refine, fixed.polish, fixed.cycles) == (0, 2, 0, 1)
    assert fixed.refine_evaluations == 200 and fixed.refine_group == 1
    assert resolved(Optimiser(refine_group=1), h2).refine_group == 1  # given, it stays
    assert resolved(fixed, h2) == fixed and resolved(opts, h2) == opts  # a checkpoint's settings stay
    assert opts.batch == fixed.batch == 1  # one process: a function at a time
    assert resolved(Optimiser(batch=4), h2).batch == 4


# --- lengths from the physics --------------------------------------------------------------
def test_an_attractive_pair_is_drawn_from_its_bohr_radius():
    for particles, Z in ((["p", "mu"], 1.0), (["alpha", "e"], 2.0), (["e+", "e"], 1.0), (["p", "pbar"], 1.0)):
        s = prebo.System(particles)
        m = s.masses
        a, outer = pair_lengths(s)
        assert a[0, 1] == pytest.approx((m[0] + m[1]) / (m[0] * m[1] * Z))
        assert outer[0, 1] == pytest.approx(a[0, 1])  # two particles: nothing screens
    a, _ = pair_lengths(prebo.System(["p", "p", "mu"]))
    assert a[0, 1] == a[0, 2] < 0.006  # muonic: 186 times smaller than the electron's, not capped at it


def test_screening_sets_the_outer_length_and_like_charges_move_on_their_partners_lengths():
    a, outer = pair_lengths(prebo.System([LI7, "e", "e", "e"]))
    assert a[0, 1] == pytest.approx(1 / 3, rel=1e-3) and outer[0, 1] == pytest.approx(1.0, rel=1e-3)  # Z = 3 − 2
    assert (a[1, 2], outer[1, 2]) == (a[0, 1], outer[0, 1])  # electrons move on their nucleus's lengths
    a, outer = pair_lengths(prebo.System(["p", "e", "e"]))
    assert outer[0, 1] == pytest.approx(2 * a[0, 1])  # H⁻: the outer electron held by polarisation, Z = 1/2
    a, outer = pair_lengths(prebo.System(["p", "p", "e", "e"]))
    assert a[0, 1] == pytest.approx(a[0, 2]) and outer[0, 1] == pytest.approx(outer[0, 2])  # the bond: ~1 bohr


def test_the_sampler_draws_every_pair_within_its_range():
    s = prebo.System(["p", "mu", "e"])
    opts = resolved(Optimiser(length_range=(0.5, 2.0)), s)
    from prebo.optimise.sampler import Sampler
    sampler = Sampler(s, opts, np.random.default_rng(1))
    for i, j in sampler.pairs:
        b = [sampler._b(i, j) for _ in range(200)]
        assert 0.5 * sampler.a[i, j] <= min(b) and max(b) <= 2.0 * sampler.a_outer[i, j]


# --- the adaptive schedule -------------------------------------------------------------------
def passes(schedule, *rows):
    """Record passes (kind, nb, gain, seconds) one after another, as the driver would (the first
    from no function: no energy before it)."""
    E, t = (schedule.passes[-1].after, schedule.passes[-1].end) if schedule.passes else (None, 0.0)
    for kind, nb, gain, seconds in rows:
        after = -1.0 if E is None else E - gain
        schedule.passes.append(Pass(kind, nb, E, after, t, t + seconds, nb if kind in ("grow", "polish", "prune") else
                                    min(CHUNK, nb)))
        E, t = after, t + seconds
    return E


def now(schedule):
    """The seconds of the run at the end of the last recorded pass."""
    return schedule.passes[-1].end if schedule.passes else 0.0


def test_growth_first_then_every_kind_once_then_the_best_rate():
    s = Adaptive(resolved(Optimiser(size=100), prebo.System(["alpha", "e", "e"])))
    assert s.first() == Cursor("grow", target=8)
    assert s.choose(0, np.inf, now(s)) == "grow"
    E = passes(s, ("grow", 8, None, 1.0))
    assert [s.choose(8, E, now(s)), s.begin("refine", 8, 1)] == ["refine", Cursor("refine", number=1)]
    E = passes(s, ("refine", 8, 1e-3, 1.0), ("sweep", 8, 1e-3, 2.0), ("polish", 8, 1e-4, 1.0))
    assert s.choose(8, E, now(s)) == "grow"  # the first growth pass: no energy before it, an unbounded rate
    E = passes(s, ("grow", 16, 1e-4, 1.0))  # growth slows: refinement (1e-3 Eh/s) pays best now
    assert s.choose(16, E, now(s)) == "refine"
    assert s.begin("grow", 80, 9) == Cursor("grow", target=100, number=9)  # a quarter, capped at size


def test_a_pass_ends_after_a_chunk_and_the_next_sweep_goes_on_where_it_stopped():
    opts = resolved(Optimiser(size=120), prebo.System(["alpha", "e", "e"]))
    s = Adaptive(opts)
    passes(s, ("grow", 120, None, 1.0), ("refine", 120, 1e-3, 1.0), ("sweep", 120, 1e-3, 1.0), ("polish", 120, 1, 1))
    c = Cursor("refine", index=100, number=4)
    for k in range(CHUNK - 1):
        c = s.advance(c, 120, -3.0, 20.0)
        assert (c.phase, c.visited, c.index) == ("refine", k + 1, (101 + k) % 120)
    c = s.advance(c, 120, -3.0, 20.0)
    assert s.passes[-1].kind == "refine" and s.passes[-1].functions == CHUNK and c.number == 5
    assert s.next["refine"] == (100 + CHUNK) % 120 and s.begin("refine", 120, 6).index == 30
    grow = Cursor("grow", target=10, number=7)
    assert s.advance(grow, 9, -3.0, 21.0) == grow  # growth goes on to its target size


def test_a_batch_of_refinements_moves_a_sweep_on_by_the_functions_it_visited():
    """methods.Refine with batch > 1 visits several functions in one unit of work; both
    schedules go on after them, and the adaptive pass ends once it visited a chunk."""
    opts = resolved(Optimiser(size=120), prebo.System(["alpha", "e", "e"]))
    s = Adaptive(opts)
    passes(s, ("grow", 120, None, 1.0), ("refine", 120, 1e-3, 1.0), ("sweep", 120, 1e-3, 1.0), ("polish", 120, 1, 1))
    c = s.advance(Cursor("refine", index=100, number=4), 120, -3.0, 20.0, functions=20)
    assert (c.phase, c.visited, c.index) == ("refine", 20, 0)
    c = s.advance(c, 120, -3.0, 20.0, functions=CHUNK - 20)
    assert s.passes[-1].functions == CHUNK and s.next["refine"] == CHUNK - 20 and c.number == 5
    fixed = Fixed(resolved(Optimiser(size=5, refine=2), prebo.System(["p", "e"])))
    assert fixed.advance(Cursor("refine"), 5, -0.5, 1.0, functions=3) == Cursor("refine", index=3)
    assert fixed.advance(Cursor("refine", index=3), 5, -0.5, 1.0, functions=2) == Cursor("refine", sweep=1)


def test_a_pruning_is_one_pass_of_one_step_at_full_size():
    s = Adaptive(resolved(Optimiser(size=120), prebo.System(["alpha", "e", "e"])))
    passes(s, ("grow", 120, None, 1.0), ("refine", 120, 1e-3, 1.0), ("sweep", 120, 1e-3, 1.0), ("polish", 120, 1, 1))
    assert s.choose(120, -3.0, 4.0) == "prune" and s.choose(119, -3.0, 4.0) == "grow"  # only at full size
    assert pruned(120) == 12 and pruned(500) == PRUNE and pruned(5) == 1
    c = s.advance(s.begin("prune", 120, 4), 120, -3.5, 6.0)
    p = s.passes[-1]
    assert (p.kind, p.size, p.after, p.end, p.functions) == ("prune", 120, -3.5, 6.0, 120) and c.number == 5  # visits every function


def test_at_full_size_the_basis_moves_on_after_every_EVERY_passes_that_moved_functions_since_a_move_or_pruning():
    s = Adaptive(resolved(Optimiser(size=120), prebo.System(["alpha", "e", "e"])))
    E = passes(s, ("grow", 120, None, 1.0), ("refine", 120, 1e-3, 1.0), ("sweep", 120, 1e-4, 1.0),
               ("polish", 120, 1e-4, 1), ("prune", 120, 1e-5, 1))
    kinds = ("refine", "sweep", "polish")
    for k in range(EVERY - 1):
        E = passes(s, (kinds[k % 3], 120, 1e-3, 1.0))
        assert s.choose(120, E, now(s)) != "momentum"
    E = passes(s, ("sweep", 120, 1e-3, 1.0))
    assert s.choose(120, E, now(s)) == "momentum" and s.choose(119, E, now(s)) != "momentum"  # full size only
    c = s.advance(s.begin("momentum", 120, 9), 120, E - 1e-2, now(s) + 1.0)
    assert s.passes[-1].kind == "momentum" and s.passes[-1].functions == 120 and c.phase == "refine"  # its rate is not used
    E = passes(s, *[("refine", 120, 1e-3, 1.0)] * (EVERY - 1), ("prune", 120, 1e-3, 1.0), ("refine", 120, 1e-3, 1.0))
    assert s.choose(120, E, now(s)) != "momentum"  # counted again from the pruning
    assert Adaptive.check(s.opts, json.loads(json.dumps(s.to_dict()))).passes == s.passes


def test_a_move_s_gain_is_shared_among_the_passes_whose_displacement_it_extrapolated():
    """Refinement gains half as much per second as the replacement sweeps, but the move after two
    refinement passes gains twice their gain, the one after two sweeps nothing: refinement's rate,
    three times its own, is the best. Its next pass, before its move, counts with that factor."""
    s = Adaptive(resolved(Optimiser(size=100), prebo.System(["alpha", "e", "e"])))
    E = passes(s, ("grow", 100, None, 1.0), ("polish", 100, 1e-6, 10.0), ("prune", 100, 1e-6, 10.0),
               ("refine", 100, 1e-4, 10.0), ("refine", 100, 1e-4, 10.0), ("momentum", 100, 4e-4, 1.0),
               ("sweep", 100, 2e-4, 10.0), ("sweep", 100, 2e-4, 10.0), ("momentum", 100, 0.0, 1.0))
    assert s.rates()["refine"] == pytest.approx(3e-5) and s.rates()["sweep"] == pytest.approx(2e-5)
    assert s.choose(100, E, now(s)) == "refine"
    E = passes(s, ("refine", 100, 0.5e-4, 10.0))  # its move not come yet
    assert s.rates()["refine"] == pytest.approx(1.5e-5) and s.choose(100, E, now(s)) == "sweep"


def test_a_kind_not_run_for_REVISIT_times_its_shortest_recent_pass_is_tried_again():
    """Refinement's last pass took 40 s (a busy machine, say) and gained at 1/40 of the
    replacements' rate: it is tried again once REVISIT × 10 s (its pass before) have passed without
    it, not before; the joint step and the pruning, whose last passes took 100 s, wait longer."""
    s = Adaptive(resolved(Optimiser(size=100), prebo.System(["alpha", "e", "e"])))
    E = passes(s, ("grow", 100, None, 1.0), ("polish", 100, 1e-5, 100.0), ("prune", 100, 1e-5, 100.0),
               ("refine", 100, 1e-4, 10.0), ("refine", 100, 1e-4, 40.0))
    refined = now(s)
    while (kind := s.choose(100, E, now(s))) in ("sweep", "momentum"):
        assert now(s) - refined <= REVISIT * 10.0
        E = passes(s, ("sweep", 100, 1e-4, 1.0) if kind == "sweep" else ("momentum", 100, 1e-6, 0.01))
    assert kind == "refine" and now(s) - refined > REVISIT * 10.0


def test_the_basis_is_exhausted_when_every_kind_gains_less_than_a_tenth_of_growth_or_the_tolerance():
    opts = resolved(Optimiser(size=100), prebo.System(["alpha", "e", "e"]))
    s = Adaptive(opts)
    E = passes(s, ("grow", 80, None, 1.0), ("grow", 100, 1e-3, 1.0), ("refine", 100, 2e-4, 1.0),
               ("sweep", 100, 1e-4, 1.0), ("polish", 100, 1e-4, 1.0))
    assert s.choose(100, E, now(s)) == "prune"  # at full size the pruning is tried too
    E = passes(s, ("prune", 100, 1e-4, 1.0))
    assert s.choose(100, E, now(s)) == "refine"
    E = passes(s, ("refine", 100, 0.5 * RATIO * 1e-3, 1.0), ("sweep", 100, 0.5 * RATIO * 1e-3, 1.0),
               ("polish", 100, 0.9 * RATIO * 1e-3, 1.0), ("prune", 100, 0.5 * RATIO * 1e-3, 1.0))
    assert s.choose(100, E, now(s)) is None and s.stopped == "exhausted"
    assert s.advantage(100) == pytest.approx(1e-3 / (0.9 * RATIO * 1e-3))
    assert s.choose(99, E, now(s)) == "grow"  # below full size the basis grows instead

    t = Adaptive(resolved(Optimiser(size=8, tolerance=1e-6), prebo.System(["alpha", "e", "e"])))
    E = passes(t, ("grow", 8, None, 1.0), ("refine", 8, 2e-6, 1.0), ("sweep", 8, 1e-7, 1.0), ("polish", 8, 1e-7, 1.0),
               ("prune", 8, 1e-7, 1.0))
    assert t.choose(8, E, now(t)) == "refine"  # one pass in one growth step: no growth rate, the tolerance decides
    E = passes(t, ("refine", 8, 5e-7, 1.0))
    assert t.choose(8, E, now(t)) is None and t.stopped == "converged"


def test_a_budget_overrides_exhaustion_until_the_time_left_would_gain_less_than_the_tolerance():
    """The rates of the exhausted basis above, but with a budget: the run goes on while the best
    kind's last rate times the seconds left exceeds the tolerance, and then ends as its budget does."""
    he = prebo.System(["alpha", "e", "e"])
    rows = (("grow", 80, None, 1.0), ("grow", 100, 1e-3, 1.0), ("refine", 100, 0.5 * RATIO * 1e-3, 1.0),
            ("sweep", 100, 0.5 * RATIO * 1e-3, 1.0), ("polish", 100, 0.9 * RATIO * 1e-3, 1.0),
            ("prune", 100, 0.5 * RATIO * 1e-3, 1.0))
    s = Adaptive(resolved(Optimiser(size=100, budget=600.0), he))
    E = passes(s, *rows)
    assert s.choose(100, E, now(s)) == "polish" and s.stopped is None  # 1.8e-5 Eh/s for 595 s more
    assert s.advantage(100) > 1 / RATIO  # the report still says a larger basis would gain faster
    tolerance = s.tolerance(E)
    end = 600.0 - 0.5 * tolerance / (0.9 * RATIO * 1e-3)  # half the tolerance left to gain
    assert s.choose(100, E, end) is None and s.stopped == "budget"
    s.opts = replace(s.opts, budget=1200.0)  # resumed with a larger budget (driver.optimise): it goes on
    cursor, stopped = s.resume(Cursor("done"), "budget", 100, E, end)
    assert cursor.phase in ("refine", "sweep", "polish", "prune") and stopped is None
    assert s.resume(Cursor("done"), "converged", 100, E, end) == (Cursor("done"), "converged")  # it stays converged


def test_a_budget_is_used_while_the_passes_still_gain():
    """Issue 37, case 14: He with 700 functions at 2.2e-10 Eh above the exact energy, 192 s into a
    300-s budget, every kind's last pass gaining ~3e-11 Eh per sweep of the basis: the run goes on
    (the old default tolerance, 1e-10 |E| = 2.9e-10 Eh, called it converged)."""
    he = prebo.System(["alpha", "e", "e"], spin={"e": 0})
    s = Adaptive(resolved(Optimiser(size=700, budget=300.0), he))
    s.passes.append(Pass("grow", 700, -2.9033045, -2.9033045575, 0.0, 150.0, 700))
    E = passes(s, ("refine", 700, 2e-12, 10.0), ("sweep", 700, 2e-12, 12.0), ("polish", 700, 1e-13, 10.0),
               ("prune", 700, 1e-12, 10.0))
    assert 700 / CHUNK * 2e-12 < 1e-10 * abs(E) and now(s) == 192.0
    assert s.choose(700, E, now(s)) in ("refine", "sweep", "momentum") and s.stopped is None


def test_without_a_growth_rate_the_best_rate_at_full_size_is_the_reference():
    """A basis grown in one pass (no energy before it, no rate) is exhausted when every kind gains
    less than RATIO of the best rate seen at full size, though each still gains above the tolerance."""
    s = Adaptive(resolved(Optimiser(size=6), prebo.System(["p", "e", "e"])))
    E = passes(s, ("grow", 6, None, 1.0), ("refine", 6, 1e-2, 1.0), ("sweep", 6, 1e-3, 1.0), ("polish", 6, 1e-3, 1.0),
               ("prune", 6, 0.5 * RATIO * 1e-2, 1.0))
    assert s.choose(6, E, now(s)) == "refine"
    E = passes(s, ("refine", 6, 0.9 * RATIO * 1e-2, 1.0), ("sweep", 6, 0.5 * RATIO * 1e-2, 1.0))
    if s.choose(6, E, now(s)) == "momentum":  # after EVERY = 2 passes that moved functions
        E = passes(s, ("momentum", 6, 0.0, 0.01))
    assert s.choose(6, E, now(s)) == "polish"  # polish's last rate, 1e-3, is above RATIO of the best
    E = passes(s, ("polish", 6, 0.5 * RATIO * 1e-2, 1.0))
    assert 0.5 * RATIO * 1e-2 > s.tolerance(E)
    assert s.choose(6, E, now(s)) is None


@pytest.mark.parametrize("block", [
    {"passes": [], "start": [None, 0.0]},  # no "next"
    {"passes": [["grow", 1, None, -1.0, 0.0, 1.0]], "start": [None, 0.0], "next": {"refine": 0, "sweep": 0}},
    {"passes": [["jump", 1, None, -1.0, 0.0, 1.0, 1]], "start": [None, 0.0], "next": {"refine": 0, "sweep": 0}},
    {"passes": [["grow", 1, None, None, 0.0, 1.0, 1]], "start": [None, 0.0], "next": {"refine": 0, "sweep": 0}},
    {"passes": [], "start": [None, -1.0], "next": {"refine": 0, "sweep": 0}},
    {"passes": [], "start": [None, 0.0], "next": {"refine": -1, "sweep": 0}},
    {"passes": [], "start": [None, 0.0], "next": {"refine": 0, "sweep": 0}, "restarts": -1},
    [], "x",
])
def test_a_malformed_schedule_block_is_refused(block):
    with pytest.raises(ValueError, match="schedule must be"):
        Adaptive.check(Optimiser(), block)
    good = {"passes": [["grow", 1, None, -1.0, 0.0, 1.0, 1]], "start": [-1.0, 1.0], "next": {"refine": 0, "sweep": 0}}
    assert Adaptive.check(Optimiser(), good).passes == [Pass("grow", 1, None, -1.0, 0.0, 1.0, 1)]
    assert json.loads(json.dumps(Adaptive.check(Optimiser(), good).to_dict())) == good | {"stalled": None, "restarts": 0}


# --- the convergence report ------------------------------------------------------------------
def test_the_extrapolation_is_exact_for_geometrically_falling_gains():
    """Gains falling by q per equal span of time: Aitken's Δ² gives the remaining g q/(1 − q) exactly."""
    E_inf, q = -2.0, 0.5
    history = [Step(5, -1.0, "grow", 1.0)] + [Step(10, E_inf + q ** (k / 10), "refine", 10.0 + k) for k in range(31)]
    r = convergence(history, Optimiser(), "exhausted", 40.0)
    assert r["extrapolation"]["remaining"] == pytest.approx(history[-1].energy - E_inf, rel=1e-12)
    assert r["extrapolation"]["energy"] == pytest.approx(E_inf, rel=1e-12)
    assert "not the error against the exact energy" in r["extrapolation"]["caveat"]
    assert r["recent"]["steps"] == 10 and r["recent"]["gain"] == pytest.approx(history[-11].energy - history[-1].energy)
    assert r["recent"]["rate"] == pytest.approx(r["recent"]["gain"] / 10.0)
    rising = [Step(10, -1.0 - 0.01 * k * k, "refine", float(k)) for k in range(30)]  # gains not yet falling
    assert convergence(rising, Optimiser(), "budget", 30.0)["extrapolation"] is None


# --- end to end ------------------------------------------------------------------------------
def test_an_input_without_optimiser_table_runs_to_an_exhausted_basis_with_a_report(tmp_path):
    (tmp_path / "he.toml").write_text('[system]\nparticles = ["alpha", "e", "e"]\n[state]\nspin = { e = 0 }\n'
                                      "[basis]\nsize = 24\n")
    r = subprocess.run([sys.executable, "-m", "prebo", "run", tmp_path / "he.toml", "--out", tmp_path / "he"],
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    assert "stopped" in r.stdout and "basis exhausted" in r.stdout and "basis size" not in r.stdout
    result = json.loads((tmp_path / "he" / "result.json").read_text())
    c = result["convergence"]
    assert c["stopped"] == "exhausted" and c["advantage"] > 1 / RATIO and c["adaptive"] and 0 < c["seconds"] <= result["wall_seconds"] + 0.05  # 0.1 s
    assert c["recent"]["steps"] >= 1 and c["recent"]["gain"] >= 0 and c["recent"]["seconds"] >= 0
    assert c["extrapolation"] is None or (c["extrapolation"]["remaining"] > 0 and c["extrapolation"]["caveat"])
    assert result["n_basis"] == 24 and result["basis_type"] == "pecg"
    assert -2.90330455773 < result["energy"] < -2.9030  # the literature energy (Drake), variational
    d = json.loads((tmp_path / "he" / "basis.json").read_text())
    kinds = [p[0] for p in d["schedule"]["passes"]]
    assert kinds[0] == "grow" and {"refine", "sweep", "polish", "prune"} <= set(kinds) and d["stopped"] == "exhausted"
    prunings = [p for p in d["schedule"]["passes"] if p[0] == "prune"]
    assert all(p[1] == 24 and p[3] <= p[2] for p in prunings)  # back to the size, never above where it began
    again = subprocess.run([sys.executable, "-m", "prebo", "run", "--resume", tmp_path / "he", "--quiet"],
                           capture_output=True, text=True, timeout=600)  # still exhausted: nothing more
    assert again.returncode == 0 and json.loads((tmp_path / "he" / "basis.json").read_text())["schedule"] == d["schedule"]
    budget = d["elapsed"] + 1.5  # the user's word: spend 1.5 s more at this size
    again = subprocess.run([sys.executable, "-m", "prebo", "run", "--resume", tmp_path / "he", "--budget", str(budget),
                            "--quiet"], capture_output=True, text=True, timeout=600)
    assert again.returncode == 0, again.stderr
    more = json.loads((tmp_path / "he" / "basis.json").read_text())
    assert more["stopped"] in ("budget", "converged") and more["elapsed"] >= d["elapsed"] and more["energy"] <= d["energy"]
    # the budget overrides exhaustion while the best kind's last rate buys a gain of the tolerance in
    # the 1.5 s: then the run goes on (passes ended, or one in flight when the budget ran out, its
    # cursor kept); else it ends at once as the budget's end (which of the two depends on the
    # measured seconds of the first run)
    schedule = Adaptive.check(resolved(Optimiser(size=24), prebo.System(["alpha", "e", "e"], spin={"e": 0})),
                              d["schedule"])
    buys = schedule.best() * (budget - d["elapsed"]) >= schedule.tolerance(d["energy"])
    went_on = len(more["schedule"]["passes"]) > len(d["schedule"]["passes"]) or more["progress"]["phase"] != "done"
    assert went_on == buys and (buys or more["stopped"] == "budget"), (schedule.best(), more["stopped"])


def test_the_budget_stops_a_run_and_a_resumed_adaptive_run_goes_on(tmp_path):
    he = prebo.System(["alpha", "e", "e"], spin={"e": 0})
    basis = prebo.optimise(he, Optimiser(size=400, budget=2.0), out=tmp_path, progress=False)
    assert basis.convergence["stopped"] == "budget" and 2.0 <= basis.convergence["seconds"] < 30
    assert 0 < len(basis) < 400
    d = json.loads((tmp_path / "basis.json").read_text())
    assert d["stopped"] == "budget" and d["progress"]["phase"] != "done"  # where it goes on
    again, _ = resume_from(tmp_path, progress=False)  # the same budget: nothing more
    assert again.convergence["stopped"] == "budget" and len(again) == len(basis)
    assert json.loads((tmp_path / "basis.json").read_text())["history"] == d["history"]
    d["optimiser"]["budget"] = d["elapsed"] + 1.0  # one more second
    (tmp_path / "basis.json").write_text(json.dumps(d))
    more, _ = resume_from(tmp_path, progress=False)  # goes on where it stopped, in whichever phase
    assert more.convergence["stopped"] == "budget" and len(more) >= len(basis)
    d2 = json.loads((tmp_path / "basis.json").read_text())
    assert len(d2["history"]) > len(d["history"]) and d2["history"][:len(d["history"])] == d["history"]
    assert d2["history"][-1][1] <= d["history"][-1][1] and d2["progress"] != d["progress"]
    assert d2["schedule"]["passes"][:len(d["schedule"]["passes"])] == d["schedule"]["passes"]


def test_growth_that_stalls_ends_at_the_size_reached_in_an_adaptive_schedule(tmp_path, monkeypatch):
    """Every trial rejected (here: max_overlap 1e-9, no trial is that far from every function) — a
    fixed schedule stops with StalledError, the adaptive one keeps the size reached and goes on."""
    from prebo.errors import StalledError
    from prebo.optimise import methods
    monkeypatch.setattr(methods, "STALL_STEPS", 5)
    h = prebo.System(["p", "e"])
    with pytest.raises(StalledError):
        prebo.optimise(h, Optimiser(size=10, max_overlap=1e-9, sweeps=0), progress=False)
    basis = prebo.optimise(h, Optimiser(size=10, max_overlap=1e-9), out=tmp_path, progress=False)
    d = json.loads((tmp_path / "basis.json").read_text())
    assert len(basis) == d["schedule"]["stalled"] == 1 and basis.convergence["stopped"] == "converged"
    assert {p[0] for p in d["schedule"]["passes"]} == {"grow", "refine", "sweep", "polish", "prune"}


def test_the_convergence_report_starts_after_the_last_pruning():
    """A basis grown past its size and pruned back starts again from a higher energy: the recent
    gain and the extrapolation are those of the steps since, never a loss across the pruning."""
    grown = [Step(3, -1.0, "grow", 1.0), Step(4, -1.2, "prune", 2.0), Step(5, -1.3, "prune", 3.0)]
    since = [Step(3, -1.1 - 0.1 * (1 - 0.5**k), "refine", 4.0 + k) for k in range(7)]
    report = convergence(grown + since, Optimiser(size=3, prune=2, refine=1), "schedule", 11.0)
    assert report["recent"]["steps"] == 6 and report["recent"]["gain"] == pytest.approx(since[0].energy - since[-1].energy)
    assert report["extrapolation"]["energy"] == pytest.approx(-1.2, abs=2e-3)


def test_growth_starts_afresh_once_when_it_settles_on_a_fragment_and_a_distant_particle():
    """At min(size, RESTART_AT) functions, just grown and not bound: a fresh start, RESTARTS at most."""
    s = Adaptive(resolved(Optimiser(size=40), prebo.System(["p", "d", "e"])))
    fresh = s.restart("grow", 20, -0.4998, -0.4998)
    assert fresh.restarts == 1 and fresh.passes == [] and fresh.first() == s.first()
    assert s.restart("grow", 20, -0.5, -0.4998) is None and s.restart("grow", 19, -0.1, -0.4998) is None
    assert s.restart("refine", 20, -0.1, -0.4998) is None  # only just grown
    assert Adaptive(s.opts, restarts=2).restart("grow", 20, -0.1, -0.4998) is None
    assert Adaptive.check(s.opts, Adaptive(s.opts, restarts=1).to_dict()).restarts == 1


def test_hd_plus_from_seed_1_is_bound(tmp_path):
    """HD+ from defaults and seed 1 grew a D atom with the proton far away (-0.49986 Eh, "not bound")
    and stayed there; a fresh start finds the molecule (-0.59773 with 37 functions in 30 s)."""
    hd = prebo.System(["p", "d", "e"])
    basis = prebo.optimise(hd, Optimiser(size=30, seed=1, budget=20), out=tmp_path, progress=False)
    r = prebo.evaluate(basis)
    assert r["bound"] and r["energy"] < -0.59
    assert json.loads((tmp_path / "basis.json").read_text())["schedule"]["restarts"] == 1
