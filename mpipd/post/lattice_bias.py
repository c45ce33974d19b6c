"""Lattice bias of the crack pattern on one section (issue 15): do the cracks
prefer the cubic lattice's axes and diagonals?

Ring.  The failed points (:func:`mpipd.post.cracks.failed_points`) are taken in
the ring of crack-density zone 2 (:func:`mpipd.post.cracks.zone_edges`),

    R_b + w <= r < R_b + 2 w,     w = (R_o - R_b) / 3,

the same ring (and so the same failed count) as zone 2 of Fig. 12.  Zone 1 holds
the crushed zone, where nearly every point fails whatever its direction (that
dilutes any angular pattern toward zero); zone 3 holds the spalls and boundary
chips of the wave reflected at the free outer boundary, another mechanism.  The
middle ring is crossed by the radial cracks alone, the pattern whose direction
the lattice may bias.

Fourier amplitudes.  With g(theta) the failed fraction of the ring's points at
angle theta (theta about the borehole axis, 0 = the lattice's x axis), its
Fourier coefficients are c_m = (1/2pi) int g(theta) e^{-i m theta} dtheta, and
|c_m| / c_0 lies in [0, 1] (1 when every failed point lies on the m rays
theta_m + 2 pi k / m; a modulation g ~ 1 + A cos m(theta - theta_m) has A = 2 |c_m| / c_0).  The
direct estimate over the N_F failed points, (1/N_F) sum_F e^{-i m theta_j}, would
be c_m / c_0 if the lattice's points were spread uniformly in angle.  They are
not: the angular density of the ring's N points is
rho(theta) = (N / 2pi) sum_k eps_k e^{i k theta} (eps_0 = 1; on a square lattice
centred on the axis eps_k != 0 only for k a multiple of 4, from the digital
edges of the ring), and that estimate is c_m / c_0 + eps_m + O(eps c / c_0).  The
same estimate over ALL the ring's points is exactly mu_m = eps_m, so

    a_m = | (1/N_F) sum_{j in F} e^{-i m theta_j}  -  (1/N) sum_{j in ring} e^{-i m theta_j} |

is |c_m| / c_0 with the lattice's own density divided out to first order: exactly 0
when the whole ring has failed, unbiased for failure independent of the angle,
and within about |mu_m| of |c_m| / c_0 for strong patterns (thin rays: the
subtraction moves a_4 by mu_4, and a_m may exceed 1 by as much).  |mu_4| ~ 1e-2
on a ring 9 dx wide (``lattice_a4`` is reported): less than the noise level
(next paragraph) for N_F < (0.886 / |mu_4|)^2 ~ 1e4 failed points.  a_4 and a_8
are reported; the 4-fold maxima lie at theta_4 = -arg(X_4)/4 (mod 90 deg: 0 =
the lattice axes, 45 = the diagonals), X_m the complex difference inside |.|.

Noise level.  If failure does not depend on the angle (H0: the failed points are
N_F of the ring's N points drawn regardless of theta; each point failing with
the same probability p is this, given N_F), the difference X_m is the mean of a
sample of N_F drawn without replacement from the ring's z_j = e^{-i m theta_j},
minus their mean: E X_m = 0 and

    E |X_m|^2 = sigma_m^2 (N - N_F) / (N_F (N - 1)),   sigma_m^2 = 1 - |mu_m|^2 <= 1.

For N_F large X_m is close to a circular complex Gaussian, so a_m = |X_m| is
Rayleigh distributed with mean (sqrt(pi)/2) sqrt(E |X_m|^2):

    noise = (sqrt(pi)/2) sqrt((N - N_F) / (N_F (N - 1)))   (-> 0.886 / sqrt(N_F), N_F << N)

(sigma_m^2 taken as 1: an upper bound within |mu_m|^2 ~ 1e-4).  Under H0,
P(a_m > 3 noise) = exp(-9 pi / 4) ~ 1e-3.

Major radial cracks: :func:`mpipd.post.cracks.radial_cracks` on the section.
"""
from __future__ import annotations

import numpy as np

from . import cracks

MODES = (4, 8)
RING = ("crack-density zone 2, R_b + w <= r < R_b + 2w with w = (R_o - R_b)/3: between the "
        "crushed zone (zone 1) and the boundary spalls (zone 3), crossed by the radial cracks")


def ring(r_wall: float, r_out: float) -> tuple[float, float]:
    """Inner and outer radius of the ring (crack-density zone 2)."""
    e = cracks.zone_edges(r_wall, r_out)
    return float(e[1]), float(e[2])


def noise_level(n_failed: int, n_points: int) -> float:
    """Mean a_m of failed points drawn regardless of angle (H0, module docstring)."""
    if n_failed <= 0:
        return float("nan")
    if n_failed >= n_points:
        return 0.0              # the whole ring: nothing is drawn
    return float(0.5 * np.sqrt(np.pi) * np.sqrt((n_points - n_failed)
                                                / (n_failed * (n_points - 1.0))))


def modes(theta: np.ndarray, failed: np.ndarray, m: int) -> tuple[complex, complex]:
    """X_m (failed minus all points of the ring) and mu_m (all points)."""
    z = np.exp(-1j * m * theta)
    mu = z.mean()
    return complex(z[failed].mean() - mu), complex(mu)


def measure(x, y, failed, center, dx, r_wall, r_out, horizon=None) -> dict:
    """Lattice-bias measures of one section (module docstring); a section without a
    failed point in the ring is ``{"not_available": reason}``."""
    x, y, failed = np.asarray(x, float), np.asarray(y, float), np.asarray(failed, bool)
    r0, r1 = ring(r_wall, r_out)
    r = np.hypot(x - center[0], y - center[1])
    inside = (r >= r0) & (r < r1)
    n, nf = int(np.count_nonzero(inside)), int(np.count_nonzero(failed & inside))
    if nf == 0:
        return {"not_available": f"no failed point in the ring {r0 * 1e3:.4g}-{r1 * 1e3:.4g} mm"}
    theta = np.arctan2(y[inside] - center[1], x[inside] - center[0])
    (x4, mu4), (x8, _) = (modes(theta, failed[inside], m) for m in MODES)
    rc = cracks.radial_cracks(x, y, failed, center, dx, r_wall, r_out, horizon=horizon)
    return {"ring_mm": [r0 * 1e3, r1 * 1e3], "n_points": n, "n_failed": nf,
            "a4": abs(x4), "a8": abs(x8),
            "a4_direction_deg": float(np.degrees(-np.angle(x4) / 4.0) % 90.0),
            "lattice_a4": abs(mu4), "noise": noise_level(nf, n),
            "major_radial_cracks": rc["count"]}
