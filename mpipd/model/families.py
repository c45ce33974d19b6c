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
        owner of its lower-gid end holds that copy."""
        rows = np.repeat(np.arange(len(self.offsets) - 1), np.diff(self.offsets))
        b = self.broken.astype(bool)
        gi, gj = gid[rows[b]], gid[self.nbr[b]]
        if lower:
            keep = gi < gj
            gi, gj = gi[keep], gj[keep]
        return np.stack([gi, gj], axis=1).astype(np.int64)

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
