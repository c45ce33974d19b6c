"""Ductile failure of a metal: Johnson–Cook cumulative damage (not in the paper).

Johnson & Cook (1985, Eng. Fract. Mech. 21(1) 31–48, Eq. 2 without the
temperature term) accumulate the damage

    D = sum deps_p / eps_f,   eps_f = (d1 + d2 exp(d3 eta)) (1 + d4 ln<edot_p / rate0>)

over the plastic strain increments deps_p of the von Mises return
(mpipd.kernels.plasticity), with the stress triaxiality eta = sigma_m / sigma_eq
(mean over von Mises stress, tension positive) and <x> = max(x, 1).  At D >= 1
the point fails (mode 4, "ductile"): its stress is zeroed and its bonds break
like any failed point's (mpipd.model.failure).  The defaults are the paper's
constants for OFHC copper (Johnson & Cook 1985: D1 = 0.54, D2 = 4.89,
D3 = -3.03, D4 = 0.014, with the reference rate 1 1/s); the temperature term
(D5 = 1.12) needs a temperature, which the solids do not carry, and is left out
(at room temperature it is 1).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numba

from ..input.schema import fail, join, positive


@numba.njit(cache=True, inline="always")
def failure_strain(eta, rate, d1, d2, d3, d4, rate0):
    """eps_f of the module docstring at triaxiality ``eta`` and plastic strain rate
    ``rate`` (1/s)."""
    f = d1 + d2 * math.exp(d3 * eta)
    if rate > rate0:
        f *= 1.0 + d4 * math.log(rate / rate0)
    return f


@dataclass(frozen=True)
class DuctileFailure:
    """``d1``, ``d2``, ``d3``, ``d4`` (dimensionless), ``rate0`` (1/s): Johnson–Cook."""
    d1: float = 0.54
    d2: float = 4.89
    d3: float = -3.03
    d4: float = 0.014
    rate0: float = 1.0

    def check(self, path):
        positive(self, path, "rate0")
        if not self.d1 + self.d2 > 0:
            fail(join(path, "d1"), f"d1 + d2 (the failure strain at eta = 0) must be "
                                   f"positive (got {self.d1 + self.d2})")

    @property
    def constants(self) -> tuple:
        """The kernel's arguments, in failure_strain's order."""
        return self.d1, self.d2, self.d3, self.d4, self.rate0
