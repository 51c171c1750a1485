"""Issue 37: a basis file is a claim to be checked, not a source of truth. An edited basis.json,
checkpoint or ecgpack file is evaluated as the state its label says or refused in one line naming
the file (and the function and key) — never a number for another state, never a traceback."""
import json

import numpy as np
import pytest

import prebo
from prebo.cli import main
from prebo.errors import BasisFileError, InputError
from prebo.io import basis_json, ecgpack
from prebo.validation import MAX_SIZE
from conftest import ROOT, cli_error, edited, prebo_process
from test_fuzz import Accepted, accepting

BASES = ROOT / "examples" / "bases"
HE = BASES / "he" / "basis.json"  # singlet He, plain ECGs
GVR = BASES / "h2plus-gvr" / "basis.json"
FECG = BASES / "h2plus-fecg" / "basis.json"
RUN = BASES / "auto-h" / "basis.json"  # a finished run's checkpoint (H, plain ECGs)
DATA = ROOT / "tests" / "data" / "ecgpack"


def energy(capsys, f) -> float:
    assert main(["energy", str(f), "--json"]) == 0
    return json.loads(capsys.readouterr().out)["energy"]


# --- cases 1-3: the stored symmetry against the state -------------------------------------
def spin(S):
    return lambda d: d["system"]["state"].update(spin={"e": S})


def coefficients(c):
    return lambda d: d["symmetry"].update(coefficients=c)


def identity_only(d):
    d["symmetry"] = {"permutations": [[0, 1, 2]], "coefficients": [1.0]}


@pytest.mark.parametrize("edit", [spin(1), coefficients([1, -1]), identity_only, coefficients([1, 0.5])],
                         ids=["spin relabelled", "coefficients [1, -1]", "identity only", "coefficients [1, 0.5]"])
def test_a_stored_symmetry_that_is_not_the_states_is_refused(tmp_path, capsys, edit):
    f = edited(tmp_path, HE, edit)
    err = cli_error(capsys, "energy", f)
    assert str(f) in err and "the stored symmetry is not that of the state" in err


def test_a_relabelled_state_is_evaluated_as_its_label_says(tmp_path, capsys):
    """The triplet label with the triplet's operator, or with none stored: the triplet's energy."""
    singlet = energy(capsys, HE)
    both = energy(capsys, edited(tmp_path, HE, lambda d: (spin(1)(d), coefficients([1, -1])(d)), "a.json"))
    derived = energy(capsys, edited(tmp_path, HE, lambda d: (spin(1)(d), d.pop("symmetry")), "b.json"))
    assert both == derived and derived > singlet + 0.5
    cli_error(capsys, "energy", edited(tmp_path, HE, spin(1), "c.json"))  # the singlet's operator, labelled triplet


@pytest.mark.parametrize("block,words", [
    ({"permutations": [[0, 1, 2], [0, True, 2]], "coefficients": [1.0, 1.0]}, "integer positions"),
    ({"permutations": [[0, 1, 2], [0, 2, 1]], "coefficients": [1.0, "1.0"]}, "numbers"),
    ({"permutations": [[0, 1, 2], [0, 2, 1]], "coefficients": [1.0, 1.0], "young": "(1+P23)"}, "young"),
    ({"permutations": [[0, 1, 2], [0, 2, 1], [0, 2, 1]], "coefficients": [1.0, 0.5, 0.5]}, "listed twice"),
])
def test_a_malformed_symmetry_block_is_refused(tmp_path, capsys, block, words):
    f = edited(tmp_path, HE, lambda d: d.update(symmetry=block))
    err = cli_error(capsys, "energy", f)
    assert str(f) in err and words in err


