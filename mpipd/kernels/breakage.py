"""Bond breakage from point failure (paper §2.4, Fig. 3) and PD damage (Eq. 39).

When point k fails, a bond (i, j) breaks if
  (a) it touches k (i == k or j == k), or
  (b) its reference segment passes within dx_k / 2 of x_k, and i or j is of k's
      material.

The material condition in (b) is mpipd's reading of the paper's rule for a body
of several materials at several resolutions.  The ball of radius dx_k / 2 stands
for the volume of k, but where a coarse part meets a fine one (the 1.2 mm rock
around the paper's 0.3 mm copper tube, 0.6 mm thick) that ball reaches across the
interface, into the other material.  A bond between two points of another
material lies in that other material: it does not cross k's volume, and k's
failure (a crushed rock) is no failure of it.  Without the condition, the rock
crushed at the borehole wall broke 8 % of the copper's own bonds (every bond
along the tube within 0.6 mm of a failed rock point) and left 1344 of the
20,040 copper points of the reduced paper scene with too few bonds for a shape
tensor (README, "Bond breakage across materials").
Both ranks holding the two directions of a bond evaluate (b) with the endpoints
ordered by global id, so they perform the same floating-point operations and
reach the same verdict: bond (i, j) and bond (j, i) break on the same step.
"""
import numba
import numpy as np

from .index import family, neighbour


@numba.njit(cache=True, inline="always")
def segment_dist2(x, a, b, k):
    """Squared distance from x[k] to the segment x[a]..x[b]."""
    d0 = x[b, 0] - x[a, 0]
    d1 = x[b, 1] - x[a, 1]
    d2 = x[b, 2] - x[a, 2]
    w0 = x[k, 0] - x[a, 0]
    w1 = x[k, 1] - x[a, 1]
    w2 = x[k, 2] - x[a, 2]
    L2 = d0 * d0 + d1 * d1 + d2 * d2
    t = (w0 * d0 + w1 * d1 + w2 * d2) / L2 if L2 > 0.0 else 0.0
    if t < 0.0:
        t = 0.0
    elif t > 1.0:
        t = 1.0
    e0 = w0 - t * d0
    e1 = w1 - t * d1
    e2 = w2 - t * d2
    return e0 * e0 + e1 * e1 + e2 * e2


@numba.njit(cache=True)
def break_bonds(pair_k, pair_i, x, gid, dx, material, offsets, nbr, broken, touched):
    """For every (failed k, owned candidate i) pair, break i's bonds by rules (a)
    and (b) (``material``: every local point's material id).  Sets touched[i] = 1
    where a bond broke; returns the bonds broken."""
    n = 0
    for p in range(pair_k.shape[0]):
        k = pair_k[p]
        i = pair_i[p]
        r2 = (0.5 * dx[k]) ** 2
        for b in range(*family(offsets, i)):
            if broken[b]:
                continue
            j = neighbour(nbr, b)
            hit = i == k or j == k
            if not hit and (material[i] == material[k] or material[j] == material[k]):
                if gid[i] < gid[j]:
                    hit = segment_dist2(x, i, j, k) <= r2
                else:
                    hit = segment_dist2(x, j, i, k) <= r2
            if hit:
                broken[b] = 1
                touched[i] = 1
                n += 1
    return n


@numba.njit(cache=True)
def pd_damage(points, offsets, nbr, broken, vol, phi):
    """phi_i = 1 - sum_intact V_j / sum_all V_j (Eq. 39) for the listed owned points."""
    for p in range(points.shape[0]):
        i = points[p]
        tot = 0.0
        ok = 0.0
        for b in range(*family(offsets, i)):
            v = vol[neighbour(nbr, b)]
            tot += v
            if broken[b] == 0:
                ok += v
        phi[i] = 1.0 - ok / tot if tot > 0.0 else 1.0


def pairs_from_lists(lists):
    """Flatten cKDTree ball lists into (row, item) index arrays."""
    lens = np.fromiter((len(a) for a in lists), dtype=np.int64, count=len(lists))
    rows = np.repeat(np.arange(len(lists), dtype=np.int64), lens)
    items = (np.concatenate([np.asarray(a, dtype=np.int64) for a in lists])
             if lens.sum() else np.empty(0, np.int64))
    return rows, items
