"""The runaway test of the time loop: relative motion within a family.

A bond (i, j) of reference length |xi| whose ends move apart or together by
more than that length in one step,

    |v_j - v_i| dt > |xi|,

is a strain increment above 1 a step: no explicit integration at a stable dt
does that, so it marks an instability (one that the failure models may keep
finite by zeroing stresses).  The test uses velocity differences only, so it
is Galilean-invariant: a stress-free body in rigid translation at any speed
passes, and so does a rigid rotation slower than one radian a step.  Broken
bonds are skipped: fragments may fly apart at any speed.
"""
import numba
import numpy as np


@numba.njit(cache=True)
def first_runaway(offsets, nbr, broken, x, v, gid, dt):
    """The lowest gid of an owned point (row of ``offsets``) with an unbroken bond
    that stretches or shortens by more than its length in one step; -1 if none."""
    best = -1
    dt2 = dt * dt
    for i in range(offsets.shape[0] - 1):
        for b in range(offsets[i], offsets[i + 1]):
            if broken[b]:
                continue
            j = nbr[b]
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
