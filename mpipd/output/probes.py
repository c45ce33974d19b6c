"""Probes: named points whose state is recorded every step (paper Figs. 15–16).

Where a probe sits (the lattice point nearest its position, among the points of
its part; refused outside the body, a warning when moved more than dx/2) is the
scene's side, mpipd.input.probes; the solver places them and hands the
placement here.  The rank that owns a probe's point records, every step,

    t, sigma_rr, v_r            radial stress and velocity about the axis through ``center``
                                (sigma_rr = e_r . sigma . e_r, kernels.linalg.normal_stress)
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

import numpy as np

from ..kernels.classes import steps_since_update
from ..kernels.layout import GD_P
from ..kernels.linalg import normal_stress

QUANTITIES = ("t", "sigma_rr", "v_r", "p", "s", "strength", "t_state")


class Probes:
    def __init__(self, probes, where, dt, points, team, corr, v, mode, klass, gas=None):
        """``probes``: the scene's; ``where``: their points
        (mpipd.input.probes.Placement); ``dt``: the fine step; ``corr``: the
        correspondence model (stress of a point, material groups); ``v``, ``mode``
        and ``klass``: the State's velocities, failure flags and step classes;
        ``gas``: the gas model (mpipd.model.gas.Gas), if the scene has one (the
        pressure of a gas point)."""
        self.probes = list(probes)
        self.gas = gas
        self.team, self.corr, self.v, self.mode = team, corr, v, mode
        self.klass, self.dt = klass, dt
        self.points = points
        gid = points.gid[:points.n_owned]
        self.notes = list(where.notes)      # warnings for the run log
        self.gid, self.x, self.dist = list(where.gid), list(where.x), list(where.dist)
        self.part, self.material = list(where.part), list(where.material)
        self.dx = list(where.dx)            # dx of each chosen point's part
        self.mine = []                      # (probe index, local index)
        for k, g in enumerate(self.gid):
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
            srr = normal_stress(s[0], s[1], s[2], s[3], s[4], s[5], c, sn, 0.0)   # e_r . sigma . e_r
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
