"""Jones–Wilkins–Lee equation of state of the detonation products (paper Eq. 48, Table 2).

    p(V, e) = A (1 - w/(R1 V)) exp(-R1 V) + B (1 - w/(R2 V)) exp(-R2 V) + w e / V

with V = rho0/rho the relative volume and e the internal energy per unit
*initial* volume (J/m^3; e0 = 7.38 GJ/m^3 for the paper's explosive).

Chapman–Jouguet state.  From the unreacted state (V = 1, p = 0, e = e0) the
products' Hugoniot (energy jump e = e0 + p (1 - V)/2) is

    p_H(V) = [f(V) + w e0 / V] / [1 - w (1 - V) / (2 V)],   f = the two exponential terms,

and the Rayleigh line p = rho0 D^2 (1 - V) touches it where D is smallest:
D_CJ = min_V sqrt(p_H(V) / (rho0 (1 - V))).  For Table 2 this gives
D_CJ = 6688 m/s (the paper's VOD: 6690 m/s), p_CJ = 15.5 GPa, V_CJ = 0.737; the
constant-volume explosion pressure p(1, e0) is 6.79 GPa.

Isentropes of JWL are p_s(V) = A exp(-R1 V) + B exp(-R2 V) + C V^-(1 + w), with
e_s(V) = (A/R1) exp(-R1 V) + (B/R2) exp(-R2 V) + (C/w) V^-w.

The scene material ``model = "jwl"`` (:class:`Explosive`) is the explosive gas:
its parts are the "ul" model family, updated-Lagrangian points
(:class:`mpipd.model.gas.Gas`) with this EOS, a programmed detonation and its own
damping.  It is no correspondence material: it has no total-Lagrangian bonds, no
stress update and no history; the registry holds it so that a scene names it
like any material, and its moduli serve the stable-step estimate only.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from scipy.optimize import minimize_scalar

from ..input.schema import fail, join, non_negative, positive
from ..kernels import eos
from . import MATERIALS

#: the peak gas pressure the paper reports (Pa; Fig. 7, "up to 1800 MPa"): below Table 2's
#: own p(1, e0) and p_CJ (above), so a consistency row of the validation report
#: (mpipd.post.targets), quoted by the run log beside the run's CJ state (mpipd.cli)
PAPER_PEAK_PRESSURE = 1.8e9


@dataclass(frozen=True)
class BulkViscosity:
    """Artificial bulk viscosity of the gas (von Neumann & Richtmyer 1950, with the
    linear term of Landshoff 1955; the form of Wilkins 1980, J. Comput. Phys. 36,
    281-303, Eq. 3, and of LS-DYNA's Q1/Q2): a gas point whose volume decreases
    (tr L < 0) carries, besides its EOS pressure,

        q = rho l (quadratic l (tr L)^2 - linear c tr L),   l = V0^(1/3),

    with rho = rho0 / V_R and c its sound speed (products and unreacted explosive
    mixed by the burn fraction, :func:`jwl_sound_speed2`, :func:`unreacted_sound_speed2`).
    q is held to its explicit-time limit (mpipd.kernels.ul).
    Defaults 1.5 and 0.06 are the hydrocode values (LS-DYNA's Q1, Q2).  Its work is
    dissipated: the ledger's ``gas_viscous``, not the gas's e (mpipd.kernels.ul)."""
    quadratic: float = 1.5
    linear: float = 0.06

    def check(self, path):
        non_negative(self, path, "quadratic", "linear")


def _reach_check(law, path, of: str):
    """A contact law's ``distance`` (a fraction of ``of``, at most 1) and ``stiffness``
    are positive."""
    positive(law, path, "distance", "stiffness")
    if law.distance > 1.0:
        fail(join(path, "distance"), f"must be at most 1 (a fraction of {of})")


@dataclass(frozen=True)
class GasContact:
    """Non-penetration of the gas and the solids it acts on (not in the paper).

    The updated-Lagrangian force of paper Eqs. 45-48 has no term by which a solid
    pushes a gas point back: a gas point at a wall is driven into it by the gas
    behind it, and its own force state, with the wall close on one side, pushes it
    further in (its family's first moment sum omega Y V points at the wall for a
    neighbour nearer than delta / 3).  Gas then passes through the copper tube into
    the rock, where it reads the rock's compression as its own (issue 15: 48 gas
    points above p_CJ in blast_demo at 2 us, one carried from r = 2.42 to 4.71 mm).

    With this option every gas-solid pair (i, j) closer than

        d_c = min(distance l, |xi|),   l = (V_i^(1/3) + V_j^(1/3)) / 2,

    (V: reference volumes, so l is the pair's mean lattice spacing; xi = x_j - x_i the
    pair's reference separation, so the loaded configuration starts free of it, as
    Eq. 40 does for broken bonds) repels with the equal and opposite pair force

        F = stiffness K l (d_c - |Y|),   K = rho0 vod^2 (the charge's bulk modulus),

    a spring as stiff as a lattice cell of that modulus.  Its potential
    stiffness K l (d_c - |Y|)^2 / 2 is the ledger's held ``gas_contact``.
    Off by default (the paper's model); ``distance = 0.9`` and ``stiffness = 1.0``."""
    distance: float = 0.9
    stiffness: float = 1.0

    def check(self, path):
        _reach_check(self, path, "the pair's lattice spacing")


@dataclass(frozen=True)
class GasWall:
    """The wall that holds the gas: a contact of the gas with the *surface* of one
    solid it acts on (the copper tube's inner face), not with its points (not in the
    paper, whose tube is there "to prevent the explosive gas penetrating into the
    blasting-induced fractures", §2.6, but whose Eqs. 45-48 have no force by which the
    tube pushes the gas back).

    :class:`GasContact` repels gas-solid *pairs*; once the tube stretches, the gaps
    between its points open wider than two contact reaches and the gas passes
    between them (studies/validation/notes.md §48).  Here a gas point sees one
    surface interpolated over the wall's points within its horizon (Shepard
    weights w_j = (1 - |Y_j| / delta)^2, current positions): its foot c = sum w y_j /
    sum w, its normal n the direction of least spread of those points (the
    weighted covariance's smallest eigenvector, oriented as their reference normals;
    the reference normals themselves where the points do not span a plane), the face
    half a wall spacing h = sum w l_j / (2 sum w) off the points, and the gap
    g = (y_i - c) . n - h.  A gas point nearer than

        g_0 = min(distance l_i, g at the first step)     (l_i its lattice spacing)

    is pushed back along n with F = stiffness K l_i (g_0 - g) (K = rho0 vod^2, the
    charge's bulk modulus, as :class:`GasContact`), and -F is shared over the wall
    points in proportion to w_j (momentum is conserved).  The force is not the
    gradient of a potential (n and c move with the wall): its work, by the
    trapezoid over every step, is booked in the ledger's held ``gas_contact``.

    ``material``: the solid whose surface is the wall (one of ``interacts_with``);
    its wall points are those whose own family's first moment points away from the
    gas (the layer that faces it).  ``distance = 0.5`` (the gas cell's half width
    against the face) and ``stiffness = 2.0``."""
    material: str
    distance: float = 0.5
    stiffness: float = 2.0

    def check(self, path):
        _reach_check(self, path, "the gas's lattice spacing")


@dataclass(frozen=True)
class Unreacted:
    """The inert explosive before it is lit (:func:`unreacted_pressure`): ``c0`` (m/s)
    and ``s`` of the solid explosive's linear shock Hugoniot U_s = c0 + s u_p, and
    ``solid_density`` (kg/m^3; default: the charge's density, no porosity)."""
    c0: float
    s: float = 0.0
    solid_density: float | None = None

    def check(self, path):
        positive(self, path, "c0")
        non_negative(self, path, "s")
        if self.solid_density is not None:
            positive(self, path, "solid_density")


@dataclass(frozen=True)
class JWL:
    """Table 2 defaults (SI): rho0 1320 kg/m^3, A 568 GPa, B 21.6 GPa, R1 5.81,
    R2 1.77, omega 0.282, e0 7.38e9 J/m^3, VOD 6690 m/s."""
    density: float = 1320.0
    A: float = 568e9
    B: float = 21.6e9
    R1: float = 5.81
    R2: float = 1.77
    omega: float = 0.282
    e0: float = 7.38e9
    vod: float = 6690.0

    def check(self, path):
        positive(self, path, "density", "A", "R1", "R2", "omega", "e0", "vod")

    def pressure(self, V: float, e: float) -> float:
        return jwl_pressure(V, e, self.A, self.B, self.R1, self.R2, self.omega)

    def _f(self, V):
        return jwl_cold(V, self.A, self.B, self.R1, self.R2, self.omega)

    def hugoniot_pressure(self, V: float) -> float:
        """Products' Hugoniot from the unreacted state (V = 1, p = 0, e = e0)."""
        w = self.omega
        return (self._f(V) + w * self.e0 / V) / (1.0 - w * (1.0 - V) / (2.0 * V))

    def chapman_jouguet(self) -> dict:
        """CJ state: V, p, D (detonation speed) and e, from the Rayleigh-line tangency."""
        def d2(V):
            return self.hugoniot_pressure(V) / (self.density * (1.0 - V))
        r = minimize_scalar(d2, bounds=(0.2, 0.999), method="bounded",
                            options={"xatol": 1e-13})
        V = float(r.x)
        p = self.hugoniot_pressure(V)
        return {"V": V, "p": p, "D": math.sqrt(d2(V)), "e": self.e0 + 0.5 * p * (1.0 - V)}

    def isentrope_constant(self, V: float, p: float) -> float:
        """C of the isentrope through (V, p)."""
        return ((p - self.A * math.exp(-self.R1 * V) - self.B * math.exp(-self.R2 * V))
                * V ** (1.0 + self.omega))

    def isentrope_pressure(self, V: float, C: float) -> float:
        return (self.A * math.exp(-self.R1 * V) + self.B * math.exp(-self.R2 * V)
                + C * V ** -(1.0 + self.omega))


@MATERIALS.register("jwl")
@dataclass(frozen=True)
class Explosive(JWL):
    """The explosive as an updated-Lagrangian gas (paper §2.6).

    Detonation: lit at t_L = (z - initiation_z) * direction / vod (z of the
    reference position); the burn fraction ramps from 0 to 1 over
    ``burn_ramp`` * dx / vod; unlit gas carries no pressure.  ``damping`` (1/s)
    is the gas damping of §2.6 (the paper's 0.01 per microsecond = 1e4).
    ``interacts_with``: the materials the gas family includes (the copper tube).
    ``pressure_factor`` scales the JWL pressure: 1 is the physics; another value is an
    explicit, reported effective (decoupling) load.

    ``unreacted = { c0, s }``: the charge before it is lit is an inert solid that
    resists compression with its shock Hugoniot (:class:`Unreacted`); during the burn
    ramp the pressure is lam JWL(V, e) + (1 - lam) p_u(V).  Without it (the paper's
    model) unlit gas carries no pressure, which is harmless for one charge lit from
    its end (the front outruns the products, so nothing ahead of it is compressed)
    but not for a delayed charge beside a fired one, which the rock may squeeze
    before it is lit.  The compression work goes into e, so
    the ledger's ``gas`` books it.

    ``viscosity = { quadratic, linear }``: a shock (bulk) viscosity of the gas
    (:class:`BulkViscosity`); off by default (the paper's model has none).  It
    does not keep gas points out of the solids they act on (README, the delay
    study: the spikes of the delayed cases are gas passing into a tube).

    ``contact = { distance, stiffness }``: the gas's non-penetration of the solids it
    acts on (:class:`GasContact`); off by default (the paper's model has none).

    ``wall = { material, distance, stiffness }``: the gas held by the surface of one
    solid it acts on (:class:`GasWall`); off by default.
    """
    initiation_z: float = 0.0
    direction: float = 1.0
    burn_ramp: float = 3.0
    damping: float = 1e4
    interacts_with: tuple[str, ...] = ()
    pressure_factor: float = 1.0
    unreacted: Unreacted | None = None
    viscosity: BulkViscosity | None = None
    contact: GasContact | None = None
    wall: GasWall | None = None
    tension: None = None
    family = "ul"                       # its points are the updated-Lagrangian gas

    def check(self, path):
        super().check(path)
        if self.direction not in (1.0, -1.0):
            fail(join(path, "direction"), "must be 1 or -1")
        non_negative(self, path, "burn_ramp", "damping")
        positive(self, path, "pressure_factor")
        u = self.unreacted
        if u is not None:
            u.check(join(path, "unreacted"))
            if u.solid_density is not None and u.solid_density < self.density:
                fail(join(join(path, "unreacted"), "solid_density"),
                     f"must be at least the charge's density {self.density:g}")
        if self.viscosity is not None:
            self.viscosity.check(join(path, "viscosity"))
        if self.contact is not None:
            self.contact.check(join(path, "contact"))
        if self.wall is not None:
            self.wall.check(join(path, "wall"))
            if self.wall.material not in self.interacts_with:
                fail(join(join(path, "wall"), "material"),
                     f"{self.wall.material!r} is not among interacts_with "
                     f"{list(self.interacts_with)}: the gas holds only the solids it acts on")

    @property
    def bulk_viscosity(self) -> tuple[float, float]:
        """(quadratic, linear) of :class:`BulkViscosity`; (0, 0) without one."""
        q = self.viscosity
        return (0.0, 0.0) if q is None else (q.quadratic, q.linear)

    @property
    def contact_law(self) -> tuple[float, float]:
        """(distance, stiffness x K) of :class:`GasContact` (K = rho0 vod^2, Pa);
        (0, 0) without one."""
        c = self.contact
        return (0.0, 0.0) if c is None else (c.distance, c.stiffness * self.bulk_modulus)

    @property
    def wall_law(self) -> tuple[float, float]:
        """(distance, stiffness x K) of :class:`GasWall` (K = rho0 vod^2, Pa); (0, 0)
        without one."""
        w = self.wall
        return (0.0, 0.0) if w is None else (w.distance, w.stiffness * self.bulk_modulus)

    @property
    def unreacted_eos(self) -> tuple[float, float, float]:
        """(K = rho_s c0^2, s, a = rho_s / rho0) of :func:`unreacted_pressure`;
        (0, 0, 1) without one."""
        u = self.unreacted
        if u is None:
            return (0.0, 0.0, 1.0)
        rho_s = self.density if u.solid_density is None else u.solid_density
        return (rho_s * u.c0 ** 2, u.s, rho_s / self.density)

    @property
    def bulk_modulus(self) -> float:
        """rho0 vod^2: makes the stable-step estimates use the detonation speed."""
        return self.density * self.vod ** 2

    @property
    def shear_modulus(self) -> float:
        """A gas carries no shear."""
        return 0.0

    @property
    def p_wave_speed(self) -> float:
        return self.vod

    #: an explosive does not fail (no bonds; mpipd.input.scene.Scene.can_fail)
    can_fail = False


# the EOS's point functions live with the kernels (mpipd.kernels.eos); the material's
# module names them too
jwl_cold, jwl_pressure, jwl_sound_speed2 = eos.jwl_cold, eos.jwl_pressure, eos.jwl_sound_speed2
unreacted_pressure, unreacted_sound_speed2 = eos.unreacted_pressure, eos.unreacted_sound_speed2
