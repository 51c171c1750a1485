import itertools
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

pytest.register_assert_rewrite("gvr_reference", "fecg_reference")  # helper modules' asserts explained

#: a test that makes FIFOs, device nodes or sockets: POSIX only
POSIX_FILES = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="FIFOs, device nodes and sockets are POSIX files")

import prebo  # noqa: E402
from prebo.cli import main  # noqa: E402
from prebo.io import ecgpack  # noqa: E402
from prebo.io.toml import tomllib  # noqa: E402  (tomli before Python 3.11)

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def references():
    return tomllib.loads((ROOT / "tests" / "data" / "reference_energies.toml").read_text())


@pytest.fixture(scope="module")
def li():
    """Li (⁷Li, 100 plain ECGs) read from its ecgpack file."""
    return ecgpack.read_inout(ROOT / "tests" / "data" / "ecgpack" / "ecgpack-Li7-100.inout.txt")


def pair_A(system, alpha: dict, c_A: float) -> np.ndarray:
    """Σ_{i<j} α_ij w_ij w_ij^T + c_A μ μ^T, w_ij = e_i - e_j, μ = m/m_tot (A 1 = c_A μ, as prebo
    requires); `alpha`: α_ij by pair (i, j)."""
    mu = system.cm_vector
    A = c_A * np.outer(mu, mu)
    for (i, j), a in alpha.items():
        w = np.zeros(system.n)
        w[i], w[j] = 1.0, -1.0
        A += a * np.outer(w, w)
    return A


def hydrogen_s(exponents):
    """H (finite proton mass) in s Gaussians exp(-a r²) of r = r_e − r_p, one per exponent a, each
    times a CM Gaussian (c_A = 1; `pair_A`), as a basis of examples/bases/h's system. Returns
    (basis, μ)."""
    d = json.loads((ROOT / "examples" / "bases" / "h" / "basis.json").read_text())
    system = prebo.Basis.from_dict(d, "h").system
    d = {k: d[k] for k in ("format", "version", "conventions", "system", "symmetry", "basis_type")}
    d["functions"] = [{"A": pair_A(system, {(0, 1): a}, 1.0).tolist(), "c_A": 1.0, "channel": "pairs"}
                      for a in exponents]
    m = system.masses
    return prebo.Basis.from_dict(d, "H in s Gaussians"), m[0] * m[1] / (m[0] + m[1])


def random_pair_A(system, rng, c_A: float) -> np.ndarray:
    """`pair_A` with every α_ij uniform in [0.3, 1.6], drawn pair by pair."""
    return pair_A(system, {p: rng.uniform(0.3, 1.6) for p in itertools.combinations(range(system.n), 2)}, c_A)


def random_set_A(system, rng, sets, c_A=None) -> tuple:
    """(x, A, c_A): a coordinate set x drawn from `sets`, 𝒜 = L L^T + 0.05 I (random lower-triangular
    L) in x and A = U_x^T blockdiag(𝒜, c_A) U_x; `c_A=None` draws c_A uniform in [0.3, 3]."""
    n = system.n
    x = sets[rng.integers(len(sets))]
    L = np.tril(rng.normal(size=(n - 1, n - 1)))
    c = rng.uniform(0.3, 3.0) if c_A is None else c_A
    return x, x.to_lab(L @ L.T + 0.05 * np.eye(n - 1), c), c


def random_basis(system, nb, rng, c_A=None, sets=None):
    """nb random CM-separable pECGs of `system`, each drawn in a random coordinate set (`random_set_A`;
    `sets` default: prebo.all_sets). `c_A=None` draws a different c_A per function."""
    sets = sets or prebo.all_sets(system.masses)
    A, cs, names = [], [], []
    for _ in range(nb):
        x, a, c = random_set_A(system, rng, sets, c_A)
        A.append(a)
        cs.append(c)
        names.append(x.name)
    return prebo.Basis(system, np.array(A), np.array(cs), names)


