"""The leading QED correction E⁽³⁾ of a level, order α³ Eh, term by term from ⟨δ³(r_ab)⟩,
⟨P(1/r_ab³)⟩ and the Bethe logarithm ln k₀ (docs/relativistic.md, "The leading QED correction E⁽³⁾").

The atomic form. For electrons i, j about clamped nuclei a of charge Z_a (infinite mass; hartree
atomic units, E_h = m_e α²c², so α³ Eh = m_e c² α⁵; ln k₀ in the Rydberg R_∞ = ½ Eh):

    E⁽³⁾ = α³ { Σ_{i,a} (4Z_a/3)[19/30 − 2 ln α − ln k₀] ⟨δ³(r_ia)⟩                 electron–nucleus
              + Σ_{i<j} [164/15 + (14/3) ln α] ⟨δ³(r_ij)⟩                          electron–electron
              − (7/6π) Σ_{i<j} ⟨P(1/r_ij³)⟩ }                                       Araki–Sucher

(H. Araki, Prog. Theor. Phys. 17, 619 (1957); J. Sucher, Phys. Rev. 109, 1010 (1958); the helium
form of K. Pachucki, Phys. Rev. A 74, 062510 (2006), arXiv:physics/0607070, and of the review of
V. A. Yerokhin, V. Patkóš, K. Pachucki, Symmetry 13, 1246 (2021); the molecular form, the same
with a sum over the nuclei, of J. Piszczatowski et al., J. Chem. Theory Comput. 5, 3039 (2009)
for H₂. The formula is the one prebo's issue 58 states; of these papers only the abstracts and
introductions were read here through the search tool.) 19/30 = 5/6 − 1/5 holds the one-loop
self-energy's local part and the Uehling vacuum polarisation −(4/15)Z_a δ³ of each nucleus; P(1/r³)
is the Araki–Sucher distribution, the a → 0 limit of ⟨θ(r − a)/r³⟩ + 4π(γ + ln a)⟨δ³(r)⟩.

Hydrogen-like check (exact ⟨δ³(r)⟩ = Z³/(πn³) at infinite mass, ln k₀ of the level in the reduced
Rydberg Z²/2 Eh, equal to its value in R_∞ less 2 ln Z, bethe.py on units):

    E⁽³⁾(nS) = (4α³Z⁴/(3πn³)) [ln (Zα)⁻² − ln k₀ + 19/30],

the leading one-loop Lamb shift of an S level (self-energy and vacuum polarisation) as Bethe's
logarithm enters it (H. A. Bethe, Phys. Rev. 72, 339 (1947); M. I. Eides, H. Grotch,
V. A. Shelyuto, Phys. Rep. 342, 63 (2001), recalled, not read here).

Every particle quantum. prebo's levels are those of the full Coulomb Hamiltonian, so ⟨δ³(r_ia)⟩
and ln k₀ (bethe.py: every charged particle radiates) carry the finite masses. This module applies
the atomic form to them as they are, with ln k₀ converted to R_∞ (ln k₀ + ln(R/R_∞) for ln k₀ in
the unit R). For hydrogen-like atoms this is the reduced-mass form: with ⟨δ³⟩ = (μZ)³/(πn³) and ln
k₀ in R_∞ equal to its value in the reduced Rydberg μZ²/2 plus ln(μZ²),

    E⁽³⁾ = (μ/m_e)³ (4α³Z⁴/(3πn³)) [ln (m_e/(μ(Zα)²)) − ln k₀ + 19/30],

the (m_r/m)³ scaling and the logarithm's argument m/(m_r(Zα)²) of Eides et al. (recalled). NOT
included, for want of a formula read and derived in the time of this module: the recoil terms of
order (m_e/M) α³ beyond these (Salpeter's term for hydrogen, with its own ln k₀-like logarithm and
⟨P(1/r_ia³)⟩ of each electron–nucleus pair; Pachucki 2006 gives helium's). Their size is about
m_e/M of the electron–nucleus term (5e-4 for hydrogen, 1.4e-4 for ⁴He).

Conventions per particle type. The electron is prebo's "e" (mass m_e, charge −1). A pair "e"–a
with a not a lepton (a nucleus, or any heavy particle: p, d, t, he3, alpha, pbar, user-defined)
gets the electron–nucleus term with Z_a = q_a, its charge with its sign: the term is linear in the
potential the electron sees (the self-energy's part ∝ ⟨∇²V⟩ = 4πZ_a⟨δ³⟩ and the Uehling potential
∝ Z_a), so a negative charge gives the opposite sign. "e"–"e" gets the electron–electron and
Araki–Sucher terms. Left out (reported under "omitted" with the reason): pairs with a positron
(e⁺e⁻ annihilation, which enters positronium at this order, and the positron's own terms are not
those above), with a muon (its self-energy scales as 1/m_μ² and the electron loop's vacuum
polarisation is not local on a muonic orbit), and pairs of two non-leptons (their contact density
is negligible; the nuclei's self-energy is of order (m_e/M)² and beyond). Also left out: finite
nuclear size (it needs charge radii, and its formula was not read here), higher orders (α⁴ Eh and
up), and the relativistic and recoil corrections to ln k₀.
"""
from __future__ import annotations

import math

from .. import eigen
from ..errors import InputError
from .bethe import R_INFINITY, bethe_logarithm
from .evaluate import HARTREE_CM
from .expectation import members
from .relativistic import ALPHA

