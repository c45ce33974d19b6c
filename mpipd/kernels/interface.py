"""Kernels of the resolution-interface correction (see :mod:`mpipd.model.interface`).

Under a uniform first Piola stress P the gathered force density (Eq. 1 with
dual horizons) on point i is P g_i with the purely geometric vector

    g_i = sum_j (omega_i K_i^-1 + omega_j K_j^-1) xi_ij V_j ,

(omega_i with point i's influence function and horizon, omega_j with j's; see
mpipd.kernels.influence), which vanishes by symmetry inside a uniform lattice
but not where horizons, spacings or influence functions change.  The correction
subtracts P_i g_i = A_i q_i at the chosen points, with A_i = P_i K_i^-1 = B_i + h_i F_i
(the force data) and q_i = K_i g_i.
"""
import math

import numba

from .classes import weight
from .index import family, neighbour
from .influence import influence
from .layout import FD_H, FD_SPRING, KINV_FLAG


@numba.njit(cache=True)
def interface_vectors(x, vol, horizon, infl, offsets, nbr, broken, kinv, points, g):
    """g_i (1/m) of the owned points in ``points``.  ``kinv`` (n_local, 10) holds
    K^-1 row-major and, in column 9, 1.0 for a point without one (bond-spring
    fallback or not total-Lagrangian): such neighbours contribute nothing."""
    for p in range(points.shape[0]):
        i = points[p]
        g0 = g1 = g2 = 0.0
        di = horizon[i]
        ci = infl[i]
        own = kinv[i, KINV_FLAG] == 0.0
        for b in range(*family(offsets, i)):
            if broken[b]:
                continue
            j = neighbour(nbr, b)
            e0 = x[j, 0] - x[i, 0]
            e1 = x[j, 1] - x[i, 1]
            e2 = x[j, 2] - x[i, 2]
            r = math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
            vj = vol[j]
            wi = influence(ci, di, r) * vj if own else 0.0
            if wi > 0.0:
                g0 += wi * (kinv[i, 0] * e0 + kinv[i, 1] * e1 + kinv[i, 2] * e2)
                g1 += wi * (kinv[i, 3] * e0 + kinv[i, 4] * e1 + kinv[i, 5] * e2)
                g2 += wi * (kinv[i, 6] * e0 + kinv[i, 7] * e1 + kinv[i, 8] * e2)
            wj = influence(infl[j], horizon[j], r) * vj
            if wj > 0.0 and kinv[j, KINV_FLAG] == 0.0:
                g0 += wj * (kinv[j, 0] * e0 + kinv[j, 1] * e1 + kinv[j, 2] * e2)
                g1 += wj * (kinv[j, 3] * e0 + kinv[j, 4] * e1 + kinv[j, 5] * e2)
                g2 += wj * (kinv[j, 6] * e0 + kinv[j, 7] * e1 + kinv[j, 8] * e2)
        g[p, 0] = g0
        g[p, 1] = g1
        g[p, 2] = g2


@numba.njit(cache=True)
def subtract_ghost_force(fd, F, idx, q, active, f, fc, klass, level):
    """f_i -= A_i q_i with A_i = B_i + h_i F_i, at the active points ``idx``;
    fc[p] = -A_i q_i, the correction's force density (0 where it does not act),
    for the energy ledger.  It is part of point i's force state: with step
    classes it acts with i's weight 2^k_i where i's class acts at ``level``
    (kernels.classes)."""
    for p in range(idx.shape[0]):
        for r in range(3):
            fc[p, r] = 0.0
        if not active[p]:
            continue
        i = idx[p]
        ri = weight(klass[i], level)
        if ri == 0.0:
            continue
        if fd[i, FD_SPRING] != 0.0:                  # bond-spring fallback this step: no P
            continue
        h = fd[i, FD_H]
        for r in range(3):
            acc = 0.0
            for c in range(3):
                acc += (fd[i, 3 * r + c] + h * F[i, r, c]) * q[p, c]
            acc *= ri
            f[i, r] -= acc
            fc[p, r] = -acc


@numba.njit(cache=True)
def retire(idx, active, offsets, nbr, broken, mode):
    """Switch the correction off for good at points that lost a bond or whose
    family holds a failed point (their geometry is no longer the reference one).
    Returns how many were switched off."""
    n = 0
    for p in range(idx.shape[0]):
        if not active[p]:
            continue
        i = idx[p]
        hit = mode[i] != 0
        b = offsets[i]
        while not hit and b < offsets[i + 1]:
            hit = broken[b] != 0 or mode[neighbour(nbr, b)] != 0
            b += 1
        if hit:
            active[p] = 0
            n += 1
    return n


@numba.njit(cache=True)
def family_reach(horizon, offsets, nbr, idx, out):
    """out[p] = the largest horizon among point idx[p] and its family."""
    for p in range(idx.shape[0]):
        i = idx[p]
        m = horizon[i]
        for b in range(*family(offsets, i)):
            m = max(m, horizon[neighbour(nbr, b)])
        out[p] = m


@numba.njit(cache=True)
def mixed_families(dx, horizon, infl, offsets, nbr, n_owned, out):
    """out[i] = 1 for owned i whose family holds a point of another dx, horizon
    or influence function."""
    for i in range(n_owned):
        hit = 0
        for b in range(*family(offsets, i)):
            j = neighbour(nbr, b)
            if dx[j] != dx[i] or horizon[j] != horizon[i] or infl[j] != infl[i]:
                hit = 1
                break
        out[i] = hit


@numba.njit(cache=True)
def spread(flag, offsets, nbr, n_owned, out):
    """out[i] = 1 for owned i flagged itself or with a flagged family member."""
    for i in range(n_owned):
        hit = flag[i]
        b = offsets[i]
        while hit == 0 and b < offsets[i + 1]:
            hit = flag[neighbour(nbr, b)]
            b += 1
        out[i] = hit
