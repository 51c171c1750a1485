"""Lines between two bases (prebo.transitions, level/transitions.py): hydrogen with the proton's
finite mass against the closed forms, the elements' coordinate and family independence, the
velocity form against the length form through [H, d], and bad input."""
import numpy as np
import pytest

import prebo
from prebo.coordinates import jacobi
from prebo.errors import InputError, UnsupportedError
from prebo.integrals import laboratory, translationally_invariant
from prebo.level.transitions import ALPHA, AU_TIME, dipole_vectors, transitions

#: even-tempered exponents (bohr⁻²) of the relative coordinate: 1s and 2p to ~1e-11 Eh
EXPONENTS = 0.002 * 1.7 ** np.arange(40)


def hydrogen(N: int, exponents=EXPONENTS, kind=None, c_A=0.7, nucleus="p") -> prebo.Basis:
    """p e of N = 0 (plain ECGs) or N = 1 (ECG-GVR, K = 0, u = r_e − r_p), the Gaussians exp(−a r²)
    of the relative coordinate with one CM exponent c_A."""
    system = prebo.System([nucleus, "e"], N=N, parity=(-1) ** N)
    coords = jacobi(system.masses)
    A = np.array([coords.to_lab(np.array([[a]]), c_A) for a in exponents])
    kind = kind or ("pecg" if N == 0 else "ecg-gvr")
    if kind == "pecg":
        return prebo.Basis(system, A, np.full(len(A), c_A))
    u = np.tile([-1.0, 1.0], (len(A), 1))
    return prebo.Basis(system, A, np.full(len(A), c_A), kind="ecg-gvr", u=u, K=np.zeros(len(A), int))


@pytest.fixture(scope="module")
def lines():
    return transitions(hydrogen(0), hydrogen(1), roots=1)


def test_hydrogen_1s_2p_matches_the_closed_forms_with_the_reduced_mass(lines):
    # R_{10,21} = ∫ R_10 R_21 r³ dr = 2^7 √6 / 3^5 a_0 at infinite mass, lengths scale as 1/μ and
    # energies as μ; d = −(r_e − r_p) about the CM; S = R² (Σ over M and q of the 3j symbols)
    mu = prebo.System(["p", "e"]).masses.prod() / prebo.System(["p", "e"]).m_total
    R = 2 ** 7 * 6 ** 0.5 / 3 ** 5 / mu
    de = 3 * mu / 8
    (line,) = lines["lines"]
    assert abs(line["Eh"] - de) < 1e-10
    assert abs(abs(line["length"]) - R) < 1e-9 * R
    assert abs(line["velocity"] - line["length"]) < 1e-9 * R
    assert abs(line["acceleration"] - line["length"]) < 1e-9 * R  # 1.3e-10 R measured (5e-5 R with 20 exponents)
    assert abs(line["line_strength"] - R * R) < 2e-9 * R * R
    assert abs(line["oscillator_strength"] - 2 / 3 * de * R * R) < 2e-9
    want_A = 4 / 3 * ALPHA ** 3 * de ** 3 * R * R / 3 / AU_TIME
    assert abs(line["einstein_A"] - want_A) < 1e-8 * want_A
    assert lines["lifetimes"] == [{"level": line["upper"], "lifetime": 1 / line["einstein_A"], "lines": 1}]
    assert [lv["N"] for lv in lines["levels"]] == [0, 1]


