"""Point functions of the explosive's equations of state, compiled for the gas kernels
(mpipd.kernels.ul) and used by the material (mpipd.materials.jwl, which documents
them): the JWL pressure of the products (paper Eq. 48, Table 2), its energy-free part,
the products' isentropic sound speed, and the unreacted charge's Hugoniot pressure and
sound speed.  Scalars in, scalars out; SI units."""
from __future__ import annotations

import math

import numba


@numba.njit(cache=True, inline="always")
def jwl_cold(V, A, B, R1, R2, w):
    """The energy-independent part of Eq. 48 at relative volume V (Pa):
    f(V) = A (1 - w/(R1 V)) exp(-R1 V) + B (1 - w/(R2 V)) exp(-R2 V)."""
    return (A * (1.0 - w / (R1 * V)) * math.exp(-R1 * V)
            + B * (1.0 - w / (R2 * V)) * math.exp(-R2 * V))


@numba.njit(cache=True, inline="always")
def jwl_pressure(V, e, A, B, R1, R2, w):
    """Eq. 48: pressure (Pa) at relative volume V and energy per initial volume e,
    p = f(V) + w e / V (f: :func:`jwl_cold`)."""
    return jwl_cold(V, A, B, R1, R2, w) + w * e / V


@numba.njit(cache=True, inline="always")
def unreacted_pressure(VR, K, s, a):
    """Pressure (Pa) of the unreacted explosive at relative volume VR (to the charge's
    density rho0).  The charge is a porous bed of the solid explosive (density
    rho_s = a rho0, a >= 1) that compacts without resistance until it reaches
    rho_s (the snowplow limit of compaction: the crush strength, ~0.07 GPa for PETN
    in Saenz & Stewart 2008, is neglected), then follows the solid's linear shock
    Hugoniot U_s = c0 + s u_p (Meyers 1994, §4.3):

        eta = 1 - rho_s / rho = 1 - a VR  (the solid's compression),  p = K eta / (1 - s eta)^2,  K = rho_s c0^2,

    for eta > 0 and p = 0 otherwise (a charge carries no tension).  K = 0: no
    unreacted EOS (p = 0)."""
    eta = 1.0 - a * VR
    if K == 0.0 or eta <= 0.0:
        return 0.0
    q = 1.0 - s * eta
    return K * eta / (q * q)


@numba.njit(cache=True, inline="always")
def jwl_sound_speed2(VR, p, rho0, A, B, R1, R2, w):
    """Squared sound speed (m^2/s^2) of the products at (VR, p) along their isentrope
    (module docstring): with p_s(V) = A exp(-R1 V) + B exp(-R2 V) + C V^-(1+w) through
    (VR, p) and rho = rho0 / V,

        c^2 = dp_s/drho = (VR^2 / rho0) [R1 A e1 + R2 B e2 + (1 + w)(p - A e1 - B e2) / VR],

    e1 = exp(-R1 VR), e2 = exp(-R2 VR)."""
    e1 = A * math.exp(-R1 * VR)
    e2 = B * math.exp(-R2 * VR)
    return VR * VR / rho0 * (R1 * e1 + R2 * e2 + (1.0 + w) * (p - e1 - e2) / VR)


@numba.njit(cache=True, inline="always")
def unreacted_sound_speed2(VR, rho0, K, s, a):
    """Squared sound speed (m^2/s^2) of the unreacted explosive along its Hugoniot
    (:func:`unreacted_pressure`): c^2 = -(VR^2 / rho0) dp/dVR = (VR^2 / rho0) a K
    (1 + s eta) / (1 - s eta)^3 for eta = 1 - a VR > 0, else 0 (the loose bed)."""
    eta = 1.0 - a * VR
    if K == 0.0 or eta <= 0.0:
        return 0.0
    q = 1.0 - s * eta
    return VR * VR / rho0 * a * K * (1.0 + s * eta) / (q * q * q)
