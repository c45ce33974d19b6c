"""The explosive gas: updated-Lagrangian points with the JWL EOS and a programmed
detonation (paper §2.6, Eqs. 45–48).  Built only when a scene has a ``jwl``
material.

* Every rank holds every gas point (owned, or as a ghost: the halo replicates the
  gas, which moves far from its reference slab, and is a few per cent of a model;
  :func:`mpipd.parallel.decomp.replicated_parts`).  The solids it acts on (its
  ``interacts_with`` materials) are held as their slabs are; the ones an owned gas
  point may reach beyond this rank's static halo come as *remote* rows from their
  owners (:class:`mpipd.parallel.near.NearHalo`), appended after the local points
  in the arrays the gas kernels read (``y_ext``, ``v_ext``, ...).
* Families live in the current configuration: for each owned gas point, the gas
  and the ``interacts_with`` solids within the gas horizon; for each owned such
  solid, the gas points whose horizon reaches it.  No total-Lagrangian bond
  touches a gas point, and there are no gas-solid pairs with solids the scene does
  not list.  They are searched with a cell list (mpipd.kernels.search; a cKDTree
  if the points spread too far for its keys) out to the horizon plus a skin s
  (a Verlet list) and searched again (with a new remote plan) only once some gas
  point or owned acted-on solid, on any rank, has moved more than s / 2 since:
  until then every pair within the horizon is in the list.  The kernels keep only
  pairs inside the horizon, in gid order, so the result is exactly that of a
  search every step, on any number of ranks, whatever s is.  s is a cost balance
  (Verlet 1967, Phys. Rev. 159; Allen & Tildesley, Computer Simulation of Liquids,
  on neighbour lists): a larger skin means fewer searches and longer lists.  In a
  blast the balance moves: the dense gas of the first microseconds has long lists
  and is searched cheaply, the spread gas of the late run has almost no pairs and
  moves at km/s, so a fixed skin of 0.2 horizons is searched again at every step.
  So s follows the measured cost (:class:`SkinTuner`): at each search the time per
  step of the last list (its search and the gas kernels while it lasted) is
  compared with the list's before, and s moves on by a factor SKIN_STEP in the
  same direction if it got cheaper, else turns back, within SKIN and SKIN_MAX
  horizons.  Only the time changes with s, never the answer.
* It is the "ul" model family (:class:`mpipd.model.base.Model`): ``update`` moves
  the families, volume, energy and pressure on; ``force_data`` hands the halo the
  force data ``gd`` that ``update`` made; ``gather`` adds the pair forces.
* Kernels: mpipd.kernels.ul.  The gas energy (per initial volume) changes by
  exactly the trapezoidal work of the gas's pressure forces; it is the ledger's
  ``gas``.  With a bulk viscosity (the material's ``viscosity``), the work of its
  q is summed in ``viscous_work`` (this rank's share): the ledger's ``gas_viscous``.
  With a contact (the material's ``contact``), gas-solid pairs repel when close:
  its potential is the ledger's ``gas_contact``.  With a wall (the material's
  ``wall``, mpipd.materials.jwl.GasWall; kernels mpipd.kernels.wall), the gas is
  held by the interpolated surface of one solid; the work done against it (the
  trapezoid over every step, this rank's owned points) is the ledger's ``gas_wall``.
"""
from __future__ import annotations

import time

import numpy as np
from scipy.spatial import cKDTree

from ..kernels.energy import trapezoid_work
from ..kernels.layout import GD_A, GD_P, GD_V, GD_WIDTH
from ..kernels.search import MAX_CELLS, cell_counts, cell_pairs, max_moved2, merge_rows, near_cells
from ..kernels.ul import GasParams, gas_contact_energy, gas_gather, gas_update
from ..kernels.wall import wall_gather, wall_update
from ..parallel.near import NearHalo
from ..state import AUX, LOCAL
from .base import Model
from .families import _csr_by_row

#: Verlet skin of the gas families, smallest and largest, as fractions of the gas
#: horizon, and its factor of change at a search (SkinTuner)
SKIN = 0.2
SKIN_MAX = 1.0
SKIN_STEP = 1.25
#: reference coordinate given to remote rows (:meth:`Gas._extend`)
FAR = 1e30


