"""Issue 13: every bad input is refused with one line (CLI: `prebo: error: ...`, exit 2) or a
PreboError subclass (API) naming the file or argument, the value and what is allowed; no
wrong-state numbers, no hangs, no NaN results. The CLI runs in-process (fast); the cases that
need a real process (a closed pipe, a kill) are in test_fuzz.py."""
import ast
import importlib
import json
import sys
import types
from pathlib import Path

import numpy as np
import pytest

import prebo
from prebo.cli import main
from prebo.errors import InputError, PreboError

from conftest import cli_error, edited, h_input, toml_text

ROOT = Path(__file__).resolve().parents[1]
H_TOML = '[system]\nparticles = ["p", "e"]\n[basis]\nsize = 3\n[optimiser]\ntrials = 4\nseed = 3\n'
HMINUS_TOML = '[system]\nparticles = ["p", "e", "e"]\n[basis]\nsize = 3\n[optimiser]\ntrials = 4\nseed = 3\n'


def toml_error(capsys, tmp_path, text, *words) -> str:
    """`prebo run` of a TOML input must fail cleanly, naming the file and `words`."""
    f = tmp_path / "in.toml"
    f.write_text(text)
    err = cli_error(capsys, "run", f, "--out", tmp_path / "out", "--quiet")
    for w in (str(f), *words):
        assert w in err, err
    return err


@pytest.fixture(scope="module")
def bases(tmp_path_factory):
    """Small basis.json files: plain-ECG H (p e) and ECG-GVR H 2p (p e, N = 1, parity -1)."""
    d = tmp_path_factory.mktemp("bases")
    h = prebo.optimise(prebo.System(["p", "e"]), prebo.Optimiser(size=3, trials=4, seed=3), progress=False)
    h.save(d / "h.json")
    p2 = prebo.System(["p", "e"], N=1, parity=-1)
    gvr = prebo.optimise(p2, prebo.Optimiser(size=3, trials=4, seed=3, kind="ecg-gvr", K_max=2), progress=False)
    gvr.save(d / "h2p.json")
    return {"pecg": d / "h.json", "gvr": d / "h2p.json"}


# --- 2: a basis type that cannot describe the state ---------------------------------------
@pytest.mark.parametrize("N, parity", [(1, -1), (1, 1), (0, -1)])
def test_plain_ecg_basis_file_with_another_state_is_refused(bases, tmp_path, capsys, N, parity):
    f = edited(tmp_path, bases["pecg"], lambda d: d["system"]["state"].update(N=N, parity=parity))
    err = cli_error(capsys, "energy", f, "--json")
    assert str(f) in err and "N = 0, parity +1" in err and f"not N = {N}, parity {parity:+d}" in err


def test_gvr_basis_file_with_unnatural_parity_is_refused(bases, tmp_path, capsys):
    f = edited(tmp_path, bases["gvr"], lambda d: d["system"]["state"].update(parity=1))
    assert "natural parity (-1)^N = -1" in cli_error(capsys, "energy", f)


def test_plain_ecgs_for_a_p_state_are_refused_by_the_api():
    p2 = prebo.System(["p", "e"], N=1, parity=-1)
    with pytest.raises(InputError, match="plain ECGs .* not N = 1, parity -1"):
        prebo.optimise(p2, prebo.Optimiser(size=4, kind="pecg"), progress=False)
    with pytest.raises(InputError, match="N = 0, parity \\+1"):
        prebo.Basis(p2, np.eye(2)[None], [1.0])
    with pytest.raises(InputError, match="natural parity"):
        prebo.Basis(prebo.System(["p", "e"], N=1, parity=1), np.eye(2)[None], [1.0], kind="ecg-gvr",
                    u=[[1.0, -1.0]], K=[0])


def test_toml_with_plain_ecgs_or_unnatural_parity_is_refused(tmp_path, capsys):
    toml_error(capsys, tmp_path, H_TOML.replace("size = 3", 'size = 3\ntype = "pecg"') + "[state]\nN = 1\nparity = -1\n",
               "not N = 1, parity -1")
    toml_error(capsys, tmp_path, H_TOML.replace("size = 3", 'size = 3\ntype = "ecg-gvr"') + "[state]\nN = 2\nparity = -1\n",
               "natural parity (-1)^N = +1")