def test_hydrogen_2p_3d_matches_the_closed_forms_with_the_reduced_mass():
    # ⟨R_32|r|R_21⟩ = ∫ R_32 R_21 r³ dr = 2¹¹ 3⁴ / 5^{13/2} a_0 at infinite mass (R_21 = r e^{−r/2}/(2√6),
    # R_32 = 4 r² e^{−r/3}/(81√30), ∫ r⁶ e^{−5r/6} dr = 6! (6/5)⁷), ⟨2‖C_1‖1⟩ = √2 (Edmonds: (−1)^l'
    # ((2l'+1)(2l+1))^{1/2} (l' 1 l; 0 0 0)); lengths scale as 1/μ, energies as μ; d = −(r_e − r_p)
    # 60 even-tempered Gaussians from 5e-4 (EXPONENTS leave 3d 6e-11 Eh high and the moment 1.9e-9 off)
    fine = 5e-4 * 1.4 ** np.arange(60)
    mu = prebo.System(["p", "e"]).masses.prod() / prebo.System(["p", "e"]).m_total
    R = 2 ** 0.5 * 2 ** 11 * 3 ** 4 / 5 ** 6.5 / mu
    de = 5 * mu / 72
    r = transitions(hydrogen(1, fine), hydrogen(2, fine), roots=1)
    (line,) = r["lines"]
    assert abs(line["Eh"] - de) < 1e-13
    assert abs(abs(line["length"]) - R) < 1e-12 * R
    assert abs(line["velocity"] - line["length"]) < 1e-12 * R
    assert abs(line["line_strength"] - R * R) < 2e-12 * R * R
    assert abs(line["oscillator_strength"] - 2 / 3 * de * R * R / 3) < 1e-11
    want_A = 4 / 3 * ALPHA ** 3 * de ** 3 * R * R / 5 / AU_TIME
    assert abs(line["einstein_A"] - want_A) < 1e-11 * want_A
    assert line["acceleration"] is None and line["acceleration/length"] is None
    assert [lv["N"] for lv in r["levels"]] == [1, 2]
    (flipped,) = transitions(hydrogen(2, fine), hydrogen(1, fine), roots=1)["lines"]
    assert flipped["length"] == line["length"] and flipped["velocity"] == line["velocity"]


def test_the_thomas_reiche_kuhn_sum_over_pseudostates_is_one_over_mu():
    # Σ_n f_0n = Σ_k q_k²/m_k − Q²/m_tot = 1/m_e + 1/m_p: the N = 1 basis holds d ψ_0 exactly
    lower, upper = hydrogen(0), hydrogen(1)
    r = transitions(lower, upper, roots=(1, len(EXPONENTS)))
    assert all(r["levels"][line["lower"]]["N"] == 0 for line in r["lines"])
    f = sum(line["oscillator_strength"] for line in r["lines"])
    mu = 1 / (1 + 1 / 1836.15267343)
    assert abs(f - 1 / mu) < 1e-6


def test_laboratory_and_translationally_invariant_elements_agree():
    lower, upper = hydrogen(0, EXPONENTS[:6]), hydrogen(1, EXPONENTS[2:9])
    w, w_v = dipole_vectors(lower.system)
    for name, v, momentum in [("dipole", w, False), ("velocity", w_v, True), ("acceleration", w_v, True)]:
        lab = laboratory(lower.system).between(name, lower, upper, v[None], momentum)[0]
        ti = translationally_invariant(lower.system).between(name, lower, upper, v[None], momentum)[0]
        assert np.max(np.abs(lab - ti)) < 1e-11 * np.max(np.abs(lab))


def test_laboratory_and_translationally_invariant_elements_agree_between_n_1_and_2():
    # hydrogen p–d, and p p e: random ECG-GVR functions (K ∈ {0, 1}) of N = 1 and N = 2 at one c_A and
    # c_U = 0, the kets symmetrised over the protons' images
    from test_operators import family_basis

    rng = np.random.default_rng(7)
    ppe = prebo.System(["p", "p", "e"], N=1, parity=-1)
    pairs = [(hydrogen(1, EXPONENTS[:6]), hydrogen(2, EXPONENTS[2:9])),
             (family_basis("ecg-gvr", ppe, rng, nb=4, shared_c_A=0.9, cm_free=True),
              family_basis("ecg-gvr", prebo.System(["p", "p", "e"], N=2, parity=1), rng, nb=3, shared_c_A=0.9,
                           cm_free=True))]
    for lower, upper in pairs:
        w, w_v = dipole_vectors(lower.system)
        for name, v, momentum in [("dipole", w, False), ("velocity", w_v, True)]:
            lab = laboratory(lower.system).between(name, lower, upper, v[None], momentum)[0]
            ti = translationally_invariant(lower.system).between(name, lower, upper, v[None], momentum)[0]
            assert np.max(np.abs(lab - ti)) < 1e-11 * np.max(np.abs(lab)) and np.min(np.abs(lab)) > 0, name