def lighting_times(scene, part: np.ndarray, x: np.ndarray, mat) -> np.ndarray:
    """The time each gas point (reference position ``x``, (n, 3)) is lit (programmed
    burn, paper §2.6): for a charge with its own ``initiation``, from its face or
    point (mpipd.input.scene.Initiation.times), otherwise the material's
    t_L = (z - initiation_z) direction / vod.  Several charges of one explosive
    each follow their own schedule (delays)."""
    t = (x[:, 2] - mat.initiation_z) * mat.direction / mat.vod
    for k, q in enumerate(scene.parts):
        ini = q.initiation
        if ini is not None:
            sel = part == k
            t[sel] = ini.times(x[sel], mat.vod)
    return t


def check_charges(scene) -> None:
    """Bad input (SceneError, one line naming the key) for a charge that the run
    would not light as its scene says: a plane (the charge's own ``initiation``, or
    its material's initiation_z and direction) more than a dx from the charge's end
    face the front leaves from -- outside it, a late start, or inside or beyond it,
    lighting the points behind it at once; a primer ``point`` more than a dx from
    every point of the charge; and a charge none of whose points is lit before the
    run's end (``initiation.never = true`` says so on purpose).  On the unjittered
    lattice (mpipd.input.geometry.part_points); ``mpipd run`` and ``mpipd check`` call it."""
    from ..input.geometry import part_points
    from ..input.schema import fail
    t_end = scene.time.n_steps * scene.time.dt
    for k, q in enumerate(scene.parts):
        if q.material not in scene.gas_materials:
            continue
        mat, ini = scene.materials[q.material], q.initiation
        if ini is not None and ini.never:
            continue
        pts = part_points(q)
        if ini is not None and ini.point is not None:
            d = float(np.linalg.norm(pts - np.asarray(ini.point), axis=1).min())
            if d > q.dx:
                fail(f"parts.{k}.initiation.point",
                     f"the primer point {list(ini.point)} m lies {d * 1e3:.3g} mm from the "
                     f"nearest point of charge {q.name!r} (more than its dx, "
                     f"{q.dx * 1e3:.3g} mm): outside it, lit {d / mat.vod * 1e6:.3g} us late")
        else:
            z0, sign = (ini.z, ini.direction) if ini is not None else (mat.initiation_z,
                                                                        mat.direction)
            key = (f"parts.{k}.initiation.z" if ini is not None
                   else f"materials.{q.material}.initiation_z")
            lo, hi = float(pts[:, 2].min()) - 0.5 * q.dx, float(pts[:, 2].max()) + 0.5 * q.dx
            face = lo if sign > 0 else hi
            ahead = (pts[:, 2] - z0) * sign          # the front's distance to each point
            where = (f"the initiation plane z = {z0:g} m ({'+' if sign > 0 else '-'}z) "
                     f"of charge {q.name!r} (z {lo:g}..{hi:g} m)")
            if ahead.min() > q.dx:
                fail(key, f"{where} lies outside it, {ahead.min() * 1e3:.3g} mm before its "
                          f"first point (lit {ahead.min() / mat.vod * 1e6:.3g} us late): put "
                          f"it on the face the front leaves from, z = {face:g} m")
            if ahead.min() < -q.dx:
                behind = int(np.count_nonzero(ahead < 0.0))
                fail(key, f"{where} lies {'beyond' if ahead.max() < 0 else 'inside'} it: "
                          f"{behind} of its {len(pts)} points are behind the plane and lit "
                          f"at once at t = {(ini.time if ini is not None else 0.0) * 1e6:.4g} "
                          f"us; put it on the face the front leaves from, z = {face:g} m")
        first = float(lighting_times(scene, np.full(len(pts), k), pts, mat).min())
        if not first < t_end:
            timed = ini is not None and ini.time > 0
            fail(f"parts.{k}.initiation" + (".time" if timed else ""),
                 f"charge {q.name!r} is first lit at {first * 1e6:.4g} us, not before the "
                 f"run's end t_end = {t_end * 1e6:.4g} us: none of it burns in this run (run "
                 "to its time and stop earlier with --stop-after, or set initiation.never = "
                 "true for a charge never lit)")


