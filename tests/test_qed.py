"""The leading QED correction E⁽³⁾ (level/qed.py): the atomic form for clamped nuclei from given
numbers, hydrogen-like nS levels against the one-loop Lamb shift's closed form with the exact
⟨δ³⟩ and Drake & Swainson's ln k₀, the units, the pair classes left out, bad input, and the
gathering from a basis against the numbers it gathered."""
import math

import numpy as np
import pytest

import prebo
from prebo.errors import InputError
from prebo.level.evaluate import HARTREE_CM
from prebo.level.qed import TERMS, of_level, terms
from prebo.level.relativistic import ALPHA

from test_bethe import DRAKE_SWAINSON, GROUND, RESPONSE
from test_transitions import hydrogen

#: CODATA 2018 (E. Tiesinga et al., Rev. Mod. Phys. 93, 025010 (2021)): α and E_h/(hc) in cm⁻¹
CODATA_ALPHA, CODATA_HARTREE_CM = 7.2973525693e-3, 219474.6313632


def clamped(nucleus: str, electrons: int) -> prebo.System:
    """`nucleus` of infinite mass with `electrons` electrons."""
    return prebo.System([{"name": nucleus, "mass": math.inf}] + ["e"] * electrons)


def atomic(Z, d_ea, d_ee, P, ln_k0, electrons=2):
    """The atomic form as issue 58 states it (ln k₀ in R_∞; ⟨δ⟩ and P per pair), written out here."""
    a = ALPHA
    return a**3 * (electrons * 4 * Z / 3 * (19 / 30 - 2 * math.log(a) - ln_k0) * d_ea
                   + (164 / 15 + 14 / 3 * math.log(a)) * d_ee - 7 / (6 * math.pi) * P)


def test_clamped_helium_is_the_atomic_form():
    # numbers of helium's size, not its values: the function against the formula written out
    d_ea, d_ee, P, ln_k0 = 1.81, 0.106, 0.989, 4.37
    out = terms(clamped("alpha", 2), {"alpha-e": d_ea, "e-e": d_ee}, {"e-e": P}, ln_k0)
    assert out["Eh"]["total"] == pytest.approx(atomic(2, d_ea, d_ee, P, ln_k0), rel=1e-14)
    assert set(out["Eh"]) == set(TERMS) | {"total"}
    assert out["classes"]["electron_nucleus"] == {"alpha-e": pytest.approx(atomic(2, d_ea, 0, 0, ln_k0))}
    assert out["classes"]["araki_sucher"]["e-e"] == pytest.approx(-ALPHA**3 * 7 / (6 * math.pi) * P)
    assert out["omitted"] == {}
    # ln k₀ in another unit: converted to R_∞ = ½ Eh
    again = terms(clamped("alpha", 2), {"alpha-e": d_ea, "e-e": d_ee}, {"e-e": P}, ln_k0 - math.log(4), rydberg=2.0)
    assert again["Eh"]["total"] == pytest.approx(out["Eh"]["total"], rel=1e-14)
    # the sign of the nucleus's charge: the electron–nucleus term is linear in Z_a
    anti = prebo.System([{"name": "pbar", "mass": math.inf}, "e"])
    assert terms(anti, {"e-pbar": d_ea}, {}, ln_k0)["Eh"]["total"] == pytest.approx(-atomic(1, d_ea, 0, 0, ln_k0, 1))