def test_an_ecgpack_operator_is_kept_and_checked_against_the_state(li, tmp_path, capsys):
    """Li's Young operator is another row of the doublet: kept through basis.json with the same
    energy, refused under a quartet label or with a coefficient edited."""
    f = tmp_path / "li.json"
    li.save(f)
    assert energy(capsys, f) == prebo.evaluate(li)["energy"]
    for edit in (spin(1.5), lambda d: d["symmetry"]["coefficients"].__setitem__(1, 0.75)):
        g = edited(tmp_path, f, edit, "edited.json")
        err = cli_error(capsys, "energy", g)
        assert str(g) in err and "the stored symmetry is not that of the state (e: S = " in err


def test_an_ecgpack_symmetry_of_no_single_spin_state_is_refused(tmp_path):
    """SYMMETRY (1) for He is no spin state: its energy would be that of no symmetry at all."""
    text = (DATA / "ecgpack-He4-490.inout.txt").read_text()
    f = tmp_path / "he.inout.txt"
    f.write_text(text.replace(" SYMMETRY (1+P23)", " SYMMETRY (1)"))
    with pytest.raises(BasisFileError, match=f"{f}:5: SYMMETRY '\\(1\\)' is no spin state"):
        ecgpack.read_inout(f)


# --- cases 4, 5 and 13: each family's keys and types ----------------------------------------
@pytest.mark.parametrize("src,kind,key,owner", [
    (GVR, "pecg", "u", "ecg-gvr"), (FECG, "pecg", "s", "fecg"), (FECG, "ecg-gvr", "s", "fecg"),
    (GVR, "fecg", "u", "ecg-gvr")])
def test_a_relabelled_basis_type_is_refused_not_its_parameters_ignored(tmp_path, capsys, src, kind, key, owner):
    f = edited(tmp_path, src, lambda d: d.update(basis_type=kind))
    err = cli_error(capsys, "energy", f)
    assert f"{f}: function 0: key {key!r} belongs to {owner} functions, not to the file's basis_type {kind!r}" in err


def set_function(key, value, i=3):
    return lambda d: d["functions"][i].update({key: value})


@pytest.mark.parametrize("src,edit,words", [
    (GVR, set_function("K", True), "function 3: K must be an integer, not True"),
    (GVR, set_function("K", 1.0), "function 3: K must be an integer, not 1.0"),
    (HE, set_function("c_A", "1.0"), "function 3: c_A must be a number, not '1.0'"),
    (HE, lambda d: d["functions"][2]["A"][1].__setitem__(1, "1.0"), "function 2: A must be 3 x 3 numbers"),
    (GVR, lambda d: d["functions"][4]["u"].__setitem__(0, False), "function 4: u must be 3 numbers"),
    (HE, set_function("channel", 1), "function 3: channel must be a string"),
    (HE, set_function("channel", "jacobi:0-1"), "channel 'jacobi:0-1': Jacobi order"),
    (HE, set_function("x", 1.0), "function 3: key 'x' is unknown (a pecg function has A, c_A and channel)"),
    (HE, lambda d: d.update(extra=1), "unknown keys ['extra']"),
    (HE, lambda d: d["system"].update(title="He"), "system: unknown keys ['title']"),
    (HE, lambda d: d.update(coefficients=["1.0"] * 150), "coefficients must be 150 numbers"),
    (HE, lambda d: d.update(energy="-2.9"), "energy = '-2.9': must be a finite number"),
    (HE, lambda d: d.update(optimiser={"threshold": 2.0}), "optimiser threshold = 2.0"),
    (HE, lambda d: d.update(optimiser={"threshold": 5.0}), "optimiser threshold = 5.0"),
    (HE, lambda d: d.update(optimiser={"thresold": 1e-10}), "optimiser: unknown setting 'thresold'"),
    (HE, lambda d: d["conventions"].update(gaussian="exp(-r^T A r / 2)"), "conventions = "),
])
def test_keys_and_types_a_family_does_not_take_are_refused(tmp_path, capsys, src, edit, words):
    f = edited(tmp_path, src, edit)
    err = cli_error(capsys, "energy", f)
    assert f"{f}: " in err and words in err, err


