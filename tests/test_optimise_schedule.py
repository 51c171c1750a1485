"""The fixed schedule's cursor, the schedule kind ([optimiser] schedule), the checkpoint's progress
and schedule blocks, the progress line."""
import json
from dataclasses import replace

import pytest

import prebo
from prebo.errors import InputError
from prebo.optimise import Cursor, Optimiser
from prebo.optimise.adaptive import Adaptive
from prebo.optimise.defaults import resolved
from prebo.optimise.fixed import Fixed
from prebo.optimise.schedule import kind_of


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
    for block in (Fixed(opts).to_dict(), IDLE, IDLE | {"restarts": 0}, None):
        assert isinstance(schedule_of(opts, json.loads(json.dumps(block))), Fixed)
    with pytest.raises(ValueError, match="schedule"):
        schedule_of(opts, Adaptive(opts).to_dict() | {"restarts": 1})
    assert isinstance(schedule_of(resolved(Optimiser(size=2), prebo.System(["p", "e"]))), Adaptive)


def test_the_schedule_kind_is_explicit_or_implied_as_before_and_contradictions_are_refused():
    """[optimiser] schedule names the kind; without it a fixed-schedule setting implies the fixed
    one (the inputs before it); a setting of the other kind is refused in one line naming it."""
    he = prebo.System(["alpha", "e", "e"])
    assert kind_of(Optimiser()) is Adaptive and kind_of(Optimiser(polish=1)) is Fixed
    assert kind_of(Optimiser(schedule="fixed")) is Fixed
    assert kind_of(Optimiser(schedule="adaptive", tolerance=1e-9)) is Adaptive
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
        growing, removing = {"phase": "prune", "sweep": 0, "index": 0, "cycle": 1}, {"index": 1}
        assert s.cursor(growing, 10) == Cursor("prune", target=12, cycle=1)
        assert s.cursor(growing | removing, 11) == Cursor("prune", target=10, cycle=1)
        refine = {"phase": "refine", "sweep": 1, "index": 4, "cycle": 2}
        assert s.cursor(refine, 10) == Cursor("refine", index=4, sweep=1, cycle=2)
        assert s.cursor({"phase": "grow", "sweep": 0, "index": 0, "cycle": 0}, 3) == s.first()
    else:
        assert s.cursor({"phase": "grow", "sweep": 9, "index": 0, "cycle": 3}, 8) == Cursor("grow", target=9, number=3)
        sweep = {"phase": "sweep", "sweep": 6, "index": 7, "cycle": 4}
        assert s.cursor(sweep, 10) == Cursor("sweep", index=7, number=4, visited=6)
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
