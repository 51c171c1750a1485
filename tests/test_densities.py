"""Distance distributions P(r) = 4πr²ρ̄(r) of inter-particle distances and of the particles'
distances from the centre of mass (issue 40, item 4): on wave functions against closed forms and
against the expectation values of the pair operators, which do not go through the densities
(element checks against the damped overlap: crates/prebo-core/src/operators/density.rs)."""
import csv

import numpy as np
import pytest

import prebo
from prebo.cli import main
from prebo.errors import InputError, NonFiniteError
from prebo import eigen
from prebo.integrals import laboratory, translationally_invariant
from prebo.level.evaluate import grids
from prebo.level.expectation import densities
from prebo.level.properties import rms

from conftest import ROOT, cli_error, hydrogen_s

BASES = ROOT / "examples" / "bases"


def gauss_legendre(n: int, top: float) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weights of the n-point Gauss–Legendre rule on [0, top]."""
    x, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * top * (x + 1), 0.5 * top * w


def test_hydrogen_1s_and_2s_distributions_match_the_closed_forms():
    """H (finite proton mass) in 80 even-tempered s Gaussians: P(r) of 1s, 4μ³r²e^{−2μr}, and of 2s,
    (μ³/2)r²(1 − μr/2)²e^{−μr}, within 2e-5 of the peak over 0.05–12 bohr (measured 3e-6 and 5e-6:
    Gaussians miss the cusp and the tail); the electron's and the proton's distributions about the
    centre of mass are r_ep's scaled by m_p/M and m_e/M (exact)."""
    basis, mu = hydrogen_s(3e-4 * 1.35 ** np.arange(80))
    r = np.linspace(0.05, 12.0, 240)
    table = prebo.densities(basis, roots=[0, 1], r=r)
    exact = (4 * mu**3 * r**2 * np.exp(-2 * mu * r), mu**3 / 2 * r**2 * (1 - mu * r / 2) ** 2 * np.exp(-mu * r))
    m = {p.name: p.mass for p in basis.system.particles}
    m_e, m_p = m["e"], m["p"]
    for level, want in zip(table["levels"], exact):
        got = level["pairs"]["e-p"]
        assert np.max(np.abs(got - want)) < 2e-5 * want.max(), np.max(np.abs(got - want)) / want.max()
        # |r_e − R| = (m_p/M) r_ep: P_e(s) = (M/m_p) P_ep(sM/m_p), on the closed form's side
    levels = prebo.densities(basis, roots=[0], r=r * m_p / (m_e + m_p))["levels"][0]
    assert np.allclose(levels["particles"]["e"], table["levels"][0]["pairs"]["e-p"] * (m_e + m_p) / m_p,
                       rtol=1e-10, atol=1e-14)
    levels = prebo.densities(basis, roots=[0], r=r * m_e / (m_e + m_p))["levels"][0]
    assert np.allclose(levels["particles"]["p"], table["levels"][0]["pairs"]["e-p"] * (m_e + m_p) / m_e,
                       rtol=1e-10, atol=1e-14)


@pytest.mark.parametrize("name, roots", [("h2plus-n1", [0, 1]), ("h2plus-fecg", [0]), ("he", [0])])
def test_distributions_are_normalised_and_give_the_mean_distances(name, roots):
    """ECG-GVR with K up to 29 and N = 1 (the H2⁺ N = 1 ladder), floating ECGs, plain ECGs: on a
    400-node rule over 0–12 root-mean-square distances of each class (`properties.rms`: the
    particles' about the centre of mass from the pairs'), ∫P dr = 1 for every class of pairs and
    particles and ∫r P dr = ⟨r_ij⟩ of the operator "r" for every class of pairs, within 1e-10 plus
    the rounding of the contraction Σ c_I c_J ρ_IJ, ε Σ|c_I||S_IJ||c_J| of the lowest level (floating ECGs:
    1.1e7, and the difference, 1e-10 to 2e-10, does not fall with 400, 800 or 1600 nodes)."""
    basis = prebo.Basis.load(BASES / name / "basis.json")
    r_ops = prebo.evaluate(basis, roots=max(roots) + 1, operators=["r", "r2"])
    levels = r_ops.get("levels", [r_ops])
    reach = [rms(basis.system, levels[k]["expectation"]["r2"]) for k in roots]
    rules = {g: {c: gauss_legendre(400, 12 * max(x[g][c] for x in reach)) for c in classes} for g, classes in reach[0].items()}
    table = prebo.densities(basis, roots=roots, r={g: {c: rule[0] for c, rule in cs.items()} for g, cs in rules.items()})
    c = np.abs(r_ops["coefficients"])  # the ground state's, for every level
    tol = 1e-10 + np.finfo(float).eps * (c @ np.abs(laboratory(basis.system).matrices(basis)["S"]) @ c)
    for k, level in zip(roots, table["levels"]):
        for group in ("pairs", "particles"):
            for label, p in level[group].items():
                r, w = rules[group][label]
                assert abs(w @ p - 1) < tol, (name, k, label, w @ p, tol)
                if group == "pairs":
                    mean = levels[k]["expectation"]["r"][label]
                    assert abs(w @ (r * p) - mean) < tol * mean, (name, k, label, w @ (r * p), mean, tol)