def test_ecgpack_import_goes_through_the_same_check(monkeypatch):
    """An ecgpack file is read as an N = 0 state; the Basis it becomes is checked against the state."""
    from prebo.io import ecgpack
    li = ROOT / "tests" / "data" / "ecgpack" / "ecgpack-Li7-100.inout.txt"
    state = prebo.State(N=1, parity=-1, spin={"e": 0.5})
    monkeypatch.setattr(ecgpack, "State", lambda **kw: state)
    with pytest.raises(PreboError, match="plain ECGs"):
        ecgpack.read_inout(li)


# --- 3: nothing hangs ---------------------------------------------------------------------
def test_max_overlap_zero_is_refused(tmp_path, capsys):
    toml_error(capsys, tmp_path, H_TOML + "max_overlap = 0\n", "[optimiser] max_overlap = 0", "0 < x ≤ 1")
    with pytest.raises(InputError, match="max_overlap = 0"):
        prebo.Optimiser(max_overlap=0)


def test_growth_whose_every_trial_is_rejected_stops_naming_the_setting(tmp_path, capsys):
    """max_overlap = 1e-9 is allowed but rejects every trial after the first function: a fixed
    schedule stops (after optimise.STALL_STEPS steps) instead of looping forever; the adaptive one
    keeps the size reached and warns, naming the same settings."""
    err = toml_error(capsys, tmp_path, H_TOML + "max_overlap = 1e-9\nsweeps = 0\n", "every trial of the last",
                     "raise max_overlap (now 1e-09)")
    assert "growth steps was rejected at 1 functions" in err
    assert json.loads((tmp_path / "out" / "basis.json").read_text())["functions"]  # the state is kept
    f = tmp_path / "adaptive.toml"
    f.write_text(H_TOML + "max_overlap = 1e-9\n")
    assert main(["run", str(f), "--out", str(tmp_path / "adaptive"), "--quiet"]) == 0
    err = capsys.readouterr().err
    assert err.startswith("prebo: warning: growth stalled") and "raise max_overlap (now 1e-09)" in err
    result = json.loads((tmp_path / "adaptive" / "result.json").read_text())
    assert result["n_basis"] == result["convergence"]["stalled"]["size"] == 1



def test_growth_stalled_at_the_overlap_threshold_names_the_threshold():
    """Near an overlap condition of 1/threshold a new function costs a dropped direction: the
    message names `threshold`, not the linear-dependence guard."""
    from prebo.optimise.methods import stalled
    opts = prebo.Optimiser(threshold=1e-13)
    at_limit = stalled(427, opts, 9.98e12)
    assert "overlap condition, 9.98e+12, is near 1/threshold" in at_limit and "lower threshold (now 1e-13)" in at_limit
    assert "raise max_overlap" in stalled(427, opts, 9.0e11) and "threshold" not in stalled(427, opts, 9.0e11)


def test_growth_stalled_by_the_uncertainty_says_so():
    """He's growth stalled at 580 functions with σ = 1.0e-13 Eh (benchmarks/record/schedules.md,
    "Defaults that know the numerics"): the message, which blamed linear dependence alone, names
    the uncertainty and its price."""
    from prebo.optimise.methods import stalled
    why = stalled(580, prebo.Optimiser(threshold=2.0**-53), 3.65e14, 1.0e-13)  # that run's threshold
    assert "gaining less than the energy's uncertainty σ = 1.0e-13 Eh and 100 times what it adds to σ" in why
    assert "overlap condition 3.6e+14" in why

def test_size_beyond_memory_is_refused(tmp_path, capsys):
    from prebo.validation import MAX_SIZE
    err = toml_error(capsys, tmp_path, H_TOML.replace("size = 3", "size = 1_000_000_000"),
                     "[basis] size = 1000000000", f"1..{MAX_SIZE}")
    assert "memory" in err
    assert prebo.Optimiser(size=MAX_SIZE).size == MAX_SIZE
    with pytest.raises(InputError, match=f"size = {MAX_SIZE + 1}"):
        prebo.Optimiser(size=MAX_SIZE + 1)
    assert 1000 < MAX_SIZE < 10**6


# --- 4: results are finite and valid JSON -------------------------------------------------
def test_overflowing_basis_gives_an_error_not_nan(bases, tmp_path, capsys):
    def scale(d):
        d["functions"] = d["functions"][:1]
        del d["coefficients"]
        f = d["functions"][0]
        f["A"] = (np.array(f["A"]) * 1e300).tolist()
        f["c_A"] *= 1e300
    f = edited(tmp_path, bases["pecg"], scale)
    for extra in ([], ["--json"]):
        err = cli_error(capsys, "energy", f, *extra)
        assert str(f) in err and "finite" in err


