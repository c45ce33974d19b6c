"""Lattice fill of the scene's shapes.

A part is filled with a simple cubic lattice of spacing ``dx``, aligned with
the axes: points at cell centres, so a part is the union of its points' cubes
and every point has volume ``dx**3``.  Most shapes are prisms along z (the
thickness axis, along which the model is decomposed into slabs): a box, a
cylinder, an annulus, each with the same cross-section at every z level.  A
``rod`` (a cylinder or tube between two end points, along any axis) and a box
with a hole along another axis are not (``prism = False``): their
cross-section changes with z, and each has ``section(dx, z)``.

The model is described completely by a table of *layers* — one per (part, z
level) — each knowing its point count without generating a single point.  The decomposition
(:mod:`mpipd.parallel.decomp`) balances ranks on that table, and each rank then
generates only the layers it owns or needs as ghosts.

Within a layer, points are ordered by (y, x); global ids run over layers in
(z, material, part) order, so gids follow (z, material, y, x).

Jitter.  A part with ``jitter = a`` (0 <= a < 1/2) moves each of its points off
its lattice site by a uniform offset in [-a dx, a dx] on each axis, drawn from
(``jitter_seed``, axis, gid) by mpipd.kernels.hashrng — the same on every rank
count.  A point whose moved position would leave its part (outside the
cross-section, or beyond the part's z range) stays on its site, so the part's
points stay inside it; volumes stay dx^3 and the point keeps its layer (its gid
and owner), so a point may sit up to a dx off its layer's z: the halo of
mpipd.parallel.decomp grows by twice the largest a dx to cover that.  Two
points are at least (1 - 2a) dx apart.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..kernels.hashrng import STREAM_JITTER, uniform
from .schema import Registry, fail, join, ordered_box, positive

SHAPES = Registry("shape", "kind")


def _cells(lo: float, hi: float, dx: float) -> np.ndarray:
    """Cell-centre coordinates filling [lo, hi] with spacing dx (n = round(L/dx)): none
    for L below dx/2 (a centre at lo + dx/2 would lie outside; mpipd.input.geometry.
    check_parts refuses the part, as it refuses a cylinder thinner than the lattice)."""
    n = int(round((hi - lo) / dx))
    return lo + (np.arange(n) + 0.5) * dx


def _centred(radius: float, dx: float) -> np.ndarray:
    """Offsets ±(k + 1/2) dx covering [-radius, radius], symmetric about 0."""
    n = int(np.ceil(radius / dx))
    k = np.arange(-n, n) + 0.5
    return k * dx


def _sorted_yx(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    order = np.lexsort((x, y))
    return x[order], y[order]


@dataclass(frozen=True)
class Hole:
    """A hole through a box, of ``radius`` (m): along z through the whole box about
    ``center`` (x, y), or along any axis from ``start`` to ``end`` (x, y, z), a
    drilled hole that may end inside the rock (a lattice point is removed where it
    lies within the radius of the segment's axis, between its two end planes)."""
    center: tuple[float, float] | None = None
    radius: float = 0.0
    start: tuple[float, float, float] | None = None
    end: tuple[float, float, float] | None = None

    def check(self, path):
        positive(self, path, "radius")
        if (self.center is None) == (self.start is None and self.end is None):
            fail(path, "give either center (a hole along z) or start and end (any axis)")
        if self.center is None:
            if self.start is None or self.end is None:
                fail(path, "a hole along an axis needs both start and end")
            if not np.linalg.norm(np.subtract(self.end, self.start)) > 0.0:
                fail(join(path, "end"), "must differ from start")

    @property
    def along_z(self) -> bool:
        return self.center is not None

    def segment(self) -> "Rod":
        """The hole's volume as a rod (an axis hole)."""
        return Rod(start=self.start, end=self.end, radius=self.radius)


@SHAPES.register("box")
@dataclass(frozen=True)
class Box:
    """Axis-aligned box ``lo``..``hi`` (m), optionally with ``holes`` along z through
    it (boreholes: a lattice point is kept where r >= radius from every hole's
    centre, the annulus's rule for its inner radius)."""
    lo: tuple[float, float, float]
    hi: tuple[float, float, float]
    holes: tuple[Hole, ...] = ()

    @property
    def prism(self) -> bool:
        return all(h.along_z for h in self.holes)

    def check(self, path):
        ordered_box(self, path, strict=True)
        for i, h in enumerate(self.holes):
            if not h.along_z:
                continue
            c, r = h.center, h.radius
            if not (self.lo[0] < c[0] - r and c[0] + r < self.hi[0]
                    and self.lo[1] < c[1] - r and c[1] + r < self.hi[1]):
                fail(join(join(path, "holes"), i), "a hole must lie inside the box's x-y "
                                                   "section (a free face needs rock in front)")

    def _outside_holes(self, x, y, margin):
        keep = np.ones(np.shape(x), bool)
        for h in self.holes:
            if h.along_z:
                keep &= np.hypot(x - h.center[0], y - h.center[1]) > h.radius + margin
        return keep

    def _axis_holes(self):
        return [h.segment() for h in self.holes if not h.along_z]

    def z_levels(self, dx):
        return _cells(self.lo[2], self.hi[2], dx)

    @property
    def z_range(self):
        return self.lo[2], self.hi[2]

    @property
    def area(self):
        return ((self.hi[0] - self.lo[0]) * (self.hi[1] - self.lo[1])
                - sum(np.pi * h.radius ** 2 for h in self.holes if h.along_z))

    def contains_xy(self, x, y, margin):
        """Inside the x-y section, ignoring the holes along other axes."""
        return ((x > self.lo[0] + margin) & (x < self.hi[0] - margin)
                & (y > self.lo[1] + margin) & (y < self.hi[1] - margin)
                & self._outside_holes(x, y, margin))

    def contains(self, x, y, z, margin):
        keep = (self.contains_xy(x, y, margin)
                & (z > self.lo[2] + margin) & (z < self.hi[2] - margin))
        for rod in self._axis_holes():
            keep &= ~rod.contains(x, y, z, -margin)
        return keep

    def near_other_axis(self, x, y, z, reach):
        """Within ``reach`` of a hole along another axis (where the box is no prism)."""
        out = np.zeros(np.shape(x), bool)
        for rod in self._axis_holes():
            out |= rod.contains(x, y, z, -reach)
        return out

    def section(self, dx, z):
        """The lattice points of level ``z``, (y, x) order, without the axis holes'."""
        x, y = self.cross_section(dx)
        for rod in self._axis_holes():
            keep = ~rod.covers(x, y, np.full(len(x), z))
            x, y = x[keep], y[keep]
        return x, y

    def cross_section(self, dx):
        xs = _cells(self.lo[0], self.hi[0], dx)
        ys = _cells(self.lo[1], self.hi[1], dx)
        X, Y = np.meshgrid(xs, ys, indexing="xy")    # rows = y, so ravel is (y, x) order
        X, Y = X.ravel(), Y.ravel()
        keep = np.ones(len(X), bool)
        for h in self.holes:
            if h.along_z:
                keep &= (X - h.center[0]) ** 2 + (Y - h.center[1]) ** 2 >= h.radius ** 2
        return X[keep], Y[keep]


@SHAPES.register("cylinder")
@dataclass(frozen=True)
class Cylinder:
    """Solid cylinder with axis along z: ``center`` (x, y), ``radius``, ``z`` = (z0, z1)."""
    center: tuple[float, float]
    radius: float
    z: tuple[float, float]
    prism = True

    def check(self, path):
        positive(self, path, "radius")
        if not self.z[1] > self.z[0]:
            fail(join(path, "z"), "z[1] must exceed z[0]")

    def contains(self, x, y, z, margin):
        return (self.contains_xy(x, y, margin)
                & (z > self.z[0] + margin) & (z < self.z[1] - margin))

    def section(self, dx, z):
        return self.cross_section(dx)

    def z_levels(self, dx):
        return _cells(self.z[0], self.z[1], dx)

    @property
    def z_range(self):
        return self.z

    @property
    def area(self):
        return np.pi * self.radius ** 2

    def _r(self, x, y):
        return np.hypot(x - self.center[0], y - self.center[1])

    def contains_xy(self, x, y, margin):
        return self._r(x, y) < self.radius - margin

    def _ring(self, dx, r_in, r_out):
        o = _centred(r_out, dx)
        X, Y = np.meshgrid(o, o, indexing="xy")
        r2 = X * X + Y * Y
        keep = (r2 <= r_out * r_out) & (r2 >= r_in * r_in)
        return _sorted_yx(X[keep] + self.center[0], Y[keep] + self.center[1])

    def cross_section(self, dx):
        return self._ring(dx, 0.0, self.radius)


@SHAPES.register("annulus")
@dataclass(frozen=True)
class Annulus(Cylinder):
    """Hollow cylinder along z: ``center``, ``inner_radius`` < ``radius``, ``z``."""
    inner_radius: float

    def check(self, path):
        super().check(path)
        positive(self, path, "inner_radius")
        if not self.inner_radius < self.radius:
            fail(join(path, "inner_radius"), "must be smaller than radius")

    @property
    def area(self):
        return np.pi * (self.radius ** 2 - self.inner_radius ** 2)

    def contains_xy(self, x, y, margin):
        r = self._r(x, y)
        return (r > self.inner_radius + margin) & (r < self.radius - margin)

    def cross_section(self, dx):
        return self._ring(dx, self.inner_radius, self.radius)


@SHAPES.register("rod")
@dataclass(frozen=True)
class Rod:
    """A cylinder along any axis, from ``start`` to ``end`` (x, y, z: points on its
    axis, m), of ``radius``; a tube if ``inner_radius`` > 0.  A charge or a tube
    lying across the slabs (a horizontal hole), or tilted.

    Lattice: the sites ``start + (i + 1/2, j + 1/2, k + 1/2) dx`` (integers i, j,
    k) whose axial coordinate s = (p - start).a lies in [0, L] and whose distance
    from the axis d = |p - start - s a| lies in [inner_radius, radius] (a the unit
    axis, L the length).  Along an axis of the lattice this is the
    :class:`Cylinder`'s lattice turned onto that axis, point for point: the
    cylinder's sites are centre +- (k + 1/2) dx across and z0 + (k + 1/2) dx
    along, and the same inequalities on the same offsets select them."""
    start: tuple[float, float, float]
    end: tuple[float, float, float]
    radius: float
    inner_radius: float = 0.0
    prism = False

    def check(self, path):
        positive(self, path, "radius")
        if not 0.0 <= self.inner_radius < self.radius:
            fail(join(path, "inner_radius"), "must be in [0, radius)")
        if not self.length > 0.0:
            fail(join(path, "end"), "must differ from start")

    @property
    def length(self) -> float:
        return float(np.linalg.norm(np.subtract(self.end, self.start)))

    @property
    def axis(self) -> np.ndarray:
        return np.subtract(self.end, self.start) / self.length

    def _bounds(self):
        """The axis-aligned box holding the rod (lo, hi), each (3,)."""
        a, s0, s1 = self.axis, np.asarray(self.start, float), np.asarray(self.end, float)
        half = self.radius * np.sqrt(np.clip(1.0 - a * a, 0.0, 1.0))
        return np.minimum(s0, s1) - half, np.maximum(s0, s1) + half

    def _split(self, ox, oy, oz):
        """Axial coordinate s and squared distance from the axis d2 of the offsets
        (ox, oy, oz) from ``start``."""
        a = self.axis
        s = ox * a[0] + oy * a[1] + oz * a[2]
        px, py, pz = ox - s * a[0], oy - s * a[1], oz - s * a[2]
        return s, px * px + py * py + pz * pz

    def _closed(self, s, d2):
        """The lattice rule (class docstring): the closed solid, from _split."""
        return ((s >= 0.0) & (s <= self.length) & (d2 <= self.radius ** 2)
                & (d2 >= self.inner_radius ** 2))

    def contains(self, x, y, z, margin):
        """Inside, ``margin`` from the surface (outward for a negative margin)."""
        s, d2 = self._split(x - self.start[0], y - self.start[1], z - self.start[2])
        r = self.radius - margin
        ok = (s > margin) & (s < self.length - margin) & (d2 < r * r) & (r > 0.0)
        if self.inner_radius > 0.0:                 # margin may be an array (a reach per point)
            ri = self.inner_radius + margin
            ok &= (ri <= 0.0) | (d2 > ri * ri)
        return ok

    def covers(self, x, y, z):
        """The lattice rule (class docstring), at any points: the closed solid."""
        return self._closed(*self._split(x - self.start[0], y - self.start[1], z - self.start[2]))

    def _offsets(self, lo, hi, k, dx):
        """Site offsets (i + 1/2) dx from start along axis k within [lo, hi]."""
        i0 = int(np.floor((lo[k] - self.start[k]) / dx - 0.5)) - 1
        i1 = int(np.ceil((hi[k] - self.start[k]) / dx - 0.5)) + 1
        return (np.arange(i0, i1 + 1) + 0.5) * dx

    def _level_offset(self, dx, z):
        """The offset (k + 1/2) dx from start of the level nearest ``z``."""
        return (np.round((z - self.start[2]) / dx - 0.5) + 0.5) * dx

    def section(self, dx, z):
        lo, hi = self._bounds()
        ox, oy = self._offsets(lo, hi, 0, dx), self._offsets(lo, hi, 1, dx)
        X, Y = np.meshgrid(ox, oy, indexing="xy")      # rows = y: ravel is (y, x) order
        X, Y = X.ravel(), Y.ravel()
        keep = self._closed(*self._split(X, Y, self._level_offset(dx, z)))
        return X[keep] + self.start[0], Y[keep] + self.start[1]

    def z_levels(self, dx):
        lo, hi = self._bounds()
        z = self._offsets(lo, hi, 2, dx) + self.start[2]
        return np.array([v for v in z if len(self.section(dx, v)[0])])

    @property
    def z_range(self):
        lo, hi = self._bounds()
        return float(lo[2]), float(hi[2])

    @property
    def area(self):
        """An upper bound of a level's section area (the bounding box's x-y face)."""
        lo, hi = self._bounds()
        return float((hi[0] - lo[0]) * (hi[1] - lo[1]))

    def near_other_axis(self, x, y, z, reach):
        return self.contains(x, y, z, -reach)


@dataclass(frozen=True)
class LayerTable:
    """All layers of the model in global (z, material, part) order.

    Arrays are indexed by layer: ``z``, ``part``, ``count`` and ``start`` (the
    gid of the layer's first point).  ``n_points`` is the model's total.
    """
    z: np.ndarray
    part: np.ndarray
    count: np.ndarray
    start: np.ndarray

    @property
    def n_points(self) -> int:
        return int(self.start[-1] + self.count[-1]) if len(self.count) else 0

    @classmethod
    def from_parts(cls, parts, material_ids) -> "LayerTable":
        """The layer table; refuses parts that are empty, absurdly large or overlapping."""
        check_parts(parts)
        zs, ps, ms, cs = [], [], [], []
        for p, part in enumerate(parts):
            z = part.shape.z_levels(part.dx)
            if part.shape.prism:
                n = np.full(len(z), len(part.shape.cross_section(part.dx)[0]))
            else:
                n = np.array([len(part.shape.section(part.dx, v)[0]) for v in z], np.int64)
            zs.append(z)
            ps.append(np.full(len(z), p))
            ms.append(np.full(len(z), material_ids[part.material]))
            cs.append(n)
        z, part, mat, count = (np.concatenate(a) for a in (zs, ps, ms, cs))
        order = np.lexsort((part, mat, z))
        count = count[order].astype(np.int64)
        start = np.concatenate(([0], np.cumsum(count)[:-1])).astype(np.int64)
        return cls(z=z[order], part=part[order], count=count, start=start)


#: most lattice points one cross-section may have (a layer is generated whole)
MAX_SECTION_POINTS = 50_000_000


def part_points(part) -> np.ndarray:
    """Every lattice site of a part, (n, 3) (no jitter)."""
    if part.shape.prism:
        x, y = part.shape.cross_section(part.dx)
        z = part.shape.z_levels(part.dx)
        return np.column_stack((np.tile(x, len(z)), np.tile(y, len(z)), np.repeat(z, len(x))))
    out = [np.column_stack((x, y, np.full(len(x), z)))
           for z in part.shape.z_levels(part.dx)
           for x, y in [part.shape.section(part.dx, z)]]
    return np.concatenate(out) if out else np.empty((0, 3))


def check_parts(parts) -> None:
    """Each part yields points, no section is absurdly large, no two parts overlap
    (a point of one inside another by more than a quarter of the finer dx)."""
    sections = []
    for k, part in enumerate(parts):
        est = part.shape.area / part.dx ** 2
        if est > MAX_SECTION_POINTS:
            fail(f"parts.{k}.dx", f"gives ~{est:.3g} points per z level "
                                   f"(at most {MAX_SECTION_POINTS:.0e}); dx is too small")
        pts = (part.shape.cross_section(part.dx) if part.shape.prism
               else part_points(part))
        n = len(pts[0]) if part.shape.prism else len(pts)
        if n == 0 or len(part.shape.z_levels(part.dx)) == 0:
            fail(f"parts.{k}.shape", f"part {part.name!r} holds no lattice point at "
                                      f"dx = {part.dx} (shape smaller than the lattice)")
        sections.append(pts)
    for a in range(len(parts)):
        for b in range(len(parts)):
            if a == b:
                continue
            za, zb = parts[a].shape.z_range, parts[b].shape.z_range
            margin = 0.25 * min(parts[a].dx, parts[b].dx)
            if max(za[0], zb[0]) >= min(za[1], zb[1]) - margin:
                continue
            if parts[a].shape.prism and parts[b].shape.prism:
                x, y = sections[a]
                hit = np.any(parts[b].shape.contains_xy(x, y, margin))
            else:
                pts = sections[a] if not parts[a].shape.prism else part_points(parts[a])
                hit = np.any(parts[b].shape.contains(pts[:, 0], pts[:, 1], pts[:, 2], margin))
            if hit:
                fail(f"parts.{a}", f"part {parts[a].name!r} overlaps part {parts[b].name!r}")


def fill_layers(parts, table: LayerTable, layers: np.ndarray):
    """Generate the points of the given layers (in the given order).

    Returns ``x`` (n, 3) reference positions, ``part`` (n,) part index and
    ``gid`` (n,) global ids.
    """
    sections = {}
    xs, ps, gs = [], [], []
    for L in layers:
        p = int(table.part[L])
        shape = parts[p].shape
        key = p if shape.prism else (p, int(L))
        if key not in sections:
            sections[key] = (shape.cross_section(parts[p].dx) if shape.prism
                             else shape.section(parts[p].dx, table.z[L]))
        sx, sy = sections[key]
        n = len(sx)
        x = np.empty((n, 3))
        x[:, 0] = sx
        x[:, 1] = sy
        x[:, 2] = table.z[L]
        gid = table.start[L] + np.arange(n, dtype=np.int64)
        if parts[p].jitter > 0.0:
            x = jittered(parts[p], x, gid)
        xs.append(x)
        ps.append(np.full(n, p, dtype=np.int32))
        gs.append(gid)
    if not xs:
        return np.empty((0, 3)), np.empty(0, np.int32), np.empty(0, np.int64)
    return np.concatenate(xs), np.concatenate(ps), np.concatenate(gs)


def jittered(part, x: np.ndarray, gid: np.ndarray) -> np.ndarray:
    """The part's points ``x`` (lattice sites, global ids ``gid``) moved by its jitter
    (module docstring); points whose move would leave the part stay on their sites."""
    a = part.jitter * part.dx
    off = np.stack([a * (2.0 * uniform(part.jitter_seed, STREAM_JITTER + k, gid) - 1.0)
                    for k in range(3)], axis=1)
    y = x + off
    keep = part.shape.contains(y[:, 0], y[:, 1], y[:, 2], 0.0)
    return np.where(keep[:, None], y, x)


def _sphere_directions(n: int) -> np.ndarray:
    """n nearly uniform unit vectors (Fibonacci sphere)."""
    k = np.arange(n) + 0.5
    z = 1.0 - 2.0 * k / n
    phi = np.pi * (1.0 + 5 ** 0.5) * k
    s = np.sqrt(1.0 - z * z)
    return np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=1)


