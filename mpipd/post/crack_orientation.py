"""Crack orientation on one section: radial against circumferential (ring) cracks.

The paper reports cracks in both directions: "minor cracks are developed in both
the radial and the circumferential directions" (§3.2, Figs. 9, 13), and for
Table 3's case 5 "some small ring cracks (spalling)" (§3.5, Fig. 22e).  The crack
density of Fig. 12 counts failed points whatever their direction, and the major
radial cracks (:func:`mpipd.post.cracks.radial_cracks`) count only what reaches
the boundary from zone 1; this module measures the direction of the rest.

Local direction.  A crack on a section is a chain of failed points
(:func:`mpipd.post.cracks.failed_points`) one or two spacings wide.  For each
failed point i, the failed points within the horizon delta_i (Euclidean, i
included) are its neighbourhood; with C_i their covariance about their centroid,

    C_i = (1/n) sum_j (x_j - xbar)(x_j - xbar)^T,   eigenvalues l1 >= l2 >= 0,

the crack runs along the eigenvector t_i of l1 where the neighbourhood is a line:
l2 <= LINEAR * l1 (a chain two points wide and seven long has l2/l1 ~ 0.06; a
full disc of failed points 1).  A point with fewer than MIN_NEIGHBOURS failed
points within its horizon, itself included, is *isolated*; one whose
neighbourhood is not a line (a junction, the crushed zone, a band wider than
about three points) is *unresolved*.  The others are classed by the angle psi
between t_i and the radial direction e_r = (x_i - c)/|x_i - c|:

    radial           psi <  30 deg
    oblique     30 <= psi <= 60 deg
    circumferential  psi >  60 deg

so that failure whose direction is random gives each class a third of the
classified points (psi uniform on [0, 90 deg]).

Per crack-density zone (:func:`mpipd.post.cracks.zone_edges`), each class's
count and its crack length (each point stands for its own dx, as in Fig. 12: a
crack two points wide counts twice, as in the crack density), and the
circumferential crack density: circumferential length / ring area (mm/mm^2, the
same area as Fig. 12's).

Ring arcs.  The circumferential points joined within the larger of their
horizons (max-norm, as the radial cracks' chains) form arcs.  An arc's length is
geometric, its mean radius times the angle it covers (:func:`arc_span`), so a
crack two points wide is not counted twice; it counts when that length is at
least RING_MIN_HORIZONS horizons: longer than any single neighbourhood.  Their
count, radii (mean r) and lengths are reported.  A radial crack that crosses a
ring makes the points about the crossing unresolved (not a line), so a ring
crossed by k radial cracks is k arcs: the count is of arcs, the length is the
measure of how much ring cracking there is.

Failed rings.  A ring crack wider than about three points (a spall band) is
unresolved by the local direction, and is found by the failed fraction in rings
of width dx from the wall (:func:`mpipd.post.cracks.ring_index`, as the crushed
zone's): beyond the crushed zone and the qualifying rings joined to it, each
unbroken run of rings in which at least RING_FRACTION = 1/2 of the points have
failed, and fewer than half of those are radial, is a failed ring: more than half
its circumference cracked at that radius, and not by radial cracks, whose share of
a ring is n w / (2 pi r) (n cracks of width w: 0.1-0.3 at the paper's geometry,
but 1/2 at r = n w / pi close to the bore).  A ring one point wide can fall
across two of the profile's rings at about 1/2 each; the ring arcs find it.
"""
from __future__ import annotations

import numpy as np

from . import cracks

LINEAR = 0.25               # l2 / l1 at most this: the neighbourhood is a line
MIN_NEIGHBOURS = 4          # failed points within the horizon, the point included
RADIAL_DEG = 30.0
CIRCUMFERENTIAL_DEG = 60.0
RING_MIN_HORIZONS = 2.0
RING_FRACTION = 0.5         # failed share of a ring of width dx for a failed ring
CLASSES = ("radial", "oblique", "circumferential", "unresolved", "isolated")


