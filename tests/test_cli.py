"""The command line: a full run, re-evaluation, and clear one-line errors (exit 2, no traceback)."""
import json
from pathlib import Path

import numpy as np
import pytest

from prebo.level.expectation import OPERATORS

from conftest import prebo_process

REQUIRED = {"energy", "energy_lab", "virial", "n_basis", "basis_type", "particles", "symmetry"}


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    d = tmp_path_factory.mktemp("run")
    (d / "h.toml").write_text(
        '[system]\nparticles = ["p", "e"]\n[basis]\nsize = 6\n[optimiser]\ntrials = 8\nseed = 3\nrefine = 1\n'
    )
    r = prebo_process("run", d / "h.toml", "--out", d / "out", "--quiet")
    assert r.returncode == 0, r.stderr
    return d / "out"


def test_run_writes_result_and_basis(run_dir):
    result = json.loads((run_dir / "result.json").read_text())
    assert REQUIRED <= set(result)
    assert result["n_basis"] == 6 and result["basis_type"] == "pecg"
    assert [p["name"] for p in result["particles"]] == ["p", "e"]
    m = 1836.15267343
    assert -0.5 * m / (1 + m) < result["energy"] < -0.49  # variational, and a real optimisation
    # the properties block: every operator plain ECGs evaluate, per pair or particle class
    assert set(result["expectation"]) == set(OPERATORS) and set(result["expectation"]["p2"]) == {"p", "e"}
    assert result["expectation"]["p2"]["e"] / (2 * 1.0) + result["expectation"]["p2"]["p"] / (2 * m) == \
        pytest.approx(result["kinetic"], rel=1e-10)
    basis = json.loads((run_dir / "basis.json").read_text())
    assert basis["format"] == "prebo-basis" and len(basis["functions"]) == 6
    assert {"A", "c_A", "channel"} <= set(basis["functions"][0])


@pytest.mark.parametrize("coordinates", ["lab", "ti"])
def test_energy_json_reproduces_the_run(run_dir, coordinates):
    r = prebo_process("energy", run_dir / "basis.json", "--coordinates", coordinates, "--json")
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)
    assert REQUIRED <= set(out)
    ref = json.loads((run_dir / "result.json").read_text())
    assert out["energy"] == pytest.approx(ref["energy"], rel=1e-12)
    assert out["energy_lab"] == pytest.approx(ref["energy_lab"], rel=1e-12)


def test_same_seed_same_basis(run_dir, tmp_path):
    """A fixed schedule repeats bit for bit (the adaptive one follows measured seconds)."""
    r = prebo_process("run", run_dir.parent / "h.toml", "--out", tmp_path, "--quiet")
    assert r.returncode == 0
    a = json.loads((run_dir / "basis.json").read_text())["functions"]
    b = json.loads((tmp_path / "basis.json").read_text())["functions"]
    assert a == b


def test_a_new_run_refuses_a_folder_holding_a_checkpoint(run_dir, tmp_path):
    """`prebo run X.toml --out DIR` silently overwrote the run whose checkpoint DIR holds (and let two
    runs share a folder), or its result (issue 37, case 6); a folder with other files only is a run's
    to write, and --force starts over in one holding an earlier run."""
    toml, before = run_dir.parent / "h.toml", (run_dir / "basis.json").read_bytes()
    assert_clean_error(prebo_process("run", toml, "--out", run_dir, "--quiet"),
                       f"{run_dir}: the output folder holds a run's checkpoint (basis.json): continue that run "
                       f"with `prebo run --resume {run_dir}`, or give another --out (or --force to start over)")
    assert (run_dir / "basis.json").read_bytes() == before
    (tmp_path / "lowest.json").write_bytes(before)
    assert_clean_error(prebo_process("run", toml, "--out", tmp_path, "--quiet"), "checkpoint (lowest.json)")
    (tmp_path / "lowest.json").unlink()
    (tmp_path / "notes.txt").write_text("mine")
    assert prebo_process("run", toml, "--out", tmp_path, "--quiet").returncode == 0
    assert json.loads((tmp_path / "basis.json").read_text())["functions"] == json.loads(before)["functions"]
    assert (tmp_path / "notes.txt").read_text() == "mine"
    (tmp_path / "basis.json").unlink()
    result = (tmp_path / "result.json").read_bytes()
    assert_clean_error(prebo_process("run", toml, "--out", tmp_path, "--quiet"),
                       f"{tmp_path}: the output folder holds a run's result (result.json): give another --out, "
                       "or --force to replace it")
    assert (tmp_path / "result.json").read_bytes() == result and not (tmp_path / "basis.json").exists()
    (tmp_path / "lowest.json").write_bytes(before)  # an earlier run's lowest state: not the new run's
    assert prebo_process("run", toml, "--out", tmp_path, "--quiet", "--force").returncode == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["basis.json", "notes.txt", "result.json"]
    assert json.loads((tmp_path / "result.json").read_text())["wall_seconds"] != json.loads(result)["wall_seconds"]