def test_energy_json_is_strict_json(bases, capsys):
    assert main(["energy", str(bases["gvr"]), "--json"]) == 0
    r = json.loads(capsys.readouterr().out, parse_constant=lambda c: pytest.fail(f"{c} in JSON"))
    assert np.isfinite(r["energy"])


# --- 5: one line instead of a traceback ---------------------------------------------------
@pytest.mark.parametrize("text, words", [
    (HMINUS_TOML + '[state]\nspin = {e = "zero"}\n', ["spin of 'e' = 'zero'", "0, 1/2, 1"]),
    (HMINUS_TOML + "[state]\nspin = 0\n", ["spin = 0", "must map particle names"]),
    (H_TOML.replace("seed = 3", "seed = -1"), ["[optimiser] seed = -1", "integer ≥ 0"]),
    (H_TOML.replace("seed = 3", 'seed = "x"'), ["[optimiser] seed = 'x'", "integer ≥ 0"]),
    (H_TOML + "length_range = [1.0]\n", ["length_range = [1.0]", "0.0001 ≤ lo < hi ≤ 10000"]),
    (H_TOML + "length_range = [0.1, inf]\n", ["length_range = [0.1, inf]", "0.0001 ≤ lo < hi ≤ 10000"]),
    (HMINUS_TOML + 'channels = ["hpc:9"]\n', ["channels", "hpc:9", "particle 9 is not one of 0..2"]),
    (HMINUS_TOML + 'channels = ["cmc:-1"]\n', ["channels", "cmc:-1"]),
    ('[system]\nparticles = ' + str(["p", "e"] * 15).replace("'", '"') + '\n', ["2 to 8 particle"]),
    # a new user's cases: no [basis] ran with 50 functions, K_max of plain ECGs was ignored, a
    # misspelled top-level key was called a table
    ('[system]\nparticles = ["p", "e"]\n', ["[basis] needs 'size'"]),
    (H_TOML.replace("size = 3", 'size = 3\ntype = "pecg"\nK_max = 4'), ["K_max", "pecg functions have no power K"]),
    ('tittle = "H"\n' + H_TOML, ["unknown top-level keys or tables ['tittle']", "allowed: title"]),
])
def test_bad_toml_values_give_one_line(tmp_path, capsys, text, words):
    toml_error(capsys, tmp_path, text, *words)


@pytest.mark.parametrize("bad", [5, None, ""])
def test_toml_load_refuses_a_path_that_is_not_a_file_name(bad):
    """toml.load(5) raised TypeError."""
    from prebo.io import toml
    with pytest.raises(InputError, match=r"toml.load: path = .*must be a file name \(a str or path\)"):
        toml.load(bad)


def test_basis_file_without_functions(bases, tmp_path, capsys):
    def empty(d):
        d["functions"] = []
        del d["coefficients"]
    f = edited(tmp_path, bases["pecg"], empty)
    assert "the basis has no functions" in cli_error(capsys, "energy", f)


def test_import_with_non_positive_c_A(tmp_path, capsys):
    li = ROOT / "tests" / "data" / "ecgpack" / "ecgpack-Li7-100.inout.txt"
    for value in ("0", "-1", "nan"):
        err = cli_error(capsys, "import", li, "--c-A", value, "--out", tmp_path / "li.json")
        assert "--c-A = " in err and "0.01 ≤ x ≤ 1000" in err
    from prebo.io.ecgpack import read_inout
    with pytest.raises(InputError, match="c_A = 0"):
        read_inout(li, c_A=0)


def test_outputs_that_cannot_be_written(bases, tmp_path, capsys):
    li = ROOT / "tests" / "data" / "ecgpack" / "ecgpack-Li7-100.inout.txt"
    (tmp_path / "toml").mkdir()
    f = tmp_path / "toml" / "h.toml"
    f.write_text(H_TOML)
    existing = tmp_path / "a-file"
    existing.write_text("")
    assert f"{existing}: a file, not a folder" in cli_error(capsys, "run", f, "--out", existing, "--quiet")
    assert "Not a directory" in cli_error(capsys, "run", f, "--out", existing / "sub", "--quiet")
    err = cli_error(capsys, "import", li, "--out", existing / "li.json")
    assert str(existing / "li.json") in err and "cannot write" in err
    (tmp_path / "dir").mkdir()
    err = cli_error(capsys, "export", bases["pecg"], "--format", "ecgpack", "--out", tmp_path / "dir")
    assert "cannot write" in err


