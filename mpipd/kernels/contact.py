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
def contact_force(y0, y1, y2, r, cs, delta):
    """Factor g such that the force density on i is g * Y * V_j (Y = y_j - y_i)."""
    ly = math.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
    if ly >= r or ly == 0.0 or r >= delta:
        return 0.0
    w = 1.0 - r / delta
    return cs * w * w * (ly - r) / delta / ly
