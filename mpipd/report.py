"""``mpipd check``: sizes, memory, halo and stable time step of a scene, without running it.

Nothing here generates the model's points: counts come from the layer table
and each part's bulk family (the lattice offsets within the horizon), so a
check of the paper's 1.65-million-point model takes a moment on a laptop.

Stable time step.  Two estimates per part, and the scene's dt against the smaller:

* Silling & Askari (2005), bond-based bound for a bulk point:
  dt_c = sqrt(2 rho / sum_j V_j c / |xi_j|), c = 18 K / (pi delta^4);
* the P-wave transit of one lattice spacing, dx / sqrt((K + 4G/3) / rho).
"""
from __future__ import annotations

import math

import numpy as np

from .decomp import decompose, halo_width
from .geometry import LayerTable

#: memory model, bytes — kept equal to the arrays :class:`mpipd.solver.Simulation`
#: allocates (``tests/test_memory.py`` checks it against a walk of every array)
BYTES_PER_LOCAL_POINT = 209     # x, gid, part, material, volume, horizon, dx, u, v, fd, cbb, mode
BYTES_PER_OWNED_POINT = 642     # a, f, rho, fixed, offsets, K^-1, tr K, gamma, spring, F,
#                                 F_old, Fdot, R, V, sigma, d, J, W, hourglass modulus, group index
BYTES_PER_BOND = 5              # nbr (int32) + broken (uint8)
FAILURE_LOCAL, FAILURE_OWNED = 33, 9     # done flags + search tree; phi, touched
DAMPING_OWNED = 8
VISCOSITY_LOCAL, VISCOSITY_OWNED = 16, 24
JH2_OWNED = 40                  # D, eps_p, dp, pressure, strain rate
GAS_LOCAL, GAS_OWNED = 74, 24   # gas force data (8), flags, gas horizon; UL offsets, V ratio, damping
BYTES_PER_GAS_POINT = 48        # index, V0, e, lighting time, eligible/row lists


def is_gas_part(scene, part) -> bool:
    return bool(getattr(scene.materials[part.material], "is_gas", False))


def memory_model(scene) -> tuple[int, int]:
    """(bytes per local point, bytes per owned point) for the scene's features; a
    scene with an explosive adds BYTES_PER_GAS_POINT per gas point on every rank
    (plus its current-configuration families)."""
    local, owned = BYTES_PER_LOCAL_POINT, BYTES_PER_OWNED_POINT
    if any(is_gas_part(scene, q) for q in scene.parts):
        local += GAS_LOCAL
        owned += GAS_OWNED
    if scene.can_fail:
        local += FAILURE_LOCAL
        owned += FAILURE_OWNED + (DAMPING_OWNED if scene.solver.damping > 0 else 0)
    if scene.solver.viscosity is not None:
        local += VISCOSITY_LOCAL
        owned += VISCOSITY_OWNED
    if scene.has_model("jh2"):
        owned += JH2_OWNED            # an upper bound when only some parts are JH2
    return local, owned


def bulk_family(dx: float, horizon: float) -> np.ndarray:
    """Bond lengths |xi| of a bulk lattice point's family."""
    n = int(math.ceil(horizon / dx))
    k = np.arange(-n, n + 1)
    I, J, K = np.meshgrid(k, k, k, indexing="ij")
    r = dx * np.sqrt(I * I + J * J + K * K).ravel()
    return r[(r > 0) & (r < horizon)]


def stable_dt(part, material) -> tuple[float, float]:
    """(Silling–Askari dt, dx / c_p) for a bulk point of ``part``."""
    r = bulk_family(part.dx, part.horizon)
    c = 18.0 * material.bulk_modulus / (math.pi * part.horizon ** 4)
    dt_sa = math.sqrt(2.0 * material.density / np.sum(part.dx ** 3 * c / r))
    return dt_sa, part.dx / material.p_wave_speed


def check_report(scene, ranks: int) -> str:
    table = LayerTable.from_parts(scene.parts, scene.material_ids)
    halo = halo_width(scene)
    slabs = decompose(table, ranks, halo)
    out = [f"scene {scene.name!r}: {scene.scene.description}".rstrip(": ")]
    out.append(f"  steps: {scene.time.n_steps} of dt = {scene.time.dt:.4e} s "
               f"(t_end = {scene.time.n_steps * scene.time.dt:.4e} s)")
    total_bonds = 0
    family = {}
    dt_limits = []
    gas_points = 0
    for k, p in enumerate(scene.parts):
        npts = int(table.count[table.part == k].sum())
        fam = 0 if is_gas_part(scene, p) else len(bulk_family(p.dx, p.horizon))
        if is_gas_part(scene, p):
            gas_points += npts
        family[k] = fam
        total_bonds += npts * fam
        mat = scene.materials[p.material]
        dt_sa, dt_cfl = stable_dt(p, mat)
        dt_limits.append(min(dt_sa, dt_cfl))
        out.append(f"  part {p.name!r}: {p.shape.registry_name}, material {p.material!r} "
                   f"({mat.registry_name}), dx = {p.dx:.4g} m, horizon = {p.horizon:.4g} m "
                   f"({p.horizon_factor:g} dx), {npts} points, "
                   + ("updated-Lagrangian gas: families re-found every step, held on every rank"
                      if is_gas_part(scene, p) else f"{fam} bonds per bulk point"))
        out.append(f"    stable dt: Silling-Askari {dt_sa:.4e} s, dx/c_p {dt_cfl:.4e} s "
                   f"(c_p = {mat.p_wave_speed:.1f} m/s)")
    for name, mat in scene.materials.items():
        region = getattr(mat, "negative_tangent", lambda: None)()
        if region is not None:
            out.append(f"  material {name!r}: EOS tangent dp/dmu < 0 for mu in "
                       f"{region[0]:.5f}..{region[1]:.5f} (K2 = {mat.K2:.4g} Pa, "
                       f"K3 = {mat.K3:.4g} Pa): the wave speed and the viscosity use K1 there")
    out.append(f"  total: {table.n_points} points, <= {total_bonds} bonds "
               f"(bulk families; surface points have fewer)")
    dt_max = min(dt_limits)
    verdict = "OK" if scene.time.dt <= dt_max else "TOO LARGE - the run will be unstable"
    out.append(f"  time step: dt = {scene.time.dt:.4e} s vs stable {dt_max:.4e} s "
               f"(ratio {scene.time.dt / dt_max:.2f}): {verdict}")
    per_local, per_owned = memory_model(scene)
    out.append(f"  decomposition: {ranks} rank(s) along z, halo = {halo:.4g} m "
               "(largest horizon + dx/2)")
    for r in range(ranks):
        owned, ghost = slabs.points_of(r)
        z0, z1 = slabs.z_range(r)
        a, b = slabs.owned(r)
        layers = np.arange(a, b)
        bonds = int(sum(table.count[L] * family[int(table.part[L])] for L in layers))
        mem = (per_local * (owned + ghost) + per_owned * owned + BYTES_PER_BOND * bonds
               + BYTES_PER_GAS_POINT * gas_points)
        thick = z1 - z0 + float(scene.max_dx)
        recv, _ = slabs.plan(r)
        peers = len(recv)
        hop = " (thinner than the halo: multi-hop exchange)" if thick < halo and ranks > 1 else ""
        out.append(f"    rank {r}: z {z0:.4g}..{z1:.4g} m ({thick:.4g} m thick), {owned} owned + "
                   f"{ghost} ghost points, <= {bonds} bonds, ~{mem / 2**20:.1f} MiB, "
                   f"{peers} halo peer(s){hop}")
    return "\n".join(out)
