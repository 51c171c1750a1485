"""Named particles with CODATA 2018 masses (electron masses), charges (e) and spins (hbar).

Source: E. Tiesinga et al., CODATA 2018, Rev. Mod. Phys. 93, 025010 (2021):
m_p/m_e, m_d/m_e, m_t/m_e, m_mu/m_e, m_alpha/m_e, m_h/m_e (helion = 3He nucleus).

The ranges a particle may have (`MASS`, `CHARGE`): masses from 1e-6 m_e (no charged particle is
lighter than the electron; lighter ones are models, and only mass ratios matter) to 1e12 m_e
(nuclei reach 4.4e5; at 1e12 the finite-mass corrections, ~m_e/M = 1e-12 relative, are as small
as the errors of the best ECG energies: the infinite-mass limit); charges 0 or 1e-3 ≤ |q| ≤ 1e3 e
(every nucleus, and fractional model charges; a pair's Bohr radius grows as 1/|q| and its binding
falls as q²: 1e3 bohr and 5e-7 Eh for an electron at |q| = 1e-3). Within these ranges, and those
of length_range and c_A (optimise/settings.py), every length and exponent the sampler draws is a
finite double (optimise/sampler.py; tests/test_messages.py).

A mass may also be infinite (`math.inf`, TOML's `inf`): a clamped particle, a nucleus in the
Born–Oppenheimer sense, with no kinetic term (M_ii = 1/(2 m_i) = 0) and the centre of mass on it
(m/m_tot = e_i, `prebo.coordinates.mass_fractions`); at most one particle of a system may be
(`prebo.System`). JSON has no infinity: basis.json and result.json store such a mass as the string
"inf" (`INFINITE`).
"""
from __future__ import annotations

import math
import numbers
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from ..errors import InputError
from ..validation import Magnitude, Real, checked, half_integer

#: the stored form of an infinite mass in basis.json and result.json (JSON has no infinity)
INFINITE = "inf"


@dataclass(frozen=True)
class Mass:
    """A finite mass of the range `finite`, or +∞ (a clamped particle; module docstring)."""

    finite: Real

    @property
    def allowed(self) -> str:
        """What the rule allows, for error messages."""
        return f"{self.finite.allowed}, or inf (a clamped particle of infinite mass)"

    def __call__(self, v) -> float:
        if isinstance(v, numbers.Real) and not isinstance(v, (bool, np.bool_)) and v == math.inf:
            return math.inf
        return self.finite(v)


#: particle masses in m_e and charges in e (module docstring)
MASS = Mass(Real(1e-6, 1e12, True, True))
CHARGE = Magnitude(1e-3, 1e3)


@dataclass(frozen=True)
class Particle:
    """A point particle: `name`, `mass` in m_e (1e-6..1e12 or inf, `MASS`), `charge` in e (0 or
    1e-3 ≤ |q| ≤ 1e3, `CHARGE`), `spin` in ħ (0, 1/2, 1, ...); InputError for anything else."""

    name: str
    mass: float
    charge: float
    spin: Fraction

    def __post_init__(self):
        if not isinstance(self.name, str) or not self.name:
            raise InputError(f"particle name {self.name!r}: must be a non-empty string")
        label = f"particle {self.name!r}"
        object.__setattr__(self, "mass", checked(MASS, self.mass, f"{label}: mass", "electron masses"))
        object.__setattr__(self, "charge", checked(CHARGE, self.charge, f"{label}: charge", "elementary charges"))
        object.__setattr__(self, "spin", half_integer(self.spin, f"{label}: spin"))

    @property
    def fermion(self) -> bool:
        """Half-integer spin."""
        return self.spin.denominator == 2

    def to_dict(self) -> dict:
        """{name, mass, charge, spin} as basis.json stores it (an infinite mass as `INFINITE`)."""
        mass = INFINITE if self.mass == math.inf else self.mass
        return {"name": self.name, "mass": mass, "charge": self.charge, "spin": float(self.spin)}


_h = Fraction(1, 2)
#: name -> (mass / m_e, charge / e, spin / hbar), CODATA 2018.
KNOWN = {
    "e": (1.0, -1.0, _h),
    "e+": (1.0, 1.0, _h),
    "p": (1836.15267343, 1.0, _h),
    "pbar": (1836.15267343, -1.0, _h),
    "d": (3670.48296788, 1.0, Fraction(1)),
    "t": (5496.92153573, 1.0, _h),
    "mu": (206.7682830, -1.0, _h),
    "mu+": (206.7682830, 1.0, _h),
    "he3": (5495.88528007, 2.0, _h),
    "alpha": (7294.29954142, 2.0, Fraction(0)),
}
ALIASES = {"e-": "e", "electron": "e", "positron": "e+", "proton": "p", "deuteron": "d",
           "triton": "t", "muon": "mu", "mu-": "mu", "helion": "he3", "he4": "alpha"}


def reduced_mass(m_a, m_b):
    """μ = m_a m_b / (m_a + m_b) (m_e) of a pair of particles, and its limit m_b for an infinite
    m_a (m_a for an infinite m_b); elementwise for arrays."""
    with np.errstate(invalid="ignore"):  # ∞/∞ of an infinite mass: its limit below
        mu = m_a * m_b / (m_a + m_b)
    if np.ndim(mu) == 0:
        return m_b if math.isinf(m_a) else m_a if math.isinf(m_b) else mu
    return np.where(np.isinf(m_a), m_b, np.where(np.isinf(m_b), m_a, mu))


def particle(spec) -> Particle:
    """A particle from a name (`"p"`) or a mapping (`{name, mass?, charge?, spin?}`).

    A known name (`KNOWN`, `ALIASES`: "e", "p", "d", "mu", "alpha", ...) supplies CODATA 2018
    defaults that explicit keys override (mass in m_e, charge in e, spin in ħ); an unknown
    name must give mass, charge and spin explicitly. Returns the `Particle`; InputError otherwise.
    """
    if isinstance(spec, Particle):
        return spec
    if isinstance(spec, str):
        spec = {"name": spec}
    if not isinstance(spec, dict) or not isinstance(spec.get("name"), str):
        raise InputError(f"a particle is a name or a table with a 'name' string, got {spec!r}")
    unknown_keys = set(spec) - {"name", "mass", "charge", "spin"}
    if unknown_keys:
        raise InputError(f"particle {spec['name']!r}: unknown keys {sorted(unknown_keys)}")
    name = spec["name"]
    key = ALIASES.get(name, name)
    if key in KNOWN:
        mass, charge, spin = KNOWN[key]
    else:
        missing = [k for k in ("mass", "charge", "spin") if k not in spec]
        if missing:
            raise InputError(
                f"unknown particle {name!r}: give {', '.join(missing)} explicitly "
                f"or use one of {', '.join(sorted(KNOWN))}"
            )
        mass, charge, spin = spec["mass"], spec["charge"], spec["spin"]
        key = name
    return Particle(key, spec.get("mass", mass), spec.get("charge", charge), spec.get("spin", spin))
