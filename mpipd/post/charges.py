"""Sections through the rock of any scene and the measures of each charge on them.

Sections.  :func:`rock_levels` names the rock's own z levels (the points of the rock
part and its zones: :mod:`mpipd.post.sections`): its lowest level ("bottom of the
rock"), the level nearest the middle of its thickness ("mid-height of the rock") and
its highest level ("top of the rock"), duplicates dropped.  Each section holds rock
points only, so a section never shows a charge or a tube instead of the rock.

Per charge (``model.charges``), on each section, over the rock points nearer its axis
than any other charge's (each point belongs to one charge):

* ``r_free``: the room around the charge, the distance from its axis to the nearest
  edge of the section's rock (its bounding box in x and y, half a spacing beyond the
  outermost points) or half the distance to the nearest other charge, whichever is
  less;
* the damaged extent: the largest distance from the axis of a failed point
  (:func:`mpipd.post.cracks.failed_points`), in mm and in hole radii beyond the wall;
* the crushed zone: :func:`mpipd.post.cracks.crushed_zone` from the hole's wall
  (the charge's radius) out to ``r_free``;
* the lattice bias: :func:`mpipd.post.lattice_bias.measure` in the ring of the middle
  third between the wall and ``r_free`` (the paper report's crack-density zone 2).
"""
from __future__ import annotations

import numpy as np

from . import cracks, lattice_bias
from . import sections as secs

NAMES = ("bottom of the rock", "mid-height of the rock", "top of the rock")


def rock_levels(run, model) -> dict[str, dict[int, float]]:
    """Section name -> {rock zone: z level} (collective; the same on every rank)."""
    levels = secs.zone_levels(run, model)
    ref = np.asarray(levels[model.rock])
    if not len(ref):
        return {}
    want = {NAMES[0]: float(ref.min()), NAMES[1]: 0.5 * float(ref.min() + ref.max()),
            NAMES[2]: float(ref.max())}
    out, seen = {}, set()
    for name in (NAMES[1], NAMES[0], NAMES[2]):
        z = secs.nearest(ref, want[name])
        if z in seen:
            continue
        seen.add(z)
        out[name] = {p: (z if p == model.rock else secs.nearest(lv, z))
                     for p, lv in levels.items() if len(lv)}
    return {n: out[n] for n in NAMES if n in out}


def owner(x, y, charges) -> np.ndarray:
    """Index of the charge whose axis is nearest each point (-1 without charges)."""
    if not charges:
        return np.full(len(x), -1)
    d = np.stack([np.hypot(x - c["center"][0], y - c["center"][1]) for c in charges])
    return np.argmin(d, axis=0)


def room(sec, charges, k) -> float:
    """``r_free`` of charge k on a section (module docstring)."""
    c = charges[k]
    h = float(np.max(sec["h"])) if len(sec["h"]) else 0.0
    x0, x1 = sec["x"].min() - 0.5 * h, sec["x"].max() + 0.5 * h
    y0, y1 = sec["y"].min() - 0.5 * h, sec["y"].max() + 0.5 * h
    cx, cy = c["center"]
    r = min(cx - x0, x1 - cx, cy - y0, y1 - cy)
    for j, o in enumerate(charges):
        if j != k:
            r = min(r, 0.5 * float(np.hypot(o["center"][0] - cx, o["center"][1] - cy)))
    return float(r)


def measure(sec, charges, frame, mode_frame=None) -> dict:
    """Per charge name, the measures of one gathered section at ``frame``."""
    failed, crit = cracks.failed_points(sec, frame)
    own = owner(sec["x"], sec["y"], charges)
    out = {}
    for k, c in enumerate(charges):
        m = own == k
        x, y, h, f = sec["x"][m], sec["y"][m], sec["h"][m], failed[m]
        r_hole, r_free = c["radius"], room(sec, charges, k)
        r = np.hypot(x - c["center"][0], y - c["center"][1])
        row = {"points": int(m.sum()), "failed_points": int(f.sum()), "r_free_mm": r_free * 1e3,
               "criterion": crit}
        if f.any():
            far = float(r[f].max())
            row["damaged_extent_mm"] = far * 1e3
            row["damaged_extent_hole_radii"] = (far - r_hole) / r_hole
        else:
            row["damaged_extent_mm"] = None
            row["damaged_extent_hole_radii"] = None
        if r_free > r_hole and m.any():
            mode = sec.get(("failure_mode", mode_frame if mode_frame is not None else frame))
            cz = cracks.crushed_zone(x, y, f, c["center"], h, r_hole, r_free,
                                     mode=None if mode is None else mode[m])
            row["crushed_zone"] = {"r_c_mm": cz["r_c_mm"], "extent_mm": cz["extent_mm"],
                                   "extent_hole_radii": cz["extent_borehole_radii"],
                                   "mode_share": cz.get("mode_share", {})}
            row["lattice_bias"] = lattice_bias.measure(x, y, f, c["center"], h, r_hole, r_free,
                                                       horizon=sec["link"][m])
        else:
            why = ("no room between the hole and the rock's edge" if m.any()
                   else "no rock point nearer this charge")
            row["crushed_zone"] = {"not_available": why}
            row["lattice_bias"] = {"not_available": why}
        out[c["name"]] = row
    return out
