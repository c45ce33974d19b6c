"""Updated-Lagrangian (Eulerian) correspondence kernels for the explosive gas
(paper §2.6, Eqs. 45–48; Silling et al. 2017; Behzadinasab & Foster 2020).

Bonds live in the current configuration: Y = y_j - y_i, omega_i = (delta_i - |Y|)^2,
always quadratic (a part's ``influence`` key acts on the total-Lagrangian kernels only).
For an owned gas point i over its current family (gas and the solids it acts on):

    M_i = sum_j omega_i Y (x) Y V_j                      (Eq. 45)
    L_i = [sum_j omega_i Ydot (x) Y V_j] M_i^-1           (Eq. 46)
    V_i <- V_i exp(tr L_i dt),  V_R = V_i / V0_i        (volume from tr L)
    e_i <- e_i - p_i (V_R,new - V_R,old)                 (adiabatic, per initial volume)
    p_i = lambda(t) k JWL(V_R, e_i),  A_i = sigma_i M_i^-1 = -p_i M_i^-1   (Eqs. 47, 48)

with lambda the programmed-burn fraction and k the explosive's pressure
factor.  Force density on any owned point i, per unit reference volume:

    f_i = (V_i / V0_i) sum_j [omega_i A_i Y + omega_j A_j Y] V_j

(gathered; omega is zero for a solid's own side).  The power of these forces
is sum_i V_i p_i tr L_i, exactly the rate at which the energy equation takes
energy out of the gas, so energy is conserved up to the time discretisation.
Per point, the halo carries gd = [A (6, Voigt), V, p].
"""
import math

import numba
import numpy as np

from .linalg import inv3

#: fewest current neighbours, and smallest det M / (tr M / 3)^3, for a gas point to act
MIN_NEIGHBOURS = 6
RCOND_M = 1e-3


@numba.njit(cache=True, inline="always")
def current_bond(y, i, j):
    """Deformed bond Y = y_j - y_i and |Y|."""
    y0 = y[j, 0] - y[i, 0]
    y1 = y[j, 1] - y[i, 1]
    y2 = y[j, 2] - y[i, 2]
    return y0, y1, y2, math.sqrt(y0 * y0 + y1 * y1 + y2 * y2)


