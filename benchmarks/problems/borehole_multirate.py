"""``borehole_multirate``: a borehole-pressure pulse crossing a multi-rate class
boundary (mpipd.model.multirate; issue 17's "borehole-pressure load").

The elastic granite ring of ``studies/diagnoses/wave_ring_elastic.toml`` (r 3.2 to
30 mm, 12 mm thick, Table 1's moduli, hourglass 0.01) under the borehole pressure
p(t) = 300 MPa (e^-2e5 t - e^-2e6 t), with probes A, B and C at r = 10, 14 and 25.2 mm.
The rock with r < 12 mm is held in class 0 and the rest in class log2(ratio)
(``Simulation.hold_classes``), so the cylindrical wave leaves the loaded wall in the
fine class and crosses the boundary between A and B.  dt = 2e-8 s for every ratio (the
coarse class at ratio 8 steps at 0.16 µs, 0.73 of the rock's dx/c_P).

References, both computed here:

* the exact plane-strain cavity response to the same pressure history
  (:func:`benchmarks.diagnoses.wave_speed.closed_form`, Achenbach 1973 §4.7, §7.2):
  the error is the worst relative error of the peak -sigma_rr over A, B and C;
* the single-rate run at the same dt (ratio 1): the worst difference of the
  -sigma_rr records over A, B, C, relative to each probe's single-rate peak, with the
  probes' records taken at their states' times (``t_state``; a coarse probe holds its
  stress between updates) and interpolated onto the single-rate times; and the
  difference of the first arrivals (``mpipd.post.arrivals``) in units of dt.

Each row also gives the ledger's largest |balance| at the coarse steps after the first
µs (before it the load has put in almost nothing, and the balance, relative to the
energy put in, means nothing; single-rate then stays within 2e-6).
"""
from __future__ import annotations

import numpy as np

from .common import G_GR, K_GR, RHO, build_scene, timed_simulation

PROBES = {"A": 0.0100, "B": 0.0140, "C": 0.0252}
R_SPLIT = 0.012
RATIOS = (1, 2, 4, 8)
DT = 2.0e-8
T_END = 1.2e-5


def scene_dict(dx, ratio):
    z = 0.012
    d = {"scene": {"name": "verify_borehole_multirate"},
         "time": {"dt": DT, "t_end": T_END},
         "materials": {"granite": {"model": "elastic", "density": RHO,
                                   "bulk_modulus": K_GR, "shear_modulus": G_GR}},
         "parts": [{"name": "rock", "material": "granite", "dx": dx, "horizon_factor": 3.0,
                    "shape": {"kind": "annulus", "center": [0.0, 0.0], "inner_radius": 0.0032,
                              "radius": 0.030, "z": [0.0, z]}}],
         "solver": {"hourglass": 0.01},
         "loads": [{"kind": "borehole_pressure", "center": [0.0, 0.0], "radius": 0.0032,
                    "p0": 3.0e8, "alpha": 2.0e5, "beta": 2.0e6}],
         "output": {"every": 8},
         "probes": [{"name": n, "position": [r, 0.0, 0.5 * z], "part": "rock"}
                    for n, r in PROBES.items()]}
    if ratio > 1:
        d["time"]["multirate"] = {"max_ratio": ratio, "safety": 1.0}
    return d


def records(team, sim) -> dict:
    """name -> (t, t_state, -sigma_rr, r) of the probes, on every rank."""
    mine = {}
    for k, i in sim.probes.mine:
        a = np.array(sim.probes.rows[k])
        mine[sim.probes.probes[k].name] = (a[:, 0], a[:, 6], -a[:, 1],
                                           float(np.hypot(*sim.points.x[i, :2])))
    out = {}
    for part in team.gather(mine):
        out.update(part)
    return out


class BoreholeMultirate:
    name = "borehole pulse across a class boundary"
    measure = "worst |peak - closed form| / closed form over A-C"
    RESOLUTIONS = (1.5e-3, 1.0e-3)
    QUICK = (2.0e-3,)                 # not in --quick (verify.QUICK_SKIP)

    def run(self, team, dx, steps=None):
        from diagnoses.wave_speed import closed_form

        from mpipd.input.loads import BoreholePressure
        from mpipd.post.arrivals import first_arrival, state_samples
        rows, ref = [], None
        for ratio in RATIOS:
            d = scene_dict(dx, ratio)
            if steps is not None:
                d["time"] = {"dt": DT, "steps": 8}
            scene = build_scene(d)
            tm, sim = timed_simulation(team, scene)
            n = sim.points.n_owned
            if ratio > 1:
                r = np.hypot(sim.points.x[:n, 0], sim.points.x[:n, 1])
                sim.hold_classes(np.where(r < R_SPLIT, 0, ratio.bit_length() - 1))
            bal = 0.0
            while sim.step_count < scene.time.n_steps:
                sim.step()
                if sim.probes is not None:
                    sim.probes.sample(sim.step_count, sim.t)
                if sim.at_boundary and sim.t >= 1e-6:
                    bal = max(bal, abs(sim.energies().balance))
            sim.check_finite()
            wall = tm.stop()
            if steps is not None:
                continue
            rec = records(team, sim)
            load = next(ld for ld in scene.loads if isinstance(ld, BoreholePressure))
            errs, arr, diff = [], [], []
            for name, (t, ts, y, r) in sorted(rec.items()):
                exact, _ = closed_form(t, r, load.radius, load, RHO, K_GR, G_GR)
                errs.append(abs(y.max() - exact.max()) / exact.max())
                tq, yq = state_samples({"t": t, "t_state": ts}, y)
                arr.append(first_arrival(tq, yq)["t_s"])
                if ref is not None:
                    t0, y0, a0 = ref[name]
                    diff.append(float(np.abs(np.interp(t0, tq, yq) - y0).max() / y0.max()))
                    arr[-1] -= a0
            if ref is None:
                ref = {name: (rec[name][0], rec[name][2], a)
                       for name, a in zip(sorted(rec), arr)}
            row = {"problem": f"{self.name} (ratio {ratio})", "dx": dx,
                   "points": sim.n_global, "steps": scene.time.n_steps, "wall_s": wall,
                   "error": max(errs), "value": max(errs), "reference": 0.0,
                   "value_name": "peak error", "balance": bal}
            if ratio > 1:
                row.update(record_diff_vs_single_rate=max(diff), value=max(diff),
                           value_name="records vs single-rate",
                           arrival_shift_dt=max(arr, key=abs) / DT)
            rows.append(row)
        return None if steps is not None else rows
