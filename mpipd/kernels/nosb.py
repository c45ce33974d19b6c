"""Correspondence (non-ordinary state-based) kernels, gather form.

Notation (paper §2.1): xi = x_j - x_i (reference bond), Y = xi + u_j - u_i
(deformed bond), omega_i = omega(|xi|) with point i's influence function and
horizon delta_i (mpipd.kernels.influence; ``infl`` holds every local point's
code, ghosts included), zero for |xi| >= delta_i:

      quadratic (default, the paper's)  omega = (delta - |xi|)^2
      constant  (Peridigm's default)    omega = 1
      inverse                           omega = delta / |xi|

omega_j of the same bond always uses point j's function and horizon.

* Shape tensor (Eq. 4):    K_i = sum_j omega_i xi (x) xi V_j
* Deformation gradient (Eq. 5) and its rate (Eq. 13):
      F_i = [sum_j omega_i Y (x) xi V_j] K_i^-1,  Fdot_i = [sum_j omega_i Ydot (x) xi V_j] K_i^-1
* Force state (Eq. 2) with P = J sigma F^-T (Eq. 3 corrected, see DESIGN §6):
      T_i<xi> = omega_i A_i xi,  A_i = P_i K_i^-1
* Hourglass penalty (Eq. 15), made dimensionally consistent and conservative:
      T^hg_i<xi> = omega_i h_i (Y - F_i xi),  h_i = 2 c M / tr(K_i)
  with M a material modulus (the shear modulus) and c the scene's coefficient.
  It is the gradient of the energy  E_hg = sum_i V_i (h_i / 2) sum_j omega_i |Y - F_i xi|^2 V_j;
  since F_i is the omega-weighted least-squares fit of Y, dE/dF_i = 0 and the
  force is exactly this state.  Affine fields feel no penalty (Y = F xi).
* The pair force density on owned point i (Eq. 1) is gathered, never scattered:
      f_i = sum_j (T_i<xi_ij> - T_j<xi_ji>) V_j
          = sum_j [omega_i (B_i xi + h_i Y) + omega_j (B_j xi + h_j Y)] V_j,
  with the per-point force data B = A - h F, h and the fallback flag, which
  the owner of every ghost computes and the halo copies — 11 numbers a point.
  Point i's own term is summed before its 3x3 product: sum_j omega_i (B_i xi +
  h_i Y) V_j = B_i s_xi + h_i s_Y, s_xi = sum_j omega_i V_j xi, s_Y likewise of Y.
* Bond-spring fallback (paper §2.1) where K (too few intact bonds) or F
  (J <= 0) cannot be inverted, or where K has lost so much of its smallest
  eigenvalue that the point's force is stiffer than the step can integrate
  (mpipd.model.correspondence.stable_floor): that side of the bond acts as a
  bond-based spring, T = (c_bb / 2) s Y/|Y| with c_bb = 18 k / (pi delta^4) and
      s = (|Y| - |G_i xi|) / |xi|,
  G_i the point's spring reference map: its last regular F when it switched to the
  springs (I until then).  The spring holds the elastic stretch from the
  configuration the point had reached, not its whole stretch from the reference:
  the standard PMB stretch s = |Y|/|xi| - 1 (G = I) would charge a point that flowed plastically to
  twice its length with springs loaded to s ~ 1, energy its stress never held
  (studies/validation/notes.md §40).  G is owned-point state, copied to the ghosts
  with the force data.
"""
import math

import numba
import numpy as np

from . import BOND_LOOP
from .classes import weights
from .contact import contact_force
from .index import family, neighbour
from .influence import influence
from .layout import (
    CORRESPONDENCE,
    FD_H,
    FD_SPRING,
    FD_VISC_L,
    FD_VISC_Q,
    NOT_TL,
    SPRING_F,
    SPRING_K,
)
from .linalg import det3, inv3, mul3, mul3_bt, principal_max_min, voigt_to_mat
from .viscosity import viscous_bond


@numba.njit(cache=True, inline="always")
def bond(x, i, j, code, delta):
    """Reference bond xi = x_j - x_i, |xi| and omega_i (no volume), for point i's
    influence ``code`` and horizon ``delta``."""
    e0 = x[j, 0] - x[i, 0]
    e1 = x[j, 1] - x[i, 1]
    e2 = x[j, 2] - x[i, 2]
    r = math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
    return e0, e1, e2, r, influence(code, delta, r)


