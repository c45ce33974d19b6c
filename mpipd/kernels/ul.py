"""Updated-Lagrangian (Eulerian) correspondence kernels for the explosive gas
(paper §2.6, Eqs. 45–48; Silling et al. 2017; Behzadinasab & Foster 2020).

Bonds live in the current configuration: Y = y_j - y_i, omega_i = (delta_i - |Y|)^2,
always quadratic (a part's ``influence`` key acts on the total-Lagrangian kernels only).
For an owned gas point i over its current family (gas and the solids it acts on):

    M_i = sum_j omega_i Y (x) Y V_j                      (Eq. 45)
    L_i = [sum_j omega_i Ydot (x) Y V_j] M_i^-1           (Eq. 46)
    V_i <- V_i exp(tr L_i dt),  V_R = V_i / V0_i        (volume from tr L)
    e_i <- e_i - (p_i,old + p_i,new)/2 (V_R,new - V_R,old)   (adiabatic, per initial volume)
    p_i = lambda(t) k JWL(V_R, e_i) + (1 - lambda) p_u(V_R),  A_i = -p_i M_i^-1   (Eqs. 47, 48)

(p_u: the unreacted explosive's Hugoniot pressure, mpipd.materials.jwl.unreacted_pressure;
0 without one.)

Bulk viscosity (mpipd.materials.jwl.BulkViscosity; off when both coefficients are 0).
A point whose volume decreases, tr L_i < 0, carries q_i = rho l (C_q l (tr L)^2 - C_l c tr L)
(rho = rho0 / V_R, c^2 = lam k c_JWL^2 + (1 - lam) c_u^2, l = V0^(1/3): the point's lattice
spacing, for its horizon does not grow with it) besides p_i, and its force state is
A_i = -(p_i + q_i) M_i^-1.  q is a viscosity nu = q / (rho |tr L|), explicit in time, so
it is held to the diffusion limit nu dt / l^2 <= 1/2: q <= rho l^2 |tr L| / (2 dt) (it
binds only where C_q |tr L| dt > 1/2, on a point deforming by tens of per cent in a
step: an escaped point with a sparse family, whose q would otherwise pump energy in).
The energy equation below takes the work of the p part only; the work of the q part
(of the same trapezoid, split in proportion p : q, which is exact because the force
is linear in A) is dissipated, -W_q >= 0, and returned (the ledger's ``gas_viscous``).

Where the gas acts.  A gas point carries a pressure force only where its current
family is a gas neighbourhood (:func:`well_posed`): at least MIN_NEIGHBOURS
neighbours whose second moment M spans a volume, and the same of its gas neighbours
alone, M_g = sum over gas j of omega Y (x) Y V_j.  The solid neighbours give a gas
point at the edge of the gas the motion of the wall; a lone gas point carried in
among solid points (into a crack, below what the lattice resolves) would take the
solid's deformation for its own volume change, and the rock, stiff and nearly
incompressible, would hold it near the detonation pressure, an explosive inclusion
that pushes the rock apart from inside (issue 15: such points at V_R 0.1-0.3 and
67-113 GPa in the contained blast_paper:dx1.2 run, whose energy balance then failed).
Such a point carries no force, its volume and energy stay as they are (its energy
is held: the ledger's ``gas``), and it acts again once it is among gas.

Nor does a point whose family would change its volume by more than a factor
exp(MAX_VOLUME_STRAIN) in one step, |tr L| dt > MAX_VOLUME_STRAIN: its neighbours
then move by a large part of their distance in a step (points passing through one
another), which no continuum update describes, and the implicit energy update below
has no physical solution once its denominator V0 + lam k w b / (2 V_R) turns
negative (for a compression s = -tr L dt, at s e^s = 2 / (lam k w): s ~ 1.5 for
k = 1, w = 0.282; at s = 0.5 it is 0.88 V0 or more for k = 1).  Issue 15: in blast_paper:paper_coupling
four force-free gas points at V_R = 34 coasting onto the charge's axis at 770 m/s met
there at 14 us; their family, well posed again at micrometre spacings, compressed
them to V_R 0.15-0.33 in one step (tr L dt = -4.7), e turned to -1e11 J/m^3, p to
-1.2 GPa, and they left at 100-190 km/s with 3.5 kJ the ledger did not book.  Normal
gas flow stays far below the bound: a detonation front compresses the charge by about
25 % over the 2-3 steps it takes to cross a spacing.

Energy.  The internal energy changes by exactly the trapezoidal work of the
point's own force state (what the energy ledger books for every force, the
"compatible" energy update of Owen 2014 for SPH).  Pair weights are the
volumes at the start of the step, V^w, for M, N and the force alike (so the
force from state i on the pair (i, j), V^w_i V^w_j omega A_i Y, is equal and
opposite); the work of state i's force over the step's displacement
dY = dt Ydot (u^{n+1} - u^n = dt v^{n+1/2}) is

    W = -V^w_i A_i : sum_j omega V^w_j dY (x) Y = p_i V^w_i tr(M_i^-1 N_i) dt,

evaluated for the force of the last step (A^n, positions y^n = y - dt v,
weights V^{w,n}: W_a) and of this step (A^{n+1} = -p^{n+1} M^-1: W_b = p^{n+1} b,
b = V^w_i tr L_i dt), and

    e^{n+1} V0 = e^n V0 - (W_a + W_b) / 2.

JWL is linear in e, p = lam k (f(V_R) + w e / V_R) + (1 - lam) p_u(V_R), so the
implicit update has the closed form
e^{n+1} = (e^n V0 - W_a/2 - (lam k f + (1 - lam) p_u) b/2) / (V0 + lam k w b / (2 V_R)).
The volume itself, V <- V exp(tr L dt), is the EOS's argument.

Contact (mpipd.materials.jwl.GasContact; off when ``frac`` is 0).  A gas-solid pair
closer than d_c = min(frac l, |xi|), l the mean of the two points' lattice spacings
V^(1/3), repels with F = k l (d_c - |Y|) on each point, k = stiffness x rho0 vod^2:
equal and opposite, a potential force (:func:`gas_contact_energy`).

Per point, the halo carries gd = [A (6, Voigt), V, p].
"""
import math
from typing import NamedTuple

