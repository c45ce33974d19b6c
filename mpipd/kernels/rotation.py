"""Rotation and left-stretch update, unrotated rate of deformation (paper Eqs. 6–14).

Per point, with F_mid = (F_n + F_{n+1}) / 2 (midpoint, so a rigid rotation
gives an exactly skew L — the Cayley transform of the step rotation — and no
spurious stretching, Hughes & Winget 1980):

    L = Fdot F_mid^-1,  D = sym L,  W = skew L                    (Eqs. 11–12)
    w = axial(W)                     (W a = w x a, Eq. 9)
    chi_i = e_ijk (D V)_jk                                         (Eq. 10)
    varpi = w - (tr(V) I - V)^-1 chi                                (Eq. 8)
    Omega a = varpi x a;  R_{n+1} = exp(dt Omega) R_n (Rodrigues)   (Eq. 7)
    V_{n+1} = V_n + dt (L V_n - V_n Omega)                          (Eq. 14)
    d = R_{n+1}^T D R_{n+1}                                         (Eq. 6)

Sign note: requiring V̇ to stay symmetric in V̇ = L V − V Ω gives
axial(V Δ + Δ V) = axial(D V − V D) for Δ = Ω − W, i.e. (tr V I − V) δ = −chi;
the paper's Eqs. 7–10 print a different mix of sign conventions.  The test
``test_rotation.py`` checks V R = F along a stretching, rotating history.
"""
import math

import numba
import numpy as np

from .layout import NOT_TL, SPRING_K
from .linalg import det3, inv3, mat_to_voigt, mul3, mul3_at


@numba.njit(cache=True)
def rotate_stretch(F_old, F_new, Fdot, R, V, dt, spring, d, J, J_end, Jfac, klass, level, held):
    """Advance R and V of every owned point whose step class acts at ``level``
    (kernels.classes) by its step dt_i = 2^k_i dt; write d (Voigt), J = c det F_mid
    (for the stress power and the viscosity, which live at mid-step) and
    J_end = c det F_{n+1}: the volume the new stress acts on, from which a
    total-volume EOS (JH2's mu = 1/J - 1) must take its pressure.  Taking it
    from F_mid would delay the restoring force by dt/2, which makes the central
    difference scheme unstable at any dt (growth ~ (omega dt)^2 / 4 a step).

    c = ``Jfac[i]`` is the point's volume factor (1 until its shape tensor is
    rebuilt after bonds broke; see Correspondence.rebuild_shape): the volume
    ratio of the point is c det F, continuous across a change of family.

    A point of a coarse class (k_i > 0) takes Fdot = (F_{n+1} - F_n) / dt_i,
    the mean rate over its own step (its neighbours of finer classes moved at
    several speeds within it); class 0 keeps Fdot of Eq. 13 from the mid-step
    velocities, which is the same for a family of one class.

    ``held[i]`` is set to 1 for a total-Lagrangian point that has no continuum
    kinematics this step (on the bond springs, SPRING_K, or with a non-positive or
    non-finite det F_mid): its d = 0 and J = 1 are placeholders, not a state, so the
    material update and the tension check must leave it alone (Correspondence.hold);
    0 for every other point of the level."""
    n = F_new.shape[0]
    Fm = np.empty((3, 3))
    Fi = np.empty((3, 3))
    L = np.empty((3, 3))
    DV = np.empty((3, 3))
    M = np.empty((3, 3))
    Mi = np.empty((3, 3))
    Om = np.empty((3, 3))
    Q = np.empty((3, 3))
    T = np.empty((3, 3))
    Dm = np.empty((3, 3))
    Vn = np.empty((3, 3))
    for i in range(n):
        k = klass[i]
        if k > level:
            continue
        h = dt * float(1 << k)
        if k > 0:
            for r in range(3):
                for c in range(3):
                    Fdot[i, r, c] = (F_new[i, r, c] - F_old[i, r, c]) / h
        for r in range(3):
            for c in range(3):
                Fm[r, c] = 0.5 * (F_old[i, r, c] + F_new[i, r, c])
        Jm = det3(Fm)
        if spring[i] == SPRING_K or spring[i] == NOT_TL or not (Jm > 0.0 and math.isfinite(Jm)):
            for c in range(6):                  # no continuum kinematics this step
                d[i, c] = 0.0
            J[i] = 1.0
            J_end[i] = 1.0
            held[i] = 0 if spring[i] == NOT_TL else 1
            continue
        held[i] = 0
        c = Jfac[i]
        J[i] = c * inv3(Fm, Fi)
        Je = det3(F_new[i])
        J_end[i] = c * (Je if (Je > 0.0 and math.isfinite(Je)) else Jm)
        mul3(Fdot[i], Fi, L)
        for r in range(3):
            for c in range(3):
                Dm[r, c] = 0.5 * (L[r, c] + L[c, r])
        w0 = 0.5 * (L[2, 1] - L[1, 2])
        w1 = 0.5 * (L[0, 2] - L[2, 0])
        w2 = 0.5 * (L[1, 0] - L[0, 1])
        mul3(Dm, V[i], DV)
        c0 = DV[1, 2] - DV[2, 1]
        c1 = DV[2, 0] - DV[0, 2]
        c2 = DV[0, 1] - DV[1, 0]
        tv = V[i, 0, 0] + V[i, 1, 1] + V[i, 2, 2]
        for r in range(3):
            for c in range(3):
                M[r, c] = -V[i, r, c]
            M[r, r] += tv
        inv3(M, Mi)
        o0 = w0 - (Mi[0, 0] * c0 + Mi[0, 1] * c1 + Mi[0, 2] * c2)
        o1 = w1 - (Mi[1, 0] * c0 + Mi[1, 1] * c1 + Mi[1, 2] * c2)
        o2 = w2 - (Mi[2, 0] * c0 + Mi[2, 1] * c1 + Mi[2, 2] * c2)
        Om[0, 0] = Om[1, 1] = Om[2, 2] = 0.0
        Om[0, 1] = -o2
        Om[1, 0] = o2
        Om[0, 2] = o1
        Om[2, 0] = -o1
        Om[1, 2] = -o0
        Om[2, 1] = o0
        # V_{n+1} = V + dt (L V - V Omega), from the old V
        mul3(L, V[i], T)
        mul3(V[i], Om, M)
        for r in range(3):
            for c in range(3):
                Vn[r, c] = V[i, r, c] + h * (T[r, c] - M[r, c])
        # R_{n+1} = exp(dt Omega) R_n
        a = math.sqrt(o0 * o0 + o1 * o1 + o2 * o2)
        th = a * h
        if a > 0.0:
            s1 = math.sin(th) / a
            s2 = (1.0 - math.cos(th)) / (a * a)
        else:
            s1 = h
            s2 = 0.5 * h * h
        mul3(Om, Om, T)
        for r in range(3):
            for c in range(3):
                Q[r, c] = (1.0 if r == c else 0.0) + s1 * Om[r, c] + s2 * T[r, c]
        mul3(Q, R[i], T)
        for r in range(3):
            for c in range(3):
                R[i, r, c] = T[r, c]
                V[i, r, c] = Vn[r, c]
        # d = R^T D R
        mul3_at(R[i], Dm, T)
        mul3(T, R[i], M)
        mat_to_voigt(M, d[i])