def local_directions(x, y, failed, horizon) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per failed point (in the order of ``np.flatnonzero(failed)``): the unit
    direction t (2 columns), l2/l1 and the neighbour count (module docstring)."""
    from scipy.spatial import cKDTree
    idx = np.flatnonzero(failed)
    pts = np.column_stack([x[idx], y[idx]])
    h = horizon[idx]
    tree = cKDTree(pts)
    d = tree.sparse_distance_matrix(tree, float(h.max()) * (1 + 1e-9), output_type="ndarray")
    keep = (d["v"] <= h[d["i"]] * (1 + 1e-9)) & (d["i"] != d["j"])
    i, j = d["i"][keep], d["j"][keep]
    i, j = np.concatenate([i, np.arange(len(idx))]), np.concatenate([j, np.arange(len(idx))])
    n = np.bincount(i, minlength=len(idx)).astype(float)
    m = [np.bincount(i, weights=w, minlength=len(idx)) / n
         for w in (pts[j, 0], pts[j, 1])]
    dxj, dyj = pts[j, 0] - m[0][i], pts[j, 1] - m[1][i]
    cxx, cyy, cxy = (np.bincount(i, weights=w, minlength=len(idx)) / n
                     for w in (dxj * dxj, dyj * dyj, dxj * dyj))
    half, diff = 0.5 * (cxx + cyy), np.hypot(0.5 * (cxx - cyy), cxy)
    l1, l2 = half + diff, np.maximum(half - diff, 0.0)
    phi = 0.5 * np.arctan2(2.0 * cxy, cxx - cyy)         # direction of l1
    t = np.column_stack([np.cos(phi), np.sin(phi)])
    ratio = np.where(l1 > 0, l2 / np.where(l1 > 0, l1, 1.0), 1.0)
    return t, ratio, n.astype(np.int64)


def classify(x, y, failed, center, horizon) -> np.ndarray:
    """Class index into CLASSES per point (-1 for a point that has not failed)."""
    x, y, failed = np.asarray(x, float), np.asarray(y, float), np.asarray(failed, bool)
    h = cracks.per_point(horizon, x)
    out = np.full(len(x), -1, dtype=np.int64)
    idx = np.flatnonzero(failed)
    if len(idx) == 0:
        return out
    t, ratio, count = local_directions(x, y, failed, h)
    er = np.column_stack([x[idx] - center[0], y[idx] - center[1]])
    er /= np.maximum(np.linalg.norm(er, axis=1), 1e-300)[:, None]
    psi = np.degrees(np.arccos(np.clip(np.abs((t * er).sum(axis=1)), 0.0, 1.0)))
    cls = np.where(psi < RADIAL_DEG, 0, np.where(psi > CIRCUMFERENTIAL_DEG, 2, 1))
    cls = np.where(ratio > LINEAR, 3, cls)
    cls = np.where(count < MIN_NEIGHBOURS, 4, cls)
    out[idx] = cls
    return out


def arc_span(theta: np.ndarray) -> float:
    """Angle (rad) an arc's points cover: 2 pi less the largest gap between neighbours
    in angle (the gap across +-pi included), 0 for one point."""
    if len(theta) < 2:
        return 0.0
    t = np.sort(theta)
    gaps = np.append(np.diff(t), t[0] + 2.0 * np.pi - t[-1])
    return float(2.0 * np.pi - gaps.max())


def ring_arcs(x, y, circ, center, dx, horizon) -> list[dict]:
    """Arcs of circumferential points whose length (mean radius x angular span) is at
    least RING_MIN_HORIZONS horizons."""
    if not np.any(circ):
        return []
    lab = cracks._cracks(x, y, circ, horizon)
    r = np.hypot(x - center[0], y - center[1])
    th = np.arctan2(y - center[1], x - center[0])
    out = []
    for k in range(1, int(lab.max()) + 1):
        m = lab == k
        length = float(r[m].mean()) * arc_span(th[m])
        if length >= RING_MIN_HORIZONS * float(horizon[m].max()):
            out.append({"r_mm": float(r[m].mean()) * 1e3, "length_mm": length * 1e3,
                        "points": int(np.count_nonzero(m))})
    return sorted(out, key=lambda a: a["r_mm"])


def failed_rings(cls, x, y, center, dx, r_wall, r_out) -> list[dict]:
    """Runs of rings beyond the crushed zone with >= RING_FRACTION failed, under half of
    them radial (module docstring): each its radii [inner, outer] (mm) and its largest
    failed fraction.  ``cls`` is :func:`classify`'s."""
    frac, w = cracks.ring_fractions(x, y, cls >= 0, center, dx, r_wall, r_out)
    radial, _ = cracks.ring_fractions(x, y, cls == 0, center, dx, r_wall, r_out)
    ring = (frac >= RING_FRACTION) & (radial < 0.5 * frac)
    empty, nb = np.isnan(frac), len(frac)
    j = cracks.crushed_rings(frac)
    while j < nb and (ring[j] or empty[j]):
        j += 1
    out = []
    while j < nb:
        if not ring[j]:
            j += 1
            continue
        a = j
        while j < nb and (ring[j] or empty[j]):
            j += 1
        out.append({"r_mm": [(r_wall + a * w) * 1e3, (r_wall + j * w) * 1e3],
                    "peak_fraction": float(np.nanmax(frac[a:j]))})
    return out


