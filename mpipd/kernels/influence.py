"""Influence functions omega(|xi|) of the correspondence model, chosen per part.

A part's ``influence`` key names one; every point carries its code (uint8), and
omega_i of a bond always uses point i's function and horizon delta_i:

    "quadratic"  code 0   omega = (delta - |xi|)^2   the paper's, the default
    "constant"   code 1   omega = 1                  Peridigm's default
    "inverse"    code 2   omega = delta / |xi|

each for |xi| < delta and 0 outside.  omega enters K, F, Fdot, the force state,
the hourglass penalty, the viscosity and the interface correction
(:mod:`mpipd.kernels.nosb`, :mod:`mpipd.kernels.interface`).  The gas's
updated-Lagrangian kernels (:mod:`mpipd.kernels.ul`) keep the quadratic
function of the current bond, and contact (:mod:`mpipd.kernels.contact`) its
own dimensionless weight.
"""
import numba

QUADRATIC = 0
CONSTANT = 1
INVERSE = 2

#: scene name -> code (the one place the names are defined)
CODES = {"quadratic": QUADRATIC, "constant": CONSTANT, "inverse": INVERSE}


@numba.njit(cache=True, inline="always")
def influence(code, delta, r):
    """omega of a bond of length r for influence ``code`` and horizon delta."""
    w = delta - r
    if not w > 0.0:
        return 0.0
    if code == QUADRATIC:
        return w * w
    if code == CONSTANT:
        return 1.0
    return delta / r