def test_the_core_refuses_the_pairs_of_n_it_has_not_derived():
    p, d = hydrogen(1, EXPONENTS[::8]), hydrogen(2, EXPONENTS[::8])
    w, w_v = dipole_vectors(p.system)
    rep = laboratory(p.system)
    with pytest.raises(UnsupportedError, match=r"between a bra of N = 1 and a ket of N = 1 .*join N = L to N = L \+ 1"):
        rep.between("dipole", p, p, w[None])
    with pytest.raises(UnsupportedError, match=r"join N = 0 to N = 1; derived there alone"):
        rep.between("acceleration", p, d, w_v[None], momentum=True)


def test_bases_of_different_cm_exponents_give_the_internal_elements():
    """A two-basis element is that of the internal functions: bases optimised at different c_A
    (their CM Gaussians' overlap 0.977 at 0.7 and 1.0) give the lines and α of one c_A."""
    same = transitions(hydrogen(0), hydrogen(1), roots=1)["lines"][0]
    other = transitions(hydrogen(0, c_A=0.7), hydrogen(1, c_A=1.0), roots=1)["lines"][0]
    for key in ("length", "velocity", "line_strength"):  # the levels at c_A = 1 move by ~5e-10 in rounding
        assert abs(other[key]) == pytest.approx(abs(same[key]), rel=1e-8), key
    alpha = prebo.polarisability(hydrogen(0), hydrogen(1, c_A=1.0))["alpha"][0]
    assert alpha == pytest.approx(prebo.polarisability(hydrogen(0), hydrogen(1))["alpha"][0], rel=1e-8)


def test_a_plain_bra_equals_the_ecg_gvr_bra_at_k_0():
    upper = hydrogen(1, EXPONENTS[3:10])
    w, w_v = dipole_vectors(upper.system)
    rep = laboratory(upper.system)
    for name, v, momentum in [("dipole", w, False), ("velocity", w_v, True), ("acceleration", w_v, True)]:
        plain = rep.between(name, hydrogen(0, EXPONENTS[:8]), upper, v[None], momentum)[0]
        gvr = rep.between(name, hydrogen(0, EXPONENTS[:8], kind="ecg-gvr"), upper, v[None], momentum)[0]
        assert np.array_equal(plain, gvr)


def test_the_derivatives_along_the_ket_function_match_a_difference_of_the_elements():
    # He 1S (plain ECGs) against one ECG-GVR function of 1P, K = 1, along θ of its parametrisation
    from prebo.optimise import Optimiser, Sampler
    from prebo.optimise.parametrisation import Parametrisation

    def sample(state, kind, count):
        system = prebo.System(["alpha", "e", "e"], state)
        opts = Optimiser(kind=kind, K_max=int(kind == "ecg-gvr"), channels="all", length_range=(0.3, 3.0), seed=5)
        sampler = Sampler(system, opts, np.random.default_rng(5))
        fs = [sampler.fresh() for _ in range(count)]
        for g in fs[1:]:
            fs[0].append(g)
        return fs[0]

    bra = sample(prebo.State(N=0, spin={"e": 0}), "pecg", 4)
    p = Parametrisation.of(sample(prebo.State(N=1, parity=-1, spin={"e": 0}), "ecg-gvr", 1))
    theta = p.theta() + 0.2 * np.random.default_rng(2).standard_normal(len(p.theta()))
    rep = laboratory(p.f.system)
    w, w_v = dipole_vectors(p.f.system)
    assert len(rep.sym_c) == 2
    for name, v, momentum in [("dipole", w, False), ("velocity", w_v, True)]:
        exact = rep.between_gradient(name, bra, p.function(theta), *p.directions(theta), v[None], momentum)[0]
        assert exact.shape == (1 + len(theta), len(bra))

        def values(t):
            return rep.between(name, bra, p.function(t), v[None], momentum)[0, :, 0]

        assert np.array_equal(exact[0], values(theta))
        for k in range(len(theta)):
            e = np.zeros_like(theta)
            e[k] = 1e-4
            fd = (8 * (values(theta + e) - values(theta - e)) - (values(theta + 2 * e) - values(theta - 2 * e))) / 12e-4
            assert np.max(np.abs(exact[1 + k] - fd)) < 1e-8 * np.max(np.abs(exact[1:])), (name, k)