@numba.njit(cache=True)
def shape_tensors(x, vol, horizon, infl, offsets, nbr, broken, Kinv, trK, gamma, lam, spring,
                  rcond, floor, points):
    """K^-1, tr K, lambda_min(K) (``lam``; 0 where K cannot be inverted) and
    gamma = sum_j omega V_j (Eq. 43) for the owned points in ``points``.

    A point is marked ``spring[i] = SPRING_K`` (bond-spring fallback) if it has fewer
    than 3 intact bonds, if det K <= rcond (tr K / 3)^3 (K cannot be inverted), or if
    lambda_min(K) < floor[i]: its correspondence force would be stiffer than the
    step can integrate (``floor``: mpipd.model.correspondence.stable_floor).
    Returns how many are.
    """
    K = np.empty((3, 3))
    n_spring = 0
    for p in range(points.shape[0]):
        i = points[p]
        k00 = k01 = k02 = k11 = k12 = k22 = 0.0
        g = 0.0
        nb = 0
        di = horizon[i]
        ci = infl[i]
        for b in range(*family(offsets, i)):
            if broken[b]:
                continue
            j = neighbour(nbr, b)
            e0, e1, e2, r, w = bond(x, i, j, ci, di)
            if w == 0.0:
                continue
            w *= vol[j]
            g += w
            k00 += w * e0 * e0
            k01 += w * e0 * e1
            k02 += w * e0 * e2
            k11 += w * e1 * e1
            k12 += w * e1 * e2
            k22 += w * e2 * e2
            nb += 1
        K[0, 0] = k00
        K[1, 1] = k11
        K[2, 2] = k22
        K[0, 1] = K[1, 0] = k01
        K[0, 2] = K[2, 0] = k02
        K[1, 2] = K[2, 1] = k12
        tr = k00 + k11 + k22
        trK[i] = tr
        gamma[i] = g
        d = det3(K)
        lmin = 0.0
        if nb >= 3 and d > rcond * (tr / 3.0) ** 3:
            lmin = principal_max_min(k00, k11, k22, k12, k02, k01)[1]
        lam[i] = lmin
        if lmin == 0.0 or lmin < floor[i]:
            spring[i] = SPRING_K
            n_spring += 1
            for r_ in range(3):
                for c in range(3):
                    Kinv[i, r_, c] = 0.0
        else:
            spring[i] = CORRESPONDENCE
            inv3(K, Kinv[i])
    return n_spring


@numba.njit(cache=True)
def bond_influence(x, horizon, infl, offsets, nbr, wi, wj, rinv):
    """Both ends' influence of every bond b = (i, j) of the reference configuration:
    wi[b] = omega_i(|xi|) (point i's function and horizon), wj[b] = omega_j(|xi|),
    and rinv[b] = 1 / |xi|.  They depend on reference positions only, so they are
    computed once; the hot kernels read them instead of evaluating |xi| and omega
    each step (a square root and a division a bond saved where the viscosity and
    the dilatation rate need the unit bond xi/|xi|)."""
    n = offsets.shape[0] - 1
    for i in range(n):
        for b in range(*family(offsets, i)):
            j = neighbour(nbr, b)
            r, wi[b] = bond(x, i, j, infl[i], horizon[i])[3:]
            wj[b] = influence(infl[j], horizon[j], r)
            rinv[b] = 1.0 / r


