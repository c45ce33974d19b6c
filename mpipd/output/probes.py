"""Probes: named points whose state is recorded every step (paper Figs. 15–16).

Each probe is the lattice point nearest its ``position`` (lowest gid on a tie),
among the points of its ``part`` if it names one (a probe farther than that
point's horizon from it is refused as outside the body; one moved by more
than half the dx of the point's part, in 3-D distance from the requested
position, is a warning in the run log naming the probe, the requested and the
snapped positions and the distance: it samples the material elsewhere than asked,
e.g. blast_paper's P1, asked 0.8 mm from the wall, sits 0.42 mm from it, 0.57 mm
from its position; paper Fig. 15) (a part name matches the part
and its zones ``<part>.band``, ``<part>.0``, ... of :meth:`mpipd.input.scene.Part.zones`,
so ``part = "rock"`` samples the rock whatever its resolution bands); the rank
that owns it records, every step,

    t, sigma_rr, v_r            radial stress and velocity about the axis through ``center``
    p                           pressure -tr(sigma)/3 (compression positive)
    s                           von Mises equivalent stress
                                (a point of the explosive gas: its stress is the JWL
                                pressure's, sigma = -p I, with p the gas model's, as
                                in ``/fields/pressure`` (mpipd.model.gas: the EOS
                                pressure, without the bulk viscosity q), so
                                sigma_rr = -p and s = 0)
    strength                    JH2 yield strength sigma_y at the point's p*, edot*, D
                                (NaN for other materials)
    t_state                     the time of the state its stress was taken at: t in
                                the fine class; under multi-rate, a point of class k
                                at step n was last updated at step n - (n mod 2^k)
                                (docs/multirate.md), so t_state = t - (n mod 2^k) dt

into ``/probes/<name>/{t, sigma_rr, v_r, p, s, strength, t_state}``, with ``/probes/<name>``
attributes ``gid``, ``position`` (requested), ``x`` (the chosen point), ``distance``
(m, from the requested position to the chosen point), ``dx`` (m, the lattice spacing
of the chosen point's part), ``part`` (the zone holding the point), ``material`` and
``requested_part`` (the probe's ``part``, "" if none).
Rows are kept in memory between frames and written by the owner at each frame.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..input.schema import fail
from ..kernels.layout import GD_P
from ..model.multirate import steps_since_update

QUANTITIES = ("t", "sigma_rr", "v_r", "p", "s", "strength", "t_state")
#: a snap farther than this many dx of the point's part is a warning in the run log
SNAP_WARN = 0.5


@dataclass(frozen=True)
class Probe:
    """``name``, ``position`` (m), ``center`` (x, y) of the radial axis (default 0, 0),
    ``part``: the part whose points it may snap to (default: any point)."""
    name: str
    position: tuple[float, float, float]
    center: tuple[float, float] = (0.0, 0.0)
    part: str | None = None


def snap_note(name, position, x, dist, dx) -> str:
    """The run log's warning for a probe moved more than ``SNAP_WARN`` dx by its snap."""
    def at(p):
        return "(" + ", ".join(f"{float(c) * 1e3:.4g}" for c in p) + ") mm"
    return (f"probe {name!r} moved {dist * 1e3:.3g} mm (more than dx/2 = {SNAP_WARN * dx * 1e3:.3g} "
            f"mm of its part) from the requested position {at(position)} to the nearest point "
            f"{at(x)}")


def part_matches(part: str, name: str) -> bool:
    """Does the scene part (or zone) ``name`` belong to the probe's ``part``?"""
    return name == part or name.startswith(part + ".")


def nearest(pr, part_names, x, gid, part, material, dx, horizon) -> tuple:
    """The candidate point of probe ``pr`` among the points ``x`` (with their gid,
    part index, material id, dx and horizon): (distance, gid, x, part, material, dx,
    horizon) of the nearest point of its part (any point if it names none), or
    (inf, -1) if there is none.  The min of the candidates of every piece of the
    model is the probe's point (lowest gid on a tie).  Probes (the run, on each
    rank's owned points) and mpipd.check (the lattice, layer by layer) both use it."""
    n = len(x)
    d = np.linalg.norm(x - np.asarray(pr.position), axis=1) if n else np.empty(0)
    if pr.part is not None and n:
        ok = np.array([part_matches(pr.part, q) for q in part_names], bool)
        d = np.where(ok[part], d, np.inf)
    if not n or not np.isfinite(d).any():
        return (math.inf, -1)
    j = int(np.argmin(d))          # the first minimum: the lowest gid of a piece in gid order
    return (float(d[j]), int(gid[j]), tuple(map(float, x[j])), int(part[j]),
            int(material[j]), float(dx[j]), float(horizon[j]))