def random_centres(system, nb, rng, cm_free=False, scale=0.5) -> np.ndarray:
    """(nb, n, 3) centres normal with spread `scale`; `cm_free`: μ^T s = 0 for every function."""
    s = rng.normal(scale=scale, size=(nb, system.n, 3))
    if cm_free:
        s -= np.einsum("i,bic->bc", system.cm_vector, s)[:, None, :]
    return s


#: a short fixed-schedule run of H⁻ (ECG-GVR functions, every kind of step) to kill and resume
#: (test_optimise.py, test_mpi.py)
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


def custom(name: str, mass: float, charge: float) -> dict:
    """A particle of its own, given by its table: spin ½, `mass` (m_e) and `charge` (e)."""
    return {"name": name, "mass": mass, "charge": charge, "spin": 0.5}


def scaled_error(got, ref, scale=None) -> float:
    """max_IJ |got - ref| / max(|ref_IJ|, sqrt|scale_II scale_JJ|) of two matrices (`scale`: ref if None)."""
    sc = ref if scale is None else scale
    d = np.sqrt(np.abs(np.outer(np.diag(sc), np.diag(sc))))
    return float(np.max(np.abs(got - ref) / np.maximum(np.abs(ref), d)))


def edited(tmp_path, src, edit, name="basis.json") -> Path:
    """A copy of basis file `src` with `edit(d)` applied to its mapping."""
    d = json.loads(Path(src).read_text())
    edit(d)
    f = tmp_path / name
    f.write_text(json.dumps(d))
    return f


def toml_value(v) -> str:
    """A TOML literal of a Python value (strings, numbers with nan/inf, booleans, lists, tables)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, float) and not np.isfinite(v):
        return "nan" if v != v else ("inf" if v > 0 else "-inf")
    if isinstance(v, (int, float)):
        return repr(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(map(toml_value, v)) + "]"
    return "{" + ", ".join(f"{json.dumps(k)} = {toml_value(x)}" for k, x in v.items()) + "}"


def toml_text(doc: dict) -> str:
    """A TOML document of tables (a non-table value stays a top-level key)."""
    top = [f"{json.dumps(k)} = {toml_value(v)}" for k, v in doc.items() if not isinstance(v, dict)]
    tables = [f"[{json.dumps(k)}]\n" + "".join(f"{json.dumps(a)} = {toml_value(x)}\n" for a, x in v.items())
              for k, v in doc.items() if isinstance(v, dict)]
    return "".join(line + "\n" for line in top) + "".join(tables)


def h_input(**optimiser) -> dict:
    """The input of a 3-function H run (the `optimiser` settings added) as a TOML document's dict."""
    return {"system": {"particles": ["p", "e"]}, "basis": {"size": 3}, "optimiser": {"trials": 4, "seed": 3} | optimiser}


def cli_error(capsys, *argv) -> str:
    """Run `prebo ARGV` in-process; assert exit 2 (returned, or argparse's SystemExit) and exactly one
    `prebo: error:` line on stderr; return that line."""
    try:
        rc = main([str(a) for a in argv])
    except SystemExit as exc:  # argparse's refusals
        rc = exc.code
    out, err = capsys.readouterr()
    assert rc == 2, (rc, out, err)
    assert err.startswith("prebo: error: ") and err.count("\n") == 1 and "Traceback" not in err, err
    assert out == ""
    return err


def prebo_process(*args, timeout: float = 300, **kw) -> subprocess.CompletedProcess:
    """`python -m prebo ARGS` in a process of its own, its output captured as text."""
    return subprocess.run([sys.executable, "-m", "prebo", *map(str, args)], capture_output=True, text=True,
                          timeout=timeout, **kw)


def hydrogen_1s(count: int = 40) -> "prebo.Basis":
    """Hydrogen's 1s (finite proton mass) in `count` Gaussians exp(−a r²), a = 0.002·1.7^k, of the
    relative coordinate (c_A = 0.7): 1e-11 Eh from −μ/2 at 40."""
    from prebo.coordinates import jacobi

    system = prebo.System(["p", "e"])
    coords = jacobi(system.masses)
    A = np.array([coords.to_lab(np.array([[0.002 * 1.7 ** k]]), 0.7) for k in range(count)])
    return prebo.Basis(system, A, np.full(len(A), 0.7))
