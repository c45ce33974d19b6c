"""The runaway test of the time loop: relative motion within a family.

A pair (i, j) of a family, of reference distance |xi|, whose points move apart
or together by more than that distance in one step,

    |v_j - v_i| dt > |xi|,

has a relative speed above |xi| / dt >= dx / dt, which at a stable dt exceeds
the material's fastest wave speed (dt < dx / c): no deformation, fracture or
fragment flight does that, so it marks an instability (one that the failure
models may keep finite by zeroing stresses, after which the points' bonds are
broken: broken bonds are tested too).  The test uses velocity differences only,
so it is Galilean-invariant: a stress-free body in rigid translation at any
speed passes, and so does a rigid rotation slower than one radian a step.
"""
import numba
import numpy as np

from .index import family, neighbour


@numba.njit(cache=True)
def first_runaway(offsets, nbr, x, v, gid, dt):
    """The lowest gid of an owned point (row of ``offsets``) with a family member
    that moves towards or away from it by more than their reference distance in
    one step; -1 if none."""
    best = -1
    dt2 = dt * dt
    for i in range(offsets.shape[0] - 1):
        for b in range(*family(offsets, i)):
            j = neighbour(nbr, b)
            dv2 = 0.0
            xi2 = 0.0
            for c in range(3):
                dv2 += (v[j, c] - v[i, c]) ** 2
                xi2 += (x[j, c] - x[i, c]) ** 2
            if dv2 * dt2 > xi2 or not np.isfinite(dv2):
                if best < 0 or gid[i] < best:
                    best = gid[i]
                break
    return best
