"""Elastic–perfectly-plastic von Mises (J2) solid: the paper's copper tube (§3.1).

Hypoelastic trial stress in the unrotated frame (as :mod:`.elastic`), then a
radial return of the deviator onto the yield surface:

    S' = S + 2 G dev(d) dt,  s = sqrt(3/2 S':S');  if s > sigma_y:  S = (sigma_y / s) S',
    deps_p = (s - sigma_y) / (3 G),

with the pressure integrated elastically (K tr(d) dt); the paper applies no EOS
to the copper.  Defaults: the paper's copper, rho 8960 kg/m^3, K 130 GPa,
G 45 GPa, sigma_y 450 MPa.
"""
from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from ..input.schema import positive, tagged
from ..kernels.plasticity import deviatoric_rate, radial_return, trial_deviator, von_mises
from . import MATERIALS
from .base import Material
from .heterogeneity import DISTRIBUTIONS
from .tension import TensionFailure


@numba.njit(cache=True)
def j2_update(idx, d, dt, sigma, mode, eps_p, K, G, sy):
    """Advance the unrotated stress of the points ``idx`` (eps_p: compact, entry k
    of point idx[k]); the radial return is mpipd.kernels.plasticity's."""
    for k in range(idx.shape[0]):
        i = idx[k]
        if mode[i] != 0:
            continue
        tr = d[i, 0] + d[i, 1] + d[i, 2]
        p_new = (sigma[i, 0] + sigma[i, 1] + sigma[i, 2]) / 3.0 + K * tr * dt
        s = trial_deviator(sigma, i, deviatoric_rate(d, i), G, dt)
        seq = von_mises(s)
        if seq > sy:
            s = radial_return(s, seq, sy)
            eps_p[k] += (seq - sy) / (3.0 * G)
        sigma[i, 0] = s[0] + p_new
        sigma[i, 1] = s[1] + p_new
        sigma[i, 2] = s[2] + p_new
        sigma[i, 3] = s[3]
        sigma[i, 4] = s[4]
        sigma[i, 5] = s[5]


@MATERIALS.register("j2")
@dataclass(frozen=True)
class J2(Material):
    """``density``, ``bulk_modulus``, ``shear_modulus``, ``yield_stress`` (Pa)."""
    density: float = 8960.0
    bulk_modulus: float = 130e9
    shear_modulus: float = 45e9
    yield_stress: float = 450e6
    tension: TensionFailure | None = None
    heterogeneity: object = tagged(DISTRIBUTIONS, default=None)

    def check(self, path):
        super().check(path)
        positive(self, path, "yield_stress")

    def new_state(self, n: int) -> dict:
        return {"eps_p": np.zeros(n)}

    def update(self, idx, d, J, dt, sigma, mode, state):
        j2_update(idx, d, dt, sigma, mode, state["eps_p"], self.bulk_modulus,
                  self.shear_modulus, self.yield_stress)
