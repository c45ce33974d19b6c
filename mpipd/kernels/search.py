"""Pair search in the current configuration by a cell list (the gas's Verlet list,
mpipd.model.gas).

The candidate points are binned into cubic cells of side ``cell`` (at least the
largest cut-off), keyed (ix n_y + iy) n_z + iz and sorted by key; each row point
scans the 27 cells around its own (binary search of the sorted keys), so the work
is O(points x neighbours) and no dense grid is held however far the gas spreads.
A pair (i, j) is kept when i != j and |y_i - y_j| < max(h_i, h_j) + skin; each
row is returned sorted by neighbour gid (the order every kernel sums in).
"""
from __future__ import annotations

import numba
import numpy as np

#: largest number of cells the int64 keys may address (the caller falls back to a
#: tree search beyond it: points spread over more than ~2e6 cells along each axis)
MAX_CELLS = 1 << 62


def cell_counts(y_el: np.ndarray, cell: float) -> tuple[np.ndarray, np.ndarray]:
    """Lower corner and cells per axis of the candidates' bounding box."""
    lo = y_el.min(axis=0)
    dims = np.floor((y_el.max(axis=0) - lo) / cell).astype(np.int64) + 1
    return lo, dims


@numba.njit(cache=True)
def _scan(y, rows, el, h, skin, cell, lo, dims, order, skeys, gid, counts, nbr, start, fill):
    """Count (fill == False) or write (fill == True) each row's pairs."""
    ny, nz = dims[1], dims[2]
    for q in range(rows.shape[0]):
        i = rows[q]
        cx = int((y[i, 0] - lo[0]) / cell)
        cy = int((y[i, 1] - lo[1]) / cell)
        cz = int((y[i, 2] - lo[2]) / cell)
        k = start[i] if fill else 0
        for ax in range(max(cx - 1, 0), min(cx + 2, dims[0])):
            for ay in range(max(cy - 1, 0), min(cy + 2, ny)):
                for az in range(max(cz - 1, 0), min(cz + 2, nz)):
                    key = (ax * ny + ay) * nz + az
                    a = np.searchsorted(skeys, key, "left")
                    b = np.searchsorted(skeys, key, "right")
                    for p in range(a, b):
                        j = el[order[p]]
                        if j == i:
                            continue
                        d0 = y[j, 0] - y[i, 0]
                        d1 = y[j, 1] - y[i, 1]
                        d2 = y[j, 2] - y[i, 2]
                        r = max(h[i], h[j]) + skin
                        if d0 * d0 + d1 * d1 + d2 * d2 < r * r:
                            if fill:
                                nbr[k] = j
                                k += 1
                            else:
                                counts[i] += 1
        if fill:
            sort_row_by_gid(nbr, start[i], k, gid)


@numba.njit(cache=True)
def sort_row_by_gid(nbr, a, b, gid):
    """Sort nbr[a:b] (local indices) by their gids (distinct in a row, so the order is
    the one any sort gives)."""
    if b - a < 2:
        return
    row = nbr[a:b].copy()
    keys = np.empty(b - a, gid.dtype)
    for m in range(b - a):
        keys[m] = gid[row[m]]
    srt = np.argsort(keys)
    for m in range(b - a):
        nbr[a + m] = row[srt[m]]


@numba.njit(cache=True)
def cell_pairs(y, rows, el, h, skin, cell, lo, dims, gid, n_rows):
    """Families of the points ``rows`` among the candidates ``el`` (local indices;
    rows a subset of el) at positions ``y``: (row counts over n_rows, nbr), each row
    sorted by gid.  ``lo`` and ``dims`` from :func:`cell_counts` of y[el]."""
    m = el.shape[0]
    keys = np.empty(m, np.int64)
    for p in range(m):
        j = el[p]
        ix = int((y[j, 0] - lo[0]) / cell)
        iy = int((y[j, 1] - lo[1]) / cell)
        iz = int((y[j, 2] - lo[2]) / cell)
        keys[p] = (ix * dims[1] + iy) * dims[2] + iz
    order = np.argsort(keys)
    skeys = keys[order]
    counts = np.zeros(n_rows, np.int64)
    start = np.zeros(n_rows + 1, np.int64)
    empty = np.empty(0, np.int32)
    _scan(y, rows, el, h, skin, cell, lo, dims, order, skeys, gid, counts, empty, start, False)
    for r in range(n_rows):
        start[r + 1] = start[r] + counts[r]
    nbr = np.empty(start[n_rows], np.int32)
    _scan(y, rows, el, h, skin, cell, lo, dims, order, skeys, gid, counts, nbr, start, True)
    return counts, nbr


@numba.njit(cache=True)
def max_moved2(y, idx, y_built):
    """Largest squared distance |y[idx[k]] - y_built[k]|^2 (0 for no points): how far
    the Verlet list's points have moved since it was built."""
    m = 0.0
    for k in range(idx.shape[0]):
        i = idx[k]
        d0 = y[i, 0] - y_built[k, 0]
        d1 = y[i, 1] - y_built[k, 1]
        d2 = y[i, 2] - y_built[k, 2]
        d = d0 * d0 + d1 * d1 + d2 * d2
        if d > m:
            m = d
    return m


@numba.njit(cache=True)
def merge_rows(ca, na, cb, nb):
    """One CSR (counts, nbr) from two over the same rows, each row filled by at most
    one of them (e.g. the gas rows' families and the solid rows')."""
    n = ca.shape[0]
    counts = ca + cb
    nbr = np.empty(na.shape[0] + nb.shape[0], np.int32)
    pa = pb = k = 0
    for i in range(n):
        for _ in range(ca[i]):
            nbr[k] = na[pa]
            pa += 1
            k += 1
        for _ in range(cb[i]):
            nbr[k] = nb[pb]
            pb += 1
            k += 1
    return counts, nbr