class Gas(Model):
    name = "gas"

    def __init__(self, scene, points, team, slabs=None):
        """The gas of ``scene`` among this rank's ``points`` (collective: the search
        reach is the largest gas horizon over all ranks; ``slabs``, the
        decomposition, for the remote solids of a run on several ranks)."""
        p = points
        names = list(scene.materials)
        explosives = scene.gas_materials
        self.mat = scene.materials[explosives[0]]
        gas_ids = [names.index(m) for m in explosives]
        acts = {a for m in explosives for a in scene.materials[m].interacts_with}
        n, nl = p.n_owned, p.n_local
        self.points = p
        self.team = team
        self.is_gas = np.isin(p.material, gas_ids).astype(np.uint8)
        solid = np.isin(p.material, [names.index(a) for a in acts])
        self.eligible = np.flatnonzero(self.is_gas.astype(bool) | solid)   # local ones
        self.rows = self.eligible[self.eligible < n]
        self.gas_idx = np.flatnonzero(self.is_gas[:n]).astype(np.int64)
        gas_all = self.gas_all = np.flatnonzero(self.is_gas).astype(np.int64)
        self.solids_owned = np.flatnonzero(solid[:n]).astype(np.int64)
        # whose motion triggers a new search: every gas point, this rank's solids
        self.watch = np.union1d(gas_all, self.solids_owned)
        self.gd = np.zeros((nl, GD_WIDTH))           # A (6), V, p
        self.gd[self.is_gas.astype(bool), GD_V] = p.volume[self.is_gas.astype(bool)]
        self.V0 = p.volume[self.gas_idx].copy()
        self.e = np.full(len(self.gas_idx), self.mat.e0)
        m = self.mat
        self.t_lit = lighting_times(scene, p.part[self.gas_idx], p.x[self.gas_idx], m)
        self.vr_lit = np.zeros(len(self.gas_idx))     # V_R when first lit (0: not yet)
        self.part_names = [q.name for q in scene.parts]
        dx = float(p.dx[self.gas_idx].max()) if len(self.gas_idx) else 0.0
        self.t_ramp = m.burn_ramp * dx / m.vod
        self.gas_horizon = np.where(self.is_gas.astype(bool), p.horizon, 0.0)
        self.reach = team.max(float(self.gas_horizon.max()) if nl else 0.0)
        self.V_ratio = np.ones(n)                # V_w / V0 of the owned gas (1 elsewhere)
        self.V_w = self.gd[:, GD_V].copy()          # this step's pair weights (start-of-step V)
        self.V_pw = self.V_w.copy()              # the last step's
        self.offsets = np.zeros(n + 1, np.int64)
        self.nbr = np.zeros(0, np.int32)
        self.skin = SKIN * self.reach             # the skin of the last search
        self.tuner = SkinTuner()
        self.y_built = None                      # watched points' positions at the last search
        self.searches = 0
        self.search_seconds = 0.0
        self.n_singular = 0
        self.peak_pressure = 0.0                 # largest gas pressure so far (owned)
        self.c_q, self.c_l = m.bulk_viscosity
        self.params = GasParams(float(self.t_ramp), float(m.A), float(m.B), float(m.R1),
                                float(m.R2), float(m.omega), float(m.pressure_factor),
                                float(m.density), float(self.c_q), float(self.c_l),
                                *map(float, m.unreacted_eos))
        self.contact_frac, self.contact_k = m.contact_law
        self.viscous = self.c_q > 0.0 or self.c_l > 0.0
        self.gq = np.zeros(len(self.gas_idx))    # bulk viscosity q of the last step
        self.viscous_work = 0.0                  # dissipated work of q, this rank (J): the
        #                                          ledger's gas_viscous
        self.near = None                         # the remote solids (several ranks)
        if slabs is not None and team.size > 1 and len(acts):
            self.near = _near_halo(team.comm, slabs, p, self.solids_owned, gas_all)
        self.wall_frac, self.wall_k = m.wall_law
        if self.wall_frac > 0.0:
            self._wall_table(names.index(m.wall.material))
        self._extend(0)
        self._y = np.zeros((nl, 3))              # x + u of the local points, this step
        self.y = None                            # current positions (y_ext) of the last update

    def _extend(self, n_remote: int):
        """The arrays the gas kernels read over local and remote rows: positions and
        velocities (filled every step), and volume, gid, gas flag and gas horizon
        (a remote row is a solid: flag 0, horizon 0)."""
        p = self.points
        nl = p.n_local
        near = self.near
        self.y_ext = np.zeros((nl + n_remote, 3))
        self.v_ext = np.zeros((nl + n_remote, 3))
        if n_remote:
            self.vol_ext = np.concatenate((p.volume, near.remote_volume))
            self.gid_ext = np.concatenate((p.gid, near.remote_gid))
            # a remote row's reference position is only needed for the contact's cap
            # d_c = min(frac l, |xi|): it is beyond this rank's static halo, so |xi| to
            # any owned gas point exceeds a horizon (> frac l) and a far point serves
            self.x_ext = np.concatenate((p.x, np.full((n_remote, 3), FAR)))
        else:
            self.vol_ext, self.gid_ext, self.x_ext = p.volume, p.gid, p.x
        self.isgas_ext = np.concatenate((self.is_gas, np.zeros(n_remote, np.uint8)))
        self.h_ext = np.concatenate((self.gas_horizon, np.zeros(n_remote)))
        self.el_ext = np.concatenate((self.eligible,
                                      np.arange(nl, nl + n_remote, dtype=self.eligible.dtype)))
        if self.wall_frac > 0.0:
            k = np.searchsorted(self.wall_gid, self.gid_ext)
            k = np.minimum(k, len(self.wall_gid) - 1)
            hit = self.wall_gid[k] == self.gid_ext
            self.wall_ext = hit.astype(np.uint8)
            self.wallN_ext = np.where(hit[:, None], self.wall_N[k], 0.0)
            self.walll_ext = np.where(hit, self.wall_l[k], 0.0)

    def _wall_table(self, wid: int):
        """The wall points of material ``wid`` (collective): its owned points with gas
        within the gas reach whose own family's first moment, sum (1 - r/delta)^2 V
        (x_k - x_j) over the same material, points away from the gas, and with no
        point of that material in front of them (more than half a spacing nearer
        the gas along N, within a spacing of N's line): the layer facing the gas.
        Their reference normal N = minus that moment, normalised, and lattice
        spacing V^(1/3).  Every rank gets the table of all of them, by gid
        (a remote row is looked up in it).  Reference positions; the static halo
        holds every neighbour of an owned point."""
        p = self.points
        n = p.n_owned
        same = np.flatnonzero(p.material == wid)
        cand = same[same < n]
        gas = self.gas_all
        keep = np.zeros(len(cand), bool)
        N = np.zeros((len(cand), 3))
        if len(cand) and len(gas):
            tree_s, tree_g = cKDTree(p.x[same]), cKDTree(p.x[gas])
            gid = p.gid
            for a, j in enumerate(cand):        # sums in gid order: any rank count
                nb = same[tree_s.query_ball_point(p.x[j], p.horizon[j])]
                nb = nb[np.argsort(gid[nb], kind="stable")]
                d = p.x[nb] - p.x[j]
                w = (1.0 - np.linalg.norm(d, axis=1) / p.horizon[j]) ** 2 * p.volume[nb]
                mom = (w[:, None] * d).sum(axis=0)
                ng = gas[tree_g.query_ball_point(p.x[j], self.reach)]
                ng = ng[np.argsort(gid[ng], kind="stable")]
                if not len(ng) or not np.any(mom):
                    continue
                dg = p.x[ng] - p.x[j]
                wg = (1.0 - np.linalg.norm(dg, axis=1) / self.reach) ** 2 * p.volume[ng]
                towards = (wg[:, None] * dg).sum(axis=0)
                N[a] = -mom / np.linalg.norm(mom)
                # facing the gas, with no point of its own in front of it (half a
                # spacing nearer the gas, within a spacing of its normal's line)
                lj = p.volume[j] ** (1.0 / 3.0)
                along = d @ N[a]
                side = np.linalg.norm(d - along[:, None] * N[a], axis=1)
                keep[a] = (float(N[a] @ towards) > 0.0
                           and not np.any((along > 0.5 * lj) & (side < lj)))
        got = self.team.gather((p.gid[cand[keep]], N[keep], p.volume[cand[keep]] ** (1.0 / 3.0)))
        gid = np.concatenate([g[0] for g in got]).astype(np.int64)
        order = np.argsort(gid)
        self.wall_gid = gid[order]
        self.wall_N = np.concatenate([g[1] for g in got]).reshape(-1, 3)[order]
        self.wall_l = np.concatenate([g[2] for g in got])[order]
        nl = p.n_local
        self.ell = self.V0 ** (1.0 / 3.0)
        self.g0 = np.full(len(self.gas_idx), np.nan)  # standoffs, set at first contact check
        self.gw = np.zeros((nl, 3))                   # F_i / S_i of the gas (exchanged)
        self.gF = np.zeros((nl, 3))                   # F_i of the owned gas
        self.fw = np.zeros((len(self.rows), 3))       # the wall's force densities, rows order
        self.fw_old = np.zeros_like(self.fw)
        self.wall_work = 0.0                          # work of the wall forces, this rank (J)
        self.wall_on = 0                              # owned gas points pushed, last step
        self.wall_depth = 0.0                         # their largest (g_0 - g) / l, last step
        self._booked = False                          # update() since the last gather
        self._dt = 0.0

    def register(self, state):
        """The gas's arrays in the State (owner "gas") under the checkpoint names of
        before: volume, pressure and last force state (columns of ``gd``), the last
        step's pair weights and the energy per initial volume; the gas pressure is
        offered as (its part of) the output field ``pressure``."""
        own, gd = self.name, self.gd
        add = state.add
        add("gd", own, gd, rows=LOCAL, exchanged=True)
        add("gas_V", own, gd[:, GD_V], rows=LOCAL, checkpoint=True)
        add("gas_p", own, gd[:, GD_P], rows=LOCAL, checkpoint=True)
        add("gas_A", own, gd[:, GD_A:GD_V], rows=LOCAL, checkpoint=True)
        add("gas_Vw", own, self.V_w, rows=LOCAL, checkpoint=True)
        add("gas_e", own, self.e, rows=self.gas_idx, checkpoint=True)
        add("gas_Vpw", own, self.V_pw, rows=LOCAL)
        add("gas_V_ratio", own, self.V_ratio)
        add("gas_V0", own, self.V0, rows=self.gas_idx)
        add("gas_t_lit", own, self.t_lit, rows=self.gas_idx)
        add("gas_vr_lit", own, self.vr_lit, rows=self.gas_idx, checkpoint=True)
        add("gas_is_gas", own, self.is_gas, rows=LOCAL)
        add("gas_horizon", own, self.gas_horizon, rows=LOCAL)
        for name in ("eligible", "rows", "gas_idx", "gas_all", "watch", "solids_owned"):
            add(f"gas_{name}" if name not in ("gas_idx", "gas_all") else name, own,
                getattr(self, name), rows=AUX)
        add("gas_offsets", own, get=lambda: self.offsets, rows=AUX)
        add("gas_nbr", own, get=lambda: self.nbr, rows=AUX)
        add("gas_y_built", own, get=lambda: self.y_built, rows=AUX)
        add("gas_y_local", own, self._y, rows=LOCAL)
        for name in ("y_ext", "v_ext", "vol_ext", "gid_ext", "isgas_ext", "h_ext", "el_ext"):
            add(f"gas_{name}", own, get=lambda name=name: getattr(self, name), rows=AUX)
        add("gas_q", own, self.gq, rows=self.gas_idx, checkpoint=self.viscous)
        if self.wall_frac > 0.0:
            add("gas_wall_g0", own, self.g0, rows=self.gas_idx, checkpoint=True)
            add("gas_wall_gw", own, self.gw, rows=LOCAL, exchanged=True, checkpoint=True)
            add("gas_wall_F", own, self.gF, rows=LOCAL, checkpoint=True)
            add("gas_wall_fw", own, self.fw, rows=AUX)
            add("gas_wall_fw_old", own, self.fw_old, rows=AUX)
            add("gas_wall_ell", own, self.ell, rows=self.gas_idx)
            for name in ("wall_gid", "wall_N", "wall_l"):     # the table of all wall points
                add(f"gas_{name}", own, getattr(self, name), rows=AUX)
            for name in ("wall_ext", "wallN_ext", "walll_ext"):
                add(f"gas_{name}", own, get=lambda name=name: getattr(self, name), rows=AUX)
            state.scalar("gas_wall_work", own, lambda: self.wall_work,
                         lambda v: setattr(self, "wall_work", float(v)))
        if self.viscous:
            state.scalar("gas_viscous_work", own, lambda: self.viscous_work,
                         lambda v: setattr(self, "viscous_work", float(v)))
        state.offer("pressure", own, self.pressure)
        state.offer("gas_force", own, self.carries_force)
        # the every-step peak, whole run (a restart goes on from it)
        state.scalar("gas_peak_pressure", own, lambda: self.peak_pressure,
                     lambda v: setattr(self, "peak_pressure", float(v)), reduce="max")

    def after_restore(self, halo):
        """The ghosts' pair weights and the volume ratio from the restored state."""
        halo.exchange(self.V_w)
        self.V_ratio[self.gas_idx] = self.V_w[self.gas_idx] / self.V0

    def _stale(self, y) -> bool:
        """Has some watched point, on any rank, moved half the skin since the last
        search (or was there none)?  Collective on several ranks."""
        if self.y_built is None:
            stale = True
        else:
            stale = max_moved2(y, self.watch, self.y_built) >= (0.5 * self.skin) ** 2
        if self.near is not None:
            stale = bool(self.team.max(int(stale)))
        return stale

    def search(self, y, v):
        """Fill y_ext, v_ext from the local ``y``, ``v`` and the remote rows' owners;
        then, if stale (:meth:`_stale`), a new remote plan and current-configuration
        families, each sorted by neighbour gid: every pair closer than the larger gas
        horizon plus the skin."""
        t0 = time.perf_counter()
        p = self.points
        nl, n = p.n_local, p.n_owned
        stale = self._stale(y)
        if stale and self.searches:
            cost = self.tuner.cost()
            if self.near is not None:       # one skin on every rank
                cost = self.team.max(cost)
            self.skin = self.tuner.next(cost) * self.reach
        if stale and self.near is not None:
            self._extend(self.near.plan(y, self.reach + self.skin))
        ye, ve = self.y_ext, self.v_ext
        ye[:nl] = y
        ve[:nl] = v
        if self.near is not None:
            self.near.exchange(ye, ve)
        if stale:
            self.y_built = y[self.watch]
            self.searches += 1
            self._pairs(ye, n)
        dt = time.perf_counter() - t0
        self.search_seconds += dt
        self.tuner.spent(dt, stale)

    def _pairs(self, ye, n):
        """The families at positions ``ye`` (local + remote rows): each owned gas point
        among every candidate (gas and solids), each owned solid among the gas only
        (a solid-solid pair carries no force).  Only the solids in or next to a cell
        (side: reach plus skin) that holds gas can pair (:func:`near_cells`); the
        others are skipped, however far the gas has spread."""
        el, gas = self.el_ext, self.gas_all
        if not len(self.rows) or not len(gas):
            self.offsets[:] = 0
            self.nbr = np.zeros(0, np.int32)
            return
        cell = self.reach + self.skin
        solids = near_cells(ye, el[self.isgas_ext[el] == 0], gas, cell)
        el = np.concatenate((gas, solids))
        lo_el, dims = cell_counts(ye[el], cell)
        if not float(np.prod(dims.astype(float))) < MAX_CELLS:   # too spread for int64 keys
            counts, self.nbr = self._tree_pairs(ye, n)
        else:
            ca, na = cell_pairs(ye, self.gas_idx, el, self.h_ext, self.skin, cell, lo_el, dims,
                                self.gid_ext, n)
            lo_g, dims = cell_counts(ye[gas], cell)
            cb, nb = cell_pairs(ye, solids[solids < n], gas, self.h_ext, self.skin, cell,
                                lo_g, dims, self.gid_ext, n)
            counts, self.nbr = merge_rows(ca, na, cb, nb)
        self.offsets[1:] = np.cumsum(counts)

    def _tree_pairs(self, y, n):
        """The same pairs by a k-d tree (points spread beyond the cell keys' range)."""
        el = self.el_ext
        m = cKDTree(y[self.rows]).sparse_distance_matrix(
            cKDTree(y[el]), self.reach + self.skin, output_type="ndarray")
        i, j = self.rows[m["i"]], el[m["j"]]
        h, g = self.h_ext, self.isgas_ext
        keep = ((i != j) & (m["v"] < np.maximum(h[i], h[j]) + self.skin)
                & ((g[i] > 0) | (g[j] > 0)))
        return _csr_by_row(i[keep], j[keep], self.gid_ext, n)

    def update(self, u, v, dt: float, t: float):
        """Families, then volume, energy, pressure and force data of the owned gas."""
        p = self.points
        np.add(p.x, u, out=self._y)
        self.search(self._y, v)
        y = self.y = self.y_ext                 # current positions, kept for gather()
        self.V_pw[:] = self.V_w                 # in place: the State holds these arrays
        self.V_w[:] = self.gd[:, GD_V]
        t0 = time.perf_counter()
        self.n_singular, wq = gas_update(
            self.gas_idx, y, self.v_ext, self.vol_ext, self.V_w, self.V_pw, self.gd,
            p.horizon, self.offsets, self.nbr, dt, t, self.t_lit, self.V0, self.e,
            self.isgas_ext, self.vr_lit, self.gq, self.params)
        self.tuner.step(time.perf_counter() - t0)
        self.viscous_work += wq
        self.V_ratio[self.gas_idx] = self.V_w[self.gas_idx] / self.V0
        if self.wall_frac > 0.0:
            self.wall_on, self.wall_depth = wall_update(
                self.gas_idx, y, self.offsets, self.nbr, self.wall_ext, self.wallN_ext,
                self.walll_ext, p.horizon, self.ell, self.g0, self.gw, self.gF,
                self.wall_frac, self.wall_k)
            self._booked, self._dt = True, dt
        if len(self.gas_idx):
            self.peak_pressure = max(self.peak_pressure, float(self.gd[self.gas_idx, GD_P].max()))

    def force_data(self, u, ledger=None) -> tuple:
        """The owned gas's force data, made by :meth:`update` (gd: A, V, p; with a
        wall, its F / S too)."""
        return (self.gd, self.gw) if self.wall_frac > 0.0 else (self.gd,)

    def gather(self, u, v, f, fv=None):
        """UL forces into f; u must be the displacement update() last saw, or the
        positions are taken from u (``y`` None: at step 0, after a restore)."""
        p = self.points
        if self.y is None:                      # positions from u (collective)
            self.search(p.x + u, v)
            self.y = self.y_ext
        t0 = time.perf_counter()
        gas_gather(self.rows, self.y, self.vol_ext, self.V_w, self.V_ratio, self.gd,
                   p.horizon, self.offsets, self.nbr, self.isgas_ext, f, self.x_ext,
                   self.contact_frac, self.contact_k)
        if self.wall_frac > 0.0:
            wall_gather(self.rows, self.y, self.offsets, self.nbr, self.isgas_ext,
                        self.wall_ext, p.horizon, self.gw, self.gF, self.vol_ext, f, self.fw)
            # the work over the step just taken (v = v_{n+1/2} after an update); a
            # gather without one (step 0, a restore, a refresh after breakage: the
            # same positions) only makes these forces the last ones
            if self._booked:
                self.wall_work += trapezoid_work(self.fw_old, self.fw, self.rows, v,
                                                 p.volume, self._dt)
                self._booked = False
            else:
                self.fw_old[...] = self.fw
        self.tuner.spent(time.perf_counter() - t0)

    def lit_density(self, team) -> dict:
        """Per charge (part name): the largest and the mean density at lighting over
        its lit points, as multiples of the charge's density (1: lit as loaded; a
        delayed charge beside fired holes may have been compressed), and the fraction
        of its points lit (collective)."""
        out = {}
        parts = self.points.part[self.gas_idx]
        for k, name in enumerate(self.part_names):
            sel = parts == k
            lit = sel & (self.vr_lit > 0)
            rho = 1.0 / self.vr_lit[lit]
            n_all = team.sum(int(sel.sum()))
            if n_all == 0:
                continue
            n_lit = team.sum(int(lit.sum()))
            mx = team.max(float(rho.max()) if len(rho) else 0.0)
            mean = team.sum(float(rho.sum())) / max(n_lit, 1)
            out[name] = {"max": mx, "mean": mean, "lit_fraction": n_lit / n_all}
        return out

    def energy(self) -> float:
        """Internal energy of the owned gas (J): e per initial volume times V0."""
        return float(np.dot(self.e, self.V0))

    def contact_energy(self) -> float:
        """Potential of the gas-solid contact (J) over the owned gas points' pairs at
        the positions of the last force gather (mpipd.kernels.ul.gas_contact_energy);
        0 without a contact law."""
        if self.contact_frac == 0.0 or self.y is None:
            return 0.0
        return gas_contact_energy(self.gas_idx, self.y, self.x_ext, self.vol_ext, self.offsets,
                                  self.nbr, self.isgas_ext, self.contact_frac, self.contact_k)

    def wall_energy(self) -> float:
        """The work done against the gas wall (J, this rank's owned points): minus the
        trapezoidal work of its forces since step 0; 0 without a wall."""
        return -self.wall_work if self.wall_frac > 0.0 else 0.0

    def carries_force(self) -> np.ndarray:
        """1 at the owned gas points whose force state is not zero after the last update
        (lit, and with a gas neighbourhood: mpipd.kernels.ul.well_posed), 0 elsewhere."""
        out = np.zeros(self.points.n_owned)
        out[self.gas_idx] = np.any(self.gd[self.gas_idx, GD_A:GD_V] != 0.0, axis=1)
        return out

    def pressure(self) -> np.ndarray:
        """Gas pressure over all owned points (0 elsewhere)."""
        out = np.zeros(self.points.n_owned)
        out[self.gas_idx] = self.gd[self.gas_idx, GD_P]
        return out