@numba.njit(**BOND_LOOP)
def deformation_gradients(x, u, v, vol, wi, rinv, offsets, nbr, broken, Kinv, spring, F, Fdot,
                          dil, klass, level):
    """F (Eq. 5) and Fdot (Eq. 13) of every owned point whose step class
    ``klass[i]`` acts at ``level`` (kernels.classes), from u and v (``wi``: the
    bonds' omega_i, :func:`bond_influence`).  If ``dil`` has rows, also
    dil_i = sum_j omega Ydot . xi/|xi| V_j (gamma phi of Eq. 44; ``rinv``: 1/|xi|)."""
    want_dil = dil.shape[0] > 0
    n = offsets.shape[0] - 1
    N = np.empty((3, 3))
    Nd = np.empty((3, 3))
    for i in range(n):
        if klass[i] > level:
            continue
        if spring[i] == SPRING_K or spring[i] == NOT_TL:         # no F
            for r in range(3):
                for c in range(3):
                    F[i, r, c] = 1.0 if r == c else 0.0
                    Fdot[i, r, c] = 0.0
            continue
        n00 = n01 = n02 = n10 = n11 = n12 = n20 = n21 = n22 = 0.0
        acc = 0.0
        m00 = m01 = m02 = m10 = m11 = m12 = m20 = m21 = m22 = 0.0
        xi0, xi1, xi2 = x[i, 0], x[i, 1], x[i, 2]
        ui0, ui1, ui2 = u[i, 0], u[i, 1], u[i, 2]
        vi0, vi1, vi2 = v[i, 0], v[i, 1], v[i, 2]
        for b in range(*family(offsets, i)):
            if broken[b]:
                continue
            j = neighbour(nbr, b)
            e0 = x[j, 0] - xi0
            e1 = x[j, 1] - xi1
            e2 = x[j, 2] - xi2
            w = wi[b] * vol[j]
            y0 = e0 + (u[j, 0] - ui0)
            y1 = e1 + (u[j, 1] - ui1)
            y2 = e2 + (u[j, 2] - ui2)
            z0 = w * (v[j, 0] - vi0)
            z1 = w * (v[j, 1] - vi1)
            z2 = w * (v[j, 2] - vi2)
            y0 *= w
            y1 *= w
            y2 *= w
            n00 += y0 * e0
            n01 += y0 * e1
            n02 += y0 * e2
            n10 += y1 * e0
            n11 += y1 * e1
            n12 += y1 * e2
            n20 += y2 * e0
            n21 += y2 * e1
            n22 += y2 * e2
            m00 += z0 * e0
            m01 += z0 * e1
            m02 += z0 * e2
            m10 += z1 * e0
            m11 += z1 * e1
            m12 += z1 * e2
            m20 += z2 * e0
            m21 += z2 * e1
            m22 += z2 * e2
            if want_dil:
                acc += (z0 * e0 + z1 * e1 + z2 * e2) * rinv[b]
        if want_dil:
            dil[i] = acc
        N[0, 0], N[0, 1], N[0, 2] = n00, n01, n02
        N[1, 0], N[1, 1], N[1, 2] = n10, n11, n12
        N[2, 0], N[2, 1], N[2, 2] = n20, n21, n22
        Nd[0, 0], Nd[0, 1], Nd[0, 2] = m00, m01, m02
        Nd[1, 0], Nd[1, 1], Nd[1, 2] = m10, m11, m12
        Nd[2, 0], Nd[2, 1], Nd[2, 2] = m20, m21, m22
        mul3(N, Kinv[i], F[i])
        mul3(Nd, Kinv[i], Fdot[i])


@numba.njit(cache=True)
def gradients_of(rows, x, u, vol, horizon, infl, offsets, nbr, broken, Kinv, spring, F):
    """F (Eq. 5) of the owned points ``rows`` only (I where spring[i] is SPRING_K or NOT_TL), into
    F[p] for rows[p]: the same sums, in the same order, as deformation_gradients."""
    N = np.empty((3, 3))
    for p in range(rows.shape[0]):
        i = rows[p]
        for r in range(3):
            for c in range(3):
                N[r, c] = 0.0
                F[p, r, c] = 1.0 if r == c else 0.0
        if spring[i] == SPRING_K or spring[i] == NOT_TL:
            continue
        di = horizon[i]
        ci = infl[i]
        for b in range(*family(offsets, i)):
            if broken[b]:
                continue
            j = neighbour(nbr, b)
            e0 = x[j, 0] - x[i, 0]
            e1 = x[j, 1] - x[i, 1]
            e2 = x[j, 2] - x[i, 2]
            r = math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
            w = influence(ci, di, r) * vol[j]
            y0 = w * (e0 + (u[j, 0] - u[i, 0]))
            y1 = w * (e1 + (u[j, 1] - u[i, 1]))
            y2 = w * (e2 + (u[j, 2] - u[i, 2]))
            N[0, 0] += y0 * e0
            N[0, 1] += y0 * e1
            N[0, 2] += y0 * e2
            N[1, 0] += y1 * e0
            N[1, 1] += y1 * e1
            N[1, 2] += y1 * e2
            N[2, 0] += y2 * e0
            N[2, 1] += y2 * e1
            N[2, 2] += y2 * e2
        mul3(N, Kinv[i], F[p])