def assert_clean_error(r, *words):
    assert r.returncode == 2, (r.returncode, r.stdout, r.stderr)
    assert "Traceback" not in r.stderr
    assert r.stderr.startswith("prebo: error:")
    for w in words:
        assert w in r.stderr, r.stderr


@pytest.mark.parametrize("particles, state, words", [
    ('["p", "xyz"]', "", ["unknown particle 'xyz'"]),
    ('[{name = "p", mass = -3.0}, "e"]', "", ["mass = -3.0: must be a finite positive number"]),
    ('[{name = "p", mass = 0}, "e"]', "", ["mass = 0: must be a finite positive number"]),
    ('["alpha", "e", "e", "e"]', "[state]\nspin = { e = 1 }\n", ["cannot couple to total spin 1"]),
    ('["p", "e", "e"]', "[state]\nspin = { e = 0.3 }\n", ["spin of 'e' = 0.3: must be a spin 0, 1/2, 1"]),
    ('["p", "e"]', "[state]\nN = 1\n", ["natural parity", "not parity +1 with N = 1"]),  # ECG-GVR chosen for N = 1
    ('["p", "e"]', "[optimiser]\ncycle = 2\n", ["unknown keys ['cycle']", "'cycles'"]),
    ('["p", "e"]', "[optimiser]\ncycles = 0\n", ["[optimiser] cycles = 0: must be an integer ≥ 1"]),
])
def test_bad_input_gives_a_clear_error(tmp_path, particles, state, words):
    f = tmp_path / "bad.toml"
    f.write_text(f"[system]\nparticles = {particles}\n{state}[basis]\nsize = 2\n")
    assert_clean_error(prebo_process("run", f, "--out", tmp_path / "o", "--quiet"), str(f), *words)


def test_malformed_toml(tmp_path):
    f = tmp_path / "bad.toml"
    f.write_text("[system\nparticles = 3")
    assert_clean_error(prebo_process("run", f, "--quiet"), "not valid TOML")


def _edit_basis(run_dir, tmp_path, edit):
    d = json.loads((run_dir / "basis.json").read_text())
    edit(d)
    f = tmp_path / "basis.json"
    f.write_text(json.dumps(d))
    return f


def test_non_positive_definite_A(run_dir, tmp_path):
    def edit(d):
        # subtracting a large multiple of (e_1 - e_2)(e_1 - e_2)^T keeps A 1 = c_A m/m_tot but breaks definiteness
        A = np.array(d["functions"][2]["A"])
        d["functions"][2]["A"] = (A - 5.0 * abs(A).max() * np.array([[1, -1], [-1, 1]])).tolist()
    assert_clean_error(prebo_process("energy", _edit_basis(run_dir, tmp_path, edit)), "function 2", "not positive definite")


