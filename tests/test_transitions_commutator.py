"""The core's dipole elements in length and velocity form against [H, d], and in acceleration form
against the Coulomb element's gradient under a translation, for single pairs of functions, from
the floating-ECG engine's overlap, kinetic and Coulomb elements (no dipole kernel).

With d_z = Σ_k w_k z_k, w = q − Q m/m_tot (`dipole_vectors`), and the laboratory-frame kinetic
energy T = −Σ_k ∇_k²/(2 m_k), [d_z, T] = Σ_k (w_k/m_k) ∂/∂z_k = ∂_{w′,z}, w′ = q/m − Q/m_tot; the
potential commutes with d. The CM part of T, −∇_R²/(2 m_tot), commutes with d (1ᵀw = 0: d is
internal), and ∂_{w′} has no CM component (mᵀw′ = 0), so the identity holds alike with T_ti, the
kinetic energy of the functions' CM Gaussians eliminated. For a bra φ of N = 0 and the M = 0
component χ = (u_Jᵀr_z) exp(−rᵀA_J r) of an ECG-GVR ket of N = 1, K = 0:

    ⟨φ|d_z|χ⟩,   ⟨φ|∂_{w′,z}|χ⟩ = ⟨d_z φ|T|χ⟩ − ⟨φ|T|d_z χ⟩.

Each factor is a derivative of a floating Gaussian, exp(−rᵀAr − bᵀr_z) = exp(bᵀA⁻¹b/4)
exp(−(r − s)ᵀA(r − s)) with s_z = −A⁻¹b/2, s_x = s_y = 0 (for A 1 = c_A μ still a CM Gaussian
times an internal function): d_z f = −∂_λ[e^{−λ wᵀr_z} f], χ = −∂_μ[e^{−μ u_Jᵀr_z} e^{−rᵀA_J r}],
and an ECG-GVR bra of K = 1 is |u_Iᵀr|² exp(−rᵀA_I r) = −∂_α exp(−rᵀ(A_I + α u_I u_Iᵀ)r). So both
elements are mixed partial derivatives at 0 of un-normalised FECG S and T (the engine's normalised
ones times the norms (π^n/det 2A)^{3/4}), taken by sixth-order central differences in (α,) λ, μ.

The core reports Edmonds' reduced elements ⟨1‖O‖0⟩ = √3 ⟨1 0|O_z|0 0⟩ between normalised
functions (crates/prebo-core/src/families/ecg_gvr/transition.rs); its dropped sign is that of the
M = 0 component χ, so with ∂ anti-Hermitian

    dipole = √3 ⟨χ̂|d_z|φ̂⟩,   velocity = √3 ⟨χ̂|∂_{w′,z}|φ̂⟩ = −√3 ⟨φ̂|∂_{w′,z}|χ̂⟩,

‖χ‖ = (u_JᵀA_J⁻¹u_J/4)^{1/2} ‖e^{−rᵀA_J r}‖ and ‖|v|² e^{−rᵀA_I r}‖ = √15 x ‖e^{−rᵀA_I r}‖,
x = u_IᵀA_I⁻¹u_I/4 (the Gaussian's moments E|v|⁴ = 15x²). The bra and ket have different c_A:
`Representation.between` divides each laboratory-frame element by the overlap of the normalised CM
Gaussians (the internal element of CM-separable functions), and so does the check.

Cases: distinguishable particles (p μ e, an ion: Q ≠ 0) and He in both spin states (the ket's
images under the symmetriser). Between functions centred in the CM coordinate the total momentum
has no element (⟨g_I|∂_Z|g_J⟩ = 0 for CM Gaussians g), so the Q/m_tot of w′ shows only for a ket
whose global vector has a CM component (1ᵀu_J ≠ 0, χ ∝ Z + …): the ion's last two cases.
"""
import itertools
import math

import numpy as np
import pytest

import prebo
from prebo.coordinates import jacobi
from prebo.integrals import laboratory
from prebo.level.transitions import dipole_vectors

#: the sixth-order central first difference: (offset in steps, weight per step)
STENCIL = ((1, 3 / 4), (-1, -3 / 4), (2, -3 / 20), (-2, 3 / 20), (3, 1 / 60), (-3, -1 / 60))
#: the step in each parameter (α in bohr⁻², λ and μ in bohr⁻¹): below 5e-9 relative from 0.01 to 0.03
STEP = 0.03
#: the step of the translation h (bohr): the Coulomb elements' error falls as h⁶ (p μ e, K = 0: 9.7e-6
#: at 0.06, 1.5e-7 at 0.03, 2.4e-9 at 0.015) until rounding (~2e-8 at 0.0075)
SHIFT = 0.015