import numba
import numpy as np

from .eos import jwl_cold, jwl_sound_speed2, unreacted_pressure, unreacted_sound_speed2
from .index import family, neighbour
from .layout import GD_P, GD_V
from .linalg import det3, inv3

#: fewest current neighbours, and smallest det M / (tr M / 3)^3, for a gas point to act;
#: both hold for its whole family and for its gas neighbours alone (gas_update)
MIN_NEIGHBOURS = 6
RCOND_M = 1e-3
#: largest |tr L| dt of a step for a gas point to act (module docstring)
MAX_VOLUME_STRAIN = 0.5


@numba.njit(cache=True, inline="always")
def current_bond(y, i, j):
    """Deformed bond Y = y_j - y_i and |Y|."""
    y0 = y[j, 0] - y[i, 0]
    y1 = y[j, 1] - y[i, 1]
    y2 = y[j, 2] - y[i, 2]
    return y0, y1, y2, math.sqrt(y0 * y0 + y1 * y1 + y2 * y2)


@numba.njit(cache=True, inline="always")
def add_moment(M, wgt, y0, y1, y2):
    """M += wgt Y (x) Y, upper triangle (the caller mirrors it)."""
    M[0, 0] += wgt * y0 * y0
    M[0, 1] += wgt * y0 * y1
    M[0, 2] += wgt * y0 * y2
    M[1, 1] += wgt * y1 * y1
    M[1, 2] += wgt * y1 * y2
    M[2, 2] += wgt * y2 * y2


@numba.njit(cache=True, inline="always")
def contact_reach(x, vol, i, j, frac):
    """(d_c, l) of the gas-solid pair (i, j): l = (V_i^(1/3) + V_j^(1/3)) / 2 from the
    reference volumes, d_c = min(frac l, |x_j - x_i|) (module docstring)."""
    e0 = x[j, 0] - x[i, 0]
    e1 = x[j, 1] - x[i, 1]
    e2 = x[j, 2] - x[i, 2]
    ell = 0.5 * (vol[i] ** (1.0 / 3.0) + vol[j] ** (1.0 / 3.0))
    return min(frac * ell, math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)), ell


@numba.njit(cache=True)
def well_posed(M, nb):
    """Does a second-moment tensor M of ``nb`` bonds span a volume: nb >= MIN_NEIGHBOURS
    and det M > RCOND_M (tr M / 3)^3 (1 for an isotropic family, 0 for a plane)?"""
    tr = M[0, 0] + M[1, 1] + M[2, 2]
    return nb >= MIN_NEIGHBOURS and det3(M) > RCOND_M * (tr / 3.0) ** 3


class GasParams(NamedTuple):
    """The constants of one explosive as :func:`gas_update` reads them (SI): the burn
    ramp t_ramp (s; 0: lit at once), JWL's A, B, R1, R2, omega (Eq. 48), the factor
    kfac on the products' pressure (``pressure_factor``), the charge's density rho0,
    the bulk viscosity's c_q, c_l (0, 0: none) and the unreacted EOS K_u, s_u, a_u
    (mpipd.materials.jwl.unreacted_pressure; K_u = 0: none).  One named pack, so that
    no two constants can be swapped by position."""
    t_ramp: float
    A: float
    B: float
    R1: float
    R2: float
    w: float
    kfac: float
    rho0: float = 1.0
    c_q: float = 0.0
    c_l: float = 0.0
    K_u: float = 0.0
    s_u: float = 0.0
    a_u: float = 1.0