@numba.njit(cache=True)
def force_data(F, F_old, R, sigma, Kinv, trK, spring, hg_modulus, Jfac, fd, G, toggled, klass,
               level):
    """Per-point force data of owned points: fd[i, :9] = B = A - h F (row-major),
    fd[i, FD_H] = h, fd[i, FD_SPRING] = 1.0 for a bond-spring point, else 0.0, with
    A = c J sigma F^-T K^-1 (J = det F, c = Jfac[i] the volume factor),
    sigma = R sigma_unrot R^T, h = 2 M / tr K.

    ``hg_modulus[i]`` is c * M of the point's material.  Points whose K cannot
    be inverted (``spring[i] = SPRING_K``, set by shape_tensors) use the bond-spring
    fallback; so, for this step only, does a point whose F is singular or not
    finite (``spring[i] = SPRING_F``, re-tested every step).  The points that switched
    between 0 and 2 in this call are written to ``toggled`` (their energy is
    booked by the ledger); one that switched to 2 takes F_old, its F of the last
    step (regular), as its spring reference map G (module docstring).  Only points whose class acts at ``level``
    (kernels.classes) are evaluated; the others keep their last force data.
    Returns (points on SPRING_F, points toggled).
    """
    n_owned = F.shape[0]
    S = np.empty((3, 3))
    T1 = np.empty((3, 3))
    T2 = np.empty((3, 3))
    Finv = np.empty((3, 3))
    P = np.empty((3, 3))
    n_bad = 0
    n_tog = 0
    for i in range(n_owned):
        if klass[i] > level:
            continue
        if spring[i] == CORRESPONDENCE or spring[i] == SPRING_F:      # F exists
            was = spring[i]
            J = det3(F[i])
            if J > 0.0 and math.isfinite(J):
                spring[i] = CORRESPONDENCE
            else:
                spring[i] = SPRING_F   # singular (or non-finite) F this step
                n_bad += 1
            if spring[i] != was:
                toggled[n_tog] = i
                n_tog += 1
                if spring[i] == SPRING_F:
                    for r in range(3):
                        for c in range(3):
                            G[i, r, c] = F_old[i, r, c]
        if spring[i] != CORRESPONDENCE:
            for c in range(FD_SPRING):
                fd[i, c] = 0.0
            fd[i, FD_SPRING] = 1.0
            continue
        voigt_to_mat(sigma[i], S)
        mul3(R[i], S, T1)
        mul3_bt(T1, R[i], T2)          # sigma = R S R^T
        J = Jfac[i] * inv3(F[i], Finv)
        mul3_bt(T2, Finv, T1)          # sigma F^-T
        for r in range(3):
            for c in range(3):
                P[r, c] = J * T1[r, c]
        mul3(P, Kinv[i], T1)           # A = P K^-1
        h = 2.0 * hg_modulus[i] / trK[i]
        for r in range(3):
            for c in range(3):
                fd[i, 3 * r + c] = T1[r, c] - h * F[i, r, c]
        fd[i, FD_H] = h
        fd[i, FD_SPRING] = 0.0
    return n_bad, n_tog


@numba.njit(**BOND_LOOP)
def gather_forces(x, u, v, vol, horizon, wi, wj, rinv, offsets, nbr, broken, fd, G, cbb, contact,
                  f, fv, klass, kmin, level):
    """Internal force density f (N/m^3) of every owned point (see module docstring);
    ``wi``, ``wj``, ``rinv``: the bonds' omega_i, omega_j and 1/|xi| (:func:`bond_influence`);
    ``G``: every local point's spring reference map (read where an end is on the springs).

    ``contact``: broken bonds in compression push apart (Eq. 40, see
    kernels.contact).  If ``fd`` has 13 columns, the artificial viscosity
    (Eqs. 42–44, see kernels.viscosity) acts too, from fd[:, FD_VISC_L], fd[:, FD_VISC_Q] and v; its
    share of f is also written to ``fv`` (for the energy ledger's viscous work).  Its
    term is evaluated on every bond, without a branch: where neither end is being
    compressed its coefficients are 0 and so is the term, and a branch that the
    data decides half the time costs more than the term.

    Multi-rate (kernels.classes): each point's state enters with its weight
    2^k_i if its class acts at ``level``, else 0 (so f is the impulse of the
    step over dt); a broken pair's contact, a pair force, with the weight of the
    pair's finer class.  Both ends of a bond see the same weights, so every
    bond's impulses are equal and opposite.  A point whose closed family has
    no class acting (``kmin[i] > level``) gets f = 0.
    """
    _gather(x, u, v, vol, horizon, wi, wj, rinv, offsets, nbr, broken, fd, G, cbb, contact, f, fv,
            klass, klass, kmin, level, kmin[:0].astype(np.int64), False)


