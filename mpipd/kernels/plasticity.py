"""Von Mises plasticity in the unrotated frame, once for every material that yields
(the copper's J2, mpipd.materials.j2; the rock's JH2 strength, mpipd.materials.jh2).

Hypoelastic trial deviator (paper Eq. 31's predictor, Voigt order xx, yy, zz, yz, xz, xy):

    e = dev(d),   S' = dev(sigma) + 2 G e dt,

its von Mises equivalent s = sqrt(3/2 S':S'), and the radial return onto a yield
stress sigma_y: S = (sigma_y / s) S' when s > sigma_y, with the equivalent plastic
strain increment deps_p = (s - sigma_y) / (3 G) (Wilkins 1964; Simo & Hughes 1998,
§3.3).  Functions of scalars and arrays, inlined where they are called.
"""
import math

import numba


@numba.njit(cache=True, inline="always")
def deviatoric_rate(d, i):
    """e = dev(d_i) of point i (Voigt; the shear entries are d's own)."""
    tr = (d[i, 0] + d[i, 1] + d[i, 2]) / 3.0
    return d[i, 0] - tr, d[i, 1] - tr, d[i, 2] - tr, d[i, 3], d[i, 4], d[i, 5]


@numba.njit(cache=True, inline="always")
def trial_deviator(sigma, i, e, G, dt):
    """S' = dev(sigma_i) + 2 G e dt (Voigt), e = :func:`deviatoric_rate`."""
    sm = (sigma[i, 0] + sigma[i, 1] + sigma[i, 2]) / 3.0
    return (sigma[i, 0] - sm + 2.0 * G * e[0] * dt,
            sigma[i, 1] - sm + 2.0 * G * e[1] * dt,
            sigma[i, 2] - sm + 2.0 * G * e[2] * dt,
            sigma[i, 3] + 2.0 * G * e[3] * dt,
            sigma[i, 4] + 2.0 * G * e[4] * dt,
            sigma[i, 5] + 2.0 * G * e[5] * dt)


@numba.njit(cache=True, inline="always")
def von_mises(s):
    """sqrt(3/2 s:s) of a Voigt tensor s (a 6-tuple; the shear entries count twice).
    Of a rate e it is sqrt(3/2) |e|; the equivalent rate sqrt(2/3 e:e) is
    :func:`equivalent_rate`."""
    return math.sqrt(1.5 * (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]
                            + 2.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5])))


@numba.njit(cache=True, inline="always")
def equivalent_rate(e):
    """sqrt(2/3 e:e) of a deviatoric Voigt rate e (a 6-tuple)."""
    return math.sqrt(2.0 / 3.0 * (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]
                                  + 2.0 * (e[3] * e[3] + e[4] * e[4] + e[5] * e[5])))


@numba.njit(cache=True, inline="always")
def radial_return(s, seq, sy):
    """S = (sigma_y / s) S' (the deviator on the yield surface; 0 if s = 0) and
    deps_p = (s - sigma_y) / (3 G) is the caller's (it needs G)."""
    f = sy / seq if seq > 0.0 else 0.0
    return s[0] * f, s[1] * f, s[2] * f, s[3] * f, s[4] * f, s[5] * f
