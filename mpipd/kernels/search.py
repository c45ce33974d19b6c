"""Pair search in the current configuration by a cell list (the gas's Verlet list,
mpipd.model.gas).

Before that, :func:`near_cells` keeps only the candidates that can have a pair
at all (a solid far from every gas point has none), so a gas that has spread over
the specimen does not make every solid in its bounding box a candidate.

The candidate points are binned into cubic cells of side ``cell`` (at least the
largest cut-off), keyed (ix n_y + iy) n_z + iz and sorted by key (a counting sort
into a start per cell while the box has at most ``DENSE_CELLS`` cells, else an
argsort); each row point scans the 27 cells around its own (the three cells along
z of each x-y column are one contiguous run, found from the starts or by binary
search of the sorted keys), in one pass, so the work is O(points x neighbours) and
no dense grid is held however far the gas spreads.
A pair (i, j) is kept when i != j and |y_i - y_j| < max(h_i, h_j) + skin; each
row is returned sorted by neighbour gid (the order every kernel sums in).
"""
from __future__ import annotations

import math

import numba
import numpy as np

#: largest number of cells the int64 keys may address (the caller falls back to a
#: tree search beyond it: points spread over more than ~2e6 cells along each axis)
MAX_CELLS = 1 << 62
#: a box of at most this many cells is held densely: near_cells flags its cells (a
#: byte each) and cell_pairs counting-sorts into it (an int32 start per cell); a
#: larger one is binary-searched by sorted keys
DENSE_CELLS = 1 << 24
#: rows up to this long are sorted by insertion (sort_row_by_gid)
SHORT_ROW = 32