SYSTEMS = {"p mu e": (["p", "mu", "e"], {}), "He singlet": (["alpha", "e", "e"], {"e": 0}),
           "He triplet": (["alpha", "e", "e"], {"e": 1})}
C_A = (0.8, 0.55)  # bra, ket
A_INT = (np.array([[0.9, 0.2], [0.2, 0.5]]), np.array([[0.6, -0.15], [-0.15, 0.8]]))  # Jacobi, bra, ket
U_I = np.array([1.0, -0.4, -0.6])  # internal: 1ᵀu = 0
U_J = {"internal ket": np.array([0.3, -1.0, 0.7]), "CM-moving ket": np.array([0.3, -1.0, 0.9])}
#: (system, the bra's K, the ket's global vector u_J)
CASES = [(s, K, "internal ket") for s in SYSTEMS for K in (0, 1)] + [("p mu e", K, "CM-moving ket") for K in (0, 1)]


def norm(A: np.ndarray) -> float:
    """‖exp(−rᵀ(A ⊗ I_3)r)‖ = (π^n / det 2A)^{3/4}, whatever its centre."""
    return (math.pi ** len(A) / np.linalg.det(2 * A)) ** 0.75


def partial(f, k: int, steps=None) -> float:
    """∂^k f(x_1, …, x_k)/∂x_1…∂x_k at 0 by the central difference `STENCIL` in each variable, of
    the steps `steps` (default: STEP each)."""
    steps = steps or (STEP,) * k
    return sum(math.prod(c / h for (_, c), h in zip(combo, steps)) * f(*(o * h for (o, _), h in zip(combo, steps)))
               for combo in itertools.product(STENCIL, repeat=k))


class Elements:
    """Un-normalised symmetrised ⟨f|X|Y g⟩ (X = S, T, T_ti) of Gaussians f, g = (A, c_A, b),
    exp(−rᵀAr − bᵀr_z), from the laboratory-frame FECG engine."""

    def __init__(self, system: prebo.System):
        self.system, self.rep = system, laboratory(system)

    def __call__(self, f, g, name: str) -> float:
        (Af, cf, bf), (Ag, cg, bg) = f, g
        s = np.zeros((2, self.system.n, 3))
        s[0, :, 2], s[1, :, 2] = -np.linalg.solve(Af, bf) / 2, -np.linalg.solve(Ag, bg) / 2
        basis = prebo.Basis(self.system, np.array([Af, Ag]), [cf, cg], kind="fecg", s=s)
        scale = norm(Af) * norm(Ag) * math.exp((bf @ np.linalg.solve(Af, bf) + bg @ np.linalg.solve(Ag, bg)) / 4)
        return self.rep.matrices(basis)[name][0, 1] * scale


class Pair:
    """The case (system, the bra's K, the ket's global vector): the N = 0 system, the laboratory
    exponents A_I, A_J and CM exponents c_I, c_J, the one-function bra (plain or ECG-GVR of K = 1)
    and ECG-GVR ket (N = 1, K = 0) and their norms as un-normalised Gaussians' (module docstring)."""

    def __init__(self, key: str, K: int, ket_u: str):
        names, spin = SYSTEMS[key]
        self.K, self.u_J = K, U_J[ket_u]
        self.zero = prebo.System(names, N=0, parity=1, spin=spin)
        one = prebo.System(names, N=1, parity=-1, spin=spin)
        jac = jacobi(self.zero.masses)
        (self.A_I, self.A_J), (self.c_I, self.c_J) = (jac.to_lab(a, c) for a, c in zip(A_INT, C_A)), C_A
        self.ket = prebo.Basis(one, self.A_J[None], [self.c_J], kind="ecg-gvr", u=self.u_J[None], K=[0])
        if K == 0:
            self.bra = prebo.Basis(self.zero, self.A_I[None], [self.c_I])
            norm_I = norm(self.A_I)
        else:
            self.bra = prebo.Basis(self.zero, self.A_I[None], [self.c_I], kind="ecg-gvr", u=U_I[None], K=[1])
            norm_I = math.sqrt(15) * (U_I @ np.linalg.solve(self.A_I, U_I) / 4) * norm(self.A_I)
        norm_J = math.sqrt(self.u_J @ np.linalg.solve(self.A_J, self.u_J) / 4) * norm(self.A_J)
        cm = (2 * math.sqrt(self.c_I * self.c_J) / (self.c_I + self.c_J)) ** 1.5
        #: √3 over the norms and the CM Gaussians' overlap, with the sign (−1)^K of the bra's −∂_α
        self.scale = math.sqrt(3) / (norm_I * norm_J * cm) * (-1) ** K

    def between(self, name: str, v: np.ndarray, momentum: bool = False) -> float:
        """The core's element of the two-basis operator `name`."""
        return laboratory(self.zero).between(name, self.bra, self.ket, v[None], momentum)[0, 0, 0]

    def exponent_I(self, alpha: float) -> np.ndarray:
        """A_I + α u_I u_Iᵀ (K = 1: the bra is −∂_α of its Gaussian)."""
        return self.A_I + (alpha * np.outer(U_I, U_I) if self.K else 0.0)


