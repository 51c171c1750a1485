"""Issue 37, cases 8, 11, 12 and 13 (in part): a value outside its physical range is refused where it
is read, in one line naming the key and the range — never an overflow in the sampler, a numpy
warning, a NaN, a run folder left behind, or a message from deep inside ("not positive definite")
that names neither; API misuse raises a PreboError; integers are integers whatever their numpy
type, and bools are not. The CLI runs in-process."""
import dataclasses
import json
import re
import tempfile
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import prebo
from prebo.errors import InputError, PreboError
from prebo.optimise.defaults import resolved
from prebo.optimise.sampler import Sampler

from conftest import ROOT, cli_error, h_input, toml_text

BASES = ROOT / "examples" / "bases"
FAMILY = settings(max_examples=40, derandomize=True, database=None, deadline=None,
                  suppress_health_check=[HealthCheck.function_scoped_fixture])


def decades(lo: float, hi: float):
    """Numbers 10^x, x uniform in [lo, hi]."""
    return st.floats(lo, hi).map(lambda x: 10.0 ** x)


def refused_run(capsys, tmp_path, doc: dict, *words) -> str:
    """`prebo run` of the TOML document `doc` exits 2 with one line naming the file and `words`,
    before it writes its run folder."""
    d = Path(tempfile.mkdtemp(dir=tmp_path))
    f = d / "in.toml"
    f.write_text(toml_text(doc))
    err = cli_error(capsys, "run", f, "--out", d / "out", "--quiet")
    for w in (str(f), *words):
        assert w in err, (w, err)
    assert not (d / "out").exists(), "the refused run left its folder"
    return err


def proton(**keys) -> dict:
    return h_input() | {"system": {"particles": [{"name": "p"} | keys, "e"]}}


MASS = "1e-06 ≤ x ≤ 1e+12"
CHARGE = "0, or a finite number x with 0.001 ≤ |x| ≤ 1000"
C_A = "0.01 ≤ x ≤ 1000"
LENGTHS = "0.0001 ≤ lo < hi ≤ 10000"


def with_c_A(value) -> dict:
    doc = h_input()
    doc["basis"]["c_A"] = value
    return doc


# --- 8 and 12: out-of-range values are refused at input, naming the key and the range ------
@pytest.mark.parametrize("doc, words", [
    (proton(mass=1e-300), ["particle 'p': mass = 1e-300", MASS]),  # OverflowError in the sampler
    (proton(mass=1e300), ["particle 'p': mass = 1e+300", MASS]),  # exit 0 with a numpy RuntimeWarning
    (h_input(length_range=[1e200, 1e300]), ["[optimiser] length_range = [1e+200, 1e+300]", LENGTHS]),
    (h_input(length_range=[1e-300, 2e-300]), ["[optimiser] length_range = [1e-300, 2e-300]", LENGTHS]),  # A = nan
    (proton(charge=1e6), ["particle 'p': charge = 1000000.0", CHARGE]),  # "not positive definite", a checkpoint
    (with_c_A(1e-300), ["[basis] c_A = 1e-300", C_A]),  # "not positive definite"
    (with_c_A(1e300), ["[basis] c_A = 1e+300", C_A]),
])
def test_the_reported_values_are_refused_at_input(capsys, tmp_path, doc, words):
    refused_run(capsys, tmp_path, doc, *words)


def beyond(lo: float, hi: float):
    """Numbers outside [10^lo, 10^hi], out to 1e±300."""
    return decades(-300, lo - 0.01) | decades(hi + 0.01, 300)


OUT_OF_RANGE = st.one_of(
    beyond(-6, 12).map(lambda m: (proton(mass=m), "particle 'p': mass", MASS)),
    st.tuples(beyond(-3, 3), st.sampled_from([1, -1])).map(
        lambda q: (proton(charge=q[0] * q[1]), "particle 'p': charge", CHARGE)),
    beyond(-2, 3).map(lambda c: (with_c_A(c), "[basis] c_A", C_A)),
    st.tuples(beyond(-4, 4), decades(-4, 4) | beyond(-4, 4)).filter(lambda t: t[0] != t[1]).map(
        lambda t: (h_input(length_range=sorted(t)), "[optimiser] length_range", LENGTHS)),
    decades(-300, 300).map(lambda t: (h_input() | {"state": {"threshold": t}}, "state: threshold", "≤ 0")),
)


@FAMILY
@given(case=OUT_OF_RANGE)
def test_values_out_of_their_range_are_refused_at_input(capsys, tmp_path, case):
    doc, key, allowed = case
    refused_run(capsys, tmp_path, doc, key, allowed)


CORNERS = st.tuples(st.sampled_from([1e-6, 1.0, 1e12]), st.sampled_from([1e-3, -1e-3, 1.0, 1e3]),
                    st.sampled_from([1e-2, 1e3]), st.sampled_from([(1e-4, 1e-3), (1e3, 1e4), (1e-4, 1e4)]),
                    st.sampled_from(["pairs", "all"]))