def test_floating_ecgs_of_another_N_are_refused_naming_the_file(tmp_path, capsys):
    f = tmp_path / "in.toml"
    f.write_text('[system]\nparticles = ["p", "e"]\n[state]\nN = 1\nparity = -1\n[basis]\ntype = "fecg"\nsize = 3\n')
    err = cli_error(capsys, "run", f, "--out", tmp_path / "out", "--quiet")
    assert f"{f}: floating ECGs (fecg) take the label N = 0 only" in err
    g = edited(tmp_path, FECG, lambda d: d["system"]["state"].update(N=1, parity=-1))
    assert f"{g}: floating ECGs (fecg)" in cli_error(capsys, "energy", g)


# --- case 10: resources, before anything is built -------------------------------------------
def test_deep_nesting_and_long_integers_are_refused_in_one_line(tmp_path, capsys):
    deep = tmp_path / "deep.json"
    deep.write_text('{"functions": ' + "[" * 100_000 + "]" * 100_000 + "}")
    assert f"{deep}: JSON nested more than 16 levels deep" in cli_error(capsys, "energy", deep)
    shallow = edited(tmp_path, HE, lambda d: d["system"]["state"].update(N=json.loads("[" * 900 + "]" * 900)))
    assert "nested more than 16 levels deep" in cli_error(capsys, "energy", shallow)
    digits = tmp_path / "digits.json"
    digits.write_text(HE.read_text().replace('"version": 1', '"version": 1' + "0" * 5000, 1))
    assert f"{digits}:3: an integer of 5001 digits (at most 100 are read)" in cli_error(capsys, "energy", digits)
    toml = tmp_path / "in.toml"
    for text in ["a = " + "[" * 100_000 + "]" * 100_000, "[basis]\nsize = " + "1" * 5000]:
        toml.write_text(text)
        assert str(toml) in cli_error(capsys, "run", toml, "--out", tmp_path / "out", "--quiet")


@pytest.mark.filterwarnings("error")  # no RuntimeWarning before the error
@pytest.mark.parametrize("number", ["1e400", "-2e308", "NaN", "-Infinity"])
def test_numbers_no_double_holds_are_refused_naming_the_line(tmp_path, capsys, number):
    """Issue 55, item 2: 1e400 read as inf, refused later as `Basis: A[2, 0, 0] = inf` without its line."""
    f = tmp_path / "basis.json"
    text = HE.read_text()
    f.write_text(text.replace('"c_A": 1.0', f'"c_A": {number}', 1))
    line = text[:text.index('"c_A": 1.0')].count("\n") + 1
    assert cli_error(capsys, "energy", f).startswith(f"prebo: error: {f}:{line}: {number}: ")


@pytest.mark.filterwarnings("error")
def test_a_function_whose_integrals_overflow_is_refused_without_a_warning(tmp_path, capsys):
    """Issue 55, item 2: floating ECGs scaled by 1e301 printed `RuntimeWarning: invalid value encountered
    in add` (T + V) before the Hamiltonian's error."""
    def scale(d):
        f = d["functions"][1]
        f["A"], f["c_A"] = [[a * 1e301 for a in row] for row in f["A"]], f["c_A"] * 1e301
    f = edited(tmp_path, FECG, scale)
    assert f"{f}: the Hamiltonian matrix is not finite: H[0, 1] = inf" in cli_error(capsys, "energy", f)


@pytest.mark.parametrize("old,new,words", [
    ('"version": 1', '"version": true', "version = True: must be an integer (this prebo reads 1)"),
    ('"version": 1', '"version": 1.0', "version = 1.0: must be an integer (this prebo reads 1)"),
    ('"version": 1,', '"version": 2, "version": 1,', "key 'version' given twice in one object"),
    ('"c_A": 1.0,', '"c_A": 1.0, "c_A": 2.0,', "key 'c_A' given twice in one object"),
])
def test_a_version_that_is_no_integer_and_keys_given_twice_are_refused(tmp_path, capsys, old, new, words):
    """Issue 55, item 7: `"version": true` was read as 1; of a key given twice the last was kept."""
    f = tmp_path / "basis.json"
    f.write_text(HE.read_text().replace(old, new, 1))
    assert cli_error(capsys, "energy", f) == f"prebo: error: {f}: {words}\n"


