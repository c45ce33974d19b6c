"""Bonds that cross a joint (mpipd.input.joints): the crossing test, per bond.

A joint set is the planes n . (x - p) = c_k, c_k = k s (k integer; one plane
c_0 = 0 when there is no spacing s), each bounded to a disc of radius r about
p + c_k n when r > 0.  A bond crosses plane k when its reference segment
x_a -> x_b has n . (x - p) - c_k of opposite signs at its ends (a point on a
plane counts as above it: the sign test is on floor(n . (x - p) / s)); the
crossing point is x_a + t (x_b - x_a), t = (c_k - s_a) / (s_b - s_a).

A crossing point outside the box ``box_lo``..``box_hi`` (bounds inclusive;
infinite: no box) does not count: the joint is bounded to the box.

A plane is open at the crossing point when its patch — the square of side
``patch`` of the in-plane coordinates (e1, e2) that holds the point — is drawn
open, u(seed, k, i1, i2) < persistence (mpipd.kernels.hashrng), so a fraction
``persistence`` of the area is open, in patches, and the rest are rock bridges.

Both ends of a bond evaluate it from the end with the lower global id, so the
two directed copies of a bond (in i's family and in j's, on any rank) agree bit
for bit.
"""
from __future__ import annotations

import math

import numba
import numpy as np

from .hashrng import _mix
from .index import family, neighbour


@numba.njit(cache=True, inline="always")
def _patch_open(seed, stream, k, i1, i2, persistence):
    golden = np.uint64(0x9E3779B97F4A7C15)
    h = _mix(np.uint64(seed) * np.uint64(65536) + np.uint64(stream) + golden)
    h = _mix(h + np.uint64(k) * golden)
    h = _mix(h + np.uint64(i1) * golden)
    h = _mix(h + np.uint64(i2) * golden)
    return ((h >> np.uint64(11)) + 0.5) * (1.0 / 9007199254740992.0) < persistence


@numba.njit(cache=True)
def cut_bonds(x, gid, cuts, offsets, nbr, broken, p, n, e1, e2, spacing, radius,
              persistence, patch, seed, stream, box_lo, box_hi):
    """Set broken[b] = 1 for every bond b = (i, nbr[b]) of an owned point i whose two
    ends are both in ``cuts`` (a bool per local point) and that crosses an open
    part of the joint set inside the box ``box_lo``..``box_hi``.  ``spacing`` <= 0:
    one plane; ``radius`` <= 0: unbounded; ``persistence`` >= 1: open everywhere.
    Returns the number of bonds newly cut."""
    count = 0
    for i in range(offsets.shape[0] - 1):
        if not cuts[i]:
            continue
        for b in range(*family(offsets, i)):
            j = neighbour(nbr, b)
            if broken[b] or not cuts[j]:
                continue
            a, c = (i, j) if gid[i] < gid[j] else (j, i)
            sa = ((x[a, 0] - p[0]) * n[0] + (x[a, 1] - p[1]) * n[1] + (x[a, 2] - p[2]) * n[2])
            sb = ((x[c, 0] - p[0]) * n[0] + (x[c, 1] - p[1]) * n[1] + (x[c, 2] - p[2]) * n[2])
            if spacing > 0.0:
                ka, kb = math.floor(sa / spacing), math.floor(sb / spacing)
            else:
                ka, kb = (0.0 if sa >= 0.0 else -1.0), (0.0 if sb >= 0.0 else -1.0)
            if ka == kb:
                continue
            lo, hi = (ka, kb) if ka < kb else (kb, ka)
            cut = False
            k = lo + 1.0
            while k <= hi and not cut:
                ck = k * spacing if spacing > 0.0 else 0.0
                t = (ck - sa) / (sb - sa)
                q0 = x[a, 0] + t * (x[c, 0] - x[a, 0]) - p[0] - ck * n[0]
                q1 = x[a, 1] + t * (x[c, 1] - x[a, 1]) - p[1] - ck * n[1]
                q2 = x[a, 2] + t * (x[c, 2] - x[a, 2]) - p[2] - ck * n[2]
                inside = radius <= 0.0 or q0 * q0 + q1 * q1 + q2 * q2 <= radius * radius
                c0 = q0 + p[0] + ck * n[0]
                c1 = q1 + p[1] + ck * n[1]
                c2 = q2 + p[2] + ck * n[2]
                inside = (inside and box_lo[0] <= c0 <= box_hi[0]
                          and box_lo[1] <= c1 <= box_hi[1] and box_lo[2] <= c2 <= box_hi[2])
                if inside:
                    if persistence >= 1.0:
                        cut = True
                    else:
                        u1 = q0 * e1[0] + q1 * e1[1] + q2 * e1[2]
                        u2 = q0 * e2[0] + q1 * e2[1] + q2 * e2[2]
                        cut = _patch_open(seed, stream, np.int64(k),
                                          np.int64(math.floor(u1 / patch)),
                                          np.int64(math.floor(u2 / patch)), persistence)
                k += 1.0
            if cut:
                broken[b] = 1
                count += 1
    return count