def balls_inside(parts, x: np.ndarray, radius: np.ndarray, n_dir: int = 96,
                 shells=(0.25, 0.5, 0.75, 1.0)) -> np.ndarray:
    """True where the ball of ``radius`` around ``x`` lies inside the union of
    ``parts`` (a point set at the centre, on shells of the given fractions of
    the radius, n_dir directions each, must all lie in some part).  The parts'
    shared faces count as inside: a sample on a face between two parts is
    tested with a margin of -1e-9 dx."""
    inside = np.ones(len(x), dtype=bool)
    if not len(x):
        return inside
    d = _sphere_directions(n_dir)
    tol = 1e-9 * min(p.dx for p in parts)
    for f in shells:
        for u in d:
            y = x + (f * radius)[:, None] * u
            ok = np.zeros(len(x), dtype=bool)
            for p in parts:
                ok |= p.shape.contains(y[:, 0], y[:, 1], y[:, 2], -tol)
            inside &= ok
    return inside


def z_faces(part) -> tuple[float, float]:
    """The z faces of a part's lattice (its first and last level -/+ dx/2), which
    may differ from the shape's ``z`` when the thickness is not a multiple of dx."""
    z = part.shape.z_levels(part.dx)
    return float(z[0] - 0.5 * part.dx), float(z[-1] + 0.5 * part.dx)


