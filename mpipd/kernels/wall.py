"""The gas wall: a gas point against the interpolated surface of a solid
(mpipd.materials.jwl.GasWall; not in the paper).

For an owned gas point i and the wall points j of its current family closer than
its horizon delta_i (Y_j = y_j - y_i), with Shepard weights w_j = (1 - |Y_j| / delta_i)^2
and S = sum w_j:

    c - y_i = sum w_j Y_j / S                        the surface's foot, from y_i
    C       = sum w_j Y_j (x) Y_j / S - (c - y_i) (x) (c - y_i)   the points' spread
    n       = C's eigenvector of least spread, oriented as sum w_j N_j (the reference
              normals, towards the gas); sum w_j N_j / |.| itself where the points do
              not span a plane (fewer than 3, or a middle spread under PLANAR times
              the least)
    h       = sum w_j l_j / (2 S)                    half the wall's spacing: its face
    g       = (y_i - c) . n - h                      the gap to the face
    t       = (c - y_i) - ((c - y_i) . n) n          the foot's offset along the face
    s       = max_j (y_i - y_j) . t / |t|            how far the wall reaches past y_i
                                                     away from its foot
    F_i     = e(s) k l_i (g_0 - g) n   if -DEPTH l_i < g < g_0, else 0

(k = stiffness x rho0 vod^2, l_i the gas point's lattice spacing, g_0 its standoff,
set at its first evaluation to min(distance l_i, g), or to distance l_i for a gas
point with no wall in reach then).  The wall point j takes
-F_i w_j / S: the pair forces sum to zero.  A gas point deeper than DEPTH of its
spacing behind the face has passed the wall and is left to the gas (pulling it back
through the wall would be a force of a passed point, not of a wall: with DEPTH = 2 the
stretched tube of the paper's reduction shot such points back at 10-12 km/s, 5-8 J
each, studies/validation/notes.md §51).  Nor is a gas
point beyond the wall's edge (out of an open end of the tube, venting): the plane
fitted over the wall points near an edge extends beyond it, and a gas point flowing
round the end would be pushed back by a wall that is not there.  Over a wall, dense
or stretched sparse, wall points lie on every side of the gas point, so some lie
past it on the side away from the weighted foot: s > 0.  Over the last row of an edge
s ~ 0; beyond the edge every wall point lies behind it, s < 0.  The factor e(s) is 1
for s >= 0, falls linearly to 0 at s = -EDGE l_i and is 0 beyond (t = 0, a foot
right under the point: e = 1).  It depends on where the wall's points are, not on
how far apart they are (an earlier factor on |t| / delta fluctuated between a
stretched wall's rows and pumped energy in: studies/validation/notes.md §51).

:func:`wall_update` makes F_i and F_i / S (the halo carries the latter to the wall
points' owners) for the owned gas; :func:`wall_gather` adds every owned point's
share to f and returns the force densities for the ledger's trapezoid.
"""
import math

import numba
import numpy as np

from .index import family, neighbour
from .ul import add_moment, current_bond

#: a middle spread at least PLANAR times the least: the points span a plane
PLANAR = 4.0
#: a gas point more than DEPTH of its spacing behind the face has passed the wall
DEPTH = 0.5
#: beyond the wall's edge by EDGE gas spacings (s = -EDGE l_i) the force is 0
EDGE = 0.5


@numba.njit(cache=True)
def edge_factor(i, y, offsets, nbr, is_wall, di, t0, t1, t2, li):
    """e(s) of the module docstring for gas point i whose foot is offset by
    t = (t0, t1, t2) along the face: s = max over its wall points within di of
    (y_i - y_j) . t / |t|."""
    lt = math.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
    if lt == 0.0:
        return 1.0
    s = -math.inf
    for b in range(*family(offsets, i)):
        j = neighbour(nbr, b)
        if not is_wall[j]:
            continue
        y0, y1, y2, ly = current_bond(y, i, j)
        if ly >= di:                            # as in wall_update
            continue
        s = max(s, -(y0 * t0 + y1 * t1 + y2 * t2) / lt)
    if s >= 0.0:
        return 1.0
    return max(0.0, 1.0 + s / (EDGE * li))


