"""``mpipd check``: sizes, memory, halo and stable time step of a scene, without running it.

Nothing here generates the model's 3-D points.  Point counts come from the
layer table (one row per part and z level).  Bonds are counted per layer from
the parts' 2-D cross-sections: a point's family is every lattice point within
max(delta_i, delta_j) (:mod:`mpipd.model.families`), so the bonds of one layer are
the pairs between its cross-section and each cross-section within reach in z,
closer in x-y than sqrt(R^2 - dz^2) — counted with 2-D KD trees and cached per
(part, part, distance).  That is the solver's count (up to round-off at
|xi| = delta) at the cost of a few 2-D pair counts, so a check of the paper's
1.65-million-point model takes seconds.  The explosive gas has no
total-Lagrangian bonds; its current-configuration families are re-found every
step and are not counted.

Stable time step (mpipd.model.stability, which ``mpipd run`` and the multi-rate
classes read too).  Two estimates per part, and the scene's dt against the smaller
(``mpipd run`` refuses a dt above it unless ``--force``):

* Silling & Askari (2005), bond-based bound for a bulk point:
  dt_c = sqrt(2 rho / sum_j V_j c / |xi_j|), c = 18 K / (pi delta^4)
  (``stability.stable_dt``, ``stability.micromodulus``);
* the P-wave transit of one lattice spacing, dx / sqrt((K + 4G/3) / rho).

Both assume the reference moduli, i.e. the wave speed c_p of the material at
rest.  Scaled by c_p, the scene's dt stays below the critical step for waves up
to c_max = c_p dt_c / dt; for a JH2 EOS, whose stiffness dp/dmu grows as K3 mu^2
(and for JH2's linear ``pressure = "incremental"``, whose (1 + mu)^2 dp/dmu =
(1 + mu) K1 grows slowly), the report gives the compression mu where the P-wave speed reaches c_max (beyond it the run
needs a smaller dt; the solver cannot know the compression in advance).

Measured against these estimates (tests/test_stability.py): the correspondence
model's true critical step is larger, 1.7-1.85 x for free elastic granite and J2
copper blocks, so the refusal is conservative.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from .input.geometry import LayerTable, fill_layers, part_points
from .input.loads import refuse_empty, regions
from .model.gas import check_charges, lighting_times

# the stable-step estimates live in mpipd.model.stability; part_critical_dt is
# named here too for a release (its old home)
from .model.stability import bulk_family, critical_dt, part_critical_dt, stable_dt  # noqa: F401
from .parallel.decomp import decompose, halo_width, replicated_parts

#: memory model, bytes — kept equal to the arrays :class:`mpipd.solver.Simulation`
#: allocates (``tests/test_memory.py`` checks it against a walk of every array)
BYTES_PER_LOCAL_POINT = 284     # x, gid, part, material, volume, horizon, dx, influence, u, v,
#                                 fd, spring reference map, cbb, mode, step class and base class
BYTES_PER_OWNED_POINT = 683     # a, f, rho, fixed, offsets, K^-1, tr K, gamma, spring, F,
#                                 F_old, Fdot, R, V, sigma, d, J, W, hourglass modulus, group
#                                 index, volume factor, fallback toggles, ledger row index,
#                                 the family's finest step class, lambda_min(K) and its stable floor
MULTIRATE_LOCAL_PER_CLASS = 24  # u at the last update of each coarse class (multi-rate only)
MULTIRATE_OWNED = 66            # last family change, the row, rows_around's buffer, the
#                                 critical step, P-wave speed and coarsening margin, the
#                                 family factor's reference, factor and stale flag, each
#                                 material group's entries per class (multi-rate only; each
#                                 class's row list, made per level at first use, is not counted)
MULTIRATE_ROW_SUM_LOCAL = 89    # the row sum's element data (11 floats) and change flag
MULTIRATE_ROW_SUM_OWNED = 8     # the row sum now
BYTES_PER_BOND = 29             # nbr (int32) + broken (uint8) + omega_i, omega_j, 1/|xi| (float64)
FAILURE_LOCAL, FAILURE_OWNED = 33, 9     # done flags + search tree; phi, touched
DAMPING_OWNED = 16              # damping coefficient, the ledger's damping energy
VISCOSITY_LOCAL, VISCOSITY_OWNED = 16, 72   # fd columns; dilatation, viscous force (2 steps)
JH2_OWNED = 40                  # D, eps_p, dp, pressure, strain rate
GAS_LOCAL, GAS_OWNED = 171, 32  # gas force data (8), flags, gas horizon, pair weights (2 steps), x + u,
#                                 the kernels' positions, velocities, flags and horizons over
#                                 local + remote rows; UL offsets, V ratio, damping, the
#                                 ledger's damping energy
PEAKS_OWNED = 24                # peak_pressure, peak_sigma_rr, peak_speed (if asked for)
BYTES_PER_GAS_POINT = 56        # index, V0, e, lighting time, not-TL index, density at
#                                 lighting, last bulk q
BYTES_PER_UL_POINT = 64         # the UL search lists (eligible, rows, their extension, the
#                                 watched points and their positions at the last search, the
#                                 owned solids; an upper bound): the gas and the rank's points
#                                 of its interacts_with solids


def is_gas_part(scene, part) -> bool:
    return part.material in scene.gas_materials


def memory_model(scene) -> tuple[int, int]:
    """(bytes per local point, bytes per owned point) for the scene's features; a
    scene with an explosive adds BYTES_PER_GAS_POINT per gas point and
    BYTES_PER_UL_POINT per point the gas searches (every gas point, and the rank's
    points of the ``interacts_with`` solids) (plus its current-configuration
    families and the few remote solid rows, mpipd.parallel.near)."""
    local, owned = BYTES_PER_LOCAL_POINT, BYTES_PER_OWNED_POINT
    gas = any(is_gas_part(scene, q) for q in scene.parts)
    if gas:
        local += GAS_LOCAL
        owned += GAS_OWNED            # includes the (one) damping array and its energy
    if scene.can_fail:
        local += FAILURE_LOCAL
        owned += FAILURE_OWNED + (DAMPING_OWNED if scene.solver.damping > 0 and not gas else 0)
    if scene.solver.viscosity is not None:
        local += VISCOSITY_LOCAL
        owned += VISCOSITY_OWNED
    if scene.has_model("jh2"):
        owned += JH2_OWNED            # an upper bound when only some parts are JH2
    if any(f.startswith("peak_") for f in scene.output.fields):
        owned += PEAKS_OWNED
    mr = scene.time.multirate
    if mr is not None:
        local += MULTIRATE_LOCAL_PER_CLASS * (mr.max_ratio.bit_length() - 1)
        if mr.max_ratio > 1:
            owned += MULTIRATE_OWNED
            if mr.family_factor.startswith("row_sum"):
                local += MULTIRATE_ROW_SUM_LOCAL
                owned += MULTIRATE_ROW_SUM_OWNED
    return local, owned


def layer_bonds(scene, table) -> np.ndarray:
    """Total-Lagrangian bonds of every layer's points, counted from the cross-sections
    (see the module docstring); 0 for gas layers.  A prism's section is one for all
    its levels; a part that is no prism (a rod) has one per level."""
    parts = scene.parts
    gas = [is_gas_part(scene, q) for q in parts]
    trees, sizes = {}, {}
    z, part = table.z, table.part

    def section(L):
        k = int(part[L])
        key = k if parts[k].shape.prism else (k, int(L))
        if key not in trees:
            sx, sy = (parts[k].shape.cross_section(parts[k].dx) if parts[k].shape.prism
                      else parts[k].shape.section(parts[k].dx, z[L]))
            trees[key] = cKDTree(np.column_stack((sx, sy)))
            sizes[key] = len(sx)
        return key

    horizon = np.array([q.horizon for q in parts])
    reach = max((horizon[k] for k in range(len(parts)) if not gas[k]), default=0.0)
    pairs = {}

    def count(a, b, r):
        a, b = sorted((a, b), key=repr)
        key = (a, b, round(r / 1e-12))
        if key not in pairs:
            pairs[key] = int(trees[a].count_neighbors(trees[b], r))
        return pairs[key]

    out = np.zeros(len(z), np.int64)
    for L in range(len(z)):
        k = int(part[L])
        if gas[k]:
            continue
        lo = np.searchsorted(z, z[L] - reach, side="left")
        hi = np.searchsorted(z, z[L] + reach, side="right")
        n = 0
        for M in range(lo, hi):
            q = int(part[M])
            if gas[q]:
                continue
            R = max(horizon[k], horizon[q])
            dz = abs(z[M] - z[L])
            if dz >= R:
                continue
            r = math.sqrt(R * R - dz * dz) * (1.0 - 1e-12)     # |xi| < R, strictly
            a = section(L)
            n += count(a, section(M), r)
            if M == L:
                n -= sizes[a]                                   # a point is not its own bond
        out[L] = n
    return out


def wave_speed_limit(mat, c_max: float):
    """Smallest compression mu in (0, 1] where a JH2 EOS's P-wave speed
    (``JH2.p_wave_speed_at``) reaches c_max; None if it never does, or for other materials."""
    if not hasattr(mat, "K3"):
        return None
    mus = np.linspace(0.0, 1.0, 20001)
    above = np.flatnonzero(mat.p_wave_speed_at(mus) >= c_max)
    if not len(above) or above[0] == 0:
        return None
    lo, hi = float(mus[above[0] - 1]), float(mus[above[0]])
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if float(mat.p_wave_speed_at(mid)) >= c_max else (mid, hi)
    return hi


#: a run file's bytes besides its frames, geometry and probes (HDF5 headers, attributes)
RUN_FILE_OVERHEAD = 1 << 20
#: per point of /geometry: x (3 f8), volume (f8), material and part (i4), room for
#: z_level and a strength factor (f8 each)
GEOMETRY_BYTES = 24 + 8 + 4 + 4 + 16


def run_file_bytes(scene, n_points: int) -> int:
    """The run file's size as ``mpipd run`` allocates it before step 1
    (mpipd.output.writer): every frame of every output field (8 bytes a component),
    the time and ledger rows, the geometry, every probe's row per step and the
    bond offsets (the broken bonds grow with the run and are not counted)."""
    from .input.scene import OUTPUT_FIELDS
    from .model.ledger import TERMS
    from .output.probes import QUANTITIES
    from .output.writer import n_frames
    n_steps = scene.time.n_steps
    frames = n_frames(n_steps, scene.output.every)
    per_frame = 8 * n_points * sum(OUTPUT_FIELDS[f][0] for f in scene.output.fields) \
        + 8 * (2 + len(TERMS))
    probes = 8 * len(QUANTITIES) * (n_steps + 1) * len(scene.probes)
    return frames * per_frame + GEOMETRY_BYTES * n_points + probes + RUN_FILE_OVERHEAD


@dataclass
class Sizes:
    """What a run needs before it is built: points, bonds, the model's bytes on each
    rank of the decomposition, and the run file's bytes."""
    points: int
    bonds: int
    memory: list          # bytes per rank (the model's arrays, memory_model)
    run_file: int