def test_bad_pairs_are_refused_in_one_line():
    with pytest.raises(InputError, match="one symmetry"):
        transitions(hydrogen(0), hydrogen(0))
    with pytest.raises(InputError, match="different particles"):
        transitions(hydrogen(0), hydrogen(1, nucleus="d"))


def test_the_static_polarisability_of_hydrogen_is_nine_halves_over_mu_cubed():
    from prebo.level.response import polarisability

    mu = 1 / (1 + 1 / 1836.15267343)
    r = polarisability(hydrogen(0), hydrogen(1))
    want = 4.5 / mu ** 3
    assert abs(r["alpha"][0] - want) < 1e-8 * want
    assert r["alpha"][0] < want * (1 + 1e-12)  # Hylleraas: from below
    assert abs(r["sum_over_states"][0] - r["alpha"][0]) < 1e-10 * want
    assert r["hylleraas"] == -r["alpha"][0] / 2


def test_the_dynamic_polarisability_grows_towards_the_first_pole_and_stops_there():
    from prebo.level.response import polarisability

    r = polarisability(hydrogen(0), hydrogen(1), omega=[0.0, 0.1, 0.3])
    assert r["alpha"][0] < r["alpha"][1] < r["alpha"][2]
    assert np.allclose(r["alpha"], r["sum_over_states"], rtol=1e-9)
    with pytest.raises(InputError, match="first pole"):
        polarisability(hydrogen(0), hydrogen(1), omega=r["pole"])



def test_ecgpack_he_samples_give_the_elements_its_readme_prints():
    # ecgpack's RG_0S-1P He sample (tests/data/ecgpack/README.md): its README prints, digits cut off,
    # dE = 0.779 287 387, <S|z|P> = 0.395 665 167 for the M = 0 component (<1‖d‖0> = √3 <1 0|d_z|0 0>)
    # and <S|P_z|P> = i 0.314 193 144 with P_z the electrons' momentum (|velocity form| × ΔE / √3)
    from prebo.io.load import load_basis

    data = __import__("pathlib").Path(__file__).parent / "data" / "ecgpack"
    lower, upper = (load_basis(data / f"ecgpack-He-inf-{s}-10.inout.txt")[0] for s in ("1S", "2P"))
    (line,) = transitions(lower, upper)["lines"]
    assert 0.779287387 <= line["Eh"] < 0.779287388
    assert 0.395665167 <= abs(line["length"]) / 3 ** 0.5 < 0.395665168
    assert 0.314193144 <= abs(line["velocity"]) * line["Eh"] / 3 ** 0.5 < 0.314193145


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """basis.json files of hydrogen 1s, 2p and 3d (8 functions), H 2p with a deuteron, and a floating ECG basis."""
    d = tmp_path_factory.mktemp("lines")
    few = EXPONENTS[::5]
    hydrogen(0, few).save(d / "s.json")
    hydrogen(1, few).save(d / "p.json")
    hydrogen(2, few).save(d / "d.json")
    hydrogen(1, few, nucleus="d").save(d / "dp.json")
    s = hydrogen(0, few)
    prebo.Basis(s.system, s.A, s.c_A, kind="fecg", s=np.zeros((len(s), 2, 3))).save(d / "f.json")
    (d / "run").mkdir()
    hydrogen(1, few).save(d / "run" / "basis.json")
    (d / "broken.json").write_text('{"format": "prebo-basis", "version": 1, "system": ')
    return d


def test_the_command_prints_every_line_and_its_json(files, capsys):
    from prebo.cli import main

    assert main(["transitions", str(files / "s.json"), str(files / "run"), "--json"]) == 0
    r = __import__("json").loads(capsys.readouterr().out)
    assert r == transitions(prebo.Basis.load(files / "s.json"), prebo.Basis.load(files / "p.json"))
    assert main(["transitions", str(files / "s.json"), str(files / "p.json"), "--roots", "2", "3"]) == 0
    out = capsys.readouterr().out
    assert out.count("(N=0+) →") + out.count("(N=1−) →") == 6 and "radiative lifetimes" in out