@numba.njit(cache=True)
def gas_update(gas_idx, y, v, V_ref, V_w, V_pw, gd, delta, offsets, nbr, dt, t, t_lit,
               V0, e, is_gas, vr_lit, gq, prm):
    """Advance volume, energy and pressure of the owned gas points ``gas_idx`` and
    fill their force data gd[i] = [A (Voigt 6), V, p].  offsets/nbr: current families
    (rows = owned points); ``V_w`` the gas volumes at the start of the step (this
    step's pair weights, so the result does not depend on the update order) and
    ``V_pw`` those of the step before (the last force's weights).  Returns the
    number of gas points carrying no force (a singular M, or a family collapsing or
    bursting in a step: MAX_VOLUME_STRAIN) and the work the bulk viscosity took out
    this step (J, module docstring).  ``vr_lit[k]``: V_R of point k at the step it is
    first lit (0 until then).  ``gq[k]``: its bulk viscosity q of the last step,
    replaced by this step's; rho0, c_q, c_l: the charge's density and the
    viscosity's coefficients, and the rest of the charge's constants, are in ``prm``
    (:class:`GasParams`)."""
    t_ramp, A, B, R1, R2, w, kfac = prm.t_ramp, prm.A, prm.B, prm.R1, prm.R2, prm.w, prm.kfac
    rho0, c_q, c_l, K_u, s_u, a_u = prm.rho0, prm.c_q, prm.c_l, prm.K_u, prm.s_u, prm.a_u
    M = np.empty((3, 3))
    Mg = np.empty((3, 3))
    Mi = np.empty((3, 3))
    N = np.empty((3, 3))
    n_bad = 0
    w_q = 0.0
    for k in range(gas_idx.shape[0]):
        i = gas_idx[k]
        di = delta[i]
        for r in range(3):
            for c in range(3):
                M[r, c] = 0.0
                Mg[r, c] = 0.0
                N[r, c] = 0.0
        nb = 0
        ng = 0
        wa = 0.0                                # -A^n : sum omega V dt Ydot (x) Y^n
        a0, a1, a2 = gd[i, 0], gd[i, 1], gd[i, 2]
        a3, a4, a5 = gd[i, 3], gd[i, 4], gd[i, 5]
        old = a0 != 0.0 or a1 != 0.0 or a2 != 0.0 or a3 != 0.0 or a4 != 0.0 or a5 != 0.0
        for b in range(*family(offsets, i)):
            j = neighbour(nbr, b)
            z0 = v[j, 0] - v[i, 0]
            z1 = v[j, 1] - v[i, 1]
            z2 = v[j, 2] - v[i, 2]
            if old:                             # the last force, at y^n = y - dt v
                q0 = y[j, 0] - y[i, 0] - dt * z0
                q1 = y[j, 1] - y[i, 1] - dt * z1
                q2 = y[j, 2] - y[i, 2] - dt * z2
                lq = math.sqrt(q0 * q0 + q1 * q1 + q2 * q2)
                if lq < di:
                    wq = (di - lq) * (di - lq) * (V_pw[j] if is_gas[j] else V_ref[j])
                    wa -= wq * (a0 * z0 * q0 + a1 * z1 * q1 + a2 * z2 * q2
                                + a3 * (z1 * q2 + z2 * q1) + a4 * (z0 * q2 + z2 * q0)
                                + a5 * (z0 * q1 + z1 * q0))
            y0, y1, y2, ly = current_bond(y, i, j)
            if ly >= di:
                continue
            wgt = (di - ly) * (di - ly) * (V_w[j] if is_gas[j] else V_ref[j])
            add_moment(M, wgt, y0, y1, y2)
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
            if is_gas[j]:
                add_moment(Mg, wgt, y0, y1, y2)
                ng += 1
        W_a = wa * V_pw[i] * dt                  # of the last force, A^n = -(p^n + q^n) M^-1
        ptot = gd[i, GD_P] + gq[k]
        W_aq = W_a * gq[k] / ptot if ptot != 0.0 else 0.0
        W_a -= W_aq                             # its p part (the energy equation's)
        for r, c in ((1, 0), (2, 0), (2, 1)):
            M[r, c] = M[c, r]
            Mg[r, c] = Mg[c, r]
        # a gas point that has lost its neighbourhood (escaped, or with neighbours
        # nearly coplanar), or whose gas neighbours alone do not span a volume (a lone
        # point carried into a crack among solid points) carries no pressure force
        singular = (not well_posed(M, nb) or not well_posed(Mg, ng))
        trL = 0.0
        if not singular:
            inv3(M, Mi)
            for r in range(3):
                for c in range(3):
                    trL += N[r, c] * Mi[c, r]          # tr(N M^-1)
            if abs(trL) * dt > MAX_VOLUME_STRAIN:       # a family collapsing in a step
                singular = True
                trL = 0.0
        if singular:
            n_bad += 1
        V_old = V_w[i]
        V_new = V_old * math.exp(trL * dt)
        lam = 1.0 if t_ramp <= 0.0 else (t - t_lit[k]) / t_ramp
        lam = 0.0 if lam < 0.0 else (1.0 if lam > 1.0 else lam)
        VR = V_new / V0[k]
        if lam > 0.0 and vr_lit[k] == 0.0:
            vr_lit[k] = VR
        lk = lam * kfac
        f = jwl_cold(VR, A, B, R1, R2, w)          # Eq. 48 without w e / V
        bb = V_old * trL * dt                   # W_b = p^{n+1} bb (0 if singular)
        pu = (1.0 - lam) * unreacted_pressure(VR, K_u, s_u, a_u)
        e[k] = ((e[k] * V0[k] - 0.5 * W_a - 0.5 * (lk * f + pu) * bb)
                / (V0[k] + 0.5 * lk * w * bb / VR))
        pj = f + w * e[k] / VR                  # the products' JWL pressure
        p = (lk * pj if lam > 0.0 else 0.0) + pu
        q = 0.0
        if trL < 0.0 and (c_q > 0.0 or c_l > 0.0):
            c2 = (lk * jwl_sound_speed2(VR, pj, rho0, A, B, R1, R2, w) if lam > 0.0 else 0.0)
            c2 += (1.0 - lam) * unreacted_sound_speed2(VR, rho0, K_u, s_u, a_u)
            ell = V0[k] ** (1.0 / 3.0)
            rho = rho0 / VR
            q = rho * ell * (c_q * ell * trL * trL - c_l * math.sqrt(max(c2, 0.0)) * trL)
            q = min(q, -0.5 * rho * ell * ell * trL / dt)     # its explicit limit
        w_q -= 0.5 * (W_aq + q * bb)             # -W_q: the work q took out (trapezoid)
        gq[k] = q
        gd[i, GD_V] = V_new
        gd[i, GD_P] = p
        p += q                                  # the force state's pressure
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
    return n_bad, w_q