def rank_memory(scene, table, slabs, bonds, ranks: int) -> list[int]:
    """The model's bytes on each rank (:func:`memory_model`, bonds, the gas's lists)."""
    per_local, per_owned = memory_model(scene)
    acted = {a for m in scene.gas_materials for a in scene.materials[m].interacts_with}
    ul_parts = [k for k, q in enumerate(scene.parts)
                if is_gas_part(scene, q) or q.material in acted]
    gas_points = int(sum(int(table.count[table.part == k].sum())
                         for k, q in enumerate(scene.parts) if is_gas_part(scene, q)))
    out = []
    for r in range(ranks):
        owned, ghost = slabs.points_of(r)
        a, b = slabs.owned(r)
        nb = int(bonds[a:b].sum())
        held = np.concatenate((np.arange(a, b), slabs.ghost_layers(r)))
        ul_points = int(table.count[held][np.isin(table.part[held], ul_parts)].sum())
        out.append(per_local * (owned + ghost) + per_owned * owned + BYTES_PER_BOND * nb
                   + BYTES_PER_GAS_POINT * gas_points + BYTES_PER_UL_POINT * ul_points)
    return out


def sizes(scene, ranks: int) -> Sizes:
    """:class:`Sizes` from the layer table (nothing is built)."""
    table = LayerTable.from_parts(scene.parts, scene.material_ids)
    slabs = decompose(table, ranks, halo_width(scene), replicated_parts(scene))
    bonds = layer_bonds(scene, table)
    return Sizes(int(table.n_points), int(bonds.sum()),
                 rank_memory(scene, table, slabs, bonds, ranks),
                 run_file_bytes(scene, int(table.n_points)))