@FAMILY
@given(corner=CORNERS)
def test_draws_at_the_edges_of_the_ranges_are_finite(corner):
    """What the ranges promise (system/particles.py): two particles of any allowed mass and
    opposite charges — the shortest and the longest Bohr radii — and an electron, drawn with any
    allowed c_A and length range, give finite exponent matrices without a numpy warning."""
    mass, charge, c_A, lengths, channels = corner
    system = prebo.System([{"name": "x", "mass": mass, "charge": charge, "spin": 0},
                           {"name": "y", "mass": mass, "charge": -charge, "spin": 0}, "e"])
    opts = resolved(prebo.Optimiser(c_A=c_A, length_range=lengths, channels=channels, kind="ecg-gvr"), system)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sampler = Sampler(system, opts, np.random.default_rng(1))
        A = np.array([sampler.fresh().A[0] for _ in range(20)])
    assert np.isfinite(A).all()


def test_import_c_A_out_of_range_names_the_option(tmp_path, capsys):
    """`import --c-A 1e300` blamed positive definiteness."""
    li = ROOT / "tests" / "data" / "ecgpack" / "ecgpack-Li7-100.inout.txt"
    for value, shown in (("1e300", "1e+300"), ("1e-300", "1e-300")):
        err = cli_error(capsys, "import", li, "--c-A", value, "--out", tmp_path / "li.json")
        assert f"--c-A = {shown}: must be" in err and C_A in err and "positive definite" not in err, err
    assert not (tmp_path / "li.json").exists()


@pytest.mark.parametrize("scale", [1e200, 1e-200])
def test_a_global_vector_out_of_scale_is_named(tmp_path, capsys, scale):
    """`u = [1e200, ...]` was reported as "global vector u is zero"."""
    d = json.loads((ROOT / "examples" / "bases" / "h2plus-gvr" / "basis.json").read_text())
    d["functions"][3]["u"] = [scale, -scale, 0.0]
    (tmp_path / "b.json").write_text(json.dumps(d))
    err = cli_error(capsys, "energy", tmp_path / "b.json")
    assert "b.json: function 3: the global vector u" in err and "outside 1e-06..1e+06" in err, err


def test_the_api_refuses_the_same_values():
    for make, words in [
        (lambda: prebo.particle({"name": "p", "mass": 1e-300}), "particle 'p': mass = 1e-300"),
        (lambda: prebo.particle({"name": "x", "mass": 1.0, "charge": 1e-300, "spin": 0}),
         "particle 'x': charge = 1e-300"),
        (lambda: prebo.Optimiser(length_range=(1e200, 1e300)), "Optimiser length_range = (1e+200, 1e+300)"),
        (lambda: prebo.Optimiser(c_A=1e300), "Optimiser c_A = 1e+300"),
    ]:
        with pytest.raises(InputError, match="^" + re.escape(words)):
            make()
    assert prebo.particle({"name": "x", "mass": 1e12, "charge": 0, "spin": 0}).mass == 1e12


# --- 11: API misuse raises PreboError ---------------------------------------------------------
@pytest.mark.parametrize("bad", [5, None, "[system]", [1, 2]])
def test_toml_from_dict_of_something_not_a_table(bad):
    """from_dict(5) raised TypeError."""
    from prebo.io import toml
    with pytest.raises(InputError, match=r"an input is a table of title, \[system\]"):
        toml.from_dict(bad)


SYSTEMS = {"he": lambda: prebo.System(["alpha", "e", "e"]), "h 2p": lambda: prebo.System(["p", "e"], N=1, parity=-1),
           "none": lambda: None}


@pytest.mark.parametrize("name, other, swap", [
    ("h", "he", "assign"), ("he", "h 2p", "assign"), ("h2p", "he", "assign"), ("h", "h 2p", "assign"),
    ("h", "none", "assign"), ("h", "he", "replace"), ("h2p", "he", "replace"),
])
def test_evaluate_a_basis_whose_system_was_swapped(name, other, swap):
    """A basis given another system after it was built (ValueError, AttributeError or the core's
    N = 1 message before): refused with the constructor's own message."""
    basis = prebo.Basis.load(BASES / name / "basis.json")
    system = SYSTEMS[other]()
    with pytest.raises(PreboError, match="Basis: system = None|exponent matrices|plain ECGs|values of c_A"):
        if swap == "assign":
            basis.system = system
        else:
            basis = dataclasses.replace(basis, system=system)
        prebo.evaluate(basis)


def test_evaluate_after_a_swap_to_an_equivalent_system_gives_the_same_bits():
    basis = prebo.Basis.load(BASES / "h2p" / "basis.json")
    energy = prebo.evaluate(basis)["energy"]
    basis.system = prebo.System(["p", "e"], N=1, parity=-1)
    assert prebo.evaluate(basis)["energy"] == energy


