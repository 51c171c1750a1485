"""ecgpack / ATOM-MOL-nonBO real-ECG bases (*.inout.txt): reading, writing, and prebo's energies
against ecgpack's (issue 5). Data and the Li-100 reference: tests/data/ecgpack/README.md."""
import json
import os
import shutil
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

import prebo
from prebo import eigen
from prebo.basis import Basis
from prebo.errors import BasisFileError, InputError
from prebo.integrals import laboratory
from prebo.io import ecgpack
from prebo.system.young import young_operator, young_product, young_string

from conftest import POSIX_FILES, ROOT

DATA = Path(__file__).parent / "data" / "ecgpack"
HE = DATA / "ecgpack-He4-490.inout.txt"
LI = DATA / "ecgpack-Li7-100.inout.txt"
HE_ECGPACK = -2.903304557617398  # the file's CURRENT_ENERGY
#: Li-100 with the file's own operator Y†Y of (1+P23)(1-P24); computed once, see the README
LI_REFERENCE = -7.477376525757929


@pytest.fixture(scope="module")
def he():
    return ecgpack.read_inout(HE)


def rel(a, b):
    return abs(a - b) / abs(b)


def energy(basis):
    """prebo.evaluate(basis)["energy"] (laboratory frame), without its second, lab-frame solve."""
    m = laboratory(basis.system).matrices(basis)
    return float(eigen.solve(m["T_ti"] + m["V"], m["S"]).energies[0])


@pytest.fixture(scope="module")
def he_energy(he):
    return energy(he)


# --- the two peer files ---------------------------------------------------------------------
def test_he_header_and_system(he):
    f = ecgpack.parse_inout(HE)
    assert f.energy == HE_ECGPACK and f.symmetry == "(1+P23)" and f.L.shape == (490, 3)
    assert [p.name for p in he.system.particles] == ["alpha", "e", "e"]
    assert list(he.system.masses) == [7294.2995417, 1.0, 1.0]  # the file's masses, not CODATA's
    assert list(he.system.charges) == [2.0, -1.0, -1.0]
    # (1+P23)†(1+P23) ∝ 1 + P23 is prebo's own singlet: the spin state's operator, not an explicit one
    assert he.system.symmetriser == prebo.System(he.system.particles, he.system.state).symmetriser
    assert he.system.symmetriser.young is None and he.system.state.spin == {"e": 0.0}
    assert len(he) == 490 and np.all(he.c_A == 1.0)


def test_he_energy_matches_ecgpack(he, he_energy):
    r = prebo.evaluate(he)
    assert r["energy"] == he_energy
    assert rel(r["energy"], HE_ECGPACK) < 1e-10


def test_he_evaluated_as_ecgpack_solves_it(tmp_path, references):
    """ecgpack keeps every overlap direction; `prebo energy` of its file and of the file's import keeps
    them too (eigen.THRESHOLD, the default) and reproduces the file's energy (1.5e-13 above it), where
    the former default threshold, 1e-13, dropped 2 of the 490 directions and 1.7e-10 Eh."""
    from prebo.cli import main
    from prebo.io.load import load_basis

    assert main(["import", str(HE), "--out", str(tmp_path / "he.json")]) == 0
    for path in (HE, tmp_path / "he.json"):
        basis, threshold = load_basis(path)
        r = prebo.evaluate(basis, threshold=threshold)
        assert threshold == eigen.THRESHOLD and r["kept"] == 490
        assert 0 <= r["energy"] - HE_ECGPACK < 1e-12 and r["energy"] > references["He"]["energy"]
    assert prebo.evaluate(basis)["energy"] == r["energy"]
    assert prebo.evaluate(basis, threshold=1e-13)["energy"] - HE_ECGPACK > 1e-10



@pytest.fixture(scope="module")
def inout(tmp_path_factory):
    """H (examples/bases/h) exported as ecgpack's own file name, inout.txt, with its energy."""
    from prebo.cli import main

    folder = tmp_path_factory.mktemp("inout")
    assert main(["export", str(ROOT / "examples" / "bases" / "h" / "basis.json"), "--format", "ecgpack",
                 "--out", str(folder / "inout.txt")]) == 0
    return folder / "inout.txt", energy(Basis.load(ROOT / "examples" / "bases" / "h" / "basis.json"))