def mem_available() -> int | None:
    """This host's MemAvailable (bytes), None where /proc/meminfo has none."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return None


def gb(n: float) -> str:
    return f"{n / 1e9:.3g} GB"


#: points generated at once by :func:`lattice_checks` (memory: about 40 bytes a point)
CHECK_CHUNK = 2_000_000


def lattice_checks(scene, table) -> list[str]:
    """What ``mpipd run`` checks on its built points, here on the same points
    (mpipd.input.geometry.fill_layers, the lattice the run makes, jitter included),
    a few million at a time: every initial or boundary region holds a point
    (mpipd.input.loads.refuse_empty) and every probe's point is within its horizon
    (mpipd.input.probes.nearest and placed).  The same rules on the same points:
    ``mpipd check`` refuses what ``mpipd run`` refuses (SceneError).  Returns the
    report's lines on the probes (the point each samples; a snap warning)."""
    from .input.probes import nearest, placed
    conds = regions(scene)
    if not conds and not scene.probes:
        return []
    parts = scene.parts
    names = [q.name for q in parts]
    mid = np.array([scene.material_ids[q.material] for q in parts], np.int32)
    pdx = np.array([q.dx for q in parts])
    phor = np.array([q.horizon for q in parts])
    counts = [0] * len(conds)
    best = [(math.inf, -1)] * len(scene.probes)
    ends = np.cumsum(table.count)
    first = 0
    while first < len(table.count):                 # layers in gid order
        last = int(np.searchsorted(ends, ends[first] - table.count[first] + CHECK_CHUNK,
                                   side="right"))
        layers = np.arange(first, max(last, first + 1))
        first = int(layers[-1]) + 1
        x, part, gid = fill_layers(parts, table, layers)
        for i, (_, c) in enumerate(conds):
            counts[i] += int(np.count_nonzero(c.selects(x)))
        for k, pr in enumerate(scene.probes):
            best[k] = min(best[k], nearest(pr, names, x, gid, part, mid[part], pdx[part],
                                           phor[part]))
    refuse_empty(scene, counts)
    out = []
    for k, pr in enumerate(scene.probes):
        note = placed(k, pr, best[k])
        dist, g, xg, pg = best[k][:4]
        out.append(f"  probe {pr.name!r}: point gid {g} of part {names[pg]!r} at ("
                   + ", ".join(f"{c * 1e3:.4g}" for c in xg) + f") mm, {dist * 1e3:.3g} mm "
                   "from its position" + (f"; warning: {note}" if note else ""))
    return out


