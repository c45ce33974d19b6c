"""Probes: named points whose state is recorded every step (paper Figs. 15–16).

Each probe is the lattice point nearest its ``position`` (lowest gid on a tie),
among the points of its ``part`` if it names one (a part name matches the part
and its zones ``<part>.band``, ``<part>.0``, ... of :meth:`mpipd.scene.Part.zones`,
so ``part = "rock"`` samples the rock whatever its resolution bands); the rank
that owns it records, every step,

    t, sigma_rr, v_r            radial stress and velocity about the axis through ``center``
    p                           pressure -tr(sigma)/3 (compression positive)
    s                           von Mises equivalent stress
    strength                    JH2 yield strength sigma_y at the point's p*, edot*, D
                                (NaN for other materials)

into ``/probes/<name>/{t, sigma_rr, v_r, p, s, strength}``, with ``/probes/<name>``
attributes ``gid``, ``position`` (requested), ``x`` (the chosen point), ``distance``
(m, from the requested position to the chosen point), ``part`` (the zone holding
the point), ``material`` and ``requested_part`` (the probe's ``part``, "" if none).
Rows are kept in memory between frames and written by the owner at each frame.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .materials.jh2 import jh2_strength

QUANTITIES = ("t", "sigma_rr", "v_r", "p", "s", "strength")


@dataclass(frozen=True)
class Probe:
    """``name``, ``position`` (m), ``center`` (x, y) of the radial axis (default 0, 0),
    ``part``: the part whose points it may snap to (default: any point)."""
    name: str
    position: tuple[float, float, float]
    center: tuple[float, float] = (0.0, 0.0)
    part: str | None = None


def part_matches(part: str, name: str) -> bool:
    """Does the scene part (or zone) ``name`` belong to the probe's ``part``?"""
    return name == part or name.startswith(part + ".")


class Probes:
    def __init__(self, sim, probes):
        self.sim = sim
        self.probes = list(probes)
        n = sim.points.n_owned
        x = sim.points.x[:n]
        gid = sim.points.gid[:n]
        part = sim.points.part[:n]
        mat = sim.points.material[:n]
        parts = [q.name for q in sim.scene.parts]
        self.part_names, self.material_names = parts, list(sim.scene.materials)
        self.mine = []                      # (probe index, local index)
        self.gid, self.x, self.dist, self.part, self.material = [], [], [], [], []
        for k, pr in enumerate(self.probes):
            d = np.linalg.norm(x - np.asarray(pr.position), axis=1) if n else np.empty(0)
            if pr.part is not None:
                ok = np.array([part_matches(pr.part, q) for q in parts], bool)
                d = np.where(ok[part], d, np.inf)
            j = int(np.argmin(d)) if n else -1
            best = ((float(d[j]), int(gid[j]), tuple(map(float, x[j])), int(part[j]),
                     int(mat[j])) if n and np.isfinite(d[j]) else (math.inf, -1))
            found = min(sim.team.gather(best))
            if not math.isfinite(found[0]):
                raise ValueError(f"probe {pr.name!r}: no point of part {pr.part!r}")
            dist, g, xg, pg, mg = found
            self.gid.append(g)
            self.x.append(xg)
            self.dist.append(dist)
            self.part.append(parts[pg])
            self.material.append(self.material_names[mg])
            local = np.flatnonzero(gid == g)
            if len(local):
                self.mine.append((k, int(local[0])))
        self.rows = {k: [] for k, _ in self.mine}
        self.history = {k: [] for k, _ in self.mine}   # (t, sigma_rr, v_r, p) for the peaks
        self.start = {k: 0 for k, _ in self.mine}       # step of the first buffered row
        self._jh2 = {}
        for g in sim.corr.groups:
            if g.material.registry_name == "jh2":
                for pos, i in enumerate(g.idx):
                    self._jh2[int(i)] = (g, pos)

    def peaks(self) -> dict:
        """name -> (most compressive sigma_rr, largest |v_r|, largest p) so far, gathered
        from the owner ranks (every rank gets the same dict)."""
        local = {self.probes[k].name: (min(r[1] for r in rows), max(abs(r[2]) for r in rows),
                                       max(r[3] for r in rows))
                 for k, rows in self.history.items() if rows}
        out = {}
        for part in self.sim.team.gather(local):
            out.update(part)
        return out

    def sample(self):
        sim = self.sim
        for k, i in self.mine:
            pr = self.probes[k]
            s = sim.corr.cauchy_stress_of(i)
            dx, dy = sim.points.x[i, 0] - pr.center[0], sim.points.x[i, 1] - pr.center[1]
            r = math.hypot(dx, dy) or 1.0
            c, sn = dx / r, dy / r
            srr = s[0] * c * c + s[1] * sn * sn + 2 * s[5] * c * sn
            vr = sim.v[i, 0] * c + sim.v[i, 1] * sn
            p = -(s[0] + s[1] + s[2]) / 3.0
            dev = np.array([s[0] + p, s[1] + p, s[2] + p])
            seq = math.sqrt(1.5 * (dev @ dev + 2 * (s[3] ** 2 + s[4] ** 2 + s[5] ** 2)))
            if not self.rows[k]:
                self.start[k] = sim.step_count
            row = (sim.t, srr, vr, p, seq, self._strength(i))
            self.rows[k].append(row)
            self.history[k].append(row[:4])

    def _strength(self, i) -> float:
        if i not in self._jh2 or self.sim.mode[i] != 0:
            return math.nan if i not in self._jh2 else 0.0
        g, pos = self._jh2[i]
        m, st = g.material, g.state
        es = st["strain_rate"][pos] / m.rate_norm
        rate = 1.0 + m.C * math.log(es) if es > 1.0 else 1.0
        ps = st["pressure"][pos] / m.p_HEL
        return m.sigma_hel * jh2_strength(ps, rate, st["D"][pos], m.A, m.N, m.B, m.M,
                                          m.T / m.p_HEL)

    def create(self, h5, n_rows: int):
        """Collective: datasets for every probe (all ranks call this)."""
        self.dsets = {}
        for k, pr in enumerate(self.probes):
            grp = h5.require_group(f"probes/{pr.name}")
            grp.attrs["gid"] = self.gid[k]
            grp.attrs["position"] = pr.position
            grp.attrs["x"] = self.x[k]
            grp.attrs["distance"] = self.dist[k]
            grp.attrs["part"] = self.part[k]
            grp.attrs["material"] = self.material[k]
            grp.attrs["requested_part"] = pr.part or ""
            self.dsets[k] = {q: grp.require_dataset(q, (n_rows,), "f8", fillvalue=np.nan)
                             for q in QUANTITIES}

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