def test_ecgpacks_own_file_name_is_read_by_every_command_that_reads_a_basis(inout, tmp_path, capsys):
    """`prebo energy inout.txt` answered "corrupt or truncated JSON": only names ending in .inout.txt
    were taken for ecgpack files. A basis file is recognised by its content whatever its name, by
    the commands (energy, properties, plot --densities, export, import), and the API's loaders of one
    kind say which they were given; the names derived from inout.txt are inout.json,
    inout.inout.txt, inout.densities.png and .csv."""
    from prebo.cli import main

    path, E = inout
    shutil.copy(path, tmp_path / "inout.txt")
    path = tmp_path / "inout.txt"
    capsys.readouterr()
    assert main(["energy", str(path), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["energy"] == pytest.approx(E, rel=1e-14)
    assert main(["properties", str(path), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["energy"] == pytest.approx(E, rel=1e-14)
    assert main(["plot", "--densities", str(path), "--points", "20"]) == 0
    assert main(["import", str(path)]) == 0
    assert main(["export", str(path), "--format", "ecgpack"]) == 0
    names = {"inout.txt", "inout.densities.png", "inout.densities.csv", "inout.json", "inout.inout.txt"}
    assert {f.name for f in tmp_path.iterdir()} == names
    shutil.copy(tmp_path / "inout.json", tmp_path / "basis")  # a basis.json by any name
    capsys.readouterr()
    assert main(["energy", str(tmp_path / "basis"), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["energy"] == pytest.approx(E, rel=1e-14)
    assert energy(Basis.load(tmp_path / "basis")) == energy(ecgpack.read_inout(path)) == pytest.approx(E, rel=1e-14)
    with pytest.raises(BasisFileError, match=r"basis: a basis.json, not an ecgpack file \(prebo.Basis.load reads it\)"):
        ecgpack.read_inout(tmp_path / "basis")
    with pytest.raises(BasisFileError, match=r"inout.txt: an ecgpack file, not a basis.json \(prebo.io.ecgpack.read_"):
        Basis.load(path)


@pytest.mark.parametrize("text", ["", "  \n", "hello\n", "[1, 2]\n", "MASS 1\n"])
def test_a_file_that_is_neither_a_basis_json_nor_an_ecgpack_file_is_refused_in_one_line(tmp_path, capsys, text):
    from prebo.cli import main

    f = tmp_path / "inout.txt"
    f.write_text(text)
    assert main(["energy", str(f)]) == 2
    assert capsys.readouterr().err == (f"prebo: error: {f}: neither a basis.json (a JSON object) nor an ecgpack file "
                                       "(a header line, BASIS_TYPE, first)\n")


@POSIX_FILES
def test_a_basis_in_a_fifo_is_read_once_and_one_that_never_ends_is_refused_by_its_start(inout, tmp_path):
    """A FIFO is read once: a basis written into one is evaluated; one whose writer sent zeros and
    keeps it open (as /dev/zero) is refused by its first bytes, not read until it ends."""
    def feed(fifo, data: bytes, hold: threading.Event):
        with open(fifo, "wb") as f:
            f.write(data)
            f.flush()
            hold.wait(120)

    path, E = inout
    for data, expected in ((path.read_bytes(), 0), (bytes(1 << 16), 2)):
        fifo, hold = tmp_path / f"fifo{expected}", threading.Event()
        os.mkfifo(fifo)
        writer = threading.Thread(target=feed, args=(fifo, data, hold))
        writer.start()
        if expected == 0:
            hold.set()  # the writer closes: the end of the file
        try:
            r = subprocess.run([sys.executable, "-m", "prebo", "energy", str(fifo), "--json"], capture_output=True,
                               text=True, timeout=60)
        finally:
            hold.set()
            writer.join()
        assert r.returncode == expected, r.stderr
        if expected == 0:
            assert json.loads(r.stdout)["energy"] == pytest.approx(E, rel=1e-14)
        else:
            assert r.stderr.startswith(f"prebo: error: {fifo}: neither a basis.json") and r.stderr.count("\n") == 1

def test_li_system_keeps_the_files_operator(li):
    sys_ = li.system
    assert sys_.symmetriser.young == "(1+P23)(1-P24)" and "(1+P23)(1-P24)" in repr(sys_)
    assert [p.name for p in sys_.particles] == ["li7", "e", "e", "e"]
    assert sys_.masses[0] == 0.1278639227775000e05 and sys_.state.spin == {"e": 0.5}
    got = dict(zip(sys_.symmetriser.permutations, sys_.symmetriser.coefficients))
    # Y†Y = 2 + P23 + P34 - 2 P24 - P234 - P243, normalised; permutations as prebo tuples
    assert got == {(0, 1, 2, 3): 1.0, (0, 2, 1, 3): 0.5, (0, 1, 3, 2): 0.5, (0, 3, 2, 1): -1.0,
                   (0, 2, 3, 1): -0.5, (0, 3, 1, 2): -0.5}
    # prebo's own doublet is another row of the same representation: not this operator
    plain = prebo.System(sys_.particles, sys_.state).symmetriser
    assert dict(zip(plain.permutations, plain.coefficients)) != pytest.approx(got)


@pytest.mark.parametrize("coordinates", ["lab", "ti"])
def test_li_energy_matches_reference(li, coordinates):
    r = prebo.evaluate(li, coordinates)
    assert rel(r["energy"], LI_REFERENCE) < 1e-10
    assert rel(r["energy"], ecgpack.parse_inout(LI).energy) < 1e-10  # ecgpack's own header agrees


def test_li_needs_the_files_operator(li):
    """With prebo's spin-projected doublet the same functions give a visibly higher energy."""
    plain = Basis(prebo.System(li.system.particles, li.system.state), li.A, li.c_A)
    assert energy(plain) > LI_REFERENCE + 1e-4


# --- round trips ----------------------------------------------------------------------------
@pytest.mark.parametrize("path", [HE, LI], ids=["He-490", "Li-100"])
def test_round_trip_import_export_import(path, tmp_path):
    f1 = ecgpack.parse_inout(path)
    b1 = f1.to_basis()
    e1 = energy(b1)
    out = tmp_path / "x.inout.txt"
    ecgpack.write_inout(b1, out, energy=e1, source=f1)
    b2 = ecgpack.read_inout(out)
    assert np.array_equal(b2.A, b1.A)  # the file's own L goes back out: bit for bit
    f2 = ecgpack.parse_inout(out)
    assert f2.symmetry == f1.symmetry and np.array_equal(f2.masses, f1.masses)
    assert np.array_equal(f2.L, f1.L)
    assert f2.energy == e1
    assert rel(energy(b2), e1) < 1e-13


@pytest.mark.parametrize("path,tol", [(HE, 1e-11), (LI, 1e-13)], ids=["He-490", "Li-100"])
def test_round_trip_through_basis_json(path, tol, tmp_path):
    """Without the file's L (basis.json in between) L is the Cholesky factor of A's internal
    block: A comes back to rounding, and He-490, nearly linearly dependent, moves by ~1e-12."""
    b1 = ecgpack.read_inout(path)
    b1.save(tmp_path / "basis.json")
    loaded = Basis.load(tmp_path / "basis.json")
    # the stored operator is checked against the state and kept (Li: another row of the doublet)
    assert loaded.system.symmetriser.equivalent(b1.system.symmetriser)
    ecgpack.write_inout(loaded, tmp_path / "x.inout.txt", energy=0.0)
    b2 = ecgpack.read_inout(tmp_path / "x.inout.txt")
    assert np.max(np.abs(b2.A - b1.A)) < 1e-13 * np.max(np.abs(b1.A))
    assert rel(energy(b2), energy(b1)) < tol


def test_native_basis_exports_a_young_string(tmp_path):
    """A basis prebo made (Li doublet, spin-projected) goes out with (1-P24)(1+P23) and comes back
    as a plain System with the same matrices."""
    from conftest import random_basis

    system = prebo.System([{"name": "li7", "mass": 12786.39227775, "charge": 3, "spin": 1.5}, "e", "e", "e"],
                          prebo.State(spin={"e": 0.5}))
    basis = random_basis(system, 12, np.random.default_rng(2), c_A=1.0, sets=[prebo.heavy_particle_centred(system.masses, 0)])
    ecgpack.write_inout(basis, tmp_path / "li.inout.txt")
    f = ecgpack.parse_inout(tmp_path / "li.inout.txt")
    assert f.symmetry == "(1-P24)(1+P23)"
    back = ecgpack.read_inout(tmp_path / "li.inout.txt")
    assert back.system.symmetriser == system.symmetriser and back.system.symmetriser.young is None
    assert back.system.state.spin == {"e": 0.5}
    m1, m2 = laboratory(system).matrices(basis), laboratory(back.system).matrices(back)
    for k in ("S", "T_ti", "V"):
        assert np.allclose(m2[k], m1[k], rtol=1e-12, atol=1e-14 * np.abs(m1[k]).max())
    assert f.energy == pytest.approx(prebo.evaluate(basis)["energy"], rel=1e-14)


@pytest.mark.parametrize("particles,spin,string", [
    (["alpha", "e", "e"], {"e": 0}, "(1+P23)"),
    (["alpha", "e", "e"], {"e": 1}, "(1-P23)"),
    (["p", "p", "e", "e"], {"p": 1, "e": 0}, "(1-P12)(1+P34)"),
])
def test_young_strings_of_prebo_states(particles, spin, string):
    s = prebo.System(particles, prebo.State(spin=spin))
    assert young_string(s.symmetriser, s.groups, s.n) == string
    sym = young_operator(string, s.n)
    want = dict(zip(s.symmetriser.permutations, s.symmetriser.coefficients))
    assert dict(zip(sym.permutations, sym.coefficients)) == pytest.approx(want)


def test_operator_without_a_product_form_is_written_explicitly(tmp_path):
    """The quartet of three electrons (full antisymmetriser) is no product of (1±Pij): it is
    written as one factor with its coefficients, and read back as the same operator."""
    s = prebo.System(["alpha", "e", "e", "e"], prebo.State(spin={"e": 1.5}))
    string = young_string(s.symmetriser, s.groups, s.n)
    assert string.count("(") == 1  # one explicit factor
    sym = young_operator(string, s.n)
    want = dict(zip(s.symmetriser.permutations, s.symmetriser.coefficients))
    assert dict(zip(sym.permutations, sym.coefficients)) == pytest.approx(want)


# --- files prebo cannot take: errors name the file and the line ------------------------------
def _edit(tmp_path, old, new, src=HE):
    text = src.read_text()
    assert old in text
    p = tmp_path / "bad.inout.txt"
    p.write_text(text.replace(old, new, 1))
    return p


@pytest.mark.parametrize("old,new,line,words", [
    (" BASIS_TYPE RG_0S", " BASIS_TYPE CG_0S", 1, ["complex"]),
    (" BASIS_TYPE RG_0S", " BASIS_TYPE RG_2P", 1, ["BASIS_TYPE RG_2P", "prebo reads RG_0S"]),
    (" CHARGES  0.2000000000000000E+01 -0.1000000000000000E+01 -0.1000000000000000E+01",
     " CHARGES  0.2000000000000000E+01 -0.1000000000000000E+01", 4, ["CHARGES", "2 values"]),
    (" SYMMETRY (1+P23)", " SYMMETRY (1+P12)", 5, ["SYMMETRY", "differ"]),
    (" SYMMETRY (1+P23)", " SYMMETRY (1+Q23)", 5, ["SYMMETRY"]),
    (" SYMMETRY (1+P23)", " SYMMETRY (1+P24)", 5, ["SYMMETRY", "1..3"]),
    ("      7  0.5631628846634819E+00  0.7248822325456660E-02 -0.8322076203356323E+01",
     "      7  0.5631628846634819E+00  0.7248822325456660E-02", 640, ["function 7", "2 reals", "3"]),
    ("      7  0.5631628846634819E+00  0.7248822325456660E-02 -0.8322076203356323E+01",
     "      7  0.5631628846634819E+00  0.72488223254X6660E-02 -0.8322076203356323E+01", 640, ["not a number"]),
    ("      7  0.5631628846634819E+00", "      8  0.5631628846634819E+00", 640, ["index 8", "expected 7"]),
    ("      7  0.5631628846634819E+00", "      7  0.0000000000000000E+00", 640, ["function 7", "positive definite"]),
    (" BASIS_SIZE    490", " BASIS_SIZE    491", 1123, ["490 basis lines", "BASIS_SIZE"]),
    (" WHICH_EIGENVALUE      1", " WHICH_EIGENVALUE      0", 8, ["WHICH_EIGENVALUE", "1..BASIS_SIZE (490)"]),
    (" WHICH_EIGENVALUE      1", " WHICH_EIGENVALUE    491", 8, ["WHICH_EIGENVALUE", "491"]),
])
def test_malformed_files_name_the_line(tmp_path, old, new, line, words):
    p = _edit(tmp_path, old, new)
    with pytest.raises(BasisFileError) as exc:
        ecgpack.read_inout(p)
    msg = str(exc.value)
    assert msg.startswith(f"{p}:{line}:"), msg
    for w in words:
        assert w in msg, msg


@pytest.mark.filterwarnings("error")  # no RuntimeWarning before the error
@pytest.mark.parametrize("value", ["1.0E+301", "-1.0D+308", "1.0E+155"])
def test_an_exponent_that_overflows_is_refused_naming_its_line_and_value(tmp_path, value):
    """Issue 55, item 2: 1.0E+301 printed RuntimeWarning lines and then `Basis: A[6, 0, 0] = inf: must be
    a finite number`, naming neither the file nor the line."""
    p = _edit(tmp_path, "      7  0.5631628846634819E+00", f"      7  {value}")
    with pytest.raises(BasisFileError) as exc:
        ecgpack.read_inout(p)
    assert str(exc.value) == (f"{p}:640: basis function 7: {value!r} overflows: L Lᵀ exceeds the largest double "
                              "(1.8e+308)")


def test_which_eigenvalue_is_the_level_the_state_targets(tmp_path):
    """WHICH_EIGENVALUE k: the basis was optimised for root k − 1, which the imported state targets
    (its evaluation reports the levels up to it); the export writes it back, with CURRENT_ENERGY that
    level's energy."""
    basis = ecgpack.read_inout(_edit(tmp_path, " WHICH_EIGENVALUE      1", " WHICH_EIGENVALUE      2"))
    assert basis.system.state.levels == ((1,), (1.0,))
    r = prebo.evaluate(basis)
    assert r["targets"] == [1] and len(r["levels"]) == 2
    out = tmp_path / "out.inout.txt"
    ecgpack.write_inout(basis, out)
    back = ecgpack.parse_inout(out)
    assert back.root == 1 and back.energy == pytest.approx(r["levels"][1]["energy"], rel=1e-15)
    assert ecgpack.parse_inout(HE).root == 0


def test_complex_basis_lines_are_recognised(tmp_path):
    text = HE.read_text().splitlines()
    k = next(i for i, l in enumerate(text) if l.split()[:1] == ["1"] and len(l.split()) == 4
             and i > 600)
    text[k] = text[k] + " 0.1E+00 0.2E+00 0.3E+00"
    p = tmp_path / "c.inout.txt"
    p.write_text("\n".join(text) + "\n")
    with pytest.raises(BasisFileError, match=rf":{k + 1}: .*complex ECG"):
        ecgpack.read_inout(p)


def test_missing_header_and_not_a_file(tmp_path):
    p = _edit(tmp_path, " MASSES ", " MASS ")
    with pytest.raises(BasisFileError, match="no MASSES line"):
        ecgpack.read_inout(p)
    q = tmp_path / "empty.txt"
    q.write_text("hello\n")
    with pytest.raises(BasisFileError, match="neither a basis.json .* nor an ecgpack file"):
        ecgpack.read_inout(q)
    with pytest.raises(BasisFileError, match="cannot read"):
        ecgpack.read_inout(tmp_path / "missing.inout.txt")


@pytest.mark.parametrize("read", [ecgpack.read_inout, ecgpack.parse_inout])
@pytest.mark.parametrize("bad", [5, None, ""])
def test_a_path_that_is_not_a_file_name_is_refused(read, bad):
    """read_inout(5) raised TypeError."""
    with pytest.raises(InputError, match=rf"{read.__name__}: path = .*must be a file name \(a str or path\)"):
        read(bad)


@pytest.mark.parametrize("bad", [5, None, ""])
def test_write_inout_refuses_a_path_that_is_not_a_file_name(bad, tmp_path):
    """write_inout(basis, 5) raised TypeError; write_inout("he.json", path) AttributeError."""
    he = Basis.empty(prebo.System(["alpha", "e", "e"], spin={"e": 0}))
    with pytest.raises(InputError, match=r"write_inout: path = .*must be a file name \(a str or path\)"):
        ecgpack.write_inout(he, bad)
    with pytest.raises(InputError, match=r"write_inout: basis = 'he.json': must be a prebo Basis"):
        ecgpack.write_inout("he.json", tmp_path / "he.inout.txt")


def test_young_products_and_conventions():
    # operator product P_a P_b = P_{a∘b}: (1+P23)(1-P24) has the term -P23 P24
    y = young_product("(1+P23)(1-P24)", 4)
    assert y == {(0, 1, 2, 3): 1.0, (0, 2, 1, 3): 1.0, (0, 3, 2, 1): -1.0, (0, 3, 1, 2): -1.0}
    assert young_product("none", 3) == {(0, 1, 2): 1.0}
    assert young_product("(1 + P(2,3))", 3) == {(0, 1, 2): 1.0, (0, 2, 1): 1.0}
    for bad in ["(1+P23", "1+P23", "(1+P23)x(1-P24)", "()", "(1P23P)"]:
        with pytest.raises(ValueError):
            young_product(bad, 4)


def test_two_groups_round_trip(tmp_path):
    """Ortho-H2 (protons triplet, electrons singlet): (1-P12)(1+P34) out, the same state back."""
    from conftest import random_basis

    system = prebo.System(["p", "p", "e", "e"], prebo.State(spin={"p": 1, "e": 0}))
    basis = random_basis(system, 6, np.random.default_rng(4), c_A=1.0)
    ecgpack.write_inout(basis, tmp_path / "h2.inout.txt", energy=0.0)
    f = ecgpack.parse_inout(tmp_path / "h2.inout.txt")
    assert f.symmetry == "(1-P12)(1+P34)" and list(f.masses) == list(system.masses)
    back = ecgpack.read_inout(tmp_path / "h2.inout.txt")
    assert back.system.symmetriser == system.symmetriser
    assert [p.name for p in back.system.particles] == ["p", "p", "e", "e"]
    assert back.system.state.spin == {"p": 1.0, "e": 0.0}
    assert np.allclose(back.A, basis.A, rtol=0, atol=1e-12 * np.abs(basis.A).max())


# --- issue 57: RG_1P (P states) and ecgpack's infinite masses -------------------------------
HE_1S = DATA / "ecgpack-He-inf-1S-10.inout.txt"
HE_2P = DATA / "ecgpack-He-inf-2P-10.inout.txt"


@pytest.mark.parametrize("path", [HE_1S, HE_2P], ids=["1S", "2P"])
def test_the_he_samples_give_the_energies_ecgpack_reports(path):
    """ecgpack's RG_0S-1P He samples (infinite nuclear mass, 10 functions each): prebo's energy is
    the file's CURRENT_ENERGY (−2.9012919829575297 and −2.122004595065177) to 3e-15 relative,
    in the laboratory frame and in Jacobi coordinates."""
    f = ecgpack.parse_inout(path)
    basis = f.to_basis()
    assert basis.system.masses.tolist() == [np.inf, 1.0, 1.0]
    for coordinates in ("lab", "ti"):
        assert rel(prebo.evaluate(basis, coordinates)["energy"], f.energy) < 5e-15


def test_an_rg_1p_function_is_an_ecg_gvr_function_of_n_1():
    """z_1 exp(−rᵀ𝒜r), r_1 = R_2 − R_1: ECG-GVR, N = 1, K = 0, u = e_2 − e_1 (0-based [−1, 1, 0])."""
    f = ecgpack.parse_inout(HE_2P)
    assert f.basis_type == "RG_1P" and f.z.tolist() == [1] * 10
    basis = f.to_basis()
    assert basis.kind == "ecg-gvr" and (basis.system.state.N, basis.system.state.parity) == (1, -1)
    assert np.array_equal(basis.u, np.tile([-1.0, 1.0, 0.0], (10, 1))) and not basis.K.any()
    assert basis.channels == ["hpc:0"] * 10


def test_rg_1p_round_trips_through_import_and_export(tmp_path):
    f1 = ecgpack.parse_inout(HE_2P)
    b1 = f1.to_basis()
    e1 = prebo.evaluate(b1)["energy"]
    ecgpack.write_inout(b1, tmp_path / "x.inout.txt", source=f1)
    f2 = ecgpack.parse_inout(tmp_path / "x.inout.txt")
    assert f2.basis_type == "RG_1P" and np.array_equal(f2.z, f1.z) and np.array_equal(f2.L, f1.L)
    assert np.array_equal(f2.masses, f1.masses)
    assert " MASSES   1.0000000000000000E+30 " in (tmp_path / "x.inout.txt").read_text()
    assert f2.energy == e1 and prebo.evaluate(f2.to_basis())["energy"] == e1


def test_rg_1p_round_trips_through_the_command_line(tmp_path, capsys):
    """`prebo import`, then `prebo export` of the basis.json: the same coordinate indices, L Lᵀ to
    rounding (L is now the Cholesky factor of A's internal block, ecgpack's has columns of either
    sign), the same energy."""
    from prebo.cli import main

    assert main(["import", str(HE_2P), "--out", str(tmp_path / "p.json")]) == 0
    stored = json.loads((tmp_path / "p.json").read_text())
    assert stored["basis_type"] == "ecg-gvr" and stored["system"]["particles"][0]["mass"] == "inf"
    out = tmp_path / "p.inout.txt"
    assert main(["export", str(tmp_path / "p.json"), "--format", "ecgpack", "--out", str(out)]) == 0
    capsys.readouterr()
    f1, f2 = ecgpack.parse_inout(HE_2P), ecgpack.parse_inout(tmp_path / "p.inout.txt")
    A1, A2 = f1.exponents(), f2.exponents()
    assert np.array_equal(f2.z, f1.z) and np.max(np.abs(A2 - A1)) < 1e-14 * np.max(np.abs(A1))
    assert rel(f2.energy, f1.energy) < 5e-15


def test_a_mass_of_1e30_is_infinite(tmp_path):
    """ecgpack's 1e30 is read as ∞: the same bits as the system with `mass = inf` (through basis.json),
    and within 1e-11 relative of a nucleus of 1e12 m_e."""
    basis = ecgpack.read_inout(HE_1S)
    basis.save(tmp_path / "inf.json")
    d = json.loads((tmp_path / "inf.json").read_text())
    assert d["system"]["particles"][0] == {"name": "x1", "mass": "inf", "charge": 2.0, "spin": 0.0}
    e = prebo.evaluate(basis)["energy"]
    assert prebo.evaluate(Basis.load(tmp_path / "inf.json"))["energy"] == e
    toml_like = prebo.System([{"name": "He", "mass": float("inf"), "charge": 2, "spin": 0}, "e", "e"])
    assert prebo.evaluate(Basis(toml_like, basis.A, basis.c_A, basis.channels))["energy"] == e
    big = ecgpack.read_inout(_edit_file(tmp_path, HE_1S, "0.1000000000000000E+31", "0.1000000000000000E+13"))
    e12 = prebo.evaluate(big)["energy"]
    assert e12 != e and rel(e12, e) < 1e-11


def _edit_file(tmp_path, src, old, new, name="edited.inout.txt"):
    text = src.read_text()
    assert old in text
    p = tmp_path / name
    p.write_text(text.replace(old, new, 1))
    return p


def test_a_file_without_basis_type_is_told_by_its_lines(tmp_path):
    p = _edit_file(tmp_path, HE_2P, " BASIS_TYPE RG_1P\n", "")
    assert ecgpack.parse_inout(p).basis_type == "RG_1P"
    q = _edit_file(tmp_path, HE_1S, " BASIS_TYPE RG_0S\n", "", "s.inout.txt")
    assert ecgpack.parse_inout(q).basis_type == "RG_0S"


P_LINE = "      3      1 -0.3256830670396673E+00"


@pytest.mark.parametrize("old,new,line,words", [
    (P_LINE, "      3      0 -0.3256830670396673E+00", 33, ["basis function 3: '0' after the index", "1..2"]),
    (P_LINE, "      3      3 -0.3256830670396673E+00", 33, ["'3' after the index", "z_i, an integer in 1..2"]),
    (P_LINE, "      3    1.0 -0.3256830670396673E+00", 33, ["'1.0' after the index"]),
    (P_LINE + " -0.7132632415593938E-02", "      3      1 -0.3256830670396673E+00", 33,
     ["basis function 3: 2 reals after the coordinate index, expected n(n+1)/2 = 3"]),
    (" BASIS_TYPE RG_1P", " BASIS_TYPE RG_2D", 1, ["BASIS_TYPE RG_2D", "RG_0S", "RG_1P"]),
    ("0.1000000000000000E+01  0.1000000000000000E+01\n CHARGES", "0.1000000000000000E+31  0.1000000000000000E+31\n "
     "CHARGES", None, ["infinite masses: at most one"]),
])
def test_a_corrupt_rg_1p_file_names_the_line(tmp_path, capsys, old, new, line, words):
    p = _edit_file(tmp_path, HE_2P, old, new)
    from conftest import cli_error

    err = cli_error(capsys, "energy", p)
    assert f"{p}:{line}:" in err if line else f"{p}:" in err, err
    for w in words:
        assert w in err, err


def test_rg_0s_lines_declared_rg_1p_are_refused(tmp_path):
    p = _edit_file(tmp_path, HE_1S, " BASIS_TYPE RG_0S", " BASIS_TYPE RG_1P")
    with pytest.raises(BasisFileError, match=r":31: basis function 1: '0.4825734967754652E\+00' after the index"):
        ecgpack.read_inout(p)


def test_ecg_gvr_functions_rg_1p_does_not_hold_are_not_exported(tmp_path, capsys):
    from conftest import cli_error

    err = cli_error(capsys, "export", ROOT / "examples" / "bases" / "h2plus-gvr" / "basis.json", "--format",
                    "ecgpack", "--out", tmp_path / "x.inout.txt")
    assert "ECG-GVR functions of N = 1, not ecg-gvr functions of N = 0" in err, err
    basis = ecgpack.read_inout(HE_2P)
    basis.K[3] = 2
    with pytest.raises(prebo.errors.UnsupportedError, match="function 3: RG_1P holds .* K = 2"):
        ecgpack.write_inout(basis, tmp_path / "y.inout.txt", energy=0.0)
    basis = ecgpack.read_inout(HE_2P)
    basis.u[4] = [-1.0, 0.5, 0.5]  # the electrons' centre relative to the nucleus
    with pytest.raises(prebo.errors.UnsupportedError, match=r"function 4: .* u = \[0.5, 0.5, 0.0\]"):
        ecgpack.write_inout(basis, tmp_path / "y.inout.txt", energy=0.0)


def test_the_he_samples_give_the_transition_moments_ecgpack_prints():
    """What the import means, checked beyond the energy: prebo's eigenvectors of the two imported
    bases (normalised functions; an RG_1P function's M = 1 partner has its M = 0 function's
    matrices), put on ecgpack's own functions z_i exp(−rᵀ𝒜r) in its coordinates r_i = R_{i+1} − R_1,
    give the values ecgpack's RG_0S-1P sample README prints, cut to nine decimals (iDynbek/ecgpack, commit ad8e8f3,
    RG_0S-1P/sample_input/transition_dipole_moment_He/dipole_moment/README.md): ΔE = 0.779 287 387,
    ⟨S|z|P⟩ = 0.395 665 167 (its z is d_z = Σ_i (q_{i+1} − Q m_{i+1}/m_tot) z_i, −(z_1 + z_2) here) and
    ⟨S|P_z|P⟩ = i 0.314 193 144, P_z = −Σ_a (q_a/m_a) p_a,z (matelem.f90, main.f90); the sign of
    either eigenvector is free. Elements by the closed forms S = (πⁿ/|A|)^{3/2},
    ⟨e^{-A_I}|w·r_z|(v·r)_z e^{-A_J}⟩ = S wᵀ(A_I + A_J)⁻¹v/2 and
    ⟨e^{-A_I}|∂/∂z_i|(v·r)_z e^{-A_J}⟩ = S (A_I (A_I + A_J)⁻¹v)_i."""
    f0, f1 = ecgpack.parse_inout(HE_1S), ecgpack.parse_inout(HE_2P)
    r0, r1 = prebo.evaluate(f0.to_basis()), prebo.evaluate(f1.to_basis())
    A0, A1 = f0.exponents(), f1.exponents()
    v = np.eye(2)[f1.z - 1]
    swap = np.array([[0.0, 1.0], [1.0, 0.0]])  # P23 in r: (1 + P23), ecgpack's Y and prebo's operator

    def overlap(A, B):
        return (np.pi**2 / np.linalg.det(A + B)) ** 1.5

    def p_norm(A, w):
        return np.sqrt(overlap(A, A) * (w @ np.linalg.solve(2 * A, w)) / 2)

    d, velocity, s1 = np.zeros((3, 10, 10))
    for I in range(10):
        for J in range(10):
            for T in (np.eye(2), swap):  # the image of function J: e^{-rᵀ Tᵀ A T r} (Tᵀv · r)_z
                B, w = T.T @ A1[J] @ T, T.T @ v[J]
                S, Bi = overlap(A0[I], B), np.linalg.inv(A0[I] + B)
                norms = np.sqrt(overlap(A0[I], A0[I])) * p_norm(A1[J], v[J])
                d[I, J] += S * (-np.ones(2) @ Bi @ w) / 2 / norms
                velocity[I, J] += S * (np.ones(2) @ A0[I] @ Bi @ w) / norms
                norms = p_norm(A1[I], v[I]) * p_norm(A1[J], v[J])
                s1[I, J] += overlap(A1[I], B) * (v[I] @ np.linalg.solve(A1[I] + B, w)) / 2 / norms
    c0, c1 = np.asarray(r0["coefficients"]), np.asarray(r1["coefficients"])
    assert c1 @ s1 @ c1 == pytest.approx(1.0, rel=1e-13)  # the M = 0 functions have the same matrices
    z, p = c0 @ d @ c1, c0 @ velocity @ c1
    for value, printed in ((r1["energy"] - r0["energy"], 0.779287387), (abs(z), 0.395665167), (abs(p), 0.314193144)):
        assert 0 <= value - printed < 1e-9, (value, printed)  # the README's nine decimals, cut off
    assert np.sign(p) == -np.sign(z)  # i⟨P_z⟩... = (E_S − E_P)⟨z⟩ in the exact limit: opposite signs here