def test_files_larger_than_the_bound_are_not_read(tmp_path, capsys, monkeypatch):
    """/dev/zero is refused after MAX_BYTES + 1 bytes (patched small here), not read until memory
    runs out, as an input, and by its first bytes as a basis (io.stored); so is a basis file that
    starts as one; the bound holds a checkpoint of MAX_SIZE functions of the most particles."""
    monkeypatch.setattr(basis_json, "MAX_BYTES", 1 << 16)
    assert "/dev/zero: larger than 65536 bytes, the most prebo reads" in cli_error(
        capsys, "run", "/dev/zero", "--out", tmp_path / "out")
    assert "/dev/zero: neither a basis.json" in cli_error(capsys, "energy", "/dev/zero")
    big = tmp_path / "big.inout.txt"
    for start in ("{", " BASIS_TYPE RG_0S\n"):
        big.write_text(start + " " * (1 << 17))
        assert f"{big}: larger than 65536 bytes" in cli_error(capsys, "energy", big)
    with pytest.raises(BasisFileError, match="larger than 65536 bytes"):
        ecgpack.read_inout(big)
    monkeypatch.undo()
    n = prebo.validation.MAX_PARTICLES
    function = {"A": np.full((n, n), -1.2345678901234567e-300).tolist(), "c_A": 1.2345678901234567e-300,
                "channel": "jacobi:" + "-".join(map(str, range(n))), "s": np.full((n, 3), -1e-300).tolist()}
    assert 2 * len(json.dumps(function, indent=1)) <= basis_json.FUNCTION_BYTES
    assert basis_json.MAX_BYTES >= MAX_SIZE * basis_json.FUNCTION_BYTES