@pytest.mark.parametrize("key, K, ket_u", CASES, ids=[f"{s}-K={K}-{u}" for s, K, u in CASES])
def test_length_and_velocity_elements_are_the_dipole_and_its_commutator_with_T(key, K, ket_u):
    p = Pair(key, K, ket_u)
    w, w_v = dipole_vectors(p.zero)
    dipole, velocity = p.between("dipole", w), p.between("velocity", w_v, momentum=True)
    element = Elements(p.zero)

    def bra_of(x):  # (α,) λ: e^{−λ wᵀr_z} exp(−rᵀ(A_I + α u_I u_Iᵀ)r)
        return p.exponent_I(x[0]), p.c_I, x[-1] * w

    def overlap(*x):
        return element(bra_of(x[:-1]), (p.A_J, p.c_J, x[-1] * p.u_J), "S")

    def commutator(*x, name):  # ⟨e^{−λw}f|T|e^{−μu}g⟩ − ⟨f|T|e^{−λw − μu}g⟩
        return (element(bra_of(x[:-1]), (p.A_J, p.c_J, x[-1] * p.u_J), name)
                - element(bra_of(x[:-2] + (0.0,)), (p.A_J, p.c_J, x[-2] * w + x[-1] * p.u_J), name))

    # each −∂ of the bra's α (in p.scale), λ and the ket's μ
    want_dipole = p.scale * partial(overlap, K + 2)
    assert abs(dipole - want_dipole) < 1e-8 * abs(dipole)
    for name in ("T", "T_ti"):
        want_velocity = -p.scale * partial(lambda *x: commutator(*x, name=name), K + 2)
        assert abs(velocity - want_velocity) < 1e-8 * abs(velocity), name


@pytest.mark.parametrize("key, K, ket_u", CASES, ids=[f"{s}-K={K}-{u}" for s, K, u in CASES])
def test_the_acceleration_element_is_the_gradient_of_the_coulomb_element_under_a_shift(key, K, ket_u):
    """acceleration = √3 ⟨χ̂|∂_{w′,z} V|φ̂⟩ with V the Coulomb potential: ⟨f|a·∇V|g⟩ = ∂_h ⟨f_h|V|g_h⟩,
    f_h(r) = f(r − h a) with a = w′ on the z components, and a Gaussian shifted so is again one:
    exp(−rᵀAr − bᵀr_z) at r_z − h w′ is exp(h bᵀw′ − h² w′ᵀAw′) exp(−rᵀAr − (b − 2h A w′)ᵀr_z). So
    the element is the mixed derivative in ((α,) μ, h) of un-normalised FECG Coulomb elements."""
    p = Pair(key, K, ket_u)
    _, w_v = dipole_vectors(p.zero)
    acceleration = p.between("acceleration", w_v, momentum=True)
    element = Elements(p.zero)

    def shifted(f, h):  # (the shifted Gaussian, its factor)
        A, c, b = f
        return (A, c, b - 2 * h * A @ w_v), math.exp(h * b @ w_v - h * h * w_v @ A @ w_v)

    def coulomb(*x):  # ⟨f_h|V|g_h⟩, f = exp(−rᵀ(A_I + α u_I u_Iᵀ)r), g = e^{−μ u_Jᵀr_z} exp(−rᵀA_J r)
        (f, a), (g, b) = (shifted(f, x[-1]) for f in ((p.exponent_I(x[0]), p.c_I, np.zeros(len(U_I))),
                                                       (p.A_J, p.c_J, x[-2] * p.u_J)))
        return a * b * element(f, g, "V")

    want = -p.scale * partial(coulomb, K + 2, (STEP,) * (K + 1) + (SHIFT,))  # the ket's −∂_μ
    assert abs(acceleration - want) < 1e-8 * abs(acceleration)