def prisms_inside(parts, x: np.ndarray, radius: np.ndarray, n_dir: int = 64,
                  rings=(0.0, 0.25, 0.5, 0.75, 1.0)) -> np.ndarray:
    """True where, within ``radius`` of ``x``, the union of ``parts`` is a prism
    along z cut by flat z faces: the disk of that radius in the x-y plane lies
    inside the cross-sections of the parts at x's level, and every part reaching
    into the ball ends at the same lattice z faces there (clipped to the ball).

    There the body near x is its cross-section extruded, so a single-resolution
    lattice is mirror-symmetric in x and y about x — the test of
    :class:`mpipd.model.interface.InterfaceCorrection` for keeping only a z face's
    traction.  Disk samples: the centre and ``n_dir`` directions on each ring.
    Within ``radius`` of a part that is no prism (a rod, a hole along another
    axis) the body is no prism: False there."""
    out = np.ones(len(x), dtype=bool)
    if not len(x):
        return out
    for p in parts:
        if not p.shape.prism:
            out &= ~p.shape.near_other_axis(x[:, 0], x[:, 1], x[:, 2], radius)
    parts = [p for p in parts if hasattr(p.shape, "contains_xy")]
    tol = 1e-9 * min(p.dx for p in parts)
    ang = 2.0 * np.pi * (np.arange(n_dir) + 0.5) / n_dir
    dirs = np.stack([np.cos(ang), np.sin(ang)], axis=1)
    samples = [(x[:, 0], x[:, 1])] + [(x[:, 0] + f * radius * c, x[:, 1] + f * radius * s)
                                      for f in rings if f > 0 for c, s in dirs]
    zlo, zhi = x[:, 2] - radius, x[:, 2] + radius
    faces = [z_faces(p) for p in parts]
    covers = [(x[:, 2] > a - tol) & (x[:, 2] < b + tol) for a, b in faces]
    near = [np.zeros(len(x), dtype=bool) for _ in parts]
    for sx, sy in samples:
        ok = np.zeros(len(x), dtype=bool)
        for k, p in enumerate(parts):
            hit = p.shape.contains_xy(sx, sy, -tol)
            ok |= covers[k] & hit
            near[k] |= hit
        out &= ok
    # every part met within the ball ends at the same (clipped) z faces
    lo_min = np.full(len(x), np.inf)
    lo_max = np.full(len(x), -np.inf)
    hi_min, hi_max = lo_min.copy(), lo_max.copy()
    for k, (a, b) in enumerate(faces):
        m = near[k] & (a < zhi) & (b > zlo)
        lo = np.maximum(a, zlo)
        hi = np.minimum(b, zhi)
        lo_min[m] = np.minimum(lo_min[m], lo[m])
        lo_max[m] = np.maximum(lo_max[m], lo[m])
        hi_min[m] = np.minimum(hi_min[m], hi[m])
        hi_max[m] = np.maximum(hi_max[m], hi[m])
    return out & (lo_max - lo_min < tol) & (hi_max - hi_min < tol)