def test_unknown_option_values_give_one_line(capsys):
    with pytest.raises(SystemExit) as stop:
        main(["energy", "x.json", "--coordinates", "polar"])
    out, err = capsys.readouterr()
    assert stop.value.code == 2 and out == "" and err.count("\n") == 1
    assert err.startswith("prebo: error: energy: argument --coordinates: invalid choice: 'polar'")


# --- 6: messages that say what is wrong ---------------------------------------------------
@pytest.mark.parametrize("text, words", [
    ('[system]\nparticles = [{name = "p", charge = nan}, "e"]\n', ["particle 'p': charge = nan", "finite number"]),
    (H_TOML + "threshold = -1\n", ["[optimiser] threshold = -1", "0 < x < 1"]),
    (H_TOML + 'channels = ["polar:1"]\n', ["unknown coordinate set 'polar:1'"]),
    (H_TOML + 'channels = ["jacobi:0-2"]\n', ["Jacobi order [0, 2]"]),
])
def test_messages_name_the_file_the_value_and_what_is_allowed(tmp_path, capsys, text, words):
    toml_error(capsys, tmp_path, text, *words)


# --- 7: values that were taken unchecked --------------------------------------------------
@pytest.mark.parametrize("text, words", [
    ('[system]\nparticles = [{name = "p", charge = "1"}, "e"]\n', ["charge = '1'"]),
    ('[system]\nparticles = [{name = "p", mass = true}, "e"]\n', ["mass = True"]),
    (H_TOML + "channels = []\n", ["channels = []", "non-empty list"]),
])
def test_values_of_the_wrong_type_are_refused(tmp_path, capsys, text, words):
    toml_error(capsys, tmp_path, text, *words)


@pytest.mark.parametrize("name, bad, good", [
    ("seed", -1, 0), ("threshold", 0.0, 1e-10), ("threshold", 1.5, 1e-10), ("min_norm", -1e-8, 1e-6),
    ("min_norm", 1.0, 1e-6), ("max_overlap", 1.01, 1.0), ("learn_after", 0, 1),
    ("refine_evaluations", 0, 1), ("learned", 1.5, 1.0), ("trials", 0, 1), ("K_max", 61, 60),
])
def test_every_setting_has_a_range(tmp_path, capsys, name, bad, good):
    from prebo.optimise import SETTINGS
    with pytest.raises(InputError, match=f"Optimiser {name} = {bad!r}: must be"):
        prebo.Optimiser(**{name: bad})
    assert getattr(prebo.Optimiser(**{name: good}), name) == good
    key = SETTINGS[name].key
    table, _, k = key.partition(" ")
    doc = h_input()
    doc[table.strip("[]")][k] = bad
    toml_error(capsys, tmp_path, toml_text(doc), f"{key} = {bad!r}")


def test_settings_table_covers_every_optimiser_field():
    from dataclasses import fields

    from prebo.io import toml as inputs
    from prebo.optimise import SETTINGS
    assert set(SETTINGS) == {f.name for f in fields(prebo.Optimiser)}
    for name, s in SETTINGS.items():  # the defaults are within their ranges
        assert s.rule(getattr(prebo.Optimiser(), name)) == getattr(prebo.Optimiser(), name)
        table, _, key = s.key.partition(" ")
        assert key in (inputs.BASIS_KEYS if table == "[basis]" else inputs.OPTIMISER_KEYS)