# --- 13: [state] threshold = 5.0 --------------------------------------------------------------
def test_a_positive_threshold_is_refused(capsys, tmp_path):
    """A dissociation threshold lies at or below 0 (fragments and free particles at rest); 5.0 was
    taken and silently lost to the lower hydrogen-like one."""
    refused_run(capsys, tmp_path, h_input() | {"state": {"threshold": 5.0}}, "state: threshold = 5.0",
                "a finite number ≤ 0")
    with pytest.raises(InputError, match="state: threshold = 1e-09: must be a finite number ≤ 0"):
        prebo.State(threshold=1e-9)
    assert prebo.State(threshold=0).threshold == 0.0
    d = json.loads((BASES / "h" / "basis.json").read_text())
    d["system"]["state"]["threshold"] = 5.0
    f = tmp_path / "basis.json"
    f.write_text(json.dumps(d))
    assert "state: threshold = 5.0" in cli_error(capsys, "energy", f)


# --- 13: integers of any numpy type, never bools ----------------------------------------------
INTEGER_TYPES = [int, np.int8, np.int16, np.int32, np.int64, np.uint8, np.uint64]


@pytest.mark.parametrize("integer", INTEGER_TYPES)
def test_numpy_integers_are_integers_everywhere(integer):
    """State(N=np.int64(1)) was refused while Optimiser(size=np.int32(5)) was accepted."""
    state = prebo.State(N=integer(1), parity=-1)
    assert type(state.N) is int and state.N == 1
    assert type(prebo.State(parity=np.int64(-1)).parity) is int
    system = prebo.System(["p", "e"], N=integer(1), parity=-1)
    assert json.loads(json.dumps(system.to_dict()))["state"]["N"] == 1
    opts = prebo.Optimiser(size=integer(5), seed=integer(2))
    assert type(opts.size) is int and (opts.size, opts.seed) == (5, 2)


@pytest.mark.parametrize("make", [
    lambda: prebo.State(N=True), lambda: prebo.State(N=np.bool_(True)), lambda: prebo.State(parity=np.bool_(True)),
    lambda: prebo.State(parity=True), lambda: prebo.Optimiser(size=np.bool_(True)), lambda: prebo.Optimiser(seed=False),
    lambda: prebo.State(N=1.0), lambda: prebo.State(parity=np.int64(0)),
])
def test_bools_and_non_integers_are_refused_everywhere(make):
    with pytest.raises(InputError, match=r"(state: N|state: parity|Optimiser size|Optimiser seed) = .*: must be"):
        make()


def test_an_angular_momentum_beyond_the_core_is_refused():
    """N = 2**70 raised OverflowError in the core."""
    with pytest.raises(InputError, match=r"state: N = 1180591620717411303424: must be an integer in 0\.\.1000"):
        prebo.State(N=2**70, parity=1)
    assert prebo.State(N=np.int64(1000)).N == 1000


# --- issue 55, item 3: an error names what was read -------------------------------------------
def test_a_power_beyond_its_limit_is_named_with_its_function_and_value(tmp_path, capsys):
    """`K = 10**50` was "Basis: K = an array of shape (180,): must be one number per function"."""
    d = json.loads((BASES / "h2plus-gvr" / "basis.json").read_text())
    d["functions"][3]["K"] = 10**50
    (tmp_path / "b.json").write_text(json.dumps(d))
    err = cli_error(capsys, "energy", tmp_path / "b.json")
    assert err == (f"prebo: error: {tmp_path / 'b.json'}: function 3: K = 100000000000000000...0000000000000000000: "
                   "must be an integer in 0..60\n")


def test_targeted_levels_beyond_the_basis_are_named_as_the_file_gives_them(tmp_path, capsys):
    """`roots = [0, 500]` in a basis of 150 functions was "evaluate: roots = 501", a number not in the file."""
    d = json.loads((BASES / "he" / "basis.json").read_text())
    d["system"]["state"]["roots"] = [0, 500]
    (tmp_path / "b.json").write_text(json.dumps(d))
    err = cli_error(capsys, "energy", tmp_path / "b.json")
    assert err == (f"prebo: error: {tmp_path / 'b.json'}: state: targets levels [0, 500]: level 500 is not one of a "
                   "basis of 150 functions (0..149)\n")


@pytest.mark.parametrize("roots,weights,words", [
    ([0, 2], [1, 0.5, 2], "state: weights = [1, 0.5, 2]: 3 numbers for 2 roots"),
    (3, [1.0], "state: weights = [1.0]: 1 number for 3 roots"),
    ([1, 3], 0.5, "state: weights = 0.5: must be a list of positive numbers, one per root"),
])
def test_weights_of_another_length_say_how_many_for_how_many_roots(capsys, tmp_path, roots, weights, words):
    """A wrong length of weights was "must be 1 positive numbers, one per root"."""
    doc = h_input()
    doc["state"] = {"roots": roots, "weights": weights}
    refused_run(capsys, tmp_path, doc, words)
