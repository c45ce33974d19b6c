"""Peaks over every time step (not over the saved frames).

The solver writes per-point running peaks as output fields; each frame holds the
peak over every step up to it, so the last frame holds the peak over the run:

    /fields/peak_pressure   Pa   max over steps of -tr(sigma)/3 (solid), JWL p (gas)
    /fields/peak_sigma_rr   Pa   max over steps of -sigma_rr about the z axis through
                                 the scene's ``[output] peak_center`` (default 0, 0)
    /fields/peak_speed      m/s  max over steps of |v|

and the attribute ``peak_gas_pressure`` (Pa, the largest gas pressure of any step
since the last start or restart).  The probes are recorded every step too.  From
these, in order of preference:

* peak explosive pressure: max of ``peak_pressure`` over the charge points, else the
  ``peak_gas_pressure`` attribute;
* the rock's first layer at the borehole wall (rock points with r < R_b + wall_dx):
  the largest and the mean over the layer of ``peak_sigma_rr`` and of
  ``peak_pressure``, else the record of the ``wall`` probe (one point);
* PPV against distance from the wall (Fig. 18 beside the probes): ``peak_speed``
  of the rock points still intact at the last frame (failed points fly off freely),
  averaged in rings of width wall_dx of d = r - R_b.  It is the speed |v|, not |v_r|.

Where none exists the measure is ``{"not_available": reason}``: the saved frames
alone sample every ``output.every`` steps and miss the peak.  Maxima are reduced
with MPI MAX and sums per z level, so the numbers do not depend on the reading ranks.
"""
from __future__ import annotations

import numpy as np

BASIS = "every step"
NO_FIELDS = "the run has no {} field (peaks over every step); saved frames alone miss the peak"


def na(reason: str) -> dict:
    return {"not_available": reason}


def scan(run, model, probes) -> dict:
    x = run.geometry("x")
    pid = run.geometry("part")
    rock = model.is_rock(pid)
    last = run.frames - 1
    out = {"gas_pressure": _gas(run, model, pid, last)}
    off = float(np.hypot(model.peak_center[0] - model.center[0],
                         model.peak_center[1] - model.center[1]))
    r = model.radius(x)
    wall = rock & (r < model.r_wall + model.wall_dx)
    probe = probes.get("wall")
    if run.has_field("peak_sigma_rr") and off > 1e-3 * model.wall_dx:
        srr = na(f"peak_sigma_rr is about ({model.peak_center[0]:g}, {model.peak_center[1]:g})"
                 f" m, not the borehole axis ({model.center[0]:g}, {model.center[1]:g}) m")
    else:
        srr = _layer(run, wall, "peak_sigma_rr", last)
    out["wall_radial_stress"] = _or_probe(srr, probe, "sigma_rr", -1.0, model)
    out["wall_pressure"] = _or_probe(_layer(run, wall, "peak_pressure", last), probe, "p", 1.0,
                                     model)
    out["ppv_profile"] = _profile(run, model, rock, r, last)
    return out


def _gas(run, model, pid, last) -> dict:
    attr = run.attr("peak_gas_pressure")
    attr_mpa = None if attr is None else float(attr) / 1e6
    if model.charge is None:
        return na("the run has no explosive (jwl) part")
    if run.has_field("peak_pressure"):
        charge = pid == model.charge
        p = run.field("peak_pressure", last)
        v = run.max(float(p[charge].max()) if charge.any() else -np.inf)
        if np.isfinite(v):
            return {"peak_MPa": v / 1e6, "basis": BASIS,
                    "source": "max of the peak_pressure field over the charge points",
                    "attribute_MPa": attr_mpa}
    if attr is not None:
        return {"peak_MPa": attr_mpa, "basis": BASIS + " (since the last start or restart)",
                "source": "the run file's peak_gas_pressure attribute", "attribute_MPa": attr_mpa}
    return na(NO_FIELDS.format("peak_pressure") + " and no peak_gas_pressure attribute")


def _layer(run, mask, name, last) -> dict:
    if not run.has_field(name):
        return na(NO_FIELDS.format(name))
    n = run.sum_int(int(mask.sum()))
    if n == 0:
        return na("no rock points in the wall layer")
    v = run.field(name, last)
    peak = run.max(float(v[mask].max()) if mask.any() else -np.inf)
    total = float(run.level_total(run.per_level(np.where(mask, v, 0.0))))
    return {"peak_MPa": peak / 1e6, "layer_mean_MPa": total / n / 1e6, "points": n,
            "basis": BASIS,
            "source": f"{name} field, rock points with r < R_b + dx of the innermost rock zone"}


def _or_probe(block, probe, key, sign, model) -> dict:
    """The field's value, else the wall probe's record (every step, one point)."""
    if "not_available" not in block:
        return block
    if probe is None:
        return na(block["not_available"] + "; no wall probe")
    if probe.get("error"):
        return {"error": f"wall probe: {probe['error']}"}
    if len(probe["t"]) == 0:
        return na(block["not_available"] + "; the wall probe recorded nothing")
    y = sign * np.asarray(probe[key])
    k = int(np.nanargmax(y))
    d = probe["d"]
    where = ("in the wall layer" if d < model.wall_dx else
             f"{d * 1e3:.3g} mm from the wall, outside the wall layer")
    return {"peak_MPa": float(y[k]) / 1e6, "t_us": float(probe["t"][k]) * 1e6,
            "basis": BASIS, "source": f"wall probe (one rock point, {where}); "
            f"{block['not_available'].split(' (')[0]}"}


def _profile(run, model, rock, r, last) -> dict:
    if not run.has_field("peak_speed"):
        return na(NO_FIELDS.format("peak_speed"))
    if run.has_field("failure_mode"):
        intact = rock & (run.field("failure_mode", last) == 0)
    elif run.has_field("damage"):
        intact = rock & (run.field("damage", last) < 1.0 - 1e-9)
    else:
        intact = rock
    w = model.wall_dx
    peak = run.field("peak_speed", last)
    nb = max(1, int(np.ceil((model.r_out - model.r_wall) / w)))
    b = np.clip(((r - model.r_wall) / w).astype(int), 0, nb - 1)
    cnt = run.level_total(run.per_level_bins(b, intact, nb))
    tot = run.level_total(run.per_level_bins(b, intact, nb, peak))
    mx = np.zeros(nb)
    np.maximum.at(mx, b[intact], peak[intact])
    mx = run.max_array(mx)
    ok = cnt > 0
    return {"d_mm": ((np.arange(nb) + 0.5) * w * 1e3)[ok].tolist(),
            "mean_m_s": (tot[ok] / cnt[ok]).tolist(), "max_m_s": mx[ok].tolist(),
            "points": cnt[ok].astype(int).tolist(), "basis": BASIS,
            "source": "peak_speed field (|v|), ring means over intact rock points"}
