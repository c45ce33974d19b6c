"""Peridynamic families in CSR form, built with scipy's cKDTree.

For every owned point i, the family is every local point j != i (owned or
ghost) with |x_j - x_i| < max(delta_i, delta_j) — the union of i's horizon and
the points whose horizon reaches i, so that where horizons differ (dual
horizons, Ren et al. 2016) both halves of every pair force are gathered and
momentum is conserved.  The kernels weight i's own terms by
omega_i = (delta_i - |xi|)^2 only where |xi| < delta_i.  Families are stored as

* ``offsets`` (n_owned + 1,) int64 and ``nbr`` (n_bonds,) int32 local indices,
* each family sorted by the neighbour's **global id**,

so every per-point sum runs in the same order on any number of ranks, which
makes results bit-identical across decompositions.  Per-bond state beside
``nbr`` is one ``uint8`` (``broken``); bond vectors and influence weights are
recomputed from reference positions in the kernels rather than stored, keeping
the per-bond memory at 5 bytes.
"""
from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np
from scipy.spatial import cKDTree

from ..kernels.search import sort_row_by_gid
from ..state import AUX, BOND


@dataclass
class Families:
    offsets: np.ndarray         # (n_owned + 1,) int64
    nbr: np.ndarray             # (n_bonds,) int32
    broken: np.ndarray          # (n_bonds,) uint8

    @property
    def n_bonds(self) -> int:
        return len(self.nbr)

    def broken_pairs(self, gid: np.ndarray, lower: bool = False) -> np.ndarray:
        """(gid_i, gid_j) of the broken bonds of the owned points' families, in family
        order (gid_i ascending, then gid_j): every directed copy, or with ``lower``
        only those with gid_i < gid_j — each bond once over all ranks, since the
        owner of its lower-gid end holds that copy.  No per-bond temporary: the
        pairs themselves are the only allocation (_broken_pairs)."""
        return _broken_pairs(self.offsets, self.nbr, self.broken, gid, lower)

    def set_broken(self, gid: np.ndarray, pairs: np.ndarray, both: bool = False) -> int:
        """Set ``broken`` from (gid_i, gid_j) pairs, every other bond intact: the bond of
        owned point gid_i to gid_j, and with ``both`` also that of owned gid_j to gid_i
        (pairs given once, as broken_pairs(lower=True) writes them).  Pairs with no
        owned end are skipped.  Returns the number of pairs whose owned end has no
        such neighbour (0 when the pairs come from the same families).  By bisection
        in the gid-sorted families, O(pairs log k), no per-bond temporary
        (_mark_pairs).  The restore of ``blast_paper:dx0.7`` (283 M bonds, 51 M broken
        pairs, 2 ranks) peaks at 7.6 GB per rank with it; the per-bond keys and the
        np.isin it replaces took it past 12.4 GB per rank, and out of memory."""
        n = len(self.offsets) - 1
        owned = np.ascontiguousarray(gid[:n], dtype=np.int64)
        order = np.argsort(owned, kind="stable")
        return int(_mark_pairs(self.offsets, self.nbr, gid, owned[order], order,
                               np.ascontiguousarray(pairs, dtype=np.int64).reshape(-1, 2),
                               both, self.broken))

    def register(self, state):
        """The CSR arrays in the State (owner "families"; ``broken`` is written by
        Failure, and saved in checkpoints as gid pairs, not as a field)."""
        state.add("offsets", "families", self.offsets, rows=AUX)
        state.add("nbr", "families", self.nbr, rows=BOND)
        state.add("broken", "families", self.broken, rows=BOND)


@numba.njit(cache=True)
def _csr_by_row(i, j, gid, n_rows):
    """Counting sort of pairs (i, j) by row i, then each row by gid[j] (an argsort
    of the row's gids: O(k log k) for a family of k; the gids of a row are
    distinct, so the order is the one any sort gives).  Returns (row counts, nbr)."""
    counts = np.zeros(n_rows, np.int64)
    for k in range(i.shape[0]):
        counts[i[k]] += 1
    start = np.zeros(n_rows + 1, np.int64)
    for r in range(n_rows):
        start[r + 1] = start[r] + counts[r]
    fill = start[:-1].copy()
    nbr = np.empty(i.shape[0], np.int32)
    for k in range(i.shape[0]):
        nbr[fill[i[k]]] = j[k]
        fill[i[k]] += 1
    for r in range(n_rows):
        sort_row_by_gid(nbr, start[r], start[r + 1], gid)
    return counts, nbr