@numba.njit(cache=True)
def wall_update(gas_idx, y, offsets, nbr, is_wall, N_ref, l_wall, delta, ell, g0, gw, gF,
                frac, kc):
    """The wall force F_i of every owned gas point i = gas_idx[k] (into gF[i]) and
    F_i / S (into gw[i], for the wall points), module docstring.  ``is_wall``,
    ``N_ref`` (reference normals, towards the gas) and ``l_wall`` (lattice spacings)
    over the rows of ``y``; ``ell[k]`` the gas point's spacing; ``g0[k]`` its
    standoff (NaN: set now).  Returns (points pushed, largest penetration g_0 - g
    over them, in units of their spacing)."""
    C = np.empty((3, 3))
    n_on = 0
    worst = 0.0
    for k in range(gas_idx.shape[0]):
        i = gas_idx[k]
        di = delta[i]
        S = 0.0
        c0 = c1 = c2 = 0.0
        n0 = n1 = n2 = 0.0
        hl = 0.0
        for r in range(3):
            for c in range(3):
                C[r, c] = 0.0
        nw = 0
        for b in range(*family(offsets, i)):
            j = neighbour(nbr, b)
            if not is_wall[j]:
                continue
            y0, y1, y2, ly = current_bond(y, i, j)
            if ly >= di:
                continue
            w = (1.0 - ly / di) ** 2
            S += w
            c0 += w * y0
            c1 += w * y1
            c2 += w * y2
            add_moment(C, w, y0, y1, y2)
            n0 += w * N_ref[j, 0]
            n1 += w * N_ref[j, 1]
            n2 += w * N_ref[j, 2]
            hl += w * l_wall[j]
            nw += 1
        gw[i, 0] = gw[i, 1] = gw[i, 2] = 0.0
        gF[i, 0] = gF[i, 1] = gF[i, 2] = 0.0
        if nw == 0:
            if math.isnan(g0[k]):               # no wall in reach: it meets one later
                g0[k] = frac * ell[k]
            continue
        c0 /= S
        c1 /= S
        c2 /= S
        for r in range(3):
            for c in range(r, 3):
                C[r, c] = C[r, c] / S
        C[0, 0] -= c0 * c0
        C[0, 1] -= c0 * c1
        C[0, 2] -= c0 * c2
        C[1, 1] -= c1 * c1
        C[1, 2] -= c1 * c2
        C[2, 2] -= c2 * c2
        C[1, 0] = C[0, 1]
        C[2, 0] = C[0, 2]
        C[2, 1] = C[1, 2]
        ln = math.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
        if ln == 0.0:
            if math.isnan(g0[k]):
                g0[k] = frac * ell[k]
            continue
        n0 /= ln
        n1 /= ln
        n2 /= ln
        if nw >= 3:
            lam, vec = np.linalg.eigh(C)
            if lam[1] > PLANAR * lam[0]:
                m0, m1, m2 = vec[0, 0], vec[1, 0], vec[2, 0]
                if m0 * n0 + m1 * n1 + m2 * n2 < 0.0:
                    m0, m1, m2 = -m0, -m1, -m2
                n0, n1, n2 = m0, m1, m2
        d = -(c0 * n0 + c1 * n1 + c2 * n2)     # (y_i - c) . n
        g = d - 0.5 * hl / S
        li = ell[k]
        if math.isnan(g0[k]):
            g0[k] = min(frac * li, g)
        if g >= g0[k] or g <= -DEPTH * li:
            continue
        e = edge_factor(gas_idx[k], y, offsets, nbr, is_wall, di, c0 + d * n0,
                        c1 + d * n1, c2 + d * n2, li)
        if e == 0.0:
            continue
        pen = g0[k] - g
        F = e * kc * li * pen
        gF[i, 0] = F * n0
        gF[i, 1] = F * n1
        gF[i, 2] = F * n2
        gw[i, 0] = gF[i, 0] / S
        gw[i, 1] = gF[i, 1] / S
        gw[i, 2] = gF[i, 2] / S
        n_on += 1
        worst = max(worst, pen / li)
    return n_on, worst


@numba.njit(cache=True)
def wall_gather(rows, y, offsets, nbr, is_gas, is_wall, delta, gw, gF, V_ref, f, fw):
    """Add the wall forces of the owned points ``rows`` to f (force densities): an
    owned gas point its F_i, an owned wall point j the sum over the gas points i of
    its family within delta_i of -w_ij F_i / S_i (= -w_ij gw[i]).  fw[k] (rows order)
    is left holding the force density added to point rows[k], for the ledger."""
    for k in range(rows.shape[0]):
        i = rows[k]
        fx = fy = fz = 0.0
        if is_gas[i]:
            fx, fy, fz = gF[i, 0], gF[i, 1], gF[i, 2]
        elif is_wall[i]:
            for b in range(*family(offsets, i)):
                j = neighbour(nbr, b)
                if not is_gas[j] or (gw[j, 0] == 0.0 and gw[j, 1] == 0.0 and gw[j, 2] == 0.0):
                    continue
                y0, y1, y2, ly = current_bond(y, i, j)
                dj = delta[j]
                if ly >= dj:
                    continue
                w = (1.0 - ly / dj) ** 2
                fx -= w * gw[j, 0]
                fy -= w * gw[j, 1]
                fz -= w * gw[j, 2]
        fw[k, 0] = fx / V_ref[i]
        fw[k, 1] = fy / V_ref[i]
        fw[k, 2] = fz / V_ref[i]
        f[i, 0] += fw[k, 0]
        f[i, 1] += fw[k, 1]
        f[i, 2] += fw[k, 2]