#: the terms, in the order reported
TERMS = ("electron_nucleus", "electron_electron", "araki_sucher")

#: prebo's lepton names (system/particles.py KNOWN): a pair with one is not an electron–nucleus pair
LEPTONS = ("e", "e+", "mu", "mu+")

ELECTRON = "e"


def omitted(a, b) -> str | None:
    """Why the pair of particles a, b has no term in E⁽³⁾ here (module docstring), or None."""
    names = {a.name, b.name}
    if names & {"e+", "mu", "mu+"}:
        return "a positron or muon: its α³ terms are not those of the atomic form"
    if ELECTRON not in names:
        return "no electron: nuclear self-energy and the nuclei's contact are left out"
    return None


def terms(system, delta: dict, araki_sucher: dict, ln_k0: float, rydberg: float = R_INFINITY,
          alpha: float = ALPHA) -> dict:
    """E⁽³⁾ (module docstring) of one level of `system` from its ⟨δ³(r_ab)⟩ per pair class
    (`delta`, {"a-b": value per pair}, as `evaluate` and `drachmann.regularised` give them; bohr⁻³),
    ⟨P(1/r_ab³)⟩ per pair class (`araki_sucher`, the same convention; needed for "e-e" only) and the
    Bethe logarithm `ln_k0` in the unit `rydberg` (Eh; bethe.py's default R_∞ = ½ Eh).

    Returns {"Eh": {term: E, "total": Σ}, "cm-1": the same × HARTREE_CM, "classes": {term: {class:
    E (Eh)}}, "omitted": {class: reason}, "ln_k0": ln k₀ in R_∞, "alpha"} for the TERMS, each summed
    over its class's members. InputError where a class the terms need lacks its value."""
    a3, log_a = alpha**3, math.log(alpha)
    ln_k0_inf = ln_k0 + math.log(rydberg / R_INFINITY)
    classes = {term: {} for term in TERMS}
    left = {}
    for label, ms in members(system, pairs=True).items():
        a, b = (system.particles[k] for k in ms[0])
        reason = omitted(a, b)
        if reason is not None:
            left[label] = reason
            continue
        need = {"delta": delta} | ({"araki_sucher": araki_sucher} if a.name == b.name else {})
        for name, values in need.items():
            if label not in values:
                raise InputError(f"qed.terms: no {name} value for the pair class {label!r}")
        if a.name == b.name:
            classes["electron_electron"][label] = a3 * len(ms) * (164 / 15 + 14 / 3 * log_a) * delta[label]
            classes["araki_sucher"][label] = -a3 * len(ms) * 7 / (6 * math.pi) * araki_sucher[label]
        else:
            Z = b.charge if a.name == ELECTRON else a.charge
            classes["electron_nucleus"][label] = (a3 * len(ms) * 4 * Z / 3 * (19 / 30 - 2 * log_a - ln_k0_inf)
                                                  * delta[label])
    eh = {term: math.fsum(classes[term].values()) for term in TERMS}
    eh["total"] = math.fsum(eh.values())
    return {"Eh": eh, "cm-1": {k: v * HARTREE_CM for k, v in eh.items()}, "classes": classes, "omitted": left,
            "ln_k0": ln_k0_inf, "alpha": alpha}


def of_level(ground, response, root: int = 0, **bethe) -> dict:
    """E⁽³⁾ of the level `root` of the N = 0 basis `ground`: ln k₀ and the ⟨δ³(r_ab)⟩ it used
    (Drachmann's regularised values where bethe.py takes them) from `bethe_logarithm(ground,
    response, root, **bethe)` in R_∞, and ⟨P(1/r_ab³)⟩ per pair class from the core's operator
    "araki_sucher" on the level (evaluate). Returns `terms`' result with "bethe", the Bethe
    logarithm's result, and "araki_sucher", the values used."""
    from .evaluate import evaluate

    log = bethe_logarithm(ground, response, root=root, **({"rydberg": R_INFINITY} | bethe))
    level = evaluate(ground, threshold=bethe.get("threshold", eigen.THRESHOLD), roots=root + 1, targets=[root],
                     operators=("araki_sucher",))
    araki_sucher = dict(level["expectation"]["araki_sucher"])
    out = terms(ground.system, log["delta"], araki_sucher, log["ln_k0"], log["rydberg"])
    return out | {"bethe": log, "araki_sucher": araki_sucher}


def uncertainty(system, direct: dict, out: dict) -> float:
    """The numerical uncertainty (Eh) of `of_level`'s E⁽³⁾ `out`: ln k₀'s — the change of its
    convergence table's last row from the row before, else the integral's distance from the
    pseudostate sum — times |∂E⁽³⁾/∂ln k₀|, and in quadrature the change of E⁽³⁾ when the direct
    ⟨δ³⟩ (`direct`, per pair class) replace those used."""
    log = out["bethe"]
    rows = log["convergence"]
    d_ln = abs(rows[-1]["ln_k0"] - rows[-2]["ln_k0"]) if len(rows) > 1 else abs(log["ln_k0"] - log["pseudostate"])
    slope = math.fsum(out["classes"]["electron_nucleus"].values()) / (19 / 30 - 2 * math.log(out["alpha"]) - out["ln_k0"])
    d_delta = terms(system, direct, out["araki_sucher"], out["ln_k0"], alpha=out["alpha"])["Eh"]["total"] - out["Eh"]["total"]
    return math.hypot(slope * d_ln, d_delta)
