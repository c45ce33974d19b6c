"""Contact between points whose bond has broken (paper Eq. 40).

    f_c = c_s * omegahat * min(0, |Y| - |xi|) / delta * Y/|Y|,   c_s = 18 k / (pi delta^4)

a pair force density (per V_i V_j), repulsive only while the pair is closer than
in the reference configuration.  The paper writes the influence function omega
here, which leaves Eq. 40 without consistent units; mpipd uses its
dimensionless form omegahat = omega / delta^2 = (1 - |xi|/delta)^2, whatever
influence function the parts use (mpipd.kernels.influence).  For a pair
of points with different horizons or moduli, c_s and delta are the pair's
means, so the force is equal and opposite.
"""
import math

import numba


@numba.njit(cache=True, inline="always")
def contact_force(y0, y1, y2, r2, cs, delta):
    """Factor g such that the force density on i is g * Y * V_j (Y = y_j - y_i; ``r2``
    = |xi|^2).  A pair no closer than in the reference configuration is told from the
    squares, before any square root: most broken bonds have opened, and a correctly
    rounded square root is monotone, so the verdict is the one |Y| >= |xi| gives."""
    ly2 = y0 * y0 + y1 * y1 + y2 * y2
    if ly2 >= r2 or ly2 == 0.0:
        return 0.0
    ly = math.sqrt(ly2)
    r = math.sqrt(r2)
    if ly >= r or r >= delta:
        return 0.0
    w = 1.0 - r / delta
    return cs * w * w * (ly - r) / delta / ly
