"""Shared part of every material: reference elastic properties."""
from __future__ import annotations

import math

from ..schema import positive


class Material:
    """Mixin for material dataclasses with ``density``, ``bulk_modulus``, ``shear_modulus``."""

    exchanged: tuple[str, ...] = ()

    def check(self, path):
        positive(self, path, "density", "bulk_modulus", "shear_modulus")

    @property
    def lame_lambda(self) -> float:
        return self.bulk_modulus - 2.0 * self.shear_modulus / 3.0

    @property
    def p_wave_speed(self) -> float:
        """1-D-strain (P) wave speed sqrt((K + 4G/3) / rho)."""
        return math.sqrt((self.bulk_modulus + 4.0 * self.shear_modulus / 3.0) / self.density)

    @property
    def hourglass_modulus(self) -> float:
        """Modulus that gives the hourglass penalty (Eq. 15) its units: G."""
        return self.shear_modulus

    @property
    def can_fail(self) -> bool:
        return getattr(self, "tension", None) is not None

    def new_state(self, n: int) -> dict:
        return {}