def rings_text(section: dict) -> str:
    """A report.json section's failed rings as text, "64.8–68.8 (0.99)" each (radii in
    mm, the largest failed fraction); "—" for none, "not measured" for a report made
    before them."""
    rings = section.get("orientation", {}).get("failed_rings")
    if rings is None:
        return "not measured"
    return ", ".join(f"{a['r_mm'][0]:.3g}–{a['r_mm'][1]:.3g} ({a['peak_fraction']:.2f})"
                     for a in rings) or "—"


def measure(x, y, failed, center, dx, r_wall, r_out, horizon=None) -> dict:
    """Per-zone class counts and lengths, circumferential density and ring cracks."""
    x, y, failed = np.asarray(x, float), np.asarray(y, float), np.asarray(failed, bool)
    h = cracks.per_point(dx, x)
    link = 3.0 * h if horizon is None else cracks.per_point(horizon, x)
    cls = classify(x, y, failed, center, link)
    r = np.hypot(x - center[0], y - center[1])
    e = cracks.zone_edges(r_wall, r_out)
    zones = []
    for k, inside in enumerate(cracks.zone_masks(r, h, r_wall, r_out)):
        area = np.pi * (e[k + 1] ** 2 - e[k] ** 2) * 1e6
        row = {"zone": k + 1, "r_mm": [e[k] * 1e3, e[k + 1] * 1e3],
               "failed_points": int(np.count_nonzero(failed & inside))}
        for c, name in enumerate(CLASSES):
            m = inside & (cls == c)
            row[name] = {"points": int(np.count_nonzero(m)),
                         "length_mm": float(h[m].sum()) * 1e3}
        row["circumferential_density_mm_per_mm2"] = row["circumferential"]["length_mm"] / area
        zones.append(row)
    rings = ring_arcs(x, y, cls == 2, center, h, link)
    return {"zones": zones, "ring_arcs": len(rings), "ring_arc_length_mm": float(sum(a["length_mm"] for a in rings)),
            "rings": rings, "failed_rings": failed_rings(cls, x, y, center, h, r_wall, r_out),
            "rule": f"local direction of the failed points within the horizon (l2/l1 <= {LINEAR}, "
                    f"at least {MIN_NEIGHBOURS} points); radial < {RADIAL_DEG:g} deg < oblique < "
                    f"{CIRCUMFERENTIAL_DEG:g} deg < circumferential; a ring arc is a chain of "
                    f"circumferential points at least {RING_MIN_HORIZONS:g} horizons long; a failed ring is "
                    f"a run of rings of width dx beyond the crushed zone with at least "
                    f"{RING_FRACTION:g} of their points failed, under half of those radial"}