def test_the_command_prints_the_lines_between_n_1_and_2(files, capsys):
    from prebo.cli import main

    assert main(["transitions", str(files / "d.json"), str(files / "p.json"), "--json"]) == 0
    r = __import__("json").loads(capsys.readouterr().out)
    assert r == transitions(prebo.Basis.load(files / "d.json"), prebo.Basis.load(files / "p.json"))
    assert [lv["N"] for lv in r["levels"]] == [2, 1] and r["lines"][0]["acceleration"] is None
    assert main(["transitions", str(files / "p.json"), str(files / "d.json"), "--roots", "2", "2"]) == 0
    out = capsys.readouterr().out
    assert "electric-dipole lines" in out and out.count("(N=1−) →") + out.count("(N=2+) →") == 4


@pytest.mark.parametrize("args, words", [
    (("s.json", "s.json"), "one symmetry"),
    (("s.json", "dp.json"), "different particles"),
    (("f.json", "p.json"), "no definite N"),
    (("s.json", "broken.json"), "broken.json"),
    (("s.json", "missing.json"), "missing.json"),
    (("s.json", "p.json", "--roots", "1", "2", "3"), "--roots"),
    (("s.json", "p.json", "--roots", "99"), "roots"),
])
def test_bad_input_is_one_line(files, capsys, args, words):
    from conftest import cli_error

    err = cli_error(capsys, "transitions", *(str(files / a) if a.endswith("json") else a for a in args))
    assert words in err, err


def test_a_forbidden_pair_is_reported_as_such_never_as_a_number():
    # para H2+ (N = 0) and ortho H2+ (N = 1): the protons' spin states differ
    from prebo.io.load import load_basis

    bases = __import__("pathlib").Path(__file__).parent.parent / "examples" / "bases"
    para, ortho = (load_basis(bases / name / "basis.json")[0] for name in ("h2plus-gvr", "h2plus-n1"))
    (line,) = transitions(para, ortho)["lines"]
    assert line["forbidden"].startswith("spin-forbidden") and "length" not in line and "einstein_A" not in line


def test_the_polarisability_command_prints_alpha_and_draws_it(files, capsys, tmp_path):
    from prebo.cli import main

    args = ["polarisability", str(files / "s.json"), str(files / "p.json")]
    assert main(args + ["--omega", "0", "0.2", "--json"]) == 0
    r = __import__("json").loads(capsys.readouterr().out)
    want = prebo.polarisability(prebo.Basis.load(files / "s.json"), prebo.Basis.load(files / "p.json"), [0.0, 0.2])
    assert r == want and r["alpha"][0] < r["alpha"][1]
    assert main(args + ["--plot", str(tmp_path / "alpha.png")]) == 0
    assert (tmp_path / "alpha.png").read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize("extra, words", [
    (["--omega", "5"], "first pole"),
    (["--points", "10"], "only with --plot"),
    (["--root", "99"], "root"),
])
def test_bad_polarisability_input_is_one_line(files, capsys, extra, words):
    from conftest import cli_error

    err = cli_error(capsys, "polarisability", files / "s.json", files / "p.json", *extra)
    assert words in err, err


def test_the_polarisability_needs_a_response_basis_of_n_1():
    with pytest.raises(InputError, match="N = 0"):
        prebo.polarisability(hydrogen(0), hydrogen(0))


def test_a_run_with_a_partner_basis_writes_its_lines_into_result_json(files, tmp_path, capsys):
    from conftest import cli_error
    from prebo.cli import main

    (tmp_path / "h.toml").write_text('[system]\nparticles = ["p", "e"]\n[basis]\nsize = 4\n')
    assert main(["run", str(tmp_path / "h.toml"), "--out", str(tmp_path / "run"), "--quiet",
                 "--partner", str(files / "p.json")]) == 0
    r = __import__("json").loads((tmp_path / "run" / "result.json").read_text())
    want = transitions(prebo.Basis.load(tmp_path / "run" / "basis.json"), prebo.Basis.load(files / "p.json"))
    assert r["lines"] == {"partner": str(files / "p.json")} | want
    capsys.readouterr()
    err = cli_error(capsys, "run", tmp_path / "h.toml", "--out", tmp_path / "other", "--partner", files / "dp.json")
    assert "--partner" in err and "different particles" in err and not (tmp_path / "other").exists()
