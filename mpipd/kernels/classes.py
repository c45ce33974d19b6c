"""Step classes of multi-rate integration (mpipd.model.multirate), kernel side.

A point of class k takes steps dt_k = 2^k dt; at fine step s of a coarse
interval its state (stress, force state) is evaluated iff 2^k divides s, i.e.
iff k <= level(s) = min(v_2(s), K) with v_2 the 2-adic valuation and K the
coarsest class.  Its force state then gives the impulse dt_k f_k: in the fine
velocity-Verlet step it enters the force with the weight 2^k (Lew et al. 2003,
asynchronous variational integrators: each state's impulse at its own times).
Single-rate integration is level 0 with every class 0: every weight is 1.0,
and x * 1.0 == x, so the kernels give the single-rate numbers bit for bit.
"""
import math

import numba
import numpy as np

from .index import family, neighbour
from .layout import CORRESPONDENCE, INTACT
from .linalg import principal_max_min


def level_at(step: int, ratio: int) -> int:
    """The level of the force evaluation at the end of step ``step`` (the states of
    classes k <= level act there): the 2-adic valuation of the step within the
    coarse interval, log2(ratio) at a coarse boundary."""
    top = ratio.bit_length() - 1
    s = step % ratio
    if s == 0:
        return top
    return (s & -s).bit_length() - 1


def steps_since_update(step: int, k: int) -> int:
    """Fine steps since a class-k point's state was last updated, at the end of step
    ``step``: class k is updated at the steps that are multiples of 2^k (the same
    schedule as :func:`level_at`: level_at(step) >= k exactly there)."""
    return step % (1 << k)


@numba.njit(cache=True, inline="always")
def weight(k, level):
    """2^k if a class-k state acts at a force evaluation of ``level``, else 0.0."""
    return float(1 << k) if k <= level else 0.0


@numba.njit(cache=True)
def weights(level):
    """:func:`weight` of every uint8 class at ``level``, as a table: a bond loop reads
    the weight of a neighbour's class with one load instead of a shift, a conversion
    and a compare."""
    t = np.empty(256)
    for k in range(256):
        t[k] = weight(k, level)
    return t


@numba.njit(cache=True)
def family_min(offsets, nbr, a, rows, out):
    """out[i] = min(a[i], min over i's family of a[j]) for the owned points i in
    ``rows`` (every bond, broken or not: a broken pair can still touch through
    contact); out elsewhere is left as it is."""
    for r in range(rows.shape[0]):
        i = rows[r]
        m = a[i]
        for b in range(*family(offsets, i)):
            m = min(m, a[neighbour(nbr, b)])
        out[i] = m


@numba.njit(cache=True)
def around(offsets, nbr, flag, changed, edge, n, out):
    """out[a] = 1 for every owned a whose closed family holds a flagged point (owned or
    ghost), 0 elsewhere, reading only the families of the flagged owned points
    ``changed`` (families are symmetric: a flagged e marks its owned neighbours) and of
    the owned points ``edge`` that have ghosts in their families (a flagged ghost)."""
    for a in range(n):
        out[a] = 0
    for r in range(changed.shape[0]):
        e = changed[r]
        out[e] = 1
        for b in range(*family(offsets, e)):
            j = neighbour(nbr, b)
            if j < n:
                out[j] = 1
    for r in range(edge.shape[0]):
        a = edge[r]
        if out[a]:
            continue
        for b in range(*family(offsets, a)):
            if flag[neighbour(nbr, b)]:
                out[a] = 1
                break


@numba.njit(cache=True)
def min_stretch(V, idx, spring, mode, out):
    """out[k] = min(1, lambda_min(V_i)) for i = idx[k]: the smallest principal stretch
    (eigenvalue of the left stretch V, F = V R) of an intact point on the
    correspondence force, the factor by which the deformation has shortened its
    shortest lattice spacing; 1 for a point on the bond springs or failed (no
    stress of its material; its bonds' own lengths are not followed here)."""
    for k in range(idx.shape[0]):
        i = idx[k]
        lam = 1.0
        if spring[i] == CORRESPONDENCE and mode[i] == INTACT:
            _, lam = _sym_max_min(V, i)
            lam = min(1.0, lam)
            if lam < 1e-6:
                lam = 1e-6
        out[k] = lam


@numba.njit(cache=True)
def largest_eigenvalue(A, out):
    """out[i] = the largest eigenvalue of the symmetric 3x3 A[i] (its symmetric part)."""
    for i in range(A.shape[0]):
        out[i], _ = _sym_max_min(A, i)


