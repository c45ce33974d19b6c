"""Pre-existing joints and flaws: ``[[joints]]`` in a scene.

A joint is a plane through ``point`` with unit ``normal`` (any length; it is
normalised); ``radius`` bounds it to a disc (a penny-shaped flaw), ``spacing``
makes it a set of parallel joints at every multiple of the spacing along the
normal (a joint family).  ``box`` (``{ lo, hi }``, m) bounds it to the part of its plane inside an
axis-aligned box (a notch cut in from an edge: the plane x = 0.025 inside the
box 0 <= y <= 0.05 is a 50 mm deep cut of zero width).  ``persistence`` (0, 1] is the open fraction of each
joint's area, in square patches of side ``patch`` drawn open or closed from
``seed`` (rock bridges between them).  ``parts`` names the parts it cuts (a
graded part's rings by its name); empty: every solid part.

Every bond whose reference segment crosses an open part of a joint starts
broken (CabanaPD's pre-notch; the bond exists and is broken, so the damage
index shows the joint from t = 0 and the shape tensor K is built without it,
the same bonds as F — mpipd.kernels.nosb).  Contact (Eq. 40) acts between the
two sides through those broken bonds, so a scene with joints needs
``solver.contact = true``; without it the faces would pass through each other.
The crossing test is mpipd.kernels.joints.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..kernels.hashrng import STREAM_JOINT
from ..kernels.joints import cut_bonds
from .loads import Region
from .probes import part_matches
from .schema import fail, join, non_negative


@dataclass(frozen=True)
class Joint:
    point: tuple[float, float, float]
    normal: tuple[float, float, float]
    radius: float = 0.0                 # 0: an unbounded plane
    spacing: float = 0.0                # 0: one joint; > 0: a set at every multiple
    persistence: float = 1.0
    patch: float = 0.0                  # patch side (m); needed when persistence < 1
    seed: int = 1
    parts: tuple[str, ...] = ()
    box: Region | None = None           # None: not bounded by a box

    def check(self, path):
        if not math.hypot(*self.normal) > 0.0:
            fail(join(path, "normal"), f"must be a non-zero vector (got {list(self.normal)})")
        non_negative(self, path, "radius", "spacing", "seed", "patch")
        if not 0.0 < self.persistence <= 1.0:
            fail(join(path, "persistence"), f"must be in (0, 1] (got {self.persistence})")
        if self.persistence < 1.0 and not self.patch > 0.0:
            fail(join(path, "patch"), "a persistence below 1 needs the patch size (m) "
                                      "of the open and closed areas")

    def check_parts(self, parts, path):
        names = [q.name for q in parts]
        for i, want in enumerate(self.parts):
            if not any(part_matches(want, q) for q in names):
                fail(join(join(path, "parts"), i), f"no part {want!r} (parts: {', '.join(names)})")

    def frame(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The unit normal and two in-plane unit vectors (e1, e2): e1 is the normal
        crossed with the coordinate axis it is least aligned with."""
        n = np.asarray(self.normal, float) / math.hypot(*self.normal)
        axis = np.eye(3)[int(np.argmin(np.abs(n)))]
        e1 = np.cross(n, axis)
        e1 /= np.linalg.norm(e1)
        return n, e1, np.cross(n, e1)

    def cut(self, k: int, parts, points, families, solid) -> int:
        """Break the bonds of the owned points' families that cross this joint (the
        scene's ``k``-th); ``solid``: a bool per local point (not the gas).  Returns
        the number of bonds cut here (directed: each bond is in both its ends' families)."""
        names = [q.name for q in parts]
        if self.parts:
            mine = np.array([any(part_matches(w, nm) for w in self.parts) for nm in names])
            cuts = mine[points.part] & solid
        else:
            cuts = np.asarray(solid, bool)
        n, e1, e2 = self.frame()
        lo, hi = ((np.asarray(self.box.lo, float), np.asarray(self.box.hi, float))
                  if self.box is not None else (np.full(3, -np.inf), np.full(3, np.inf)))
        return int(cut_bonds(points.x, points.gid, cuts, families.offsets, families.nbr,
                             families.broken, np.asarray(self.point, float), n, e1, e2,
                             float(self.spacing), float(self.radius), float(self.persistence),
                             float(self.patch), int(self.seed), STREAM_JOINT + k, lo, hi))


def cut_joints(joints, parts, points, families, solid) -> int:
    """Every joint of the scene applied to the families; bonds cut here (directed)."""
    return sum(j.cut(k, parts, points, families, solid) for k, j in enumerate(joints))