@pytest.mark.parametrize("Z, nucleus", [(1, "p"), (2, "alpha")])
@pytest.mark.parametrize("n", [1, 2])
def test_hydrogen_like_is_the_lamb_shift(Z, nucleus, n):
    ln_k0 = DRAKE_SWAINSON[n - 1]  # in the reduced Rydberg, μZ²/2
    lamb = 4 * ALPHA**3 * Z**4 / (3 * math.pi * n**3) * (math.log((Z * ALPHA) ** -2) - ln_k0 + 19 / 30)
    out = terms(clamped(nucleus, 1), {f"{nucleus}-e" if nucleus < "e" else f"e-{nucleus}": Z**3 / (math.pi * n**3)},
                {}, ln_k0, rydberg=Z**2 / 2)
    assert out["Eh"]["total"] == pytest.approx(lamb, rel=1e-13)
    assert out["Eh"]["electron_electron"] == out["Eh"]["araki_sucher"] == 0.0
    # the proton's finite mass: ⟨δ³⟩ = (μZ)³/(πn³), ln k₀ in μZ²/2, the reduced-mass form
    system = prebo.System([nucleus, "e"])
    mu = float(np.prod(system.masses) / system.m_total)
    label = next(iter(out["classes"]["electron_nucleus"]))
    finite = terms(system, {label: (mu * Z) ** 3 / (math.pi * n**3)}, {}, ln_k0, rydberg=mu * Z**2 / 2)
    reduced = mu**3 * 4 * ALPHA**3 * Z**4 / (3 * math.pi * n**3) * (
        math.log(1 / (mu * (Z * ALPHA) ** 2)) - ln_k0 + 19 / 30)
    assert finite["Eh"]["total"] == pytest.approx(reduced, rel=1e-13)
    assert finite["Eh"]["total"] != pytest.approx(out["Eh"]["total"], rel=1e-4)


def test_units():
    assert ALPHA == CODATA_ALPHA and HARTREE_CM == CODATA_HARTREE_CM
    out = terms(clamped("p", 1), {"e-p": 1 / math.pi}, {}, DRAKE_SWAINSON[0])
    for key, value in out["Eh"].items():
        assert out["cm-1"][key] == pytest.approx(value * CODATA_HARTREE_CM, rel=1e-15)
    assert out["alpha"] == CODATA_ALPHA
    # hydrogen's 1s, clamped: the leading one-loop term, (4α³/3π)[−2 ln α − ln k₀ + 19/30] Eh
    assert out["cm-1"]["total"] == pytest.approx(
        4 * CODATA_ALPHA**3 / (3 * math.pi) * (-2 * math.log(CODATA_ALPHA) - DRAKE_SWAINSON[0] + 19 / 30)
        * CODATA_HARTREE_CM, rel=1e-13)


def test_left_out_and_bad_input():
    out = terms(prebo.System(["p", "e", "e+"]), {"e-p": 0.3}, {}, 3.0)
    assert set(out["omitted"]) == {"e-e+", "e+-p"}
    assert set(out["classes"]["electron_nucleus"]) == {"e-p"}
    assert "p-p" in terms(prebo.System(["p", "p", "e"]), {"e-p": 0.2}, {}, 3.0)["omitted"]
    with pytest.raises(InputError, match="araki_sucher value for the pair class 'e-e'"):
        terms(clamped("alpha", 2), {"alpha-e": 1.8, "e-e": 0.1}, {}, 4.37)
    with pytest.raises(InputError, match="delta value for the pair class 'alpha-e'"):
        terms(clamped("alpha", 2), {"e-e": 0.1}, {"e-e": 1.0}, 4.37)


def test_of_level_gathers_bethe():
    # hydrogen 1s in test_bethe's even-tempered bases: ln k₀ there is Drake & Swainson's within 1e-7
    ground, response = hydrogen(0, GROUND), hydrogen(1, RESPONSE)
    out = of_level(ground, response, K=1e5)
    log = out["bethe"]
    assert log["rydberg"] == 0.5
    assert out["Eh"] == terms(ground.system, log["delta"], {}, log["ln_k0"])["Eh"]
    # the reduced-mass form with the exact ⟨δ³⟩ and ln k₀: the basis's values within their errors
    mu = float(np.prod(ground.system.masses) / ground.system.m_total)
    exact = mu**3 * 4 * ALPHA**3 / (3 * math.pi) * (math.log(1 / (mu * ALPHA**2)) - DRAKE_SWAINSON[0] + 19 / 30)
    assert out["Eh"]["total"] == pytest.approx(exact, rel=1e-7)