def test_truncated_and_corrupt_basis_files(run_dir, tmp_path):
    text = (run_dir / "basis.json").read_text()
    f = tmp_path / "trunc.json"
    f.write_text(text[: len(text) // 2])
    assert_clean_error(prebo_process("energy", f), "corrupt or truncated")
    g = _edit_basis(run_dir, tmp_path, lambda d: d["functions"][1].pop("A"))
    assert_clean_error(prebo_process("energy", g), "function 1 has no 'A'")
    g = _edit_basis(run_dir, tmp_path, lambda d: d.update(basis_type="ecg-gvr"))  # "malformed (KeyError: 'u')" before
    assert_clean_error(prebo_process("energy", g), "function 0 has no 'u', 'K' (each ecg-gvr function has A, c_A, u, K)")
    g = _edit_basis(run_dir, tmp_path, lambda d: d["functions"][1].update(A=[[1.0]]))  # a numpy message before
    assert_clean_error(prebo_process("energy", g), "function 1: A must be 2 x 2")
    g = _edit_basis(run_dir, tmp_path, lambda d: d["functions"][1].update(A=[[-1.0, 0.0], [0.0, -1.0]]))
    assert_clean_error(prebo_process("energy", g), "function 1: exponent matrix A is not positive definite")  # not "CM"
    h = _edit_basis(run_dir, tmp_path, lambda d: d.update(format="other"))
    assert_clean_error(prebo_process("energy", h), "not a prebo basis file")
    assert_clean_error(prebo_process("energy", tmp_path / "missing.json"), "cannot read")


def test_ti_refuses_a_basis_with_unequal_c_A(run_dir, tmp_path):
    def edit(d):
        f = d["functions"][0]
        m = np.array([p["mass"] for p in d["system"]["particles"]])
        cm = m / m.sum()
        f["A"] = (np.array(f["A"]) + 0.5 * np.outer(cm, cm)).tolist()
        f["c_A"] += 0.5
    f = _edit_basis(run_dir, tmp_path, edit)
    assert prebo_process("energy", f).returncode == 0  # the laboratory-frame elimination takes it
    assert_clean_error(prebo_process("energy", f, "--coordinates", "ti"), "not separable in the CM coordinate")


def test_plot_draws_the_convergence_of_runs(run_dir, tmp_path):
    png = tmp_path / "conv.png"
    r = prebo_process("plot", run_dir, run_dir, "--reference", -0.4997278397, "--out", png)
    assert r.returncode == 0, r.stderr
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 5000
    history = json.loads((run_dir / "basis.json").read_text())["history"]
    assert [h[0] for h in history] == sorted(h[0] for h in history)  # basis size never shrinks
    assert all(b[1] <= a[1] for a, b in zip(history, history[1:]))  # energy never rises
    middle = history[len(history) // 2][3]
    r = prebo_process("plot", run_dir, "--since", middle, "--out", png, "--force")
    assert r.returncode == 0, r.stderr
    assert_clean_error(prebo_process("plot", run_dir, "--since", -1.0, "--out", png, "--force"), "nothing in its history at or before -1 s")
    logged = tmp_path / "log.png"  # a run of days beside one of minutes: the wall time on a log axis
    r = prebo_process("plot", run_dir, "--since", middle, "--log-time", "--out", logged)
    assert r.returncode == 0, r.stderr
    assert logged.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and logged.read_bytes() != png.read_bytes()
    for option in ("--reference", "--since"):  # a NaN or infinite number is refused, not drawn
        for bad in ("nan", "inf", "-inf", "x"):
            assert_clean_error(prebo_process("plot", run_dir, f"{option}={bad}", "--out", png, "--force"), option, "not a finite number")


def test_plot_file_names_and_references_a_log_axis_cannot_draw(run_dir, tmp_path):
    """A new user's cases: `--out conv.txt` (a matplotlib traceback), `--out conv` (wrote conv.png,
    said conv), a reference above the run's energies (an empty log plot, exit 0)."""
    assert_clean_error(prebo_process("plot", run_dir, "--out", tmp_path / "conv.txt"), "conv.txt", ".png, .pdf, .svg")
    r = prebo_process("plot", run_dir, "--out", tmp_path / "conv")
    assert r.returncode == 0 and r.stdout.strip() == f"wrote {tmp_path / 'conv.png'}"
    assert (tmp_path / "conv.png").read_bytes()[:4] == b"\x89PNG"
    r = prebo_process("plot", run_dir, "--out", tmp_path / "conv.pdf")
    assert r.returncode == 0 and (tmp_path / "conv.pdf").read_bytes()[:4] == b"%PDF"
    assert_clean_error(prebo_process("plot", run_dir, "--reference", -0.4, "--out", tmp_path / "c.png"),
                       "--reference -0.4 Eh is not below the energies")


def test_an_input_file_given_with_resume_is_refused(run_dir, tmp_path):
    """`prebo run OTHER.toml --resume DIR` resumed DIR and ignored the input without a word."""
    h = __import__("conftest").ROOT / "examples" / "h.toml"
    assert_clean_error(prebo_process("run", h, "--resume", run_dir), "--resume", "give no input file")
    assert_clean_error(prebo_process("run", "--resume", run_dir, "--out", tmp_path / "x"), "give no input file or --out")
    assert_clean_error(prebo_process("run", "--resume", run_dir, "--force"), "nor --force")


def test_plot_since_starts_each_run_from_its_state_at_that_moment():
    from prebo.plot import since
    h = [[1, -0.3, "grow", 1.0], [2, -0.4, "grow", 2.0], [2, -0.45, "sweep", 5.0]]
    assert since(h, 3.0) == [[2, -0.4, "grow", 3.0], [2, -0.45, "sweep", 5.0]]
    assert since(h, 2.0) == [[2, -0.4, "grow", 2.0], [2, -0.45, "sweep", 5.0]]  # a row at that moment leads
    assert since([[1, -0.3, "grow", 0.0], [2, -0.4, "grow", 0.0]], 0.0) == [[2, -0.4, "grow", 0.0]]


def test_ecgpack_import_export_and_energy(tmp_path):
    """`prebo import`, `prebo export --format ecgpack` and `prebo energy FILE.inout.txt`; the Li file's
    own Young operator survives basis.json (ecgpack energy in tests/data/ecgpack/README.md)."""
    li = __import__("conftest").ROOT / "tests" / "data" / "ecgpack" / "ecgpack-Li7-100.inout.txt"
    reference = -7.477376525757929
    direct = json.loads(prebo_process("energy", li, "--json").stdout)["energy"]
    assert direct == pytest.approx(reference, rel=1e-13)
    assert prebo_process("import", li, "--out", tmp_path / "li.json").returncode == 0
    via_json = json.loads(prebo_process("energy", tmp_path / "li.json", "--json").stdout)["energy"]
    assert via_json == pytest.approx(reference, rel=1e-13)
    assert prebo_process("export", tmp_path / "li.json", "--format", "ecgpack", "--out", tmp_path / "li.inout.txt").returncode == 0
    back = json.loads(prebo_process("energy", tmp_path / "li.inout.txt", "--json").stdout)["energy"]
    assert back == pytest.approx(reference, rel=1e-13)
    (tmp_path / "bad.inout.txt").write_text("PARTICLES 3\nbroken\n")
    assert_clean_error(prebo_process("energy", tmp_path / "bad.inout.txt"), "bad.inout.txt")


def test_run_budget_from_the_command_line_stops_a_run_and_extends_it_on_resume(tmp_path):
    """`prebo run INPUT --budget S` stops at S seconds of the run and keeps its place; `--resume DIR
    --budget S'` (the whole run's seconds) goes on from there; a budget that is not a positive
    number of seconds is refused in one line."""
    toml = tmp_path / "he.toml"
    toml.write_text('[system]\nparticles = ["alpha", "e", "e"]\n[state]\nspin = { e = 0 }\n[basis]\nsize = 400\n')
    out = tmp_path / "he"
    assert prebo_process("run", toml, "--out", out, "--budget", 2, "--quiet").returncode == 0
    first = json.loads((out / "result.json").read_text())["convergence"]
    d = json.loads((out / "basis.json").read_text())
    assert first["stopped"] == "budget" and 2.0 <= first["seconds"] < 30 and d["optimiser"]["budget"] == 2.0
    assert prebo_process("run", "--resume", out, "--budget", d["elapsed"] + 2.0, "--quiet").returncode == 0
    again = json.loads((out / "basis.json").read_text())
    assert again["stopped"] == "budget" and again["elapsed"] >= d["elapsed"] + 2.0
    assert again["history"][:len(d["history"])] == d["history"] and len(again["history"]) > len(d["history"])
    for bad in ("0", "-5", "nan", "inf", "ten"):
        assert_clean_error(prebo_process("run", toml, "--out", out, "--budget", bad), "--budget", "seconds above 0")


def test_the_result_and_a_re_evaluation_use_the_threshold_of_the_run(tmp_path):
    """The stored He basis (overlap condition 3e12) with its run's threshold raised to 1e-11: the
    result of the resumed run and `prebo energy` of its basis.json drop the same directions, and
    --threshold 1e-13 keeps them all (and a lower energy)."""
    import shutil
    from pathlib import Path
    out = tmp_path / "he"
    shutil.copytree(Path(__file__).parent.parent / "examples" / "bases" / "auto-he-400", out)
    d = json.loads((out / "basis.json").read_text())
    d["optimiser"]["threshold"] = 1e-11
    (out / "basis.json").write_text(json.dumps(d))
    r = prebo_process("run", "--resume", out, "--quiet")
    assert r.returncode == 0, r.stderr
    result = json.loads((out / "result.json").read_text())
    again = json.loads(prebo_process("energy", out / "basis.json", "--json").stdout)
    assert result["kept"] == again["kept"] < 400 and result["energy"] == again["energy"]
    full = json.loads(prebo_process("energy", out / "basis.json", "--threshold", "1e-13", "--json").stdout)
    assert full["kept"] == 400 and full["energy"] < again["energy"]
    assert_clean_error(prebo_process("energy", out / "basis.json", "--threshold", "0"), "--threshold")


def printed(*args, columns: int) -> str:
    """What `prebo ARGS` prints on a pipe of `columns` columns (COLUMNS, as a terminal of that
    width or a log would have it); exit 0."""
    import os
    r = prebo_process(*args, env=os.environ | {"COLUMNS": str(columns)})
    assert r.returncode == 0, r.stderr
    return r.stdout


BASES = Path(__file__).resolve().parents[1] / "examples" / "bases"


@pytest.mark.parametrize("columns", [80, 40])
def test_no_printed_number_is_cut_short(run_dir, columns):
    """In a pipe, a log or an 80-column terminal, `prebo energy BASIS --roots K` printed
    `-0.597139061…`: rich shortens the column that does not fit. Every table-printing command
    (energy with levels, properties with the Breit–Pauli terms, a run's result) at 80 columns and
    narrower shows no ellipsis, and each energy, expectation value and correction it prints is
    its --json value to the digits printed."""
    ladder = BASES / "h2plus-ladder" / "basis.json"
    text = printed("energy", ladder, "--roots", 4, columns=columns)
    r = json.loads(printed("energy", ladder, "--roots", 4, "--json", columns=columns))
    assert "…" not in text
    for level in r["levels"]:
        assert f"{level['energy']:.12f}" in text and f"{level['energy_uncertainty']:.1e}" in text
    for d in r["transitions"]:
        if d["upper"] == d["lower"] + 1:
            assert f"{d['Eh']:.10f}" in text and f"{d['cm-1']:.6f}" in text
    for basis in (BASES / "h2-pecg" / "basis.json",):
        text = printed("properties", basis, columns=columns)
        p = json.loads(printed("properties", basis, "--json", columns=columns))
        assert "…" not in text and f"{p['energy']:.12f}" in text
        values = [v for per in p["expectation"].values() for v in per.values()]
        values += list(p["delta_regularised"].values()) + list(p["p4_regularised"].values())
        values = [f"{v:.10g}" for v in values]
        values += [f"{e:.6e}" for e in p["breit_pauli"]["Eh"].values()]
        values += [f"{e:.6e}" for per in p["breit_pauli"]["classes"].values() for e in per.values()]
        assert [v for v in values if v not in text] == []
    text = printed("energy", run_dir / "basis.json", columns=columns)
    result = json.loads((run_dir / "result.json").read_text())
    assert "…" not in text and f"{result['energy']:.12f}" in text and f"{result['energy_lab']:.12f}" in text


@pytest.mark.parametrize("argv,line", [
    (["energy", "he.json", "--bogus"], "prebo: error: energy: unrecognized arguments: --bogus "
                                       "(see prebo energy --help)"),
    (["run", "in.toml", "extra"], "prebo: error: run: unrecognized arguments: extra (see prebo run --help)"),
    (["nosuch"], "prebo: error: argument command: invalid choice: 'nosuch' (choose from 'run', 'properties', "
                 "'energy', 'transitions', 'polarisability', 'import', 'export', 'plot') (see prebo --help)"),
    (["run", "--budget", "0"], "prebo: error: run: argument --budget: '0' is not a number of seconds above 0 "
                               "(see prebo run --help)"),
    (["properties", "he.json", "--root", "x"], "prebo: error: properties: argument --root: 'x' is not an integer ≥ 0 "
                                               "(see prebo properties --help)"),
    (["energy"], "prebo: error: energy: the following arguments are required: basis (see prebo energy --help)"),
    (["import"], "prebo: error: import: the following arguments are required: file (see prebo import --help)"),
    (["export", "he.json"], "prebo: error: export: the following arguments are required: --format "
                            "(see prebo export --help)"),
    (["plot"], "prebo: error: plot: the following arguments are required: runs (see prebo plot --help)"),
])
def test_command_line_errors_name_the_program_once(argv, line):
    """Issue 55, item 7: an unknown option printed `prebo: error: prebo: unrecognized arguments` (and a
    subcommand's errors `prebo: error: prebo energy: ...`); a subcommand's unknown argument is
    refused by that subcommand, which names its own --help."""
    r = prebo_process(*argv)
    assert r.returncode == 2 and r.stdout == "" and r.stderr == line + "\n", r.stderr