@numba.njit(**BOND_LOOP)
def gather_reweight(x, u, v, vol, horizon, wi, wj, rinv, offsets, nbr, broken, fd, G, cbb,
                    contact, rows, old, new, top, g, gv):
    """g[p] (gv[p]: its viscous share) = f_i(classes ``new``) - f_i(classes ``old``) at a
    coarse boundary (``top``: every class acts) for the owned points i = rows[p], in
    one pass over their bonds: a bond's force (:func:`gather_forces`) is linear in
    the weights of its two states and of its contact, so the difference is the
    bond's force with the differences of the weights, and a bond whose two ends
    kept their classes adds exactly 0 and is passed over unread.  The same sums as
    two gathers, up to rounding."""
    _gather(x, u, v, vol, horizon, wi, wj, rinv, offsets, nbr, broken, fd, G, cbb, contact, g, gv,
            new, old, new, top, rows, True)


@numba.njit(**BOND_LOOP)
def _gather(x, u, v, vol, horizon, wi, wj, rinv, offsets, nbr, broken, fd, G, cbb, contact, f, fv,
            klass, old, kmin, level, rows, diff):
    """Eq. 1 for owned points with the multi-rate weights: every owned point (row i of
    f) if not ``diff``; else the points rows[q] (row q of f) with the weights of
    ``klass`` minus those of ``old``."""
    n = rows.shape[0] if diff else offsets.shape[0] - 1
    visc = fd.shape[1] > 11
    wt = weights(level)
    for q in range(n):
        i = rows[q] if diff else q
        if not diff and kmin[i] > level:
            for c in range(3):
                f[q, c] = 0.0
                if visc:
                    fv[q, c] = 0.0
            continue
        ki = klass[i]
        koi = old[i]
        ri = wt[ki]
        if diff:
            ri -= wt[koi]
        xi0, xi1, xi2 = x[i, 0], x[i, 1], x[i, 2]
        ui0, ui1, ui2 = u[i, 0], u[i, 1], u[i, 2]
        di = horizon[i]
        si = fd[i, FD_SPRING]
        li = fd[i, FD_VISC_L] if visc else 0.0
        qi = fd[i, FD_VISC_Q] if visc else 0.0
        fx = fy = fz = 0.0
        gx = gy = gz = 0.0
        # i's own force state, summed over the bonds first: sum_j omega_i (B_i xi +
        # h_i Y) V_j = B_i s_xi + h_i s_Y, with s_xi = sum_j omega_i V_j xi and s_Y the
        # same of Y (its share of Eq. 1 without a 3x3 product per bond)
        sx0 = sx1 = sx2 = sy0 = sy1 = sy2 = 0.0
        for k in range(*family(offsets, i)):
            j = neighbour(nbr, k)
            kj = klass[j]
            # the bonds that carry no force (no change of force) at this level are
            # passed over before their positions are read
            rc = rj = 0.0
            if diff:
                koj = old[j]
                if ri == 0.0 and kj == koj:
                    continue
                if broken[k]:
                    rc = wt[min(ki, kj)] - wt[min(koi, koj)]
                    if not contact or rc == 0.0:
                        continue
                else:
                    rj = wt[kj] - wt[koj]
            elif broken[k]:
                if not (contact and min(ki, kj) <= level):
                    continue
                rc = wt[min(ki, kj)]
            else:
                rj = wt[kj]
                if ri == 0.0 and rj == 0.0:
                    continue
            e0 = x[j, 0] - xi0
            e1 = x[j, 1] - xi1
            e2 = x[j, 2] - xi2
            y0 = e0 + (u[j, 0] - ui0)
            y1 = e1 + (u[j, 1] - ui1)
            y2 = e2 + (u[j, 2] - ui2)
            if broken[k]:                # in contact, its pair acting now
                g = contact_force(y0, y1, y2, e0 * e0 + e1 * e1 + e2 * e2,
                                  0.5 * (cbb[i] + cbb[j]), 0.5 * (di + horizon[j])) * rc
                vj = vol[j]
                fx += g * y0 * vj
                fy += g * y1 * vj
                fz += g * y2 * vj
                continue
            # both force states without a branch on the weights: a zero weight makes its
            # term 0, and a bond-spring point's B and h are 0 (force_data); i's own sums
            # are applied after the loop only if i acts as a correspondence point
            vj = vol[j]
            a = wi[k] * vj
            sx0 += a * e0
            sx1 += a * e1
            sx2 += a * e2
            sy0 += a * y0
            sy1 += a * y1
            sy2 += a * y2
            w_i = wi[k] * ri
            w_j = wj[k] * rj
            hj = fd[j, FD_H]
            tx = w_j * (fd[j, 0] * e0 + fd[j, 1] * e1 + fd[j, 2] * e2 + hj * y0)
            ty = w_j * (fd[j, 3] * e0 + fd[j, 4] * e1 + fd[j, 5] * e2 + hj * y1)
            tz = w_j * (fd[j, 6] * e0 + fd[j, 7] * e1 + fd[j, 8] * e2 + hj * y2)
            sj = fd[j, FD_SPRING]
            if si != 0.0 or sj != 0.0:      # an end on the bond-spring fallback
                r = math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
                g = 0.0
                if si != 0.0 and w_i != 0.0:
                    g = _spring(cbb[i], r, rest_length(G, i, e0, e1, e2), y0, y1, y2) * ri
                if sj != 0.0 and w_j != 0.0:
                    g += _spring(cbb[j], r, rest_length(G, j, e0, e1, e2), y0, y1, y2) * rj
                tx += g * y0
                ty += g * y1
                tz += g * y2
            # the viscosity (0 unless an end is being compressed; no branch, see above)
            if visc:
                c = viscous_bond(w_i, w_j, li, qi, fd[j, FD_VISC_L], fd[j, FD_VISC_Q],
                                 v[j, 0] - v[i, 0], v[j, 1] - v[i, 1], v[j, 2] - v[i, 2],
                                 e0, e1, e2, rinv[k])
                cv = c * vol[j]
                gx -= cv * e0
                gy -= cv * e1
                gz -= cv * e2
            fx += tx * vj
            fy += ty * vj
            fz += tz * vj
        if ri != 0.0 and si == 0.0:     # B_i and h_i read only now: fewer values live in the loop
            b0, b1, b2 = fd[i, 0], fd[i, 1], fd[i, 2]
            b3, b4, b5 = fd[i, 3], fd[i, 4], fd[i, 5]
            b6, b7, b8 = fd[i, 6], fd[i, 7], fd[i, 8]
            hi = fd[i, FD_H]
            fx += ri * (b0 * sx0 + b1 * sx1 + b2 * sx2 + hi * sy0)
            fy += ri * (b3 * sx0 + b4 * sx1 + b5 * sx2 + hi * sy1)
            fz += ri * (b6 * sx0 + b7 * sx1 + b8 * sx2 + hi * sy2)
        f[q, 0] = fx + gx
        f[q, 1] = fy + gy
        f[q, 2] = fz + gz
        if visc:
            fv[q, 0] = gx
            fv[q, 1] = gy
            fv[q, 2] = gz


@numba.njit(cache=True, inline="always")
def _spring(c, r, rest, y0, y1, y2):
    """Half a bond-based spring: (c/2) s / |Y|, s = (|Y| - rest) / r, to multiply Y."""
    ly = math.sqrt(y0 * y0 + y1 * y1 + y2 * y2)
    if ly == 0.0:
        return 0.0
    return 0.5 * c * ((ly - rest) / r) / ly


@numba.njit(cache=True, inline="always")
def rest_length(G, i, e0, e1, e2):
    """|G_i xi|: the rest length of bond xi = (e0, e1, e2) in point i's bond springs
    (module docstring; |-xi| gives the same for the bond's other direction)."""
    a = G[i, 0, 0] * e0 + G[i, 0, 1] * e1 + G[i, 0, 2] * e2
    b = G[i, 1, 0] * e0 + G[i, 1, 1] * e1 + G[i, 1, 2] * e2
    c = G[i, 2, 0] * e0 + G[i, 2, 1] * e1 + G[i, 2, 2] * e2
    return math.sqrt(a * a + b * b + c * c)