@numba.njit(cache=True)
def gas_update(gas_idx, y, v, V_ref, V_snap, gd, delta, offsets, nbr, dt, t, t_lit, t_ramp,
               V0, e, A, B, R1, R2, w, kfac, is_gas):
    """Advance volume, energy and pressure of the owned gas points ``gas_idx`` and
    fill their force data gd[i] = [A (Voigt 6), V, p].  offsets/nbr: current families
    (rows = owned points); ``V_snap`` the gas volumes at the start of the step (so
    the result does not depend on the update order).  Returns the number of gas
    points with a singular M."""
    M = np.empty((3, 3))
    Mi = np.empty((3, 3))
    N = np.empty((3, 3))
    n_bad = 0
    for k in range(gas_idx.shape[0]):
        i = gas_idx[k]
        di = delta[i]
        for r in range(3):
            for c in range(3):
                M[r, c] = 0.0
                N[r, c] = 0.0
        nb = 0
        for b in range(offsets[i], offsets[i + 1]):
            j = nbr[b]
            y0, y1, y2, ly = current_bond(y, i, j)
            if ly >= di:
                continue
            wgt = (di - ly) * (di - ly) * (V_snap[j] if is_gas[j] else V_ref[j])
            z0 = v[j, 0] - v[i, 0]
            z1 = v[j, 1] - v[i, 1]
            z2 = v[j, 2] - v[i, 2]
            M[0, 0] += wgt * y0 * y0
            M[0, 1] += wgt * y0 * y1
            M[0, 2] += wgt * y0 * y2
            M[1, 1] += wgt * y1 * y1
            M[1, 2] += wgt * y1 * y2
            M[2, 2] += wgt * y2 * y2
            N[0, 0] += wgt * z0 * y0
            N[0, 1] += wgt * z0 * y1
            N[0, 2] += wgt * z0 * y2
            N[1, 0] += wgt * z1 * y0
            N[1, 1] += wgt * z1 * y1
            N[1, 2] += wgt * z1 * y2
            N[2, 0] += wgt * z2 * y0
            N[2, 1] += wgt * z2 * y1
            N[2, 2] += wgt * z2 * y2
            nb += 1
        M[1, 0] = M[0, 1]
        M[2, 0] = M[0, 2]
        M[2, 1] = M[1, 2]
        tr = M[0, 0] + M[1, 1] + M[2, 2]
        det = (M[0, 0] * (M[1, 1] * M[2, 2] - M[1, 2] * M[2, 1])
               - M[0, 1] * (M[1, 0] * M[2, 2] - M[1, 2] * M[2, 0])
               + M[0, 2] * (M[1, 0] * M[2, 1] - M[1, 1] * M[2, 0]))
        # a gas point that has lost its neighbourhood (escaped through a crack, or
        # with neighbours nearly coplanar) carries no pressure force
        singular = nb < MIN_NEIGHBOURS or not det > RCOND_M * (tr / 3.0) ** 3
        trL = 0.0
        if not singular:
            inv3(M, Mi)
            for r in range(3):
                for c in range(3):
                    trL += N[r, c] * Mi[c, r]          # tr(N M^-1)
        else:
            n_bad += 1
        V_old = V_snap[i]
        V_new = V_old * math.exp(trL * dt)
        p_old = gd[i, 7]
        e[k] -= p_old * (V_new - V_old) / V0[k]
        lam = 1.0 if t_ramp <= 0.0 else (t - t_lit[k]) / t_ramp
        lam = 0.0 if lam < 0.0 else (1.0 if lam > 1.0 else lam)
        VR = V_new / V0[k]
        p = 0.0
        if lam > 0.0:
            p = lam * kfac * (A * (1.0 - w / (R1 * VR)) * math.exp(-R1 * VR)
                              + B * (1.0 - w / (R2 * VR)) * math.exp(-R2 * VR) + w * e[k] / VR)
        gd[i, 6] = V_new
        gd[i, 7] = p
        if singular or p == 0.0:
            for c in range(6):
                gd[i, c] = 0.0
        else:
            gd[i, 0] = -p * Mi[0, 0]
            gd[i, 1] = -p * Mi[1, 1]
            gd[i, 2] = -p * Mi[2, 2]
            gd[i, 3] = -p * Mi[1, 2]
            gd[i, 4] = -p * Mi[0, 2]
            gd[i, 5] = -p * Mi[0, 1]
    return n_bad


@numba.njit(cache=True)
def gas_gather(rows, y, V_ref, V0_ratio, gd, delta, offsets, nbr, is_gas, f):
    """Add the updated-Lagrangian pair forces to f of the owned points ``rows``."""
    for k in range(rows.shape[0]):
        i = rows[k]
        di = delta[i] if is_gas[i] else 0.0
        fx = fy = fz = 0.0
        for b in range(offsets[i], offsets[i + 1]):
            j = nbr[b]
            y0, y1, y2, ly = current_bond(y, i, j)
            tx = ty = tz = 0.0
            if ly < di:
                w = (di - ly) * (di - ly)
                tx += w * (gd[i, 0] * y0 + gd[i, 5] * y1 + gd[i, 4] * y2)
                ty += w * (gd[i, 5] * y0 + gd[i, 1] * y1 + gd[i, 3] * y2)
                tz += w * (gd[i, 4] * y0 + gd[i, 3] * y1 + gd[i, 2] * y2)
            if is_gas[j]:
                dj = delta[j]
                if ly < dj:
                    w = (dj - ly) * (dj - ly)
                    tx += w * (gd[j, 0] * y0 + gd[j, 5] * y1 + gd[j, 4] * y2)
                    ty += w * (gd[j, 5] * y0 + gd[j, 1] * y1 + gd[j, 3] * y2)
                    tz += w * (gd[j, 4] * y0 + gd[j, 3] * y1 + gd[j, 2] * y2)
            vj = gd[j, 6] if is_gas[j] else V_ref[j]
            fx += tx * vj
            fy += ty * vj
            fz += tz * vj
        s = V0_ratio[i]
        f[i, 0] += s * fx
        f[i, 1] += s * fy
        f[i, 2] += s * fz