def test_a_new_start_removes_temporary_checkpoints_of_a_killed_run(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    stale = [out / "basis.json.k1ll3d.tmp", out / "basis.json.0x.tmp"]
    for f in stale:
        f.write_text('{"format": "prebo-ba')
    (out / "keep.tmp").write_text("")
    prebo.optimise(prebo.System(["p", "e"]), prebo.Optimiser(size=2, trials=2), out=out, progress=False)
    assert not any(f.exists() for f in stale) and (out / "keep.tmp").exists() and (out / "basis.json").exists()


# --- 8: the Python API raises PreboError subclasses ---------------------------------------
@pytest.mark.parametrize("call", [
    lambda: prebo.System(None),
    lambda: prebo.System("pe"),
    lambda: prebo.System(["p", "e"], foo=1),
    lambda: prebo.System(["p", "e"], state={"N": 0}),
    lambda: prebo.State(N=True),
    lambda: prebo.State(parity=1.0),
    lambda: prebo.Optimiser(foo=1),
    lambda: prebo.Optimiser(seed=-3),
    lambda: prebo.Optimiser(size=2.0),
    lambda: prebo.Optimiser(channels="hpc:0"),
    lambda: prebo.Optimiser.from_dict([1, 2]),
    lambda: prebo.optimise(prebo.System(["p", "e", "e"]), prebo.Optimiser(channels=["hpc:9"]), progress=False),
    lambda: prebo.optimise(prebo.System(["p", "e"]), None, progress=False),
    lambda: prebo.optimise(["p", "e"], prebo.Optimiser(), progress=False),
    lambda: prebo.particle({"name": 3, "mass": 1.0, "charge": 1.0, "spin": 0}),
    lambda: prebo.particle({"name": "x", "mass": 1.0, "charge": 1.0, "spin": "1/2"}),
    lambda: prebo.heavy_particle_centred(np.ones(3), 3),
    lambda: prebo.cm_centred(np.ones(3), -1),
    lambda: prebo.evaluate(None),
    lambda: prebo.evaluate(prebo.Basis.empty(prebo.System(["p", "e"]))),
    lambda: prebo.evaluate(prebo.optimise(prebo.System(["p", "e"]), prebo.Optimiser(size=2), progress=False), "x"),
])
def test_api_misuse_raises_prebo_errors(call):
    with pytest.raises(PreboError):
        call()


# --- 9: Python 3.10 ----------------------------------------------------------------------
def test_python_3_10_is_supported():
    """requires-python says 3.10; the TOML reader falls back to tomli there (declared for < 3.11),
    and no module uses syntax newer than 3.10."""
    from prebo.io.toml import tomllib
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert project["requires-python"] == ">=3.10"
    assert any(d.replace(" ", "").startswith("tomli>=") and "python_version<'3.11'" in d.replace(" ", "").replace('"', "'")
               for d in project["dependencies"])
    for path in [*(ROOT / "python" / "prebo").rglob("*.py"), *(ROOT / "tests").glob("*.py")]:
        ast.parse(path.read_text(), str(path), feature_version=(3, 10))


def test_toml_reader_uses_tomli_before_3_11(monkeypatch):
    from prebo.io import toml as inputs
    fake = types.ModuleType("tomli")
    fake.loads, fake.TOMLDecodeError = (lambda text: {}), ValueError
    monkeypatch.setitem(sys.modules, "tomli", fake)
    monkeypatch.setattr(sys, "version_info", (3, 10, 13, "final", 0))
    try:
        assert importlib.reload(inputs).tomllib is fake
    finally:
        monkeypatch.undo()
        importlib.reload(inputs)


def test_evaluate_refuses_bad_arguments_and_an_unchecked_basis():
    """A new user's API calls: a non-symmetric A gave another energy than its symmetric part;
    threshold = "x", 2, NaN and operators = None, 5 raised TypeError or contradictory eigen errors."""
    h = prebo.System(["p", "e"])
    cm = h.cm_vector
    good = prebo.Basis(h, np.array([np.outer(cm, cm) + 0.5 * np.array([[1.0, -1.0], [-1.0, 1.0]])]), np.ones(1))
    assert np.isfinite(prebo.evaluate(good)["energy"])
    skew = prebo.Basis(h, good.A + np.array([[[0.0, 0.1], [-0.1, 0.0]]]), np.ones(1))
    with pytest.raises(prebo.PreboError, match="not symmetric"):
        prebo.evaluate(skew)
    for bad in ("x", 2.0, float("nan"), -1.0):
        with pytest.raises(prebo.PreboError, match="evaluate: threshold"):
            prebo.evaluate(good, threshold=bad)
    for bad in (None, 5, [1]):
        with pytest.raises(prebo.PreboError, match="evaluate: operators"):
            prebo.evaluate(good, operators=bad)


def test_prebo_energy_of_an_input_file_says_so(tmp_path, capsys):
    """`prebo energy he.toml` said "corrupt or truncated JSON"."""
    f = tmp_path / "h.toml"
    f.write_text(H_TOML)
    assert "a TOML input, not a basis; optimise it with `prebo run" in cli_error(capsys, "energy", f)


def test_a_spin_given_by_an_alias_names_the_particle_it_means():
    """Particles named by an alias ("muon") are the known particle ("mu"); a state.spin key that uses
    the alias is refused with the names to use."""
    with pytest.raises(InputError, match=r"\['muon'\] \(its particles are named \['mu', 'p'\]; 'muon' is 'mu'\)"):
        prebo.System(["muon", "muon", "p"], spin={"muon": 1})
