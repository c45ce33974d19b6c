"""Heterogeneous strength: a per-point factor on a material's strength.

A rock material may carry ``heterogeneity = { distribution = "weibull",
modulus = 6.0, seed = 1, applies_to = ["tension", "T"] }``.  Every point of
the material gets one factor f > 0, drawn from the distribution with **mean 1**
— the Table 1 / §2.3 values stay the mean strengths — and the same f scales
every target it ``applies_to`` (one flaw population makes a point weak in
tension and in JH2's hydrostatic tension alike):

* ``"tension"``: the tension model's static strength, sigma_st -> f sigma_st, so
  the dynamic strength of Eq. 38 scales with it (mpipd.materials.tension);
* ``"T"``: JH2's hydrostatic tensile strength, T -> f T, wherever T enters
  (the failure test p < -T, T* = T / p_HEL in Eqs. 21 and 30).

The draw is u = hashrng.uniform(seed, STREAM_STRENGTH, gid) and f = F^-1(u): a
function of the point's global id and the seed only, so the field is the same
on any rank count and after any restart.  Distributions (registry below):

* weibull (``modulus`` m > 0): f = lambda (-ln(1 - u))^(1/m), lambda = 1 / Gamma(1 + 1/m)
  (mean 1; coefficient of variation sqrt(Gamma(1 + 2/m) / Gamma(1 + 1/m)^2 - 1));
* uniform (``width`` w in [0, 1)): f = 1 + w (2u - 1), on [1 - w, 1 + w];
* normal (``cv``, ``truncate`` t = 3): f = 1 + cv z, z standard normal truncated
  to [-t, t] by inverse-CDF sampling on [Phi(-t), Phi(t)] (mean 1 exactly;
  cv is the untruncated standard deviation; cv t < 1 keeps f > 0).

No weakest-link size scaling is applied: the factor is per point at the
scene's dx, so the field's statistics do not change with resolution.  (A
weakest-link model would scale the median as (V_ref / V)^(1/m), Weibull 1951;
the refs note cites MOOSE's VolumeWeightedWeibull.)  A per-point modulus is not
the specimen's: with a horizon of 3 dx the overlapping bonds narrow the scatter
(Jones et al., Procedia Struct. Integrity 28 (2020) 1856, Fig. 6: bonds at beta = 6
gave 2-D specimens beta = 8.65-12.46); the README's rock-mass section gives what
that means for the modulus of the built-in cases.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.special import gamma, ndtr, ndtri

from ..input.schema import Registry, fail, join, non_negative
from ..kernels.hashrng import STREAM_STRENGTH, uniform

DISTRIBUTIONS = Registry("distribution", "distribution")

#: the strengths a factor may scale, and what each means (materials name theirs)
TARGETS = {"tension": "the tension model's static strength sigma_st (Eqs. 37-38)",
           "T": "JH2's hydrostatic tensile strength T (Eqs. 21, 25, 30)"}


@dataclass(frozen=True)
class Distribution:
    """Common keys: ``seed`` (an integer >= 0, default 1) and ``applies_to`` (the
    targets, required)."""

    #: keys without a default (each distribution's parameter, and the targets)
    required = ("applies_to",)
    seed: int = 1
    applies_to: tuple[str, ...] | None = None

    def check(self, path):
        non_negative(self, path, "seed")
        for key in self.required:
            if getattr(self, key) is None:
                fail(join(path, key), "missing value")
        if not self.applies_to:
            fail(join(path, "applies_to"), "name at least one target "
                 f"(known: {', '.join(TARGETS)})")
        for i, t in enumerate(self.applies_to):
            if t not in TARGETS:
                fail(join(join(path, "applies_to"), i),
                     f"unknown target {t!r} (known: {', '.join(TARGETS)})")
        if len(set(self.applies_to)) != len(self.applies_to):
            fail(join(path, "applies_to"), "a target is listed twice")

    def scales(self, target: str) -> bool:
        return target in self.applies_to

    def factors(self, gid) -> np.ndarray:
        """The factor of each point (its global id): F^-1(u), with ``inverse_cdf`` and
        ``variation`` (the factor's coefficient of variation) given by each registered
        distribution."""
        return self.inverse_cdf(uniform(self.seed, STREAM_STRENGTH, gid))


@DISTRIBUTIONS.register("weibull")
@dataclass(frozen=True)
class Weibull(Distribution):
    """Weibull factors of ``modulus`` m > 0: f = lambda (-ln(1 - u))^(1/m) with
    lambda = 1 / Gamma(1 + 1/m), so that the mean factor is 1."""
    modulus: float | None = None
    required = ("applies_to", "modulus")

    def check(self, path):
        super().check(path)
        if not self.modulus > 0:
            fail(join(path, "modulus"), f"the Weibull modulus must be > 0 (got {self.modulus})")

    @property
    def scale(self) -> float:
        """lambda = 1 / Gamma(1 + 1/m): the mean factor is 1."""
        return 1.0 / float(gamma(1.0 + 1.0 / self.modulus))

    def inverse_cdf(self, u):
        return self.scale * (-np.log1p(-u)) ** (1.0 / self.modulus)

    def variation(self) -> float:
        m = self.modulus
        return math.sqrt(float(gamma(1 + 2 / m) / gamma(1 + 1 / m) ** 2) - 1.0)


@DISTRIBUTIONS.register("uniform")
@dataclass(frozen=True)
class Uniform(Distribution):
    """Uniform factors on [1 - w, 1 + w], ``width`` w in [0, 1): f = 1 + w (2u - 1)."""
    width: float | None = None
    required = ("applies_to", "width")

    def check(self, path):
        super().check(path)
        if not 0.0 <= self.width < 1.0:
            fail(join(path, "width"), f"must be in [0, 1) so that every factor is > 0 "
                                      f"(got {self.width})")

    def inverse_cdf(self, u):
        return 1.0 + self.width * (2.0 * u - 1.0)

    def variation(self) -> float:
        return self.width / math.sqrt(3.0)


@DISTRIBUTIONS.register("normal")
@dataclass(frozen=True)
class Normal(Distribution):
    """Normal factors f = 1 + cv z, z standard normal truncated to [-t, t]
    (``truncate`` t, default 3) by inverse-CDF sampling: mean 1 exactly; ``cv`` is
    the untruncated standard deviation, and cv t < 1 keeps every factor > 0."""
    cv: float | None = None
    truncate: float = 3.0
    required = ("applies_to", "cv")

    def check(self, path):
        super().check(path)
        non_negative(self, path, "cv")
        if not self.truncate > 0:
            fail(join(path, "truncate"), f"must be > 0 (got {self.truncate})")
        if not self.cv * self.truncate < 1.0:
            fail(join(path, "cv"), f"cv * truncate must be < 1 so that every factor is > 0 "
                                   f"(got {self.cv} * {self.truncate})")

    def inverse_cdf(self, u):
        lo = ndtr(-self.truncate)
        return 1.0 + self.cv * ndtri(lo + u * (1.0 - 2.0 * lo))

    def variation(self) -> float:
        t = self.truncate
        z = 1.0 - 2.0 * ndtr(-t)                    # truncated normal: Var = 1 - 2 t phi(t) / Z
        phi = math.exp(-0.5 * t * t) / math.sqrt(2.0 * math.pi)
        return self.cv * math.sqrt(1.0 - 2.0 * t * phi / z)