@numba.njit(cache=True)
def _broken_pairs(offsets, nbr, broken, gid, lower):
    """The (gid_i, gid_j) rows of Families.broken_pairs: a counting pass, then a fill."""
    n = offsets.shape[0] - 1
    m = 0
    for i in range(n):
        for k in range(offsets[i], offsets[i + 1]):
            if broken[k] and (not lower or gid[i] < gid[nbr[k]]):
                m += 1
    out = np.empty((m, 2), np.int64)
    m = 0
    for i in range(n):
        for k in range(offsets[i], offsets[i + 1]):
            if broken[k] and (not lower or gid[i] < gid[nbr[k]]):
                out[m, 0] = gid[i]
                out[m, 1] = gid[nbr[k]]
                m += 1
    return out


@numba.njit(cache=True)
def _mark_one(offsets, nbr, gid, sorted_owned, order, gi, gj, broken):
    """Mark the bond of owned point gid ``gi`` to gid ``gj``: 1 marked, 0 no owned
    point gi, -1 owned but no such neighbour.  Rows by bisection in the sorted owned
    gids, the neighbour by bisection in the row (families are sorted by gid)."""
    r = np.searchsorted(sorted_owned, gi)
    if r == sorted_owned.shape[0] or sorted_owned[r] != gi:
        return 0
    i = order[r]
    lo, hi = offsets[i], offsets[i + 1]
    while lo < hi:
        mid = (lo + hi) // 2
        if gid[nbr[mid]] < gj:
            lo = mid + 1
        else:
            hi = mid
    if lo < offsets[i + 1] and gid[nbr[lo]] == gj:
        broken[lo] = 1
        return 1
    return -1


@numba.njit(cache=True)
def _mark_pairs(offsets, nbr, gid, sorted_owned, order, pairs, both, broken):
    """Families.set_broken: clear ``broken``, mark every pair; count the misses."""
    broken[:] = 0
    missing = 0
    for p in range(pairs.shape[0]):
        if _mark_one(offsets, nbr, gid, sorted_owned, order, pairs[p, 0], pairs[p, 1],
                     broken) < 0:
            missing += 1
        if both and _mark_one(offsets, nbr, gid, sorted_owned, order, pairs[p, 1],
                              pairs[p, 0], broken) < 0:
            missing += 1
    return missing


def build_families(x: np.ndarray, gid: np.ndarray, horizon: np.ndarray, n_owned: int,
                   chunk: int = 16384, tl=None) -> Families:
    """Families of the first ``n_owned`` points among all ``len(x)`` local points.

    Owned points are processed in chunks, so the pair temporaries stay at
    ``chunk`` families whatever the model size.  ``tl`` (bool per local point,
    default all) marks total-Lagrangian points; others (the gas) get no bonds."""
    tree = cKDTree(x)
    counts, nbrs = [], []
    for s in range(0, n_owned, chunk):
        e = min(n_owned, s + chunk)
        sub = cKDTree(x[s:e])
        m = sub.sparse_distance_matrix(tree, float(horizon.max()), output_type="ndarray")
        i = m["i"]
        j = m["j"]
        keep = (m["v"] < np.maximum(horizon[i + s], horizon[j])) & (i + s != j)
        if tl is not None:
            keep &= tl[i + s] & tl[j]
        c, nb = _csr_by_row(i[keep], j[keep], gid, e - s)
        counts.append(c)
        nbrs.append(nb)
    offsets = np.zeros(n_owned + 1, dtype=np.int64)
    if counts:
        np.cumsum(np.concatenate(counts), out=offsets[1:])
    nbr = np.concatenate(nbrs) if nbrs else np.empty(0, np.int32)
    return Families(offsets=offsets, nbr=nbr, broken=np.zeros(len(nbr), dtype=np.uint8))