def placed(k, pr, found) -> str | None:
    """Judge probe ``k``'s point ``found`` (the min of :func:`nearest` over the
    model): bad input (SceneError) if its part has no point or the point is farther
    than its horizon (outside the body); the run log's warning (:func:`snap_note`)
    if it moved more than SNAP_WARN dx; else None."""
    if not math.isfinite(found[0]):
        fail(f"probes[{k}].part", f"probe {pr.name!r}: no point of part {pr.part!r}")
    dist, _, xg, _, _, dxg, hg = found
    if dist > hg:
        fail(f"probes[{k}].position", f"probe {pr.name!r}: the nearest point"
             f"{' of part ' + repr(pr.part) if pr.part else ''} is {dist * 1e3:.3g} mm "
             f"away, beyond its horizon ({hg * 1e3:.3g} mm): outside the body?")
    if dist > SNAP_WARN * dxg:     # more than half a lattice spacing: say so
        return snap_note(pr.name, pr.position, xg, dist, dxg)
    return None


class Probes:
    def __init__(self, probes, scene, points, team, corr, v, mode, klass, gas=None):
        """``probes``: the scene's; ``corr``: the correspondence model (stress of a
        point, material groups); ``v``, ``mode`` and ``klass``: the State's velocities,
        failure flags and step classes; ``gas``: the gas model (mpipd.model.gas.Gas),
        if the scene has one (the pressure of a gas point).  Collective (the nearest
        point is found over all ranks)."""
        self.probes = list(probes)
        self.gas = gas
        self.team, self.corr, self.v, self.mode = team, corr, v, mode
        self.klass, self.dt = klass, scene.time.dt
        self.points = points
        n = points.n_owned
        x = points.x[:n]
        gid = points.gid[:n]
        part = points.part[:n]
        mat = points.material[:n]
        parts = [q.name for q in scene.parts]
        self.part_names, self.material_names = parts, list(scene.materials)
        self.mine = []                      # (probe index, local index)
        self.notes = []                     # warnings for the run log
        self.gid, self.x, self.dist, self.part, self.material = [], [], [], [], []
        self.dx = []                        # dx of each chosen point's part
        for k, pr in enumerate(self.probes):
            best = nearest(pr, parts, x, gid, part, mat, points.dx[:n], points.horizon[:n])
            found = min(team.gather(best))
            note = placed(k, pr, found)
            if note:
                self.notes.append(note)
            dist, g, xg, pg, mg, dxg, hg = found
            self.gid.append(g)
            self.dx.append(dxg)
            self.x.append(xg)
            self.dist.append(dist)
            self.part.append(parts[pg])
            self.material.append(self.material_names[mg])
            local = np.flatnonzero(gid == g)
            if len(local):
                self.mine.append((k, int(local[0])))
        self.rows = {k: [] for k, _ in self.mine}
        # running peaks over every step of the run (checkpointed, so a restart
        # continues them): most compressive sigma_rr, largest |v_r|, largest p
        self.peak = {k: [math.inf, 0.0, -math.inf] for k, _ in self.mine}
        self.start = {k: 0 for k, _ in self.mine}       # step of the first buffered row
        # each probe point's material group and its row there (the material gives
        # the strength, or NaN if it has none)
        self._group = {}
        mine = {i for _, i in self.mine}
        for g in corr.groups:
            for pos in np.flatnonzero(np.isin(g.idx, list(mine))):
                self._group[int(g.idx[pos])] = (g, int(pos))

    def peaks(self) -> dict:
        """name -> (most compressive sigma_rr, largest |v_r|, largest p) so far, gathered
        from the owner ranks (every rank gets the same dict)."""
        local = {self.probes[k].name: tuple(pk) for k, pk in self.peak.items()
                 if math.isfinite(pk[0])}
        out = {}
        for part in self.team.gather(local):
            out.update(part)
        return out

    def sample(self, step: int, t: float):
        """Record step ``step`` (time ``t``) at every probe this rank owns."""
        for k, i in self.mine:
            pr = self.probes[k]
            s = self._stress(i)
            dx, dy = self.points.x[i, 0] - pr.center[0], self.points.x[i, 1] - pr.center[1]
            r = math.hypot(dx, dy) or 1.0
            c, sn = dx / r, dy / r
            srr = s[0] * c * c + s[1] * sn * sn + 2 * s[5] * c * sn
            vr = self.v[i, 0] * c + self.v[i, 1] * sn
            if self._is_gas(i):         # sigma = -p I: its p as it is, sigma_rr = -p, s = 0
                p, srr, seq = -s[0], s[0], 0.0
            else:
                p = -(s[0] + s[1] + s[2]) / 3.0
                dev = np.array([s[0] + p, s[1] + p, s[2] + p])
                seq = math.sqrt(1.5 * (dev @ dev + 2 * (s[3] ** 2 + s[4] ** 2 + s[5] ** 2)))
            if not self.rows[k]:
                self.start[k] = step
            lag = steps_since_update(step, int(self.klass[i]))
            row = (t, srr, vr, p, seq, self._strength(i), t - lag * self.dt)
            self.rows[k].append(row)
            pk = self.peak[k]
            pk[0], pk[1], pk[2] = min(pk[0], srr), max(pk[1], abs(vr)), max(pk[2], p)

    def _is_gas(self, i) -> bool:
        return self.gas is not None and bool(self.gas.is_gas[i])

    def _stress(self, i) -> np.ndarray:
        """Cauchy stress of owned point i, Voigt order: the correspondence model's,
        or, at a point of the gas, -p I with the gas model's pressure."""
        if self._is_gas(i):
            p = float(self.gas.gd[i, GD_P])
            return np.array([-p, -p, -p, 0.0, 0.0, 0.0])
        return self.corr.cauchy_stress_of(i)

    def restore_peaks(self, peaks: dict):
        """Continue the running peaks of a checkpoint (name -> peaks(), as written)."""
        for k in self.peak:
            if self.probes[k].name in peaks:
                self.peak[k] = list(peaks[self.probes[k].name])

    def _strength(self, i) -> float:
        """The material's strength at point i (Material.point_strength: NaN for a
        material without one), 0 once the point has failed."""
        if i not in self._group:                # a gas point: no strength model
            return math.nan
        g, pos = self._group[i]
        s = g.material.point_strength(g.state, pos)
        return s if math.isnan(s) or self.mode[i] == 0 else 0.0

    def create(self, h5, n_rows: int):
        """Collective: datasets for every probe (all ranks call this)."""
        from .writer import growable
        self.dsets = {}
        for k, pr in enumerate(self.probes):
            grp = h5.require_group(f"probes/{pr.name}")
            grp.attrs["gid"] = self.gid[k]
            grp.attrs["position"] = pr.position
            grp.attrs["x"] = self.x[k]
            grp.attrs["distance"] = self.dist[k]
            grp.attrs["dx"] = self.dx[k]
            grp.attrs["part"] = self.part[k]
            grp.attrs["material"] = self.material[k]
            grp.attrs["requested_part"] = pr.part or ""
            self.dsets[k] = {}
            for q in QUANTITIES:
                if q in grp:                        # a restart: the run length may change
                    d = grp[q]
                    if d.shape[0] != n_rows:
                        d.resize(n_rows, axis=0)
                else:
                    d = grp.create_dataset(q, (n_rows,), "f8", **growable((n_rows,)))
                self.dsets[k][q] = d

    def flush(self):
        """Owner ranks write their buffered rows at row = step (independent I/O)."""
        for k, rows in self.rows.items():
            if not rows:
                continue
            a = np.array(rows)
            r0 = self.start[k]
            for c, q in enumerate(QUANTITIES):
                self.dsets[k][q][r0:r0 + len(a)] = a[:, c]
            rows.clear()