def check_report(scene, ranks: int) -> str:
    table = LayerTable.from_parts(scene.parts, scene.material_ids)
    check_charges(scene)                     # mpipd run's checks, before any report
    probe_lines = lattice_checks(scene, table)
    halo = halo_width(scene)
    slabs = decompose(table, ranks, halo, replicated_parts(scene))
    bonds = layer_bonds(scene, table)
    dt = scene.time.dt
    out = [f"scene {scene.name!r}: {scene.scene.description}".rstrip(": ")]
    out.append(f"  steps: {scene.time.n_steps} of dt = {dt:.4e} s "
               f"(t_end = {scene.time.n_steps * dt:.4e} s)")
    gas_points = 0
    acted = {a for m in scene.gas_materials for a in scene.materials[m].interacts_with}
    ul_parts = [k for k, q in enumerate(scene.parts)       # what the gas searches
                if is_gas_part(scene, q) or q.material in acted]
    part_dt = {}
    for k, p in enumerate(scene.parts):
        sel = table.part == k
        npts = int(table.count[sel].sum())
        nb = int(bonds[sel].sum())
        mat = scene.materials[p.material]
        if is_gas_part(scene, p):
            gas_points += npts
        dt_sa, dt_cfl = part_dt[k] = stable_dt(p, mat)
        fam = len(bulk_family(p.dx, p.horizon))
        out.append(f"  part {p.name!r}: {p.shape.registry_name}, material {p.material!r} "
                   f"({mat.registry_name}), dx = {p.dx:.4g} m, horizon = {p.horizon:.4g} m "
                   f"({p.horizon_factor:g} dx), influence {p.influence}, {npts} points, "
                   + ("updated-Lagrangian gas: families re-found every step, held on every rank"
                      if is_gas_part(scene, p) else
                      f"{nb} bonds ({nb / max(npts, 1):.1f} per point, {fam} in the bulk)"
                      + ("; the gas acts on it (held as its slabs are; the points a gas "
                         "point reaches beyond its rank's halo come from their owners)"
                         if k in ul_parts else "")))
        out.append(f"    stable dt: Silling-Askari {dt_sa:.4e} s, dx/c_p {dt_cfl:.4e} s "
                   f"(c_p = {mat.p_wave_speed:.1f} m/s)")
        if is_gas_part(scene, p):
            ini = p.initiation
            pts = part_points(p)
            t_last = float(lighting_times(scene, np.full(len(pts), k), pts, mat).max())
            if ini is not None and ini.never:
                out.append("    initiation: never (initiation.never: unlit gas all run)")
            elif ini is not None and ini.point is not None:
                out.append(f"    initiation: from the point ({', '.join(f'{v:g}' for v in ini.point)})"
                           f" m at t = {ini.time * 1e6:.4g} us, the charge lit by "
                           f"{t_last * 1e6:.4g} us")
            else:
                z0, d0, t0 = ((ini.z, ini.direction, ini.time) if ini is not None
                              else (mat.initiation_z, mat.direction, 0.0))
                out.append(f"    initiation: from z = {z0:g} m at t = {t0 * 1e6:.4g} us "
                           f"({'+' if d0 > 0 else '-'}z), the charge lit by "
                           f"{t_last * 1e6:.4g} us" + ("" if ini is not None else " (the material's)"))
            u = mat.unreacted
            out.append("    before it is lit: " + (
                f"inert, compacting freely to {mat.density * mat.unreacted_eos[2]:g} kg/m^3, then "
                f"the solid's Hugoniot U_s = {u.c0:g} + {u.s:g} u_p m/s "
                f"(K = {mat.unreacted_eos[0] / 1e9:.3g} GPa)" if u is not None else
                "no pressure (no unreacted EOS: a charge lit late beside a fired one is "
                "compressed freely)"))
            cq, cl = mat.bulk_viscosity
            out.append("    bulk viscosity: " + (
                f"q = rho dx ({cq:g} dx (tr L)^2 - {cl:g} c tr L) in compression, at most "
                f"rho dx^2 |tr L| / (2 dt); its work is the ledger's gas_viscous"
                if cq > 0 or cl > 0 else "none"))
            frac, kc = mat.contact_law
            wdt = math.sqrt(6.0 * kc / mat.density) / p.dx * scene.time.dt
            out.append("    contact with the solids: " + (
                f"pairs closer than min({frac:g} l, |xi|) repel with {kc / 1e9:.3g} GPa x l "
                f"x overlap (the ledger's gas_contact); omega dt = {wdt:.3g} for a gas point "
                f"pressed on 6 solids (velocity Verlet is stable below 2)"
                if frac > 0 else "none (gas may pass into the solids it acts on)"))
            wf, wk = mat.wall_law
            # the wall's spring k l on one gas point of mass rho l^3: omega dt
            wdt = math.sqrt(wk / mat.density) / p.dx * scene.time.dt
            out.append("    wall: " + (
                f"held by the inner surface of {mat.wall.material!r}: a gas point nearer its "
                f"face than min({wf:g} l, its first gap) is pushed back with "
                f"{wk / 1e9:.3g} GPa x l x overlap (the ledger's gas_wall); omega dt = "
                f"{wdt:.3g} (velocity Verlet is stable below 2)"
                if wf > 0 else "none (nothing pushes the gas back from a tube's surface)"))
        if p.jitter > 0:
            out.append(f"    jitter: each point moved up to {p.jitter:g} dx = {p.jitter * p.dx:.3g} m "
                       f"on each axis (seed {p.jitter_seed}); bond counts are the lattice's")
    for i, bc in scene.absorbing_layers:
        cs = ", ".join(f"{m} {float(bc.c_max(mat.p_wave_speed)):.3g} 1/s "
                       f"(c_max dt = {float(bc.c_max(mat.p_wave_speed)) * scene.time.dt:.3g})"
                       for m, mat in scene.materials.items()
                       if m not in scene.gas_materials
                       and any(q.material == m for q in scene.parts))
        out.append(f"  boundaries.{i}: absorbing layer lining {bc.face} = {bc.at:g} m, "
                   f"{bc.thickness * 1e3:g} mm thick, design reflection {bc.reflection:g}: "
                   f"damping at the face {cs}")
    out.append("  per material (bonds counted from the lattice cross-sections, the model is "
               "not built; the gas's moving families are not counted):")
    for name, mat in scene.materials.items():
        ks = [k for k, q in enumerate(scene.parts) if q.material == name]
        if not ks:
            out.append(f"    {name!r} ({mat.registry_name}): not used by any part")
            continue
        sel = np.isin(table.part, ks)
        npts, nb = int(table.count[sel].sum()), int(bonds[sel].sum())
        dt_sa = min(part_dt[k][0] for k in ks)
        dt_c = min(min(part_dt[k]) for k in ks)
        c_p = mat.p_wave_speed
        c_max = c_p * dt_c / dt
        line = (f"    {name!r} ({mat.registry_name}): {npts} points, {nb} bonds; "
                f"critical dt {dt_c:.4e} s (Silling-Askari {dt_sa:.4e} s), "
                f"dt/dt_c = {dt / dt_c:.2f}; assumed wave speed c_p = {c_p:.1f} m/s, "
                f"dt holds for waves up to {c_max:.1f} m/s")
        out.append(line)
        h = getattr(mat, "heterogeneity", None)
        if h is not None:
            f = h.inverse_cdf(np.array([0.01, 0.5, 0.99]))
            out.append(f"      strength: {h.registry_name} factor, mean 1, cv {h.variation():.3f}, "
                       f"1/50/99 % {f[0]:.3f}/{f[1]:.3f}/{f[2]:.3f}, on "
                       f"{', '.join(h.applies_to)} (seed {h.seed})")
        mu = wave_speed_limit(mat, c_max)
        if mu is not None:
            c_far = float(mat.p_wave_speed_at(MU_FAR))
            what = ("stiffening of the linear pressure (dp/dmu = K1/(1+mu))"
                    if getattr(mat, "incremental", False) else "EOS stiffening")
            out.append(f"      {what}: the P-wave speed sqrt(((1+mu)^2 dp/dmu + 4G/3)/rho) passes "
                       f"{c_max:.1f} m/s at mu = {mu:.4g}; beyond, dt is above the critical step "
                       f"(at mu = {MU_FAR:g}: {c_far:.0f} m/s, dt <= {dt_c * c_p / c_far:.3e} s "
                       f"needed)")
    for name, mat in scene.materials.items():
        if getattr(mat, "incremental", False):
            out.append(f"  material {name!r}: pressure \"incremental\" (Eq. 35): p_el += -K1 tr(d) dt, "
                       f"K1 = {mat.bulk_modulus:.4g} Pa at every mu (K2, K3 not used)")
        region = getattr(mat, "negative_tangent", lambda: None)()
        if region is not None:
            out.append(f"  material {name!r}: EOS (pressure \"eos\", Eq. 25) tangent dp/dmu < 0 "
                       f"for mu in {region[0]:.5f}..{region[1]:.5f} (K2 = {mat.K2:.4g} Pa, "
                       f"K3 = {mat.K3:.4g} Pa): the wave speed and the viscosity use K1 there")
    out.append(f"  total: {table.n_points} points, {int(bonds.sum())} bonds "
               f"(counted from the cross-sections)")
    out.extend(probe_lines)
    for i, jt in enumerate(scene.joints):
        kind = ("a set, spacing " + f"{jt.spacing:g} m" if jt.spacing > 0 else "one joint")
        out.append(f"  joint {i}: {kind} through {list(jt.point)}, normal {list(jt.normal)}, "
                   + (f"discs of radius {jt.radius:g} m" if jt.radius > 0 else "unbounded")
                   + (f" within the box {list(jt.box.lo)}..{list(jt.box.hi)} m"
                      if jt.box is not None else "")
                   + f", persistence {jt.persistence:g}"
                   + (f" in {jt.patch:g} m patches (seed {jt.seed})" if jt.persistence < 1 else "")
                   + f"; cuts {', '.join(jt.parts) if jt.parts else 'every solid part'}: "
                   "its crossing bonds start broken (the run log counts them)")
    dt_max = critical_dt(scene)
    if scene.time.multirate is not None and scene.time.multirate.max_ratio > 1:
        out.extend(class_report(scene, table, bonds, part_dt))
    verdict = ("OK" if dt <= dt_max else
               "TOO LARGE - the run will be unstable; `mpipd run` refuses it without --force")
    out.append(f"  time step: dt = {dt:.4e} s vs stable {dt_max:.4e} s "
               f"(ratio {dt / dt_max:.2f}): {verdict}")
    per_local, per_owned = memory_model(scene)
    out.append(f"  decomposition: {ranks} rank(s) along z, halo = {halo:.4g} m "
               "(largest horizon + dx/2)")
    names = list(scene.materials)
    mat_of_part = np.array([names.index(q.material) for q in scene.parts])
    thin = 0
    owned_counts = [slabs.points_of(r)[0] for r in range(ranks)]
    bond_counts = [int(bonds[slice(*slabs.owned(r))].sum()) for r in range(ranks)]
    if ranks > 1:
        out.append(f"    balance (whole z levels per rank): max/mean owned points "
                   f"{max(owned_counts) / np.mean(owned_counts):.2f}, max/mean bonds "
                   f"{max(bond_counts) / max(np.mean(bond_counts), 1e-30):.2f}")
    for r in range(ranks):
        owned, ghost = slabs.points_of(r)
        z0, z1 = slabs.z_range(r)
        a, b = slabs.owned(r)
        nb = int(bonds[a:b].sum())
        held = np.concatenate((np.arange(a, b), slabs.ghost_layers(r)))
        ul_points = int(table.count[held][np.isin(table.part[held], ul_parts)].sum())
        mem = (per_local * (owned + ghost) + per_owned * owned + BYTES_PER_BOND * nb
               + BYTES_PER_GAS_POINT * gas_points + BYTES_PER_UL_POINT * ul_points)
        thick = z1 - z0 + float(scene.max_dx)
        recv, _ = slabs.plan(r)
        peers = len({e[0] for e in recv})
        hop = ""
        if thick < halo and ranks > 1:
            thin += 1
            hop = " (thinner than the halo: multi-hop exchange)"
        out.append(f"    rank {r}: z {z0:.4g}..{z1:.4g} m ({thick:.4g} m thick), {owned} owned + "
                   f"{ghost} ghost points, {nb} bonds, ~{mem / 2**20:.1f} MiB, "
                   f"{peers} halo peer(s){hop}")
        if len(names) > 1:
            mats = mat_of_part[table.part[a:b]]
            parts_txt = []
            for m, name in enumerate(names):
                sel = mats == m
                if sel.any():
                    parts_txt.append(f"{name} {int(table.count[a:b][sel].sum())} points / "
                                     f"{int(bonds[a:b][sel].sum())} bonds")
            out.append("      " + ", ".join(parts_txt))
    if thin:
        out.append(f"  note: {thin} slab(s) thinner than the halo ({halo:.4g} m): their ghosts "
                   "come from ranks beyond the neighbours (handled by the multi-hop halo, "
                   "at the cost of more messages); fewer ranks avoid it")
    mems = rank_memory(scene, table, slabs, bonds, ranks)
    avail = mem_available()
    total = sum(mems)
    line = (f"  memory: the model's arrays {gb(max(mems))} on the largest rank, {gb(total)} "
            f"on {ranks} rank(s)")
    if avail is not None:
        line += f"; this machine has {gb(avail)} available"
        if total > avail:
            line += (" - WARNING: all ranks on this machine would not fit (`mpipd run` "
                     "refuses it without --force-size; spread the ranks over nodes)")
    out.append(line)
    from .output.writer import n_frames
    rf = run_file_bytes(scene, int(table.n_points))
    out.append(f"  run file: {gb(rf)} allocated before step 1 "
               f"({n_frames(scene.time.n_steps, scene.output.every)} frame(s) x "
               f"{len(scene.output.fields)} field(s) x {table.n_points} points, plus geometry "
               "and probes; `mpipd run` refuses it, without --force-size, where it would take "
               "more than 90 % of the file system's free space)")
    return "\n".join(out)


