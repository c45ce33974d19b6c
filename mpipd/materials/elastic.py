"""Linear hypoelastic solid in the unrotated frame.

With d the unrotated rate of deformation (paper Eq. 6), the unrotated Cauchy
stress advances as (paper Eq. 19 without yielding)

    sigma_{n+1} = sigma_n + dt * (lambda tr(d) I + 2 G d),

and the correspondence module rotates it back, sigma = R sigma R^T (Eq. 36).
Because d is the rate in the frame that co-rotates with the material (Flanagan
& Taylor 1987), the model is objective for any rigid rotation.
"""
from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np

from ..input.schema import tagged
from . import MATERIALS
from .base import Material
from .heterogeneity import DISTRIBUTIONS
from .tension import TensionFailure


@numba.njit(cache=True)
def hypoelastic_update(idx, d, dt, sigma, mode, lam, mu):
    """sigma[i] += dt (lam tr(d) I + 2 mu d) for i in idx (Voigt xx yy zz yz xz xy),
    failed points (mode[i] != 0) excepted."""
    for k in range(idx.shape[0]):
        i = idx[k]
        if mode[i] != 0:
            continue
        tr = d[i, 0] + d[i, 1] + d[i, 2]
        for c in range(3):
            sigma[i, c] += dt * (lam * tr + 2.0 * mu * d[i, c])
        for c in range(3, 6):
            sigma[i, c] += dt * 2.0 * mu * d[i, c]


@MATERIALS.register("elastic")
@dataclass(frozen=True)
class Elastic(Material):
    """Isotropic elastic solid: ``density`` (kg/m³), ``bulk_modulus``, ``shear_modulus`` (Pa),
    optionally with the tension failure model (``tension``)."""
    density: float
    bulk_modulus: float
    shear_modulus: float
    tension: TensionFailure | None = None
    heterogeneity: object = tagged(DISTRIBUTIONS, default=None)

    dissipative = False

    def elastic_energy(self, idx, sigma, J, mode, state, W, out):
        """A hypoelastic solid has no potential of its own and no dissipation: its
        stored (recoverable) energy is its stress work W (0 once failed)."""
        out[idx] = np.where(mode[idx] != 0, 0.0, W[idx])

    def update(self, idx: np.ndarray, d: np.ndarray, J: np.ndarray, dt: float,
               sigma: np.ndarray, mode: np.ndarray, state: dict) -> None:
        hypoelastic_update(idx, d, dt, sigma, mode, self.lame_lambda, self.shear_modulus)
