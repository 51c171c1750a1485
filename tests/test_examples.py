"""The optimised bases in examples/bases, re-evaluated with `prebo energy`, against the literature
(tests/data/reference_energies.toml) and the variational principle."""
import json
import subprocess
import sys

import pytest

import prebo

from conftest import ROOT

BASES = ROOT / "examples" / "bases"
#: example -> (reference key, tolerance in Eh or "rel:x" relative); None: variational check only
ACCEPTANCE = {
    "h": ("H", "rel:1e-8"),
    "h2p": ("H 2p", "rel:1e-8"),
    "ps-": ("Ps-", 1e-6),
    "he": ("He", 1e-5),
    "h-": ("H-", 1e-5),
    "h2plus-pecg": ("H2+", None),
    "h2plus-gvr": ("H2+", 5.2e-9),  # issue 4 run: 4.6e-9 above the reference with 180 functions
    "h2plus-150": ("H2+", 1.13e-9),  # the H2+ 150 run's lowest state at 150 functions (benchmarks/record/h2.md)
    "h2plus-fecg": ("H2+", 5e-5),  # 4.72e-5 above after 1200 s of the defaults (benchmarks/record/h2.md)
    "h2-pecg": ("H2", None),
    "h2-fecg": ("H2", 5.5e-4),  # 5.47e-4 above after 1200 s of the defaults (benchmarks/record/h2.md)
    # inputs without an [optimiser] table (examples/auto, issue 17: within 1e-6 relative)
    "auto-h": ("H", "rel:1e-6"),
    "auto-he": ("He", "rel:1e-6"),
    "auto-h-": ("H-", "rel:1e-6"),
    "auto-ps-": ("Ps-", "rel:1e-6"),
    "auto-h2+": ("H2+", "rel:1e-6"),
    "auto-h2": ("H2", "rel:1e-6"),  # 6.2e-7 relative after 600 s with 300 functions (benchmarks/record/schedules.md)
    "auto-he-400": ("He", 9e-10),  # 8.65e-10 above after 206 s (benchmarks/record/schedules.md)
    "auto-he-700": ("He", 1e-10),  # 5.14e-11 above after 300 s, 1e-10 at 223 s (benchmarks/record/schedules.md)
    "auto-li-150": ("Li", 7.5e-5),  # 4.40e-5 above after 81 s; ecgpack's Li-100 accuracy (issue 17)
    "auto-li": ("Li", "rel:1e-6"),  # 6.1e-7 relative after 600 s with 400 functions (benchmarks/record/schedules.md)
}
#: examples whose energy is not below their lowest dissociation threshold: 60 plain ECGs cannot
#: localise H2+'s protons (examples/h2plus-pecg.toml), and stay 14 mEh above H + p
UNBOUND = {"h2plus-pecg"}


def energy(path, *extra):
    r = subprocess.run([sys.executable, "-m", "prebo", "energy", str(path), "--json", *extra],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout)


def exact(references, key, basis_file):
    ref = references[key]
    if ref["energy"] == "exact":  # hydrogen-like: -mu/(2 n^2)
        particles = json.loads(basis_file.read_text())["system"]["particles"]
        m1, m2 = (p["mass"] for p in particles)
        return -0.5 * m1 * m2 / (m1 + m2) / ref["n"] ** 2
    return ref["energy"]


@pytest.mark.parametrize("name", sorted(ACCEPTANCE))
def test_example_basis(name, references):
    key, tol = ACCEPTANCE[name]
    f = BASES / name / "basis.json"
    r = energy(f)
    e_exact = exact(references, key, f)
    masses = {p["name"]: p["mass"] for p in r["particles"]}
    for particle, m in references[key]["masses"].items():
        assert masses[particle] == m, f"{name}: {particle} mass differs from the reference's"
    assert r["energy"] > e_exact, f"{name}: {r['energy']} below the exact {e_exact}: a bug"
    assert r["bound"] is (name not in UNBOUND), (name, r["energy"], r["threshold"], r["threshold_fragments"])
    stored = json.loads((BASES / name / "result.json").read_text())
    # the stored energy is reproduced: the refined eigenvalue of the stored matrices does not
    # depend on the BLAS kernel (tests/test_machine_independence.py), but a change of operation
    # order in the integral kernels moves it by up to its energy_uncertainty (1e-8 for h2plus-pecg)
    assert r["energy"] == pytest.approx(stored["energy"], rel=1e-9, abs=0)
    assert r["energy_uncertainty"] == pytest.approx(stored["energy_uncertainty"], rel=1e-6)
    if isinstance(tol, str):
        assert (r["energy"] - e_exact) / abs(e_exact) < float(tol.split(":")[1])
    elif tol is not None:
        assert r["energy"] - e_exact < tol