def test_laboratory_and_translationally_invariant_coordinates_give_the_same_densities():
    """The H2⁺ ECG-GVR basis (one c_A), its ground state in LFCC: every class's density contracted
    in LFCC and in TICC within 1e-11 of its peak (measured 1.3e-12; single functions 2e-12). The
    states' own eigenvectors from the two representations differ by more (the p-p peak 1e-10), and
    so do poorly represented levels, whose functions' densities cancel (root 1 of this
    ground-state basis: 8e-10)."""
    basis = prebo.Basis.load(BASES / "h2plus-gvr" / "basis.json")
    lab = laboratory(basis.system)
    m = lab.matrices(basis)
    C = eigen.solve(m["T_ti"] + m["V"], m["S"], eigen.THRESHOLD).vectors[:, :1]
    radii = grids(basis.system, np.linspace(0.0, 6.0, 61))
    got = [densities(rep, basis, C, radii) for rep in (lab, translationally_invariant(basis.system))]
    for state_lab, state_ti in zip(*got):
        for group, classes in state_lab.items():
            for label, rho in classes.items():
                assert np.max(np.abs(rho - state_ti[group][label])) < 1e-11 * rho.max(), (group, label)


def test_bad_grids_and_roots_are_refused_in_one_line():
    """An empty grid, one not finite or negative, roots repeated, negative or beyond the basis."""
    basis = prebo.Basis.load(BASES / "h" / "basis.json")
    for bad in ([], [0.0, np.nan], [1.0, np.inf], [-1.0], [[1.0, 2.0]], "x"):
        with pytest.raises(InputError, match="radii"):
            prebo.densities(basis, r=bad)
    for bad in ([0, 0], [-1], [len(basis)], []):
        with pytest.raises(InputError, match="roots"):
            prebo.densities(basis, roots=bad, r=[1.0])


@pytest.mark.filterwarnings("error")  # no RuntimeWarning before the error
def test_a_grid_reaching_where_r_squared_overflows_is_refused_naming_the_radius(tmp_path, capsys):
    """Issue 55, item 2: `--rmax 1e300` printed `RuntimeWarning: overflow encountered in square` before
    its error; the core's densities are not finite where r² overflows against the exponents."""
    basis = BASES / "he" / "basis.json"
    err = cli_error(capsys, "plot", "--densities", basis, "--rmax", "1e300", "--out", tmp_path / "he.png")
    assert err == (f"prebo: error: {basis}: densities: P(r) of alpha-e (root 0) is not finite from r = 2.51e+297 "
                   "bohr on: r² overflows against the basis's exponents there: end the grid nearer\n")
    with pytest.raises(NonFiniteError, match="alpha-e .* not finite from r = 1e\\+300 bohr on"):
        prebo.densities(prebo.Basis.load(basis), r=[0.0, 1.0, 1e300])
    assert not (tmp_path / "he.png").exists()


def test_prebo_plot_densities_writes_the_picture_and_its_table(tmp_path, capsys):
    """`prebo plot --densities BASIS --roots 0 1 --rmax R --points N --out PNG`: a PNG and a CSV with
    N rows per level and class (root, group, class, r, P); an existing output refused without
    --force; the grid options without --densities, or a bad --rmax, one line and exit 2."""
    basis = str(BASES / "h2plus-n1" / "basis.json")
    png = tmp_path / "ladder.png"
    args = ["plot", "--densities", basis, "--roots", "0", "1", "--rmax", "8", "--points", "50", "--out", str(png)]
    assert main(args) == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    rows = list(csv.reader((tmp_path / "ladder.csv").open()))
    assert rows[0] == ["root", "group", "class", "r_bohr", "P_per_bohr"] and len(rows) == 1 + 2 * 4 * 50
    assert {tuple(row[:3]) for row in rows[1:]} == {(k, g, c) for k in "01" for g, c in
                                                   [("pair", "e-p"), ("pair", "p-p"), ("particle", "p"), ("particle", "e")]}
    assert float(rows[50][3]) == 8.0 and float(rows[51][3]) == 0.0
    capsys.readouterr()
    assert main(args) == 2 and "exists" in capsys.readouterr().err
    for bad in (["plot", basis, "--roots", "1"], ["plot", "--densities", basis, "--rmax", "-1"],
                ["plot", "--densities", basis, "--roots", "9999", "--out", str(tmp_path / "x.png")]):
        try:
            code = main(bad)
        except SystemExit as exc:
            code = exc.code
        err = capsys.readouterr().err
        assert code == 2 and len(err.strip().splitlines()) == 1, err
