"""Cross-sections of the rock and the axial x–z plane, gathered to rank 0.

A cross-section at height z is the z level of the rock lattice nearest z (the
points of a part lie on that part's z levels; paper Fig. 11 cuts the specimen at
5 mm, mid-thickness and 45 mm; Fig. 9 views the two end faces, Fig. 12 uses the
two end sections and the middle one).  A z level is never split between reading
ranks (:mod:`postprocess.reader`), so its owner reads it with one contiguous
hyperslab per (field, frame) and sends it to rank 0: one section, never the model.

The axial plane (paper Figs. 7, 8) is the first lattice row above the axis,
0 < y - y_c < dx_p of each part p: it runs through every rank's slab and is
gathered row by row.
"""
from __future__ import annotations

import numpy as np

#: the named sections of a specimen of thickness T (z0 = the detonation end)
NAMED = ("detonation end face", "z0 + 5 mm", "mid-thickness", "z1 - 5 mm", "far end face")


def rock_levels(run, model) -> np.ndarray:
    """Sorted z of every z level holding rock points (same array on every rank)."""
    rock = (run.geometry("part") == model.rock).astype(np.int64)
    has = run.per_level(rock) > 0
    return np.asarray(run.all_levels(run.level_z[has]))


def nearest(levels: np.ndarray, z: float) -> float:
    return float(levels[np.argmin(np.abs(levels - z))])


def named_levels(levels: np.ndarray, model) -> dict[str, float]:
    """Section name -> z level, for the faces, +-5 mm from the faces and the middle
    (duplicates dropped when the specimen is thin)."""
    z0, z1 = model.z0, model.z1
    want = {NAMED[0]: z0, NAMED[1]: z0 + 5e-3, NAMED[2]: 0.5 * (z0 + z1),
            NAMED[3]: z1 - 5e-3, NAMED[4]: z1}
    out, seen = {}, set()
    for name in (NAMED[0], NAMED[4], NAMED[2], NAMED[1], NAMED[3]):
        z = nearest(levels, want[name])
        if z not in seen:
            out[name] = z
            seen.add(z)
    return {k: out[k] for k in NAMED if k in out}


def gather_sections(run, model, zlevels, requests) -> dict | None:
    """Rock points of each z level in ``zlevels`` with ``requests`` = [(field, frame)]:
    on rank 0 a dict z -> {"x", "y", (field, frame): values}; None on other ranks.
    Missing fields are skipped (the caller checks ``run.has_field``)."""
    x = run.geometry("x")
    pid = run.geometry("part")
    local = {}
    for z in zlevels:
        idx = np.flatnonzero((pid == model.rock) & (run.z_level == z))
        if not len(idx):
            continue
        a, b = int(idx[0]), int(idx[-1]) + 1
        sec = {"x": x[idx, 0].copy(), "y": x[idx, 1].copy()}
        for name, frame in requests:
            if run.has_field(name):
                sec[(name, frame)] = run.field(name, frame, span=(a, b))[idx - a]
        local[z] = sec
    parts = run.comm.gather(local, root=0)
    if not run.root:
        return None
    out = {}
    for p in parts:
        out.update(p)
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
