"""Plain-ECG and ECG-GVR rows are oriented: a trial's row at position p, patched into the matrices of the basis
without it (or holding another function at p), gives exactly (==) the matrices of a full build, for
every instruction set of the kernel on this machine (PREBO_ISA caps it, read at every build)."""
from pathlib import Path

import numpy as np
import pytest

import prebo
from prebo.integrals import laboratory

ROOT = Path(__file__).resolve().parents[1]


def patched(m: dict, row: dict, diag, p: int, insert: bool) -> dict:
    """`m` with row and column p inserted or replaced, as Expansion.put patches them."""
    out = {}
    for n, k in enumerate(("S", "T", "T_ti", "V")):
        r = np.array(row[k][0], copy=True)
        if insert:
            r = np.insert(r, p, diag[0, n])
            M = np.insert(np.insert(m[k], p, 0.0, axis=0), p, 0.0, axis=1)
        else:
            r[p] = diag[0, n]
            M = m[k].copy()
        M[p, :] = r
        M[:, p] = r
        out[k] = M
    return out


@pytest.mark.parametrize("isa", ["avx512", "avx2", "plain"])
@pytest.mark.parametrize("name", ["h", "ps-", "h2plus-pecg", "h2-pecg", "h2plus-gvr"])
def test_patched_rows_have_the_bits_of_a_full_build(name, isa, monkeypatch):
    monkeypatch.setenv("PREBO_ISA", isa)
    basis = prebo.Basis.load(ROOT / "examples" / "bases" / name / "basis.json")
    full = basis.subset(np.arange(11))
    rep = laboratory(full.system)
    assert rep.oriented(full)
    want = rep.matrices(full)
    nb = len(full)
    for p in range(nb):
        trial = full.subset([p])
        rest = full.subset(np.arange(nb) != p)
        rows, diag = rep.rows(trial, rest, p)
        got = patched(rep.matrices(rest), rows, diag, p, True)
        assert all(np.array_equal(got[k], want[k]) for k in want), (p, "inserted")
        held = full.subset(np.arange(nb))
        held.replace(p, basis.subset([nb + p]))
        rows, diag = rep.rows(trial, held, p)
        got = patched(rep.matrices(held), rows, diag, p, False)
        assert all(np.array_equal(got[k], want[k]) for k in want), (p, "replaced")
