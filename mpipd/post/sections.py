"""Cross-sections of the rock and the axial x–z plane, gathered to rank 0.

A cross-section at height z is the z level of the rock lattice nearest z (the
points of a part lie on that part's z levels; paper Fig. 11 cuts the specimen at
5 mm, mid-thickness and 45 mm; Fig. 9 views the two end faces, Fig. 12 uses the
two end sections and the middle one).  A rock split into zones (graded rings, an
inner band: :meth:`mpipd.input.scene.Part.zones`) has one lattice per zone, with
its own dx and z levels: the section takes, in each zone, that zone's level
nearest the reference zone's level (``model.rock``), so it spans the whole rock.
Each point of a section carries its zone's ``h`` (dx) and ``link`` (horizon).

A z level is never split between reading ranks (:mod:`mpipd.post.reader`), so its
owner reads it with one contiguous hyperslab per (field, frame) and sends it to
rank 0: one section, never the model.

The axial plane (paper Figs. 7, 8) is the first lattice row above the axis,
0 < y - y_c < dx_p of each part p: it runs through every rank's slab and is
gathered row by row.

:func:`section` is the section of any run (``python -m mpipd.post fracture`` and
``mpipd.open(...).section``): the points of one z level nearest a height, of every
part or of the parts one name selects.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mpipd.input.probes import part_matches

#: the named sections of a specimen of thickness T (z0 = the detonation end)
NAMED = ("detonation end face", "z0 + 5 mm", "mid-thickness", "z1 - 5 mm", "far end face")
#: paper Fig. 11's sections: 5 mm from the detonation face, the middle, 5 mm from the far face
FIG11 = (NAMED[1], NAMED[2], NAMED[3])


def zone_levels(run, model) -> dict[int, np.ndarray]:
    """Rock zone (part index) -> sorted z of its z levels (same on every rank)."""
    pid = run.geometry("part")
    out = {}
    for p in model.zone_ids:
        has = run.per_level((pid == p).astype(np.int64)) > 0
        out[p] = np.asarray(run.all_levels(run.level_z[has]))
    return out


def nearest(levels: np.ndarray, z: float) -> float:
    return float(levels[np.argmin(np.abs(levels - z))])


def wanted(model) -> dict[str, float]:
    """Section name -> the height it is wanted at (before taking a lattice level)."""
    z0, z1 = model.z0, model.z1
    return {NAMED[0]: z0, NAMED[1]: z0 + 5e-3, NAMED[2]: 0.5 * (z0 + z1),
            NAMED[3]: z1 - 5e-3, NAMED[4]: z1}


def same_level(name: str, ref_levels, named: dict[str, float], model) -> str | None:
    """The section of ``named`` (name -> its reference zone's level) that holds the level
    ``name`` is wanted at: itself, or the one that took its level when
    :func:`named_levels` dropped it as a duplicate (a thin specimen: Fig. 11's
    "z1 - 5 mm" may be the far end face's level)."""
    z = nearest(np.asarray(ref_levels), wanted(model)[name])
    hit = [n for n, zn in named.items() if zn == z]
    return (name if name in hit else hit[0]) if hit else None


def named_levels(levels: dict[int, np.ndarray], model) -> dict[str, dict[int, float]]:
    """Section name -> {zone: z level}, for the faces, +-5 mm from the faces and the
    middle.  The reference zone's level nearest the wanted height names the section
    (duplicates dropped when the specimen is thin); every other zone takes its own
    level nearest that one."""
    want = wanted(model)
    ref = levels[model.rock]
    out, seen = {}, set()
    for name in (NAMED[0], NAMED[4], NAMED[2], NAMED[1], NAMED[3]):
        z = nearest(ref, want[name])
        if z not in seen:
            out[name] = {p: (z if p == model.rock else nearest(lv, z))
                         for p, lv in levels.items() if len(lv)}
            seen.add(z)
    return {k: out[k] for k in NAMED if k in out}


def section_z(levels: dict[int, float], model) -> float:
    """The z that names a section: its reference zone's level."""
    return levels[model.rock]


def gather_sections(run, model, named, requests) -> dict | None:
    """Rock points of each named section (``named``: name -> {zone: z level}) with
    ``requests`` = [(field, frame)]: on rank 0 a dict name -> {"x", "y", "h",
    "link", (field, frame): values}, zones in ``model.zone_ids`` order; None on other
    ranks.  Missing fields are skipped (the caller checks ``run.has_field``)."""
    x = run.geometry("x")
    pid = run.geometry("part")
    local = {}
    for name, zl in named.items():
        for p, z in zl.items():
            idx = np.flatnonzero((pid == p) & (run.z_level == z))
            if not len(idx):
                continue
            a, b = int(idx[0]), int(idx[-1]) + 1
            n = len(idx)
            sec = {"x": x[idx, 0].copy(), "y": x[idx, 1].copy(),
                   "h": np.full(n, model.dx_of(p)), "link": np.full(n, model.horizon_of(p))}
            for fname, frame in requests:
                if run.has_field(fname):
                    sec[(fname, frame)] = run.field(fname, frame, span=(a, b))[idx - a]
            local[(name, p)] = sec
    parts = run.comm.gather(local, root=0)
    if not run.root:
        return None
    got = {}
    for d in parts:
        got.update(d)
    out = {}
    for name in named:
        chunks = [got[(name, p)] for p in model.zone_ids if (name, p) in got]
        if chunks:
            out[name] = {k: np.concatenate([c[k] for c in chunks]) for k in chunks[0]}
    return out


def gather_plane(run, model, name: str, frames) -> dict | None:
    """The axial x–z plane (all parts): on rank 0 {"x", "z", "part", frame: values}."""
    x = run.geometry("x")
    h = np.cbrt(run.geometry("volume"))
    dy = x[:, 1] - model.center[1]
    idx = np.flatnonzero((dy > 0) & (dy < h))
    local = {"x": x[idx, 0], "z": x[idx, 2], "part": run.geometry("part")[idx]}
    for k in frames:
        if len(idx):
            a, b = int(idx[0]), int(idx[-1]) + 1
            local[k] = run.field(name, k, span=(a, b))[idx - a]
        else:
            local[k] = np.zeros(0)
    parts = run.comm.gather(local, root=0)
    if not run.root:
        return None
    return {key: np.concatenate([p[key] for p in parts]) for key in local}


def lattice_image(xs, ys, vals, center, dx, r_out):
    """A square image of a section on its lattice (NaN off the rock), and its extent (mm)."""
    n = int(np.ceil(r_out / dx)) + 1
    i = np.round((xs - center[0]) / dx - 0.5).astype(int) + n
    j = np.round((ys - center[1]) / dx - 0.5).astype(int) + n
    img = np.full((2 * n, 2 * n), np.nan)
    ok = (i >= 0) & (i < 2 * n) & (j >= 0) & (j < 2 * n)
    img[j[ok], i[ok]] = vals[ok]
    ext = np.array([center[0] - n * dx, center[0] + n * dx,
                    center[1] - n * dx, center[1] + n * dx]) * 1e3
    return img, ext


def section_images(sec, key, center, r_out) -> list:
    """One :func:`lattice_image` per lattice of a section (coarsest first, so the
    finer zones are drawn over it); NaN pixels are transparent."""
    h = sec["h"]
    out = []
    for dx in sorted(np.unique(h), reverse=True):
        m = h == dx
        out.append(lattice_image(sec["x"][m], sec["y"][m], sec[key][m], center, float(dx), r_out))
    return out


@dataclass(frozen=True)
class Section:
    """The points of one lattice level of z and a field's values on them, in gid order.

    ``x``, ``y``: the points' reference positions (m); ``gid``: their global ids;
    ``values``: the field at the frame, one row a point (``(n,)`` for a scalar field,
    ``(n, k)`` for a vector or tensor); ``z``: the level's z (m); ``field``,
    ``frame`` (the index of the written frame, from 0) and ``time`` (s) say what was
    read; ``part``: the part name that selected the points (None: every part)."""
    x: np.ndarray
    y: np.ndarray
    gid: np.ndarray
    values: np.ndarray
    z: float
    field: str
    frame: int
    time: float
    part: str | None


def part_mask(run, part: str | None) -> np.ndarray:
    """This rank's points that belong to ``part``: the part of that name and its zones
    (``rock`` selects ``rock`` and ``rock.ring1``: :func:`mpipd.input.probes.part_matches`);
    every point for None.  An unknown name is refused (ValueError naming the parts)."""
    pid = run.geometry("part")
    if part is None:
        return np.ones(len(pid), bool)
    names = run.names("part")
    ok = np.array([part_matches(part, q) for q in names], bool)
    if not ok.any():
        raise ValueError(f"no part {part!r} in the run (its parts: {', '.join(names) or 'none'})")
    return ok[pid] if len(pid) else np.zeros(0, bool)


def section(run, field: str = "damage", frame: int = -1, z: float | None = None,
            part: str | None = None) -> Section | None:
    """The points of the z level nearest ``z`` (default: half-way between the lowest and
    the highest point) and ``field`` at ``frame`` on them, gathered to rank 0 (one
    section, never the model): a :class:`Section` on rank 0, None on the other ranks.

    With ``part``, only that part's points (and its zones') count: the height
    defaults to the middle of the part, the level is the nearest that holds some of
    its points, and the section holds its points only.  Collective: every rank of the
    run calls it.  A part with no points is refused (ValueError)."""
    mine = part_mask(run, part)
    x = run.geometry("x")
    xs = x[mine]
    if part is not None and not run.sum_int(int(mine.sum())):
        raise ValueError(f"part {part!r} has no points")
    zmin = run.min(xs[:, 2].min() if len(xs) else np.inf)
    zmax = run.max(xs[:, 2].max() if len(xs) else -np.inf)
    target = 0.5 * (zmin + zmax) if z is None else z
    levels = np.unique(run.z_level[mine])
    near = levels[np.argmin(np.abs(levels - target))] if len(levels) else np.inf
    dist = run.min(abs(near - target))
    cands = run.comm.allgather(near if abs(near - target) == dist else np.inf)
    zlev = min(cands)
    sel = (run.z_level == zlev) & mine
    k = run.written(frame)
    vals = run.field(field, k)[sel]
    gid = run.lo + np.flatnonzero(sel)
    parts = run.comm.gather((x[sel, 0], x[sel, 1], gid, vals), root=0)
    if not run.root:
        return None
    cols = [np.concatenate([p[i] for p in parts]) for i in range(4)]
    return Section(x=cols[0], y=cols[1], gid=cols[2], values=cols[3], z=float(zlev),
                   field=field, frame=k, time=float(run.time[k]), part=part)
