"""Initial conditions and boundary conditions, resolved through registries.

Initial conditions set the velocity field at t = 0 on the reference
positions; boundary conditions mark points whose motion is prescribed; loads
apply time-dependent body forces.  Each entry of a scene's ``[[initial]]`` /
``[[boundaries]]`` / ``[[loads]]`` arrays names its ``kind``; adding a kind
means registering one small dataclass here.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .schema import Registry, fail, join, non_negative, ordered_box, positive

INITIAL = Registry("initial condition", "kind")
BOUNDARIES = Registry("boundary condition", "kind")
LOADS = Registry("load", "kind")

AXES = {"x": 0, "y": 1, "z": 2}
#: the speed of light (m/s): an initial speed at or above it is refused as input
#: (nothing moves so fast; 1e200 m/s overflowed the kinetic energy to inf and
#: surfaced as an instability, "compare dt", from inside the model's construction)
C_LIGHT = 299_792_458.0


def below_light(obj, path, name):
    """Refuse an initial velocity (vector) or speed whose magnitude is not below
    :data:`C_LIGHT`."""
    value = np.atleast_1d(np.asarray(getattr(obj, name), dtype=float))
    top = float(np.max(np.abs(value))) if np.all(np.isfinite(value)) else np.inf
    size = top * float(np.sqrt(np.sum((value / top) ** 2))) if 0.0 < top < np.inf else top
    if not size < C_LIGHT:
        fail(join(path, name), f"an initial speed of {size:.4g} m/s is not below the speed "
             f"of light ({C_LIGHT:.4g} m/s)")


@dataclass(frozen=True)
class Region:
    """Axis-aligned box region ``lo``..``hi`` (m), bounds inclusive."""
    lo: tuple[float, float, float]
    hi: tuple[float, float, float]

    def check(self, path):
        ordered_box(self, path, strict=False)

    @property
    def what(self) -> str:
        return f"the region {list(self.lo)}..{list(self.hi)} m"

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
        below_light(self, path, "velocity")

    region_key = ""

    @property
    def what(self) -> str:
        return (f"the pulse's slab |{self.axis} - {self.center:g}| < {self.half_width:g} m")

    def selects(self, x: np.ndarray) -> np.ndarray:
        return np.abs(x[:, AXES[self.axis]] - self.center) < self.half_width

    def apply(self, x: np.ndarray, v: np.ndarray) -> None:
        s = x[:, AXES[self.axis]] - self.center
        inside = self.selects(x)
        shape = np.cos(0.5 * np.pi * s[inside] / self.half_width) ** 2
        v[inside] += shape[:, None] * np.asarray(self.velocity)[None, :]


@INITIAL.register("uniform_velocity")
@dataclass(frozen=True)
class UniformVelocity:
    """v = ``velocity`` for every point inside ``region``."""
    region: Region
    velocity: tuple[float, float, float]

    region_key = "region"

    @property
    def what(self) -> str:
        return self.region.what

    def check(self, path):
        below_light(self, path, "velocity")

    def selects(self, x: np.ndarray) -> np.ndarray:
        return self.region.contains(x)

    def apply(self, x: np.ndarray, v: np.ndarray) -> None:
        v[self.selects(x)] += np.asarray(self.velocity)


@INITIAL.register("gaussian_velocity")
@dataclass(frozen=True)
class GaussianVelocity:
    """v = velocity * exp(-|x - center|^2 / (2 sigma^2)) at every point: a smooth
    3-D bump of peak ``velocity`` (m/s) and width ``sigma`` (m) about ``center`` (m)."""
    center: tuple[float, float, float]
    sigma: float
    velocity: tuple[float, float, float]

    def check(self, path):
        positive(self, path, "sigma")
        below_light(self, path, "velocity")

    def apply(self, x: np.ndarray, v: np.ndarray) -> None:
        s2 = np.sum((x - np.asarray(self.center)) ** 2, axis=1)
        v += np.exp(-0.5 * s2 / self.sigma ** 2)[:, None] * np.asarray(self.velocity)[None, :]


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
        below_light(self, path, "speed")

    region_key = ""

    @property
    def what(self) -> str:
        return (f"the ring {self.r_inner:g} <= r <= {self.r_outer:g} m about "
                f"({self.center[0]:g}, {self.center[1]:g})")

    def selects(self, x: np.ndarray) -> np.ndarray:
        r = np.hypot(x[:, 0] - self.center[0], x[:, 1] - self.center[1])
        return (r >= self.r_inner) & (r <= self.r_outer) & (r > 0)

    def apply(self, x: np.ndarray, v: np.ndarray) -> None:
        dx = x[:, 0] - self.center[0]
        dy = x[:, 1] - self.center[1]
        r = np.hypot(dx, dy)
        sel = self.selects(x)
        v[sel, 0] += self.speed * dx[sel] / r[sel]
        v[sel, 1] += self.speed * dy[sel] / r[sel]


@BOUNDARIES.register("fixed")
@dataclass(frozen=True)
class Fixed:
    """Points inside ``region`` are held at their reference position (u = v = 0)."""
    region: Region
    region_key = "region"

    @property
    def what(self) -> str:
        return self.region.what

    def mask(self, x: np.ndarray) -> np.ndarray:
        return self.region.contains(x)

    selects = mask


@BOUNDARIES.register("prescribed_velocity")
@dataclass(frozen=True)
class PrescribedVelocity:
    """Points inside ``region`` move with the prescribed ``velocity`` (m/s, a vector),
    whatever the forces on them: a struck edge, a moving grip.  With ``ramp`` > 0 (s)
    the velocity rises linearly from 0 at t = 0 to ``velocity`` at t = ramp (a ramp
    spreads the jump a sudden impact puts into the first steps over several); with
    ``ramp`` = 0 the points move at ``velocity`` from t = 0.  Their displacement
    advances with it every step (u += dt v(t + dt/2): exact for the linear ramp), and
    no force accelerates them (mpipd.model.drive).  The work the driven points do on
    the body (the power of the reaction force on them, integrated in time, plus their
    own kinetic energy's change) is the ledger's ``boundary``."""
    region: Region
    velocity: tuple[float, float, float]
    ramp: float = 0.0
    region_key = "region"

    def check(self, path):
        below_light(self, path, "velocity")
        non_negative(self, path, "ramp")

    @property
    def what(self) -> str:
        return self.region.what

    def mask(self, x: np.ndarray) -> np.ndarray:
        """The driven points: no force moves them (the solver's ``fixed`` flag); the
        drive (mpipd.model.drive) sets their velocity and displacement."""
        return self.region.contains(x)

    selects = mask

    def value(self, t: float) -> np.ndarray:
        """The prescribed velocity (m/s) at time t."""
        s = 1.0 if self.ramp <= 0.0 else min(max(t / self.ramp, 0.0), 1.0)
        return s * np.asarray(self.velocity, dtype=float)


#: a face of an axis-aligned boundary: (axis, outward sign)
FACES = {"-x": (0, -1.0), "+x": (0, 1.0), "-y": (1, -1.0), "+y": (1, 1.0),
         "-z": (2, -1.0), "+z": (2, 1.0)}


@BOUNDARIES.register("absorbing")
@dataclass(frozen=True)
class Absorbing:
    """A damping layer that lines the boundary ``face`` ("+y": the plane y = ``at``,
    the body on the y < at side) to ``thickness`` L inside it, so that a wave leaves
    through it as into an unbounded body instead of reflecting from a free face
    (Cerjan, Kosloff, Kosloff & Reshef 1985, Geophysics 50: 705-708, a graded damping
    taper).  A solid point at depth s into the layer (s = 0 at its inner edge, L at
    the face) is damped by the velocity-proportional force -rho c v (the damped update
    of kernels.integrate.kick_drift), with the quadratic profile

        c(s) = c_max (s / L)^2,    c_max = 3 c_p ln(1/R) / L.

    For frequencies well above c, a plane wave in a body damped by c decays as
    exp(-c x / (2 c_p)); across the layer and back from the face this is
    exp(-int_0^L c ds / c_p) = exp(-c_max L / (3 c_p)) = R, the design reflection
    ``reflection`` (c_p: each point's material).  Frequencies near c and below see
    the gradient and partly reflect: the layer's real reflection is measured
    (tests/test_absorbing.py).  The gas keeps its own damping.  The work the layer
    takes is the ledger's ``absorbed``."""
    face: str
    at: float
    thickness: float
    reflection: float = 0.1

    def check(self, path):
        if self.face not in FACES:
            fail(join(path, "face"), f"must be one of {', '.join(FACES)} (got {self.face!r})")
        positive(self, path, "thickness")
        if not 0.0 < self.reflection < 1.0:
            fail(join(path, "reflection"), f"must be in (0, 1) (got {self.reflection!r})")

    def c_max(self, c_p):
        """The damping coefficient (1/s) at the face for a material of P-wave speed c_p."""
        return 3.0 * c_p * np.log(1.0 / self.reflection) / self.thickness

    region_key = ""

    @property
    def what(self) -> str:
        return f"the layer {self.thickness:g} m inside {self.face} = {self.at:g} m"

    def mask(self, x: np.ndarray) -> np.ndarray:
        """No point is held fixed."""
        return np.zeros(len(x), dtype=bool)

    def selects(self, x: np.ndarray) -> np.ndarray:
        """The points the layer damps (c > 0)."""
        axis, sign = FACES[self.face]
        return self.thickness - sign * (self.at - x[:, axis]) > 0.0

    def damping(self, x: np.ndarray, c_p: np.ndarray) -> np.ndarray:
        """c (1/s) at points x of P-wave speed c_p: c_max (s/L)^2 inside the layer
        (s capped at L for points on or beyond the face), 0 elsewhere."""
        axis, sign = FACES[self.face]
        s = self.thickness - sign * (self.at - x[:, axis])
        frac = np.clip(s / self.thickness, 0.0, 1.0)
        return np.where(s > 0.0, self.c_max(c_p) * frac ** 2, 0.0)


def regions(scene) -> list[tuple[str, object]]:
    """(key, condition) of every initial and boundary condition that acts on a part of
    the body (those with ``selects(x)``: a region, a slab, a ring, a layer), each of
    which must hold a point (:func:`refuse_empty`; a gaussian_velocity acts everywhere)."""
    return [(join(f"{kind}.{i}", c.region_key) if c.region_key else f"{kind}.{i}", c)
            for kind, conds in (("initial", scene.initial), ("boundaries", scene.boundaries))
            for i, c in enumerate(conds) if hasattr(c, "selects")]


def refuse_empty(scene, counts) -> None:
    """Bad input (SceneError naming the first such condition's key): a condition of
    :func:`regions` that selects none of the body's points, given ``counts``, the points
    each selects over the whole model (mpipd.solver.Simulation counts them over the
    ranks, mpipd.check over the lattice: one rule)."""
    for (key, c), n in zip(regions(scene), counts):
        if n == 0:
            kind = getattr(c, "registry_name", type(c).__name__)
            fail(key, f"{c.what} holds no point of the body: this {kind!r} condition "
                      "would act on nothing")


@dataclass
class PreparedLoad:
    """A load bound to one rank's points: owned indices and force density per unit load."""
    load: object
    idx: np.ndarray          # owned points the load acts on
    g: np.ndarray            # (len(idx), 3) body force density per unit of load.value(t)


@LOADS.register("borehole_pressure")
@dataclass(frozen=True)
class BoreholePressure:
    """Pressure history p(t) on a borehole wall (axis along z through ``center``,
    wall radius ``radius``), applied as a radial body force on the wall's points —
    one of the simple blast loads of paper §3.1.

    History: ``p0``, ``alpha``, ``beta`` for the pulse p0 (e^-alpha t - e^-beta t), or
    ``times`` and ``pressures`` for a table (linear in between, the last value after).

    The wall's points are the first lattice layer, radius <= r < radius + dx.  The
    force on the wall per z level, p 2 pi radius dx, is shared equally by that
    level's layer points of each part, so the total force is exactly the pressure
    times the wall area.
    """
    center: tuple[float, float]
    radius: float
    p0: float | None = None
    alpha: float | None = None
    beta: float | None = None
    times: tuple[float, ...] | None = None
    pressures: tuple[float, ...] | None = None

    def check(self, path):
        positive(self, path, "radius")
        pulse = (self.p0, self.alpha, self.beta)
        table = (self.times, self.pressures)
        if all(v is not None for v in pulse) and all(v is None for v in table):
            non_negative(self, path, "alpha", "beta")
            if not self.beta > self.alpha:
                fail(join(path, "beta"), "must exceed alpha (p0 (e^-alpha t - e^-beta t) >= 0)")
        elif all(v is not None for v in table) and all(v is None for v in pulse):
            if len(self.times) != len(self.pressures) or len(self.times) < 2:
                fail(join(path, "times"), "times and pressures need the same length, >= 2")
            if any(b <= a for a, b in zip(self.times, self.times[1:])):
                fail(join(path, "times"), "must increase")
        else:
            fail(path, "give either p0, alpha, beta (pulse) or times, pressures (table)")

    def check_parts(self, parts, path):
        """The radius must be a wall: some part has a first layer there
        (radius <= r < radius + dx) and no points inside it (r < radius); every part
        is a prism along z (the load is a z borehole's, the same at every level)."""
        walls = 0
        for k, part in enumerate(parts):
            if not part.shape.prism:
                fail(path, f"a borehole pressure needs parts that are prisms along z; part "
                     f"{part.name!r} is not (parts.{k}.shape): a charge along another axis "
                     "is an explosive part (the gas)")
        for part in parts:
            sx, sy = part.shape.cross_section(part.dx)
            rr = np.hypot(sx - self.center[0], sy - self.center[1])
            layer = np.count_nonzero((rr >= self.radius) & (rr < self.radius + part.dx))
            inside = np.count_nonzero(rr < self.radius)
            if layer and inside:
                fail(join(path, "radius"), f"radius {self.radius:g} m lands inside part "
                     f"{part.name!r} ({inside} of its points a level lie at r < radius): "
                     "no borehole wall there")
            walls += layer
        if not walls:
            fail(join(path, "radius"), f"radius {self.radius:g} m about ({self.center[0]:g}, "
                 f"{self.center[1]:g}) m meets no part: no borehole wall to load")

    def value(self, t: float) -> float:
        if self.p0 is not None:
            return self.p0 * (np.exp(-self.alpha * t) - np.exp(-self.beta * t))
        return float(np.interp(t, self.times, self.pressures))

    def prepare(self, parts, points) -> PreparedLoad:
        n = points.n_owned
        x = points.x[:n]
        dxy = x[:, :2] - np.asarray(self.center)
        r = np.hypot(dxy[:, 0], dxy[:, 1])
        dx = points.dx[:n]
        layer = (r >= self.radius) & (r < self.radius + dx)
        # layer points per z level of each part, from the part's cross-section
        per_level = np.zeros(len(parts))
        for k, part in enumerate(parts):
            sx, sy = part.shape.cross_section(part.dx)
            rr = np.hypot(sx - self.center[0], sy - self.center[1])
            per_level[k] = np.count_nonzero((rr >= self.radius) & (rr < self.radius + part.dx))
        idx = np.flatnonzero(layer)
        share = 2.0 * np.pi * self.radius * dx[idx] / per_level[points.part[idx]]
        g = np.zeros((len(idx), 3))
        g[:, :2] = (share / points.volume[idx])[:, None] * dxy[idx] / r[idx, None]
        return PreparedLoad(self, idx, g)