@numba.njit(cache=True)
def near_cells(y, cand, around, cell):
    """The candidates ``cand`` (local indices, order kept) whose cell of side ``cell``
    is, or touches, a cell holding one of the points ``around`` (local indices).

    A point within ``cell`` of some ``around`` point lies at most one cell from it
    along each axis, so the result holds every candidate within ``cell`` of the
    ``around`` points (and some a little farther: callers test the distance).  The
    cells are keyed over the ``around`` points' bounding box grown by one cell; the
    occupied cells and their 26 neighbours are flagged in a byte per cell when the
    box has at most ``DENSE_CELLS`` (one load per candidate), else their keys are
    sorted and each candidate is one binary search (no dense grid however far the
    points spread).
    Where the box has too many cells for int64 keys (:data:`MAX_CELLS`) no candidate
    is dropped."""
    if around.shape[0] == 0:
        return cand[:0].copy()
    lo = np.empty(3)
    hi = np.empty(3)
    for c in range(3):
        lo[c] = y[around[0], c]
        hi[c] = lo[c]
    for p in range(around.shape[0]):
        for c in range(3):
            w = y[around[p], c]
            lo[c] = min(lo[c], w)
            hi[c] = max(hi[c], w)
    span = np.empty(3)             # cells along each axis, one spare on either side
    for c in range(3):
        span[c] = math.floor((hi[c] - lo[c]) / cell) + 3.0
    if not span[0] * span[1] * span[2] < MAX_CELLS:
        return cand.copy()
    d = span.astype(np.int64)
    occ = np.empty(around.shape[0], np.int64)
    for p in range(around.shape[0]):
        i = around[p]
        ix = int(math.floor((y[i, 0] - lo[0]) / cell)) + 1
        iy = int(math.floor((y[i, 1] - lo[1]) / cell)) + 1
        iz = int(math.floor((y[i, 2] - lo[2]) / cell)) + 1
        occ[p] = (ix * d[1] + iy) * d[2] + iz
    occ = np.unique(occ)
    grown = np.empty(27 * occ.shape[0], np.int64)
    k = 0
    for p in range(occ.shape[0]):
        iz = occ[p] % d[2]
        iy = (occ[p] // d[2]) % d[1]
        ix = occ[p] // (d[1] * d[2])
        for a in range(ix - 1, ix + 2):
            for b in range(iy - 1, iy + 2):
                for c in range(iz - 1, iz + 2):
                    grown[k] = (a * d[1] + b) * d[2] + c
                    k += 1
    dense = span[0] * span[1] * span[2] <= DENSE_CELLS
    if dense:                      # a flag per cell: one load per candidate
        flag = np.zeros(d[0] * d[1] * d[2], np.bool_)
        for p in range(k):
            flag[grown[p]] = True
    else:
        grown = np.unique(grown)
    keep = np.zeros(cand.shape[0], np.bool_)
    for q in range(cand.shape[0]):
        j = cand[q]
        gx = math.floor((y[j, 0] - lo[0]) / cell) + 1.0     # as floats: no overflow
        gy = math.floor((y[j, 1] - lo[1]) / cell) + 1.0
        gz = math.floor((y[j, 2] - lo[2]) / cell) + 1.0
        if not (0.0 <= gx < span[0] and 0.0 <= gy < span[1] and 0.0 <= gz < span[2]):
            continue
        key = (int(gx) * d[1] + int(gy)) * d[2] + int(gz)
        if dense:
            keep[q] = flag[key]
        else:
            s = np.searchsorted(grown, key)
            keep[q] = s < grown.shape[0] and grown[s] == key
    return cand[keep]


def cell_counts(y_el: np.ndarray, cell: float) -> tuple[np.ndarray, np.ndarray]:
    """Lower corner and cells per axis of the candidates' bounding box."""
    lo = y_el.min(axis=0)
    dims = np.floor((y_el.max(axis=0) - lo) / cell).astype(np.int64) + 1
    return lo, dims


@numba.njit(cache=True)
def _scan(y, rows, el, h, skin, cell, lo, dims, order, skeys, start, gid, counts, cap):
    """Each row's pairs in one pass, rows in order (so the result is CSR): the
    neighbour list, grown by doubling from ``cap`` entries, and its length.  The
    candidates' indices, positions and horizons are first copied in key order, so
    that each cell column's scan reads contiguous memory; a row's candidate runs
    are found first and the list grown once for all of them (no test per pair)."""
    m = order.shape[0]
    js = np.empty(m, np.int64)
    ys = np.empty((m, 3))
    hs = np.empty(m)
    for p in range(m):
        j = el[order[p]]
        js[p] = j
        ys[p, 0] = y[j, 0]
        ys[p, 1] = y[j, 1]
        ys[p, 2] = y[j, 2]
        hs[p] = h[j]
    ny, nz = dims[1], dims[2]
    dense = start.shape[0] > 0     # each cell's first candidate (cell_pairs), else search
    nbr = np.empty(max(cap, 16), np.int32)
    run_a = np.empty(9, np.int64)
    run_b = np.empty(9, np.int64)
    k = 0
    for q in range(rows.shape[0]):
        i = rows[q]
        cx = int((y[i, 0] - lo[0]) / cell)
        cy = int((y[i, 1] - lo[1]) / cell)
        cz = int((y[i, 2] - lo[2]) / cell)
        yi0, yi1, yi2, hi = y[i, 0], y[i, 1], y[i, 2], h[i]
        n_run = 0
        most = 0
        z0 = max(cz - 1, 0)
        z1 = min(cz + 1, nz - 1)
        for ax in range(max(cx - 1, 0), min(cx + 2, dims[0])):
            if z0 > z1:                # the row lies beyond the box along z
                break
            for ay in range(max(cy - 1, 0), min(cy + 2, ny)):
                key0 = (ax * ny + ay) * nz
                # the (up to) 3 cells along z of a column are one contiguous run
                if dense:
                    run_a[n_run] = start[key0 + z0]
                    run_b[n_run] = start[key0 + z1 + 1]
                else:
                    run_a[n_run] = np.searchsorted(skeys, key0 + z0, "left")
                    run_b[n_run] = np.searchsorted(skeys, key0 + z1, "right")
                most += run_b[n_run] - run_a[n_run]
                n_run += 1
        if k + most > nbr.shape[0]:
            grown = np.empty(max(2 * nbr.shape[0], k + most), np.int32)
            grown[:k] = nbr[:k]
            nbr = grown
        a0 = k
        for t in range(n_run):
            for p in range(run_a[t], run_b[t]):
                j = js[p]
                if j == i:
                    continue
                d0 = ys[p, 0] - yi0
                d1 = ys[p, 1] - yi1
                d2 = ys[p, 2] - yi2
                r = max(hi, hs[p]) + skin
                if d0 * d0 + d1 * d1 + d2 * d2 < r * r:
                    nbr[k] = j
                    k += 1
        counts[i] = k - a0
        sort_row_by_gid(nbr, a0, k, gid)
    return nbr, k


@numba.njit(cache=True)
def sort_row_by_gid(nbr, a, b, gid):
    """Sort nbr[a:b] (local indices) by their gids (distinct in a row, so the order is
    the one any sort gives): in place by insertion up to ``SHORT_ROW`` entries (no
    allocation: the gas's solid rows hold a few), else by an argsort."""
    if b - a < 2:
        return
    if b - a <= SHORT_ROW:
        for m in range(a + 1, b):
            v = nbr[m]
            g = gid[v]
            p = m - 1
            while p >= a and gid[nbr[p]] > g:
                nbr[p + 1] = nbr[p]
                p -= 1
            nbr[p + 1] = v
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
    n_cells = dims[0] * dims[1] * dims[2]
    if n_cells <= DENSE_CELLS:     # counting sort: each cell's first candidate, by key
        start = np.zeros(n_cells + 1, np.int32)
        for p in range(m):
            start[keys[p] + 1] += 1
        for c in range(n_cells):
            start[c + 1] += start[c]
        fill = start[:-1].copy()
        order = np.empty(m, np.int64)
        for p in range(m):
            order[fill[keys[p]]] = p
            fill[keys[p]] += 1
        skeys = keys[:0]           # the scan reads the starts, not the sorted keys
    else:
        start = np.zeros(0, np.int32)
        order = np.argsort(keys)
        skeys = keys[order]
    counts = np.zeros(n_rows, np.int64)
    nbr, k = _scan(y, rows, el, h, skin, cell, lo, dims, order, skeys, start, gid, counts,
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
