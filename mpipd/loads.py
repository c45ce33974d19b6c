"""Initial conditions and boundary conditions, resolved through registries.

Initial conditions set the velocity field at t = 0 on the reference
positions; boundary conditions mark points whose motion is prescribed.  Each
entry of a scene's ``[[initial]]`` / ``[[boundaries]]`` arrays names its
``kind``; adding a kind means registering one small dataclass here.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .schema import Registry, fail, join, non_negative, ordered_box, positive

INITIAL = Registry("initial condition", "kind")
BOUNDARIES = Registry("boundary condition", "kind")

AXES = {"x": 0, "y": 1, "z": 2}


@dataclass(frozen=True)
class Region:
    """Axis-aligned box region ``lo``..``hi`` (m), bounds inclusive."""
    lo: tuple[float, float, float]
    hi: tuple[float, float, float]

    def check(self, path):
        ordered_box(self, path, strict=False)

    def contains(self, x: np.ndarray) -> np.ndarray:
        lo, hi = np.asarray(self.lo), np.asarray(self.hi)
        return np.all((x >= lo) & (x <= hi), axis=1)


@INITIAL.register("velocity_pulse")
@dataclass(frozen=True)
class VelocityPulse:
    """v = velocity * cos²(π s / (2 w)) for |s| < w, s = x[axis] − center, w = half_width.

    Centred on a free end (``center`` at the end face), the pulse is half of a
    symmetric bump and launches one wave of peak ``velocity / 2`` into the body.
    """
    axis: str
    center: float
    half_width: float
    velocity: tuple[float, float, float]

    def check(self, path):
        if self.axis not in AXES:
            fail(join(path, "axis"), f"must be one of x, y, z (got {self.axis!r})")
        positive(self, path, "half_width")

    def apply(self, x: np.ndarray, v: np.ndarray) -> None:
        s = x[:, AXES[self.axis]] - self.center
        inside = np.abs(s) < self.half_width
        shape = np.cos(0.5 * np.pi * s[inside] / self.half_width) ** 2
        v[inside] += shape[:, None] * np.asarray(self.velocity)[None, :]


@INITIAL.register("uniform_velocity")
@dataclass(frozen=True)
class UniformVelocity:
    """v = ``velocity`` for every point inside ``region``."""
    region: Region
    velocity: tuple[float, float, float]

    def apply(self, x: np.ndarray, v: np.ndarray) -> None:
        v[self.region.contains(x)] += np.asarray(self.velocity)


@INITIAL.register("radial_velocity")
@dataclass(frozen=True)
class RadialVelocity:
    """v = ``speed`` * e_r (radial in the x-y plane about ``center``) for points with
    ``r_inner`` <= r <= ``r_outer``: the initial radial velocity of a borehole
    wall, one of the simple blast loads of paper §3.1."""
    center: tuple[float, float]
    r_inner: float
    r_outer: float
    speed: float

    def check(self, path):
        non_negative(self, path, "r_inner")
        if not self.r_outer > self.r_inner:
            fail(join(path, "r_outer"), "must exceed r_inner")

    def apply(self, x: np.ndarray, v: np.ndarray) -> None:
        dx = x[:, 0] - self.center[0]
        dy = x[:, 1] - self.center[1]
        r = np.hypot(dx, dy)
        sel = (r >= self.r_inner) & (r <= self.r_outer) & (r > 0)
        v[sel, 0] += self.speed * dx[sel] / r[sel]
        v[sel, 1] += self.speed * dy[sel] / r[sel]


@BOUNDARIES.register("fixed")
@dataclass(frozen=True)
class Fixed:
    """Points inside ``region`` are held at their reference position (u = v = 0)."""
    region: Region

    def mask(self, x: np.ndarray) -> np.ndarray:
        return self.region.contains(x)
