"""Shared part of every material: reference elastic properties."""
from __future__ import annotations

import math

import numba
import numpy as np

from ..input.schema import fail, join, positive


@numba.njit(cache=True)
def hypoelastic_energy(idx, sigma, J, mode, K, G, out):
    """Recoverable energy per reference volume of a linear solid's points ``idx``:
    out[i] = J (p^2 / (2 K) + S : S / (4 G)), p = -tr(sigma)/3, S = dev(sigma);
    0 for failed points (their stress is zero)."""
    for k in range(idx.shape[0]):
        i = idx[k]
        if mode[i] != 0:
            out[i] = 0.0
            continue
        p = -(sigma[i, 0] + sigma[i, 1] + sigma[i, 2]) / 3.0
        a, b, c = sigma[i, 0] + p, sigma[i, 1] + p, sigma[i, 2] + p
        ss = a * a + b * b + c * c + 2.0 * (sigma[i, 3] ** 2 + sigma[i, 4] ** 2
                                            + sigma[i, 5] ** 2)
        out[i] = J[i] * (p * p / (2.0 * K) + ss / (4.0 * G))


#: the output field (``[output] fields``) a material history array is offered as
STATE_OUTPUTS = {"D": "jh2_damage", "pressure": "pressure", "eps_p": "plastic_strain",
                 "strain_rate": "strain_rate"}


#: a homogeneous strength (the kernels read an empty factor array as 1)
NO_FACTOR = np.ones(0)

#: model families: "tl" total-Lagrangian correspondence points (the solids), "ul"
#: updated-Lagrangian points (the explosive gas, mpipd.model.gas)
FAMILIES = ("tl", "ul")


class Material:
    """Mixin for material dataclasses with ``density``, ``bulk_modulus``, ``shear_modulus``."""

    #: the model family whose points this material's parts are (FAMILIES)
    family = "tl"

    def check(self, path):
        positive(self, path, "density", "bulk_modulus", "shear_modulus")
        h = getattr(self, "heterogeneity", None)
        if h is not None:
            have = self.strength_targets
            for i, t in enumerate(h.applies_to):
                if t not in have:
                    fail(join(join(join(path, "heterogeneity"), "applies_to"), i),
                         f"this material has no strength {t!r} to scale "
                         f"(it has: {', '.join(have) if have else 'none'})")

    @property
    def strength_targets(self) -> tuple[str, ...]:
        """The strengths a heterogeneity field may scale (mpipd.materials.heterogeneity):
        the tension model's, if there is one."""
        return ("tension",) if getattr(self, "tension", None) is not None else ()

    def strength_factor(self, state: dict, target: str) -> np.ndarray:
        """The per-entry factor of a strength ``target`` from the history ``state``
        (an empty array — factor 1 — where the material is homogeneous in it)."""
        h = getattr(self, "heterogeneity", None)
        if h is None or not h.scales(target):
            return NO_FACTOR
        return state["strength_factor"]

    @property
    def lame_lambda(self) -> float:
        return self.bulk_modulus - 2.0 * self.shear_modulus / 3.0

    @property
    def p_wave_speed(self) -> float:
        """1-D-strain (P) wave speed sqrt((K + 4G/3) / rho)."""
        return math.sqrt((self.bulk_modulus + 4.0 * self.shear_modulus / 3.0) / self.density)

    def p_wave_speed_at(self, mu):
        """P-wave speed (m/s) at the compression mu = 1/J - 1 (an array): the
        reference speed for a material whose moduli do not depend on the
        compression (what the multi-rate class rule reads, mpipd.model.multirate)."""
        return np.full(np.shape(mu), self.p_wave_speed)

    @property
    def hourglass_modulus(self) -> float:
        """Modulus that gives the hourglass penalty (Eq. 15) its units: G."""
        return self.shear_modulus

    @property
    def can_fail(self) -> bool:
        return getattr(self, "tension", None) is not None

    def new_state(self, n: int) -> dict:
        return {}

    #: False for a material without a dissipation mechanism (the hypoelastic solid):
    #: its stress work is its stored energy and the ledger books no plastic part
    dissipative = True

    def point_strength(self, state: dict, pos: int) -> float:
        """The yield strength (Pa) of the ``pos``-th point of this material from its
        history ``state`` (what a probe records); NaN for a material without a
        strength model."""
        return math.nan

    def elastic_energy(self, idx, sigma, J, mode, state, W, out):
        """out[i] = recoverable energy per reference volume (J/m^3) of the points
        ``idx`` (W: their stress work).  Default: the linear solid's stress-based
        energy (:func:`hypoelastic_energy`)."""
        hypoelastic_energy(idx, sigma, J, mode, self.bulk_modulus, self.shear_modulus, out)
