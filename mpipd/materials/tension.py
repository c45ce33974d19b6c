"""Rate-dependent tension failure model (paper §2.3, Eqs. 37–38).

In the paper's compression-positive convention a point fails when its minor
principal stress falls below the dynamic tensile strength,

    sigma_3 < sigma_dt,   sigma_dt = sigma_st                        (edot <= edot_0)
                          sigma_dt = (edot / edot_0)^C1 sigma_st      (edot >  edot_0)

(exp[C1 ln(edot/edot_0)] = (edot/edot_0)^C1), with sigma_st < 0 (-6.9 MPa for the
paper's granite), C1 = 0.33, edot_0 = 0.4 1/s (the text; Table 3 uses 0.5, 1.0
and 0.1) and edot from Eq. 24.  mpipd is tension-positive, so the same test is
max principal stress > -sigma_dt.  Failure mode 3.

Principal stresses come from the closed-form (trigonometric) eigenvalues of the
symmetric 3x3 stress, in numba.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numba

from ..input.schema import fail, join, non_negative, positive
from ..kernels.layout import MODE_TENSION
from ..kernels.linalg import principal_max_min


@numba.njit(cache=True, inline="always")
def equivalent_strain_rate(d, i):
    """Eq. 24 on the deviatoric part of the rate of deformation (Voigt row i)."""
    tr = (d[i, 0] + d[i, 1] + d[i, 2]) / 3.0
    e0, e1, e2 = d[i, 0] - tr, d[i, 1] - tr, d[i, 2] - tr
    return math.sqrt(2.0 / 3.0 * (e0 * e0 + e1 * e1 + e2 * e2
                                  + 2.0 * (d[i, 3] ** 2 + d[i, 4] ** 2 + d[i, 5] ** 2)))


@numba.njit(cache=True, inline="always")
def dynamic_strength(edot, sigma_st, c1, rate0):
    """sigma_dt of Eq. 38 (negative: compression-positive convention)."""
    if edot <= rate0:
        return sigma_st
    return math.exp(c1 * math.log(edot / rate0)) * sigma_st


@numba.njit(cache=True)
def tension_check(idx, sigma, d, mode, sigma_st, c1, rate0, factor):
    """Mark mode[i] = 3 and zero the stress of points of ``idx`` that fail. Returns the count.
    ``factor``: entry k's strength factor (sigma_st -> factor[k] sigma_st,
    mpipd.materials.heterogeneity); empty for a homogeneous material."""
    n = 0
    hetero = factor.shape[0] > 0
    for k in range(idx.shape[0]):
        i = idx[k]
        if mode[i] != 0:
            continue
        smax, _ = principal_max_min(sigma[i, 0], sigma[i, 1], sigma[i, 2],
                                    sigma[i, 3], sigma[i, 4], sigma[i, 5])
        st = sigma_st * factor[k] if hetero else sigma_st
        sdt = dynamic_strength(equivalent_strain_rate(d, i), st, c1, rate0)
        if -smax < sdt:
            mode[i] = MODE_TENSION
            for c in range(6):
                sigma[i, c] = 0.0
            n += 1
    return n


@dataclass(frozen=True)
class TensionFailure:
    """``sigma_st`` (Pa, negative as in the paper), ``c1``, ``rate0`` (1/s)."""
    sigma_st: float = -6.9e6
    c1: float = 0.33
    rate0: float = 0.4

    def check(self, path):
        if not self.sigma_st < 0:
            fail(join(path, "sigma_st"),
                 f"the static tensile strength is negative in the paper's convention "
                 f"(got {self.sigma_st})")
        non_negative(self, path, "c1")
        positive(self, path, "rate0")

    def apply(self, idx, sigma, d, mode, factor) -> int:
        """The check of Eqs. 37–38 on the points ``idx`` (``factor``: their strength
        factors, or an empty array)."""
        return tension_check(idx, sigma, d, mode, self.sigma_st, self.c1, self.rate0, factor)
