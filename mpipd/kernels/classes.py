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
import numba

from .layout import CORRESPONDENCE, INTACT
from .linalg import principal_max_min


@numba.njit(cache=True, inline="always")
def weight(k, level):
    """2^k if a class-k state acts at a force evaluation of ``level``, else 0.0."""
    return float(1 << k) if k <= level else 0.0


@numba.njit(cache=True)
def family_min(offsets, nbr, a, out):
    """out[i] = min(a[i], min over i's family of a[j]) for the owned points (every
    bond, broken or not: a broken pair can still touch through contact)."""
    for i in range(offsets.shape[0] - 1):
        m = a[i]
        for b in range(offsets[i], offsets[i + 1]):
            if a[nbr[b]] < m:
                m = a[nbr[b]]
        out[i] = m


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


@numba.njit(cache=True, inline="always")
def _sym_max_min(A, i):
    """Largest and smallest eigenvalue of the symmetric part of A[i] (3x3)."""
    return principal_max_min(A[i, 0, 0], A[i, 1, 1], A[i, 2, 2],
                             0.5 * (A[i, 1, 2] + A[i, 2, 1]),
                             0.5 * (A[i, 0, 2] + A[i, 2, 0]),
                             0.5 * (A[i, 0, 1] + A[i, 1, 0]))