def part_classes(scene, part_dt) -> list[int]:
    """Each part's step class at rest (mpipd.model.multirate's rule without the
    buffer and the state): floor(log2(safety dt_c / dt)) in 0..log2(max_ratio),
    0 for the gas."""
    mr = scene.time.multirate
    top = mr.max_ratio.bit_length() - 1
    out = []
    for k, q in enumerate(scene.parts):
        if is_gas_part(scene, q):
            out.append(0)
            continue
        r = mr.safety * min(part_dt[k]) / scene.time.dt
        out.append(int(min(max(math.floor(math.log2(r)), 0), top)) if r > 0 else 0)
    return out


def class_report(scene, table, bonds, part_dt) -> list[str]:
    """The multi-rate classes at rest: points and bonds per class and the projected
    cost per fine step against single-rate (bond evaluations, sum_k B_k / 2^k / B)."""
    from .model.multirate import projected_cost
    mr = scene.time.multirate
    top = mr.max_ratio.bit_length() - 1
    ks = part_classes(scene, part_dt)
    of_layer = np.array(ks)[table.part]
    pts = [int(table.count[of_layer == k].sum()) for k in range(top + 1)]
    bnd = [int(bonds[of_layer == k].sum()) for k in range(top + 1)]
    cost = projected_cost(bnd)
    lines = [f"  multi-rate: max_ratio {mr.max_ratio}, safety {mr.safety:g}, {mr.buffer} buffer, "
             f"fracture class {mr.fracture_class} over {mr.fracture_window} coarse steps, family "
             f"factor {mr.family_factor}; classes at rest "
             "(before the one-family buffer next to a finer class and the state's refinement "
             "by compression, smallest stretch, the family left and fracture, which the run applies):"]
    for k in range(top + 1):
        names = [q.name for q, c in zip(scene.parts, ks) if c == k]
        lines.append(f"    class {k} (dt x {2 ** k}): {pts[k]} points, {bnd[k]} bonds"
                     + (f" - parts {', '.join(names)}" if names else ""))
    lines.append(f"    projected cost per fine step: {cost:.3f} of single-rate "
                 f"(at most {1 / cost:.2f}x faster; bond work only)")
    return lines


#: the "far beyond the negative-dp/dmu range" compression the report quotes (K3 mu^3 dominates)
MU_FAR = 0.1

