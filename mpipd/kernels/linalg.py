"""3x3 matrix helpers for per-point kernels (inlined by numba)."""
import math

import numba


@numba.njit(cache=True, inline="always")
def det3(a):
    return (a[0, 0] * (a[1, 1] * a[2, 2] - a[1, 2] * a[2, 1])
            - a[0, 1] * (a[1, 0] * a[2, 2] - a[1, 2] * a[2, 0])
            + a[0, 2] * (a[1, 0] * a[2, 1] - a[1, 1] * a[2, 0]))


@numba.njit(cache=True, inline="always")
def inv3(a, out):
    """out = a^-1; returns det(a).  ``out`` must not alias ``a``."""
    d = det3(a)
    s = 1.0 / d
    out[0, 0] = (a[1, 1] * a[2, 2] - a[1, 2] * a[2, 1]) * s
    out[0, 1] = (a[0, 2] * a[2, 1] - a[0, 1] * a[2, 2]) * s
    out[0, 2] = (a[0, 1] * a[1, 2] - a[0, 2] * a[1, 1]) * s
    out[1, 0] = (a[1, 2] * a[2, 0] - a[1, 0] * a[2, 2]) * s
    out[1, 1] = (a[0, 0] * a[2, 2] - a[0, 2] * a[2, 0]) * s
    out[1, 2] = (a[0, 2] * a[1, 0] - a[0, 0] * a[1, 2]) * s
    out[2, 0] = (a[1, 0] * a[2, 1] - a[1, 1] * a[2, 0]) * s
    out[2, 1] = (a[0, 1] * a[2, 0] - a[0, 0] * a[2, 1]) * s
    out[2, 2] = (a[0, 0] * a[1, 1] - a[0, 1] * a[1, 0]) * s
    return d


@numba.njit(cache=True, inline="always")
def mul3(a, b, out):
    """out = a b."""
    for r in range(3):
        for c in range(3):
            out[r, c] = a[r, 0] * b[0, c] + a[r, 1] * b[1, c] + a[r, 2] * b[2, c]


@numba.njit(cache=True, inline="always")
def mul3_bt(a, b, out):
    """out = a b^T."""
    for r in range(3):
        for c in range(3):
            out[r, c] = a[r, 0] * b[c, 0] + a[r, 1] * b[c, 1] + a[r, 2] * b[c, 2]


@numba.njit(cache=True, inline="always")
def mul3_at(a, b, out):
    """out = a^T b."""
    for r in range(3):
        for c in range(3):
            out[r, c] = a[0, r] * b[0, c] + a[1, r] * b[1, c] + a[2, r] * b[2, c]


#: the Voigt order of every 6-column symmetric tensor (stress, d) in mpipd
VOIGT = ("xx", "yy", "zz", "yz", "xz", "xy")


@numba.njit(cache=True, inline="always")
def voigt_to_mat(s, out):
    """Symmetric tensor from Voigt order (xx, yy, zz, yz, xz, xy)."""
    out[0, 0] = s[0]
    out[1, 1] = s[1]
    out[2, 2] = s[2]
    out[1, 2] = out[2, 1] = s[3]
    out[0, 2] = out[2, 0] = s[4]
    out[0, 1] = out[1, 0] = s[5]


@numba.njit(cache=True, inline="always")
def mat_to_voigt(m, out):
    """Voigt order (xx, yy, zz, yz, xz, xy) of the symmetric part of m."""
    out[0] = m[0, 0]
    out[1] = m[1, 1]
    out[2] = m[2, 2]
    out[3] = 0.5 * (m[1, 2] + m[2, 1])
    out[4] = 0.5 * (m[0, 2] + m[2, 0])
    out[5] = 0.5 * (m[0, 1] + m[1, 0])


@numba.njit(cache=True, inline="always")
def normal_stress(s0, s1, s2, s3, s4, s5, a0, a1, a2):
    """a . sigma . a, the normal stress on the plane of unit normal a, of sigma in Voigt
    order (s0..s5 = xx, yy, zz, yz, xz, xy):

        a . sigma . a = s0 a0^2 + s1 a1^2 + s2 a2^2 + 2 (s3 a1 a2 + s4 a0 a2 + s5 a0 a1)

    With a = e_r, the radial unit vector about an axis along z, it is sigma_rr (the
    running peak of kernels.energy.update_peaks, with a = R^T e_r on the unrotated
    stress; the probes of mpipd.output.probes, with a = e_r on the Cauchy stress)."""
    return (s0 * a0 * a0 + s1 * a1 * a1 + s2 * a2 * a2
            + 2.0 * (s3 * a1 * a2 + s4 * a0 * a2 + s5 * a0 * a1))


@numba.njit(cache=True, inline="always")
def principal_max_min(a00, a11, a22, a12, a02, a01):
    """Largest and smallest eigenvalue of a symmetric 3x3 matrix, in closed form
    (Smith 1961, Commun. ACM 4(4) 168): with q = tr/3, p^2 = |a - qI|^2 / 6 and
    r = det((a - qI)/p)/2, the eigenvalues are q + 2p cos(acos(r)/3 + 2 pi m/3)."""
    p1 = a01 * a01 + a02 * a02 + a12 * a12
    q = (a00 + a11 + a22) / 3.0
    b00, b11, b22 = a00 - q, a11 - q, a22 - q
    p2 = b00 * b00 + b11 * b11 + b22 * b22 + 2.0 * p1
    if p2 <= 1e-300:
        return q, q
    p = math.sqrt(p2 / 6.0)
    det = (b00 * (b11 * b22 - a12 * a12) - a01 * (a01 * b22 - a12 * a02)
           + a02 * (a01 * a12 - b11 * a02))
    r = det / (2.0 * p * p * p)
    if r <= -1.0:
        phi = math.pi / 3.0
    elif r >= 1.0:
        phi = 0.0
    else:
        phi = math.acos(r) / 3.0
    e1 = q + 2.0 * p * math.cos(phi)
    e3 = q + 2.0 * p * math.cos(phi + 2.0 * math.pi / 3.0)
    return e1, e3
