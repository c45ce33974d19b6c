"""``wave``: plane P wave in granite, the speed of the pulse's kinetic-energy centroid
against sqrt((K + 4G/3)/rho).  1-D strain is imposed by the harness (the lateral
acceleration and velocity of every point are zeroed after each step: rollers on the
lateral faces, i.e. a laterally infinite plate), so the reference is exactly c_p, not
the bar speed."""
from __future__ import annotations

import math

import numpy as np

from .common import C_P, build_scene, granite, stable_step, timed_simulation


class Wave:
    """Plane P wave: a cos^2 velocity pulse (half-width 20 mm at every dx) launched
    from the free end x = 0 of a 192 mm bar whose cross-section is 6 x 6 lattice
    points; 1-D strain by the harness.  The speed is the least-squares slope of the
    kinetic-energy centroid of the pulse (planes with x > 25 mm) over 12..30 us, once
    the pulse has left the end: the energy transport speed, which is c_p exactly for
    a non-dispersive continuum.  (Peak arrival times are noisier: the pulse's peak
    wobbles by a fraction of dx as dispersion reshapes it.)  dt = 0.45 of the
    stable estimate at every dx."""
    name = "P-wave speed"
    measure = "|c - c_p| / c_p"
    RESOLUTIONS = (2.0e-3, 1.4e-3, 1.0e-3, 0.7e-3)
    QUICK = (2.0e-3, 1.4e-3)
    LENGTH, HALF_WIDTH = 0.192, 0.02
    X_MIN, T_FIT, T_END = 0.025, (12e-6, 30e-6), 30e-6

    def scene(self, dx, steps=None):
        n_lat = 6
        d = {"scene": {"name": "verify_wave"},
             "time": {"dt": 1e-9, "steps": 1},
             "materials": {"granite": granite()},
             "parts": [{"name": "bar", "material": "granite", "dx": dx,
                        "shape": {"kind": "box", "lo": [0, 0, 0],
                                  "hi": [self.LENGTH, n_lat * dx, n_lat * dx]}}],
             "initial": [{"kind": "velocity_pulse", "axis": "x", "center": 0.0,
                          "half_width": self.HALF_WIDTH, "velocity": [1.0, 0.0, 0.0]}]}
        dt = 0.45 * stable_step(build_scene(d))
        d["time"] = {"dt": dt, "steps": steps if steps is not None
                     else int(math.ceil(self.T_END / dt))}
        return build_scene(d)

    @staticmethod
    def constrain(sim):
        """Rollers on the lateral faces: no lateral acceleration or velocity anywhere."""
        sim.a[:, 1:] = 0.0
        sim.v[: sim.points.n_owned, 1:] = 0.0

    def run(self, team, dx, steps=None):
        scene = self.scene(dx, steps)
        tm, sim = timed_simulation(team, scene)
        n = sim.points.n_owned
        x = sim.points.x[:n, 0]
        n_planes = int(round(self.LENGTH / dx))
        plane = np.minimum((x / dx).astype(np.int64), n_planes - 1)   # lattice plane index
        xs = (np.arange(n_planes) + 0.5) * dx
        cnt = team.sum(np.bincount(plane, minlength=n_planes).astype(float))
        self.constrain(sim)
        t, vx = [], []
        for _ in range(scene.time.n_steps):
            sim.step()
            self.constrain(sim)
            if self.T_FIT[0] <= sim.t <= self.T_FIT[1] + 0.5 * sim.dt:
                t.append(sim.t)
                vx.append(np.bincount(plane, weights=sim.v[:n, 0], minlength=n_planes))
        sim.check_finite()
        wall = tm.stop()
        if steps is not None:
            return None
        vx = team.sum(np.array(vx)) / cnt                 # section-mean v_x, (frames, planes)
        e = vx ** 2 * (xs > self.X_MIN)
        centroid = (e @ xs) / e.sum(axis=1)
        c = float(np.polyfit(np.array(t), centroid, 1)[0])
        return {"dx": dx, "points": sim.n_global, "steps": scene.time.n_steps, "wall_s": wall,
                "error": abs(c - C_P) / C_P, "value": c, "reference": C_P,
                "value_name": "c (m/s)"}
