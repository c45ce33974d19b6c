"""``wave_multirate``: the plane P wave of :mod:`.wave` crossing a multi-rate class
boundary (mpipd.model.multirate).  The half x < 96 mm of the bar is held in
class 0, the other half in class log2(ratio) (``Simulation.hold_classes``: the
boundary is the only thing that changes there), dt = 0.9 of the stable
estimate / ratio, so the coarse class steps at 0.9 of the estimate.  The
pulse starts in the fine half and crosses the boundary inside the fit window.
Error: |c - c_p| / c_p of the centroid speed, as in :mod:`.wave`; the row also
carries the relative difference of the final u from the single-rate run at the
same dt (ratio 1, its own row) and the largest change of the total momentum."""
from __future__ import annotations

import numpy as np

from .common import C_P, build_scene, stable_step, timed_simulation
from .wave import Wave

RATIOS = (1, 2, 4, 8)


class WaveMultirate(Wave):
    name = "P wave across a class boundary"
    measure = "|c - c_p| / c_p"
    RESOLUTIONS = (1.4e-3, 1.0e-3)
    QUICK = (2.0e-3,)                 # not in --quick (verify.QUICK_SKIP)

    def scene_at(self, dx, ratio, steps=None):
        base = self.scene(dx, 1)
        dt = 0.9 * stable_step(base) / 8          # one fine dt for every ratio
        n = steps if steps is not None else -(-int(np.ceil(self.T_END / dt)) // 8) * 8
        d = {"scene": {"name": "verify_wave_multirate"},
             "time": {"dt": dt, "steps": n},
             "materials": {"granite": {"model": "elastic", "density": 2660.0,
                                       "bulk_modulus": 21.9e9, "shear_modulus": 25.7e9}},
             "parts": [{"name": "bar", "material": "granite", "dx": dx,
                        "shape": {"kind": "box", "lo": [0, 0, 0],
                                  "hi": [self.LENGTH, 6 * dx, 6 * dx]}}],
             "initial": [{"kind": "velocity_pulse", "axis": "x", "center": 0.0,
                          "half_width": self.HALF_WIDTH, "velocity": [1.0, 0.0, 0.0]}],
             "output": {"every": 8}}
        if ratio > 1:
            d["time"]["multirate"] = {"max_ratio": ratio, "safety": 1.0}
        return build_scene(d)

    def run(self, team, dx, steps=None):
        rows, u_ref = [], None
        for ratio in RATIOS:
            scene = self.scene_at(dx, ratio, 8 if steps is not None else None)
            tm, sim = timed_simulation(team, scene)
            n = sim.points.n_owned
            x = sim.points.x[:n, 0]
            if ratio > 1:
                k = np.where(x < 0.5 * self.LENGTH, 0, ratio.bit_length() - 1)
                sim.hold_classes(k)
            m = sim.rho * sim.points.volume[:n]
            p0 = team.sum((m[:, None] * sim.v[:n]).sum(axis=0))
            n_planes = int(round(self.LENGTH / dx))
            plane = np.minimum((x / dx).astype(np.int64), n_planes - 1)
            xs = (np.arange(n_planes) + 0.5) * dx
            cnt = team.sum(np.bincount(plane, minlength=n_planes).astype(float))
            self.constrain(sim)
            t, vx, dp = [], [], 0.0
            for _ in range(scene.time.n_steps):
                sim.step()
                self.constrain(sim)
                if sim.at_boundary:
                    p = team.sum((m[:, None] * sim.v[:n]).sum(axis=0))
                    scale = team.sum(float(np.abs(m[:, None] * sim.v[:n]).sum()))
                    dp = max(dp, float(np.abs(p - p0)[0] / scale))
                if self.T_FIT[0] <= sim.t <= self.T_FIT[1] + 0.5 * sim.dt:
                    t.append(sim.t)
                    vx.append(np.bincount(plane, weights=sim.v[:n, 0], minlength=n_planes))
            sim.check_finite()
            wall = tm.stop()
            if steps is not None:
                continue
            vx = team.sum(np.array(vx)) / cnt
            e = vx ** 2 * (xs > self.X_MIN)
            c = float(np.polyfit(np.array(t), (e @ xs) / e.sum(axis=1), 1)[0])
            u = np.zeros((sim.n_global, 3))
            u[sim.points.gid[:n]] = sim.u[:n]
            u = team.sum(u)
            if u_ref is None:
                u_ref = u
            du = float(np.linalg.norm(u - u_ref) / np.linalg.norm(u_ref))
            rows.append({"problem": f"{self.name} (ratio {ratio})", "dx": dx,
                         "points": sim.n_global, "steps": scene.time.n_steps, "wall_s": wall,
                         "error": abs(c - C_P) / C_P, "value": c, "reference": C_P,
                         "value_name": "c (m/s)", "u_diff_vs_single_rate": du,
                         "momentum_change": dp})
        return None if steps is not None else rows