#: bases optimised for excited levels (examples/excited, issue 39) -> [(root, reference key, tolerance)],
#: each level re-evaluated and checked as ACCEPTANCE checks the lowest. A reference for an infinitely
#: heavy nucleus is met by a nucleus of at least INFINITE electron masses: with 1e9 the energy lies
#: 2e-9 relative above the limit (E ≈ μ E_∞, μ = M/(M + 1); mass polarisation ~1e-11 Eh)
LEVELS = {
    "he-2-1s": [(0, "He", 1e-8)],  # 4He: 1 1S 6.1e-9 above with 2 1S in the same 250 functions
    "he-inf-2-1s": [(1, "He 2 1S", "rel:1e-7")],
    "he-inf-2-3s": [(0, "He 2 3S", "rel:1e-7")],
    "he-inf-1s": [(0, "He inf", 5e-10)],  # mass = inf: 1.48e-10 above after 660 s with 700 functions
    "he-inf-2p": [(0, "He 2 1P", 5e-9)],  # mass = inf, ECG-GVR: 3.72e-9 above after 903 s with 300 functions
    "h2plus-ladder": [(0, "H2+", 1e-8), (1, "H2+ v=1", 1e-8), (2, "H2+ v=2", 1e-7), (3, "H2+ v=3", 1e-7)],
    "h2plus-n1": [(0, "H2+ N=1", 1e-8), (1, "H2+ N=1 v=1", 1e-8)],
}
INFINITE = 1e9


@pytest.mark.parametrize("name", sorted(LEVELS))
def test_excited_levels_of_example_bases(name, references):
    f = BASES / name / "basis.json"
    r = energy(f)
    stored = json.loads((BASES / name / "result.json").read_text())
    targets = r.get("targets", [0])
    assert targets == stored.get("targets", [0]) and r["state"] == stored["state"]
    levels = r.get("levels", [r | {"root": 0}])
    masses = {p["name"]: float(p["mass"]) for p in r["particles"]}  # an infinite mass is stored as "inf"
    for root, key, tol in LEVELS[name]:
        level, ref = levels[root], references[key]
        for particle, m in ref["masses"].items():
            assert masses.get(particle, max(masses.values())) >= INFINITE if m == float("inf") else masses[particle] == m
        assert level["root"] == root and root in targets and level["bound"]
        assert level["energy"] == pytest.approx(stored.get("levels", [stored])[root]["energy"], rel=1e-9, abs=0)
        assert level["energy"] > ref["energy"], f"{name}: root {root} {level['energy']} below the exact {ref['energy']}"
        error = level["energy"] - ref["energy"]
        assert error / abs(ref["energy"]) < float(tol.split(":")[1]) if isinstance(tol, str) else error < tol, \
            (name, root, error)


def test_h2plus_gvr_basis_meets_the_issue_targets():
    """At most 180 ECG-GVR functions, E <= -0.597139058 Eh, virial η_TI <= 1e-7 (issue 4)."""
    r = energy(BASES / "h2plus-gvr" / "basis.json")
    assert r["n_basis"] <= 180 and r["basis_type"] == "ecg-gvr"
    assert r["energy"] <= -0.597139058 and r["virial"] <= 1e-7


def test_h2plus_150_basis_meets_the_issue_target():
    """At most 150 ECG-GVR functions, E <= -0.597139062 Eh, below the paper's -0.597139061 with 180
    (issue 16; Muolo, Mátyus & Reiher, J. Chem. Phys. 148, 084112 (2018), Table 2)."""
    r = energy(BASES / "h2plus-150" / "basis.json")
    assert r["n_basis"] <= 150 and r["basis_type"] == "ecg-gvr"
    assert r["energy"] <= -0.597139062


def test_h2_500_basis_meets_the_issue_target():
    """The H2 run's checkpoint: at most 500 ECG-GVR functions, E <= -1.164025020 Eh (issue 16; the
    paper's -1.164025028 with 500, Muolo, Mátyus & Reiher, J. Chem. Phys. 148, 084112 (2018),
    Table 2); that it lies above the exact energy is test_run_checkpoints_lie_above_the_reference."""
    r = energy(ROOT / "benchmarks" / "checkpoints" / "h2-auto" / "basis.json")
    assert r["n_basis"] <= 500 and r["basis_type"] == "ecg-gvr"
    assert r["energy"] <= -1.164025020


def test_h2plus_fecg_basis_meets_the_issue_target_and_reports_n2():
    """At most 400 floating ECGs, E_TI <= -0.59704 Eh (issue 16; the paper's Table 1: -0.597006 …
    -0.597044), <N²>_TI reported and small: the N = 0 state is restored by the optimisation."""
    r = energy(BASES / "h2plus-fecg" / "basis.json")
    assert r["n_basis"] <= 400 and r["basis_type"] == "fecg"
    assert r["energy"] <= -0.59704 and 0.0 <= r["n2"] < 1e-3


