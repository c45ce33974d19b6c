"""The stable time step of a scene's parts at rest, and the bond micromodulus.

Two estimates per part (``mpipd run`` holds dt to the smaller over the parts,
mpipd.check reports them, mpipd.model.multirate and the correspondence model's
stable floor scale each point's part's):

* Silling & Askari (2005), bond-based bound for a bulk point:
  dt_c = sqrt(2 rho / sum_j V_j c / |xi_j|), c = 18 K / (pi delta^4)
  (:func:`micromodulus`), V_j = dx^3 over the bulk family;
* the P-wave transit of one lattice spacing, dx / c_p, c_p = sqrt((K + 4G/3) / rho)
  (the detonation speed of a JWL explosive).

Both assume the reference moduli, i.e. the wave speed c_p of the material at rest.
"""
from __future__ import annotations

import math

import numpy as np


def micromodulus(bulk_modulus, horizon):
    """The bond-based micromodulus c = 18 K / (pi delta^4) (Silling & Askari 2005)
    of bulk modulus K and horizon delta (floats or arrays): the bond-spring constant
    of the correspondence model's fallback and the stiffness of the Silling-Askari
    step bound (:func:`stable_dt`)."""
    return 18.0 * bulk_modulus / (math.pi * horizon ** 4)


def bulk_family(dx: float, horizon: float) -> np.ndarray:
    """Bond lengths |xi| of a bulk lattice point's family."""
    n = int(math.ceil(horizon / dx))
    k = np.arange(-n, n + 1)
    kx, ky, kz = np.meshgrid(k, k, k, indexing="ij")
    r = dx * np.sqrt(kx * kx + ky * ky + kz * kz).ravel()
    return r[(r > 0) & (r < horizon)]


def stable_dt(part, material) -> tuple[float, float]:
    """(Silling–Askari dt, dx / c_p) for a bulk point of ``part``:
    dt_c = sqrt(2 rho / sum_j V_j c / |xi_j|), c = 18 K / (pi delta^4)
    (:func:`micromodulus`), V_j = dx^3 over the bulk family, and c_p =
    ``material.p_wave_speed`` (sqrt((K + 4G/3) / rho); the detonation speed of a
    JWL explosive)."""
    r = bulk_family(part.dx, part.horizon)
    c = micromodulus(material.bulk_modulus, part.horizon)
    dt_sa = math.sqrt(2.0 * material.density / np.sum(part.dx ** 3 * c / r))
    return dt_sa, part.dx / material.p_wave_speed


def part_critical_dt(scene) -> np.ndarray:
    """Each part's stable-step estimate min(dt_c, dx / c_p) (:func:`stable_dt`), by part
    index: the critical step of a bulk point of the part at rest."""
    return np.array([min(stable_dt(q, scene.materials[q.material])) for q in scene.parts])


def critical_dt(scene) -> float:
    """The stable-step estimate ``mpipd run`` holds dt to (and ``mpipd check`` reports,
    benchmarks.verify_case scales): dt_max = min over parts of min(dt_c, dx / c_p)
    (:func:`part_critical_dt`)."""
    return float(part_critical_dt(scene).min())
