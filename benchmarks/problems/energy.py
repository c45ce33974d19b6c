"""``energy``: free elastic block with a smooth velocity field: drift of the total
energy per 1000 steps, and its largest deviation."""
from __future__ import annotations

import math

import numpy as np

from .common import build_scene, granite, stable_step, timed_simulation


class Energy:
    """Free elastic granite cube, 16 mm, with a smooth velocity field
    v = (1, 0.5, 0.25) m/s * cos^2(pi (x - 8 mm) / 16 mm) (compression and shear,
    vanishing with its slope at both ends); no load, no boundary condition, dt = 0.45
    of the stable estimate, 200 us (about 60 P-wave transits).  Two rows: the drift
    per 1000 steps (least-squares slope of the total energy over the steps, after
    the first 10 %, times 1000 / E0) and the largest |E - E0| / E0."""
    name = "energy, free body"
    RESOLUTIONS = (2.0e-3, 1.6e-3, 1.333e-3, 1.0e-3)
    QUICK = (2.0e-3, 1.6e-3)
    L, T_END = 0.016, 200e-6

    def scene(self, dx, steps=None):
        L = self.L
        d = {"scene": {"name": "verify_energy"},
             "time": {"dt": 1e-9, "steps": 1},
             "materials": {"granite": granite()},
             "parts": [{"name": "cube", "material": "granite", "dx": dx,
                        "shape": {"kind": "box", "lo": [0, 0, 0], "hi": [L, L, L]}}],
             "initial": [{"kind": "velocity_pulse", "axis": "x", "center": L / 2,
                          "half_width": L / 2, "velocity": [1.0, 0.5, 0.25]}]}
        dt = 0.45 * stable_step(build_scene(d))
        d["time"] = {"dt": dt, "steps": steps if steps is not None
                     else int(math.ceil(self.T_END / dt))}
        return build_scene(d)

    def run(self, team, dx, steps=None):
        scene = self.scene(dx, steps)
        tm, sim = timed_simulation(team, scene)
        E, S = [sim.energies().total], [0]
        for _ in range(scene.time.n_steps):
            sim.step()
            if sim.step_count % 5 == 0:
                E.append(sim.energies().total)
                S.append(sim.step_count)
        wall = tm.stop()
        if steps is not None:
            return None
        E, S = np.array(E), np.array(S)
        keep = S >= 0.1 * S[-1]
        (slope, _), cov = np.polyfit(S[keep], E[keep], 1, cov=True)
        drift = slope * 1000.0 / E[0]
        drift_se = math.sqrt(cov[0, 0]) * 1000.0 / E[0]
        dev = float(np.abs(E - E[0]).max() / E[0])
        base = {"dx": dx, "points": sim.n_global, "steps": scene.time.n_steps, "wall_s": wall}
        return [dict(base, problem="energy drift / 1000 steps", measure="|dE/E0| per 1000 steps",
                     error=abs(drift), value=drift, value_se=drift_se, reference=0.0,
                     value_name="drift per 1000 steps"),
                dict(base, problem="energy, max deviation", measure="max |E - E0| / E0",
                     error=dev, value=dev, reference=0.0, value_name="max |dE|/E0")]
