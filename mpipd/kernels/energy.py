"""Kernels of the energy ledger (mpipd.model.ledger, DESIGN §8b).

Held potential energies, each *owned by one point* (a sum over that point's own
family), so that any subset of points can be evaluated before and after an
event that changes them discontinuously (bonds breaking, a point switching to
the bond-spring fallback):

* hourglass (Eq. 15, kernels.nosb):  E_i = V_i (h_i / 2) sum_j omega_i |Y - F_i xi|^2 V_j,
  h_i = 2 c M / tr K_i, for points on the correspondence model (spring[i] = CORRESPONDENCE);
* bond-spring fallback (paper §2.1): point i's half of each intact bond inside its
  horizon, E_i = V_i sum_j (c_bb,i / 4) s^2 |xi| V_j, s = (|Y| - |G_i xi|)/|xi| — the
  potential of the half-spring force (c_bb,i / 2) s Y/|Y| (spring[i] = SPRING_K or
  SPRING_F; G_i the point's spring reference map, kernels.nosb);
* contact (Eq. 40, kernels.contact): half of each broken pair's penalty potential,
  E_i = (V_i / 2) sum_j c_s omegahat (|Y| - |xi|)^2 / (2 delta) V_j for |Y| < |xi|,
  whose gradient is the contact force.

Work of the non-conservative forces by the trapezoidal rule over a step,
W += dt sum_i V_i (f_i^n + f_i^{n+1})/2 . v_i^{n+1/2}, with
u^{n+1} - u^n = dt v^{n+1/2}: with it, velocity Verlet's kinetic energy obeys
K^{n+1} - K^n = (total trapezoidal work) + (dt^2/8) sum m (|a^{n+1}|^2 - |a^n|^2)
exactly, which is why the ledger books the last term as ``integrator``.
"""
import math

import numba

from .index import family, neighbour
from .influence import influence
from .layout import CORRESPONDENCE, NOT_TL
from .linalg import normal_stress
from .nosb import rest_length


@numba.njit(cache=True)
def point_potentials(rows, x, u, vol, horizon, infl, offsets, nbr, broken, F, G, hg_modulus,
                     trK, spring, cbb, contact, out):
    """out[p] = (hourglass, spring, contact) energy (J) owned by point rows[p]."""
    for p in range(rows.shape[0]):
        i = rows[p]
        di = horizon[i]
        ci = infl[i]
        code = spring[i]
        h = 2.0 * hg_modulus[i] / trK[i] if code == CORRESPONDENCE and trK[i] > 0.0 else 0.0
        ehg = 0.0
        esp = 0.0
        eco = 0.0
        for b in range(*family(offsets, i)):
            j = neighbour(nbr, b)
            e0 = x[j, 0] - x[i, 0]
            e1 = x[j, 1] - x[i, 1]
            e2 = x[j, 2] - x[i, 2]
            r = math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
            y0 = e0 + (u[j, 0] - u[i, 0])
            y1 = e1 + (u[j, 1] - u[i, 1])
            y2 = e2 + (u[j, 2] - u[i, 2])
            if broken[b]:
                if contact:
                    delta = 0.5 * (di + horizon[j])
                    ly = math.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
                    if ly < r and r < delta:
                        w = 1.0 - r / delta
                        cs = 0.5 * (cbb[i] + cbb[j])
                        eco += 0.5 * cs * w * w * (ly - r) ** 2 / (2.0 * delta) * vol[j]
                continue
            wi = influence(ci, di, r)
            if wi == 0.0:
                continue
            if code == CORRESPONDENCE:
                z0 = y0 - (F[i, 0, 0] * e0 + F[i, 0, 1] * e1 + F[i, 0, 2] * e2)
                z1 = y1 - (F[i, 1, 0] * e0 + F[i, 1, 1] * e1 + F[i, 1, 2] * e2)
                z2 = y2 - (F[i, 2, 0] * e0 + F[i, 2, 1] * e1 + F[i, 2, 2] * e2)
                ehg += wi * (z0 * z0 + z1 * z1 + z2 * z2) * vol[j]
            elif code != NOT_TL:
                ly = math.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
                s = (ly - rest_length(G, i, e0, e1, e2)) / r
                esp += 0.25 * cbb[i] * s * s * r * vol[j]
        out[p, 0] = vol[i] * 0.5 * h * ehg
        out[p, 1] = vol[i] * esp
        out[p, 2] = vol[i] * eco


@numba.njit(cache=True)
def trapezoid_work(f_old, f_new, rows, v, vol, dt):
    """dt sum_p V_i (f_old[p] + f_new[p])/2 . v[i] for i = rows[p] (f: force
    densities, N/m^3), then f_old <- f_new.  Returns the work (J)."""
    w = 0.0
    for p in range(rows.shape[0]):
        i = rows[p]
        acc = 0.0
        for c in range(3):
            acc += (f_old[p, c] + f_new[p, c]) * v[i, c]
            f_old[p, c] = f_new[p, c]
        w += 0.5 * dt * vol[i] * acc
    return w


@numba.njit(cache=True)
def integrator_term(a, rho, vol, dt):
    """-(dt^2 / 8) sum_i m_i |a_i|^2: kinetic energy + this is the shadow energy that
    velocity Verlet changes by exactly the trapezoidal work of the forces."""
    e = 0.0
    for i in range(a.shape[0]):
        e += rho[i] * vol[i] * (a[i, 0] ** 2 + a[i, 1] ** 2 + a[i, 2] ** 2)
    return -0.125 * dt * dt * e


@numba.njit(cache=True)
def update_peaks(x, v, sigma, R, gas_idx, gas_p, cx, cy, peak_p, peak_srr, peak_v):
    """Running per-point peaks over the steps: pressure -tr(sigma)/3 (the JWL
    pressure ``gas_p`` at the gas points), -sigma_rr about the z axis through
    (cx, cy) (sigma = R sigma_unrot R^T, so sigma_rr = a . sigma_unrot . a with
    a = R^T e_r, linalg.normal_stress), and |v|."""
    for i in range(sigma.shape[0]):
        s0, s1, s2 = sigma[i, 0], sigma[i, 1], sigma[i, 2]
        s3, s4, s5 = sigma[i, 3], sigma[i, 4], sigma[i, 5]
        p = -(s0 + s1 + s2) / 3.0
        if p > peak_p[i]:
            peak_p[i] = p
        sp = math.sqrt(v[i, 0] ** 2 + v[i, 1] ** 2 + v[i, 2] ** 2)
        if sp > peak_v[i]:
            peak_v[i] = sp
        dx = x[i, 0] - cx
        dy = x[i, 1] - cy
        r = math.sqrt(dx * dx + dy * dy)
        if r > 0.0:
            c, s = dx / r, dy / r
            a0 = R[i, 0, 0] * c + R[i, 1, 0] * s
            a1 = R[i, 0, 1] * c + R[i, 1, 1] * s
            a2 = R[i, 0, 2] * c + R[i, 1, 2] * s
            srr = normal_stress(s0, s1, s2, s3, s4, s5, a0, a1, a2)
            if -srr > peak_srr[i]:
                peak_srr[i] = -srr
    for k in range(gas_idx.shape[0]):
        i = gas_idx[k]
        if gas_p[i] > peak_p[i]:
            peak_p[i] = gas_p[i]
