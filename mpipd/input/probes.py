"""Probes in a scene: ``[[probes]]``, the part a probe samples and the point it sits on.

A probe is named, at a ``position`` (m), with the ``center`` (x, y) of the axis its
radial quantities are taken about, and optionally a ``part``: a part name matches
the part and its zones ``<part>.band``, ``<part>.0``, ... of
:meth:`mpipd.input.scene.Part.zones` (:func:`part_matches`, the rule joints use
too), so ``part = "rock"`` samples the rock whatever its resolution bands.

Each probe is the lattice point nearest its position (lowest gid on a tie), among
the points of its part if it names one (:func:`nearest`).  A probe farther than
that point's horizon from it is refused as outside the body; one moved by more
than half the dx of the point's part, in 3-D distance from the requested
position, is a warning in the run log naming the probe, the requested and the
snapped positions and the distance (:func:`placed`): it samples the material
elsewhere than asked, e.g. blast_paper's P1, asked 0.8 mm from the wall, sits
0.42 mm from it, 0.57 mm from its position; paper Fig. 15.  ``mpipd check`` (on
the lattice, layer by layer) and ``mpipd run`` (:func:`place`, on the built points
of every rank) apply the same rules to the same points.  What a probe records:
mpipd.output.probes.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .schema import fail

#: a snap farther than this many dx of the point's part is a warning in the run log
SNAP_WARN = 0.5


@dataclass(frozen=True)
class Probe:
    """``name``, ``position`` (m), ``center`` (x, y) of the radial axis (default 0, 0),
    ``part``: the part whose points it may snap to (default: any point)."""
    name: str
    position: tuple[float, float, float]
    center: tuple[float, float] = (0.0, 0.0)
    part: str | None = None


def part_matches(part: str, name: str) -> bool:
    """Does the scene part (or zone) ``name`` belong to the probe's ``part``?"""
    return name == part or name.startswith(part + ".")


def snap_note(name, position, x, dist, dx) -> str:
    """The run log's warning for a probe moved more than ``SNAP_WARN`` dx by its snap."""
    def at(p):
        return "(" + ", ".join(f"{float(c) * 1e3:.4g}" for c in p) + ") mm"
    return (f"probe {name!r} moved {dist * 1e3:.3g} mm (more than dx/2 = {SNAP_WARN * dx * 1e3:.3g} "
            f"mm of its part) from the requested position {at(position)} to the nearest point "
            f"{at(x)}")


def nearest(pr, part_names, x, gid, part, material, dx, horizon) -> tuple:
    """The candidate point of probe ``pr`` among the points ``x`` (with their gid,
    part index, material id, dx and horizon): (distance, gid, x, part, material, dx,
    horizon) of the nearest point of its part (any point if it names none), or
    (inf, -1) if there is none.  The min of the candidates of every piece of the
    model is the probe's point (lowest gid on a tie).  The run (:func:`place`, on each
    rank's owned points) and mpipd.check (the lattice, layer by layer) both use it."""
    n = len(x)
    d = np.linalg.norm(x - np.asarray(pr.position), axis=1) if n else np.empty(0)
    if pr.part is not None and n:
        ok = np.array([part_matches(pr.part, q) for q in part_names], bool)
        d = np.where(ok[part], d, np.inf)
    if not n or not np.isfinite(d).any():
        return (math.inf, -1)
    j = int(np.argmin(d))          # the first minimum: the lowest gid of a piece in gid order
    return (float(d[j]), int(gid[j]), tuple(map(float, x[j])), int(part[j]),
            int(material[j]), float(dx[j]), float(horizon[j]))


def placed(k, pr, found) -> str | None:
    """Judge probe ``k``'s point ``found`` (the min of :func:`nearest` over the
    model): bad input (SceneError) if its part has no point or the point is farther
    than its horizon (outside the body); the run log's warning (:func:`snap_note`)
    if it moved more than SNAP_WARN dx; else None."""
    if not math.isfinite(found[0]):
        fail(f"probes.{k}.part", f"probe {pr.name!r}: no point of part {pr.part!r}")
    dist, _, xg, _, _, dxg, hg = found
    if dist > hg:
        fail(f"probes.{k}.position", f"probe {pr.name!r}: the nearest point"
             f"{' of part ' + repr(pr.part) if pr.part else ''} is {dist * 1e3:.3g} mm "
             f"away, beyond its horizon ({hg * 1e3:.3g} mm): outside the body?")
    if dist > SNAP_WARN * dxg:     # more than half a lattice spacing: say so
        return snap_note(pr.name, pr.position, xg, dist, dxg)
    return None


@dataclass
class Placement:
    """Where a scene's probes sit, by probe index: the chosen point's ``gid``, ``x``,
    ``dist`` (m, from the requested position), ``dx`` (m, of its part), ``part`` (the
    zone holding it) and ``material``; ``notes``: the run log's snap warnings."""
    gid: list
    x: list
    dist: list
    dx: list
    part: list
    material: list
    notes: list


def place(probes, scene, points, team) -> Placement:
    """The point of every probe of ``probes`` among the built ``points`` of every rank
    (:func:`nearest` on each rank's owned points, the min over ``team``'s ranks, judged
    by :func:`placed`; bad input raises SceneError on every rank).  Collective."""
    n = points.n_owned
    x = points.x[:n]
    gid = points.gid[:n]
    part = points.part[:n]
    mat = points.material[:n]
    parts = [q.name for q in scene.parts]
    materials = list(scene.materials)
    out = Placement([], [], [], [], [], [], [])
    for k, pr in enumerate(probes):
        best = nearest(pr, parts, x, gid, part, mat, points.dx[:n], points.horizon[:n])
        found = min(team.gather(best))
        note = placed(k, pr, found)
        if note:
            out.notes.append(note)
        dist, g, xg, pg, mg, dxg, hg = found
        out.gid.append(g)
        out.dx.append(dxg)
        out.x.append(xg)
        out.dist.append(dist)
        out.part.append(parts[pg])
        out.material.append(materials[mg])
    return out