class SkinTuner:
    """The gas's Verlet skin as a fraction of its horizon, tuned on the measured
    cost (module docstring): a one-dimensional descent on the time per step of a
    list's life, its search plus the gas kernels and exchanges while it lasted.
    Each new list takes a skin SKIN_STEP times larger or smaller than the last,
    in the direction that made the last change cheaper (within SKIN and SKIN_MAX).
    The skin changes the time of a run, never its numbers."""

    def __init__(self):
        self.frac = SKIN
        self.up = True                          # the direction of the next change
        self.last = None                        # the last list's cost per step (s)
        self.seconds = 0.0                      # this list's time so far
        self.steps = 0                          # and its steps

    def spent(self, seconds: float, search: bool = False):
        """Book ``seconds`` to this list; a search starts a new list with them."""
        if search:
            self.seconds = 0.0
            self.steps = 0
        self.seconds += seconds

    def step(self, seconds: float):
        """A step's gas update took ``seconds``."""
        self.seconds += seconds
        self.steps += 1

    def cost(self) -> float:
        """This list's time per step so far."""
        return self.seconds / max(self.steps, 1)

    def next(self, cost: float) -> float:
        """The skin fraction of the next list, given this list's ``cost`` per step
        (the same on every rank when the ranks search together)."""
        if self.last is not None and cost > self.last:
            self.up = not self.up
        self.last = cost
        f = self.frac * (SKIN_STEP if self.up else 1.0 / SKIN_STEP)
        self.frac = min(max(f, SKIN), SKIN_MAX)
        return self.frac


def _near_halo(comm, slabs, p, solids_owned, gas_all) -> NearHalo:
    """The remote-solid halo of this rank: which of its owned acted-on solids each
    peer lacks (beyond the peer's static halo), and who owns each gas point."""
    r = comm.Get_rank()
    layer = slabs.layer_of(p.gid[solids_owned])
    lacks = {q: ~slabs.holds(q, layer) for q in range(slabs.n_ranks) if q != r}
    return NearHalo(comm, p.n_local, solids_owned, lacks, gas_all,
                    slabs.owner_of_gid(p.gid[gas_all]), p.volume, p.gid)