@numba.njit(cache=True)
def gas_gather(rows, y, V_ref, V_w, V0_ratio, gd, delta, offsets, nbr, is_gas, f,
               x, frac=0.0, kc=0.0):
    """Add the updated-Lagrangian pair forces to f of the owned points ``rows``
    (pair weights V_w for gas points, V_ref for solids; V0_ratio = V_w / V0), and the
    gas-solid contact (``frac`` > 0; x: reference positions, kc = stiffness x K)."""
    for k in range(rows.shape[0]):
        i = rows[k]
        di = delta[i] if is_gas[i] else 0.0
        fx = fy = fz = 0.0
        cx = cy = cz = 0.0                      # contact force (N)
        for b in range(*family(offsets, i)):
            j = neighbour(nbr, b)
            y0, y1, y2, ly = current_bond(y, i, j)
            if frac > 0.0 and is_gas[i] != is_gas[j] and ly > 0.0:
                dc, ell = contact_reach(x, V_ref, i, j, frac)
                if ly < dc:
                    g = kc * ell * (dc - ly) / ly       # |F| / |Y|, away from j
                    cx -= g * y0
                    cy -= g * y1
                    cz -= g * y2
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
            vj = V_w[j] if is_gas[j] else V_ref[j]
            fx += tx * vj
            fy += ty * vj
            fz += tz * vj
        s = V0_ratio[i]
        f[i, 0] += s * fx
        f[i, 1] += s * fy
        f[i, 2] += s * fz
        if frac > 0.0:
            f[i, 0] += cx / V_ref[i]
            f[i, 1] += cy / V_ref[i]
            f[i, 2] += cz / V_ref[i]


@numba.njit(cache=True)
def gas_contact_energy(gas_idx, y, x, V_ref, offsets, nbr, is_gas, frac, kc):
    """The contact's potential (J) over the gas-solid pairs of the owned gas points
    ``gas_idx`` (each pair once, from its gas point): sum kc l (d_c - |Y|)^2 / 2."""
    out = 0.0
    if frac <= 0.0:
        return out
    for k in range(gas_idx.shape[0]):
        i = gas_idx[k]
        for b in range(*family(offsets, i)):
            j = neighbour(nbr, b)
            if is_gas[j]:
                continue
            ly = current_bond(y, i, j)[3]
            dc, ell = contact_reach(x, V_ref, i, j, frac)
            if ly < dc:
                out += 0.5 * kc * ell * (dc - ly) ** 2
    return out
