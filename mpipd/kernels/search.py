"""Pair search in the current configuration by a cell list (the gas's Verlet list,
mpipd.model.gas).

The candidate points are binned into cubic cells of side ``cell`` (at least the
largest cut-off), keyed (ix n_y + iy) n_z + iz and sorted by key; each row point
scans the 27 cells around its own (binary search of the sorted keys; the three
cells along z of each x-y column are one contiguous run), in one pass, so the work
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


def in_box(y: np.ndarray, idx: np.ndarray, around: np.ndarray, reach: float) -> np.ndarray:
    """The points ``idx`` whose positions y lie in the bounding box of the points
    ``around`` (positions) grown by ``reach``: no point outside it is within reach."""
    lo, hi = around.min(axis=0) - reach, around.max(axis=0) + reach
    yi = y[idx]
    return idx[np.all((yi >= lo) & (yi <= hi), axis=1)]


def cell_counts(y_el: np.ndarray, cell: float) -> tuple[np.ndarray, np.ndarray]:
    """Lower corner and cells per axis of the candidates' bounding box."""
    lo = y_el.min(axis=0)
    dims = np.floor((y_el.max(axis=0) - lo) / cell).astype(np.int64) + 1
    return lo, dims


@numba.njit(cache=True)
def _scan(y, rows, el, h, skin, cell, lo, dims, order, skeys, gid, counts, cap):
    """Each row's pairs in one pass, rows in order (so the result is CSR): the
    neighbour list, grown by doubling from ``cap`` entries, and its length."""
    ny, nz = dims[1], dims[2]
    nbr = np.empty(max(cap, 16), np.int32)
    k = 0
    for q in range(rows.shape[0]):
        i = rows[q]
        cx = int((y[i, 0] - lo[0]) / cell)
        cy = int((y[i, 1] - lo[1]) / cell)
        cz = int((y[i, 2] - lo[2]) / cell)
        a0 = k
        for ax in range(max(cx - 1, 0), min(cx + 2, dims[0])):
            for ay in range(max(cy - 1, 0), min(cy + 2, ny)):
                key0 = (ax * ny + ay) * nz
                a = np.searchsorted(skeys, key0 + max(cz - 1, 0), "left")
                b = np.searchsorted(skeys, key0 + min(cz + 1, nz - 1), "right")
                for p in range(a, b):          # the (up to) 3 cells along z are contiguous
                    j = el[order[p]]
                    if j == i:
                        continue
                    d0 = y[j, 0] - y[i, 0]
                    d1 = y[j, 1] - y[i, 1]
                    d2 = y[j, 2] - y[i, 2]
                    r = max(h[i], h[j]) + skin
                    if d0 * d0 + d1 * d1 + d2 * d2 < r * r:
                        if k == nbr.shape[0]:
                            grown = np.empty(2 * k, np.int32)
                            grown[:k] = nbr
                            nbr = grown
                        nbr[k] = j
                        k += 1
        counts[i] = k - a0
        sort_row_by_gid(nbr, a0, k, gid)
    return nbr, k


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
    """Families of the points ``rows`` (local indices, ascending) among the candidates
    ``el`` (local indices) at positions ``y``: (row counts over n_rows, nbr), each
    row sorted by gid.  ``lo`` and ``dims`` from :func:`cell_counts` of y[el]."""
    for q in range(1, rows.shape[0]):
        if rows[q] <= rows[q - 1]:
            raise ValueError("cell_pairs: rows must be ascending")
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
    nbr, k = _scan(y, rows, el, h, skin, cell, lo, dims, order, skeys, gid, counts,
                   64 * rows.shape[0])
    return counts, nbr[:k].copy()


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