@numba.njit(cache=True)
def element_sums(x, vol, wi, offsets, nbr, broken, Kinv, on, rows, E):
    """The correspondence element of each owned point i in ``rows``, for
    :func:`row_sums`: F_i - I = sum_j (u_j - u_i) (x) B_ij over i's intact bonds
    (Eq. 5) with B_ij = omega_i V_j K_i^-1 xi_ij and the centre's weight
    B_ii = -sum_j B_ij.  E[i, 0:9] = K_i^-1, E[i, 9] = S_i = |B_ii| + sum_j |B_ij|,
    E[i, 10] = |B_ii|; all 0 where ``on[i]`` is 0 (no correspondence element: the
    gas, K not invertible).  ``wi``: the bonds' omega_i (nosb.bond_influence)."""
    for r in range(rows.shape[0]):
        i = rows[r]
        for c in range(11):
            E[i, c] = 0.0
        if not on[i]:
            continue
        K = Kinv[i]
        s = c0 = c1 = c2 = 0.0
        for b in range(*family(offsets, i)):
            if broken[b]:
                continue
            j = neighbour(nbr, b)
            e0 = x[j, 0] - x[i, 0]
            e1 = x[j, 1] - x[i, 1]
            e2 = x[j, 2] - x[i, 2]
            w = wi[b] * vol[j]
            b0 = w * (K[0, 0] * e0 + K[0, 1] * e1 + K[0, 2] * e2)
            b1 = w * (K[1, 0] * e0 + K[1, 1] * e1 + K[1, 2] * e2)
            b2 = w * (K[2, 0] * e0 + K[2, 1] * e1 + K[2, 2] * e2)
            s += math.sqrt(b0 * b0 + b1 * b1 + b2 * b2)
            c0 += b0
            c1 += b1
            c2 += b2
        bc = math.sqrt(c0 * c0 + c1 * c1 + c2 * c2)
        for a in range(3):
            for c in range(3):
                E[i, 3 * a + c] = K[a, c]
        E[i, 9] = s + bc
        E[i, 10] = bc


@numba.njit(cache=True)
def row_sums(x, vol, wj, offsets, nbr, broken, E, rows, R):
    """R[a] for each owned point a in ``rows``: the Gershgorin row sum of the
    correspondence stiffness at a, per unit modulus and mass.  The element of
    point e has the stiffness V_e B_e^T C B_e (its weights B_e.: :func:`element_sums`),
    whose block (a, c) is bounded by V_e M |B_ea| |B_ec| (M: the largest modulus of
    C), so that row a of the assembled stiffness over the mass rho V_a sums to at
    most (M / rho) R_a with

        R_a = (1 / V_a) sum over the elements e that hold a of V_e |B_ea| S_e
            = |B_aa| S_a + sum over a's intact bonds (a, e) of V_e omega_e |K_e^-1 xi_ae| S_e

    (families are symmetric: e holds a iff a holds e; B_ea = omega_e V_a K_e^-1 xi_ea).
    The largest eigenvalue of M^-1 K is below max_a (M / rho) R_a (Gershgorin), so
    sqrt(R_a) bounds the frequency a point can carry.  E holds every local point's
    element (owned and ghosts); ``wj``: the bonds' omega_j."""
    for r in range(rows.shape[0]):
        a = rows[r]
        acc = E[a, 10] * E[a, 9]
        for b in range(*family(offsets, a)):
            if broken[b]:
                continue
            e = neighbour(nbr, b)
            se = E[e, 9]
            if se == 0.0:
                continue
            e0 = x[a, 0] - x[e, 0]
            e1 = x[a, 1] - x[e, 1]
            e2 = x[a, 2] - x[e, 2]
            b0 = E[e, 0] * e0 + E[e, 1] * e1 + E[e, 2] * e2
            b1 = E[e, 3] * e0 + E[e, 4] * e1 + E[e, 5] * e2
            b2 = E[e, 6] * e0 + E[e, 7] * e1 + E[e, 8] * e2
            acc += vol[e] * wj[b] * math.sqrt(b0 * b0 + b1 * b1 + b2 * b2) * se
        R[a] = acc


@numba.njit(cache=True, inline="always")
def _sym_max_min(A, i):
    """Largest and smallest eigenvalue of the symmetric part of A[i] (3x3)."""
    return principal_max_min(A[i, 0, 0], A[i, 1, 1], A[i, 2, 2],
                             0.5 * (A[i, 1, 2] + A[i, 2, 1]),
                             0.5 * (A[i, 0, 2] + A[i, 2, 0]),
                             0.5 * (A[i, 0, 1] + A[i, 1, 0]))