def test_h2_fecg_basis_meets_the_issue_target_and_reports_n2():
    """At most 600 floating ECGs, E_TI <= -1.16272 Eh (issue 16; the paper's Table 1: -1.162669 …
    -1.162721), <N²>_TI reported and small: the N = 0 state is restored by the optimisation."""
    r = energy(BASES / "h2-fecg" / "basis.json")
    assert r["n_basis"] <= 600 and r["basis_type"] == "fecg"
    assert r["energy"] <= -1.16272 and 0.0 <= r["n2"] < 1e-3



#: every stored basis file (a run's result.json is not one) in examples/ and tests/data
STORED = sorted(f.relative_to(ROOT) for folder in ("examples", "tests/data") for f in (ROOT / folder).rglob("*.json")
                if f.name != "result.json")


@pytest.mark.parametrize("path", STORED, ids=str)
def test_stored_basis_files_hold_what_the_format_says(path):
    """docs/basis-format.md on every stored basis file: only its keys; `energy` the lowest root's
    translation-free energy of the file's own functions; `objective` (with `levels` and `followed`)
    only in the checkpoint of a run for other levels than the lowest, Σ w_k E_k of the targeted
    levels where they stand. he-2-1s, he-inf-2-1s, h2plus-ladder and h2plus-n1 held that sum in
    `energy` and had no objective; h, h2-pecg and h2plus-pecg held the energy of the code they were
    written with (1e-10, 1.3e-11 and 1.1e-8 relative from their functions')."""
    from prebo.io.load import load_basis
    from prebo.io.basis_json import KEYS

    d = json.loads((ROOT / path).read_text())
    assert set(d) <= set(KEYS), set(d) - set(KEYS)
    basis, threshold = load_basis(ROOT / path)
    targets, weights = basis.system.state.levels
    for_levels = targets != (0,) and "progress" in d
    assert ("objective" in d) == ("levels" in d) == ("followed" in d) == for_levels
    levels = d.get("levels", list(targets))
    r = prebo.evaluate(basis, threshold=threshold, roots=max(levels) + 1)
    E = [level["energy"] for level in r["levels"]] if "levels" in r else [r["energy"]]
    assert d["energy"] == pytest.approx(E[0], rel=1e-13, abs=0)
    if for_levels:
        assert d["objective"] == pytest.approx(sum(w * E[k] for k, w in zip(levels, weights)), rel=1e-13, abs=0)

#: the two evaluation paths, with the eigenvalues refined in extended precision, agree to 2e-15
#: (H, overlap condition 1.4e12; 1e-10 with LAPACK's eigenvalues alone), 6e-16 (He), 7e-16 (H2+)
#: and 1.5e-13 (Ps-, whose kernels lose more digits: see docs/conventions.md)
@pytest.mark.parametrize("name, rel", [("h", 1e-13), ("he", 1e-13), ("ps-", 1e-11), ("h2plus-gvr", 1e-13)])
def test_example_ti_evaluation_agrees(name, rel):
    f = BASES / name / "basis.json"
    assert energy(f, "--coordinates", "ti")["energy"] == pytest.approx(energy(f)["energy"], rel=rel, abs=0)


@pytest.mark.parametrize("name, key, size", [("h2", "H2", 500), ("h2-cycles", "H2", 500), ("h2-auto", "H2", 500),
                                             ("h2plus-150", "H2+", 150)])
def test_run_checkpoints_lie_above_the_reference(name, key, size, references, tmp_path):
    """The H2 and H2+ run checkpoints (benchmarks/checkpoints), and their lowest states (lowest.json)
    where the runs stand above them, re-evaluated: above the literature energy
    (its proton mass is 5e-10 relative lighter than CODATA 2018's, which lowers the energy by about
    1e-2 Eh x 5e-10 = 5e-12 Eh, far below the runs' 1.7e-7),
    and the checkpoint's own energy reproduced within its numerical uncertainty and rounding. One
    read of the file (a copy), so that a run still writing the checkpoint cannot change it between
    the evaluation and the stored energy."""
    for file in ("basis.json", "lowest.json"):  # the checkpoint, and the lowest state if the run stands above it
        try:
            text = (ROOT / "benchmarks" / "checkpoints" / name / file).read_text()
        except FileNotFoundError:
            assert file == "lowest.json"
            continue
        f = tmp_path / file
        f.write_text(text)
        r = energy(f)
        assert r["basis_type"] == "ecg-gvr" and r["n_basis"] <= size
        assert r["energy"] > references[key]["energy"], f"{name}/{file}: {r['energy']} below the reference: a bug"
        stored = json.loads(text)["energy"]
        assert abs(r["energy"] - stored) <= 10 * r["energy_uncertainty"] + 1e-14 * abs(stored)