def test_more_functions_than_memory_holds_are_refused_before_anything_is_built(tmp_path):
    """MAX_SIZE + 1 functions: one line (an abort of the Rust core with a backtrace before); a
    process of its own, as an abort would end the tests."""
    f = edited(tmp_path, HE, lambda d: (d.update(functions=(d["functions"] * (MAX_SIZE // 150 + 1))[:MAX_SIZE + 1]),
                                        d.pop("coefficients")))
    r = prebo_process("energy", f, timeout=120)
    assert r.returncode == 2 and r.stderr == (f"prebo: error: {f}: {MAX_SIZE + 1} functions, more than the "
                                              f"{MAX_SIZE} this machine's memory holds\n")


@pytest.mark.parametrize("size", ["1" * 5000, str(MAX_SIZE + 1)], ids=["5000 digits", "MAX_SIZE + 1"])
def test_an_ecgpack_basis_size_beyond_the_limit_is_refused(tmp_path, size):
    """BASIS_SIZE of 5000 digits (a ValueError before), or above MAX_SIZE with as many lines."""
    text = (DATA / "ecgpack-He4-490.inout.txt").read_text()
    head, _, lines = text.rpartition(" ==============================\n")
    lines = lines.splitlines()
    if len(size) < 10:
        lines = [f" {k + 1:6d}" + lines[k % len(lines)][7:] for k in range(int(size))]
    f = tmp_path / "he.inout.txt"
    f.write_text(head.replace(" BASIS_SIZE    490", f" BASIS_SIZE {size}") + " " + "=" * 30 + "\n" + "\n".join(lines))
    with pytest.raises(BasisFileError, match=f"{f}:6: BASIS_SIZE must be one integer in 0..{MAX_SIZE}"):
        ecgpack.read_inout(f)


# --- checkpoints: the run state --------------------------------------------------------------
def resume_error(capsys, tmp_path, edit) -> str:
    """`prebo run --resume` of the finished H run with `edit` applied to its checkpoint: the error
    line (None if the resume was accepted)."""
    run = tmp_path / "run"
    run.mkdir(exist_ok=True)
    edited(run, RUN, edit)
    with accepting():
        try:
            return cli_error(capsys, "run", "--resume", run, "--quiet")
        except Accepted:
            return None


def momentum(edit):
    def apply(d):
        d["momentum"] = json.loads(json.dumps({k: d[k] for k in ("format", "version", "system", "symmetry",
                                                                 "basis_type", "functions")}))
        edit(d["momentum"])
    return apply


@pytest.mark.parametrize("edit,words", [
    (lambda d: d.update(elapsed=-5.0), "elapsed = -5.0: must be the seconds of the run so far"),
    (lambda d: d["history"].__setitem__(3, [4, "x", "grow", 1.0]), "history row 3 = [4, 'x', 'grow', 1.0]"),
    (lambda d: d["history"].__setitem__(0, [True, -0.4, "grow", 0.0]), "history row 0"),
    (lambda d: d["history"].__setitem__(1, [2, -0.4, "nap", 0.0]), "history row 1"),
    (lambda d: d["history"].__setitem__(2, [3, -0.4, "grow", -1.0]), "history row 2"),
    (lambda d: d["history"].__setitem__(2, [3, -0.4, "grow", 1.0, 5]), "history row 2"),
    (lambda d: d["rng"]["state"].update(state=True), "rng = "),
    (lambda d: d["rng"].update(has_uint32=0.5), "rng = "),
    (lambda d: d["functions"][0].update(K=0), "function 0: key 'K' belongs to ecg-gvr functions"),
    (momentum(lambda m: m["functions"][1].update(c_A="1")), "momentum: function 1: c_A must be a number"),
    (momentum(lambda m: m.update(basis_type="fecg")), "momentum: function 0 has no 's'"),
    (momentum(lambda m: m.pop("format")), "momentum: not a prebo basis file"),
])
def test_a_malformed_run_state_is_refused_naming_the_file_and_key(tmp_path, capsys, edit, words):
    err = resume_error(capsys, tmp_path, edit)
    assert err is not None and f"{tmp_path / 'run' / 'basis.json'}: " in err and words in err, err


def test_the_momentum_block_is_checked_as_a_basis_of_the_run(tmp_path, capsys):
    assert resume_error(capsys, tmp_path, momentum(lambda m: None)) is None
    err = resume_error(capsys, tmp_path, momentum(lambda m: m["system"]["state"].update(threshold=-0.6)))
    assert f"{tmp_path / 'run' / 'basis.json'}: momentum: the reference is not a basis of this run" in err


def test_a_malformed_lowest_state_is_refused_naming_its_file(tmp_path, capsys):
    run = tmp_path / "run"
    run.mkdir()
    edited(run, RUN, lambda d: None)
    keep = ("format", "version", "conventions", "system", "symmetry", "basis_type", "functions", "energy", "optimiser")
    lowest = edited(run, RUN, lambda d: [d.pop(k) for k in set(d) - set(keep)] + [d.update(note="edited")],
                    "lowest.json")
    err = cli_error(capsys, "run", "--resume", run, "--quiet")
    assert f"{lowest}: unknown keys ['note']" in err


def test_the_api_refuses_an_operator_that_is_not_one_of_the_state():
    he = prebo.System(["alpha", "e", "e"], spin={"e": 0})
    triplet = prebo.System(["alpha", "e", "e"], spin={"e": 1}).symmetriser
    with pytest.raises(InputError, match=r"the symmetry operator is not that of the state \(e: S = 0\): it projects "
                                         "onto functions of another symmetry"):
        prebo.System(he.particles, he.state, symmetriser=triplet)
