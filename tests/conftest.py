from pathlib import Path

import numpy as np
import pytest

pytest.register_assert_rewrite("gvr_reference", "fecg_reference")  # helper modules' asserts explained

import prebo  # noqa: E402
from prebo.io.toml import tomllib  # noqa: E402  (tomli before Python 3.11)

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def references():
    return tomllib.loads((ROOT / "tests" / "data" / "reference_energies.toml").read_text())


def random_basis(system, nb, rng, c_A=None, sets=None):
    """nb random CM-separable pECGs of `system`, each drawn in a random coordinate set.

    𝒜 = L L^T + 0.05 I (random lower-triangular L) in the chosen set x, A = U_x^T blockdiag(𝒜, c_A) U_x.
    `c_A=None` draws a different c_A per function."""
    sets = sets or prebo.all_sets(system.masses)
    n = system.n
    A, cs, names = [], [], []
    for _ in range(nb):
        x = sets[rng.integers(len(sets))]
        L = np.tril(rng.normal(size=(n - 1, n - 1)))
        A_int = L @ L.T + 0.05 * np.eye(n - 1)
        c = rng.uniform(0.3, 3.0) if c_A is None else c_A
        A.append(x.to_lab(A_int, c))
        cs.append(c)
        names.append(x.name)
    return prebo.Basis(system, np.array(A), np.array(cs), names)
