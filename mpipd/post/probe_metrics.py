"""Metrics from the probes, recorded every step (``/probes/<name>``, mpipd.output.probes).

Probes A–G sit at 6.8, 10.8, 22, 29.2, 39.6, 50 and 59.6 mm from the borehole
wall, P1–P3 at 0.8, 1.6 and 4.8 mm (paper Figs. 6, 15), ``wall`` on the rock's
first layer.  A probe's distance d is measured from its actual lattice point,
d = |x - x_c| - R_b.

A probe's point is the lattice point nearest its requested position
(mpipd.output.probes); the report gives, per probe, the requested and the snapped
distance from the wall and flags a probe moved more than half the dx of its
point's part (3-D distance from the requested position, :func:`snap`): blast_paper's
P1–P3 (Fig. 15: 0.8, 1.6, 4.8 mm) sit at 0.42, 1.22 and 4.41 mm.

A probe must sample the material it names.  A file written with the probe's part
(``/probes/<name>`` attributes ``part``, ``requested_part``) is checked against
``/geometry/part`` of the probe's gid; an older file against the ``part`` of the
probe in the stored scene, and failing that the rock probes (wall, A–G, P1–P3)
must be rock points.  A probe that fails carries ``error`` and gives no numbers.

* Radial stress (Fig. 16a) and its attenuation (Fig. 17): the peak compressive
  radial stress p = max_t(-sigma_rr) at each of A–G, fitted with p = C d^-n
  (d in mm, p in MPa; paper: ~130 MPa at A, < 20 MPa at G, n = 0.798).  A probe
  whose peak is the last recorded step (the wave has not passed it yet) is shown
  but left out of the fits and of the wave speed.
* The direct wave's peak (information): the peak of each probe's **first pulse**
  (:mod:`mpipd.post.arrivals`: from the first arrival until -sigma_rr falls below half
  its running maximum), and p = C d^-n fitted over those.  The whole-run peak above is
  the largest compression at the point over every step; where a later event (the
  crushed zone's compression, a reflection, a crack reaching the point) exceeds the
  direct wave, the two differ.  The paper's Fig. 16a records show a series of waves
  of reducing magnitude, whose first is the direct wave.  A probe whose point fails
  during its first pulse, or whose first pulse has not ended by the end of the
  record, has no first-pulse peak (the reason is given).
* Wave speed (Fig. 16b): from the first arrivals at A–G (:mod:`mpipd.post.arrivals`:
  10 % of the peak of each probe's first pulse, arrival times increasing with d, least-squares slope
  of d against t; Table 1's c_P = sqrt((K + 4G/3)/rho) = 4595 m/s), and beside it the
  paper's method, the arrival time of the peak (the largest sample refined by a
  parabola; paper 4270 m/s, measured P-wave speed 4535 m/s), with the probes whose
  peak is a later pulse than the first (a reflection) named.
* PPV (Fig. 18): max_t |v_r| at each of A–G, fitted with the Holmberg–Persson
  law PPV = K d^-beta.
* Pressure–stress paths (Fig. 15): (p, s) at P1–P3 against the JH2 strength
  recorded at the point (sigma_y at its p*, edot*, D; Eqs. 21–23) and the intact
  and fractured envelopes at edot* = 1 (:func:`mpipd.materials.jh2.strength_envelope`):
      sigma_i = sigma_HEL A (p* + T*)^N,  sigma_f = sigma_HEL B p*^M.
  A point has yielded once s >= 0.99 sigma_y with sigma_y > 0 (paper: P1 yields at
  p ~ 200 MPa, P2 at s ~ 150 MPa, P3 never reaches its strength).
"""
from __future__ import annotations

import numpy as np

from mpipd.materials.jh2 import rate_factor, strength_envelope

from . import arrivals, fits
from .model import zone_of

SERIES = {"A": 6.8, "B": 10.8, "C": 22.0, "D": 29.2, "E": 39.6, "F": 50.0, "G": 59.6}
PATHS = {"P1": 0.8, "P2": 1.6, "P3": 4.8}
QUANTITIES = ("t", "sigma_rr", "v_r", "p", "s", "strength")
OPTIONAL = ("t_state",)         # absent from files written before 2026-12: t_state = t
YIELD_TOL = 0.99
SNAP_FLAG = 0.5             # a probe moved more than this many dx of its part is flagged
ROCK_PROBES = ("wall", *SERIES, *PATHS)


def na(reason: str) -> dict:
    return {"not_available": reason}


def load_probes(run, model) -> dict:
    """name -> {gid, x, d (m), t, sigma_rr, v_r, p, s, strength, t_state}; rows never
    written (NaN) are dropped.  Read by rank 0, broadcast (probes are small)."""
    out = None
    if run.root:
        out = {}
        grp = run.f.get("probes")
        for name in (grp or {}):
            g = grp[name]
            if not all(q in g for q in QUANTITIES) or "gid" not in g.attrs:
                continue
            data = {q: g[q][...] for q in QUANTITIES}
            for q in OPTIONAL:
                data[q] = g[q][...] if q in g else data["t"].copy()
            keep = np.isfinite(data["t"])
            data = {q: a[keep] for q, a in data.items()}
            gid = int(g.attrs["gid"])
            x = run.f["geometry/x"][gid]
            pid = int(run.f["geometry/part"][gid])
            dx = (float(g.attrs["dx"]) if "dx" in g.attrs else model.dx_of(pid)
                  if pid in model.zone_ids else float(np.cbrt(run.f["geometry/volume"][gid])))
            want = g.attrs.get("position")
            data.update(gid=gid, x=x.tolist(), dx=dx,
                        position=None if want is None else [float(c) for c in want],
                        d=float(np.hypot(x[0] - model.center[0], x[1] - model.center[1])
                                - model.r_wall), **_placement(run, model, name, g, gid))
            if want is not None:
                data["requested_d"] = float(np.hypot(want[0] - model.center[0],
                                                     want[1] - model.center[1]) - model.r_wall)
            out[name] = data
    return run.comm.bcast(out, root=0)


def snap(p: dict, name: str) -> dict:
    """How far a probe's snap moved it: the requested and the snapped distance from the
    wall (mm), the paper's distance of a named probe (A–G, P1–P3), the dx of its part
    (mm) and whether the snap moved it more than SNAP_FLAG dx (3-D distance from the
    requested position; None if the file does not say)."""
    dist = p.get("snap_distance_mm")
    if dist is None and p.get("position") is not None:
        dist = float(np.linalg.norm(np.subtract(p["x"], p["position"]))) * 1e3
    req = p.get("requested_d")
    return {"snap_distance_mm": dist, "requested_d_mm": None if req is None else req * 1e3,
            "paper_d_mm": {**SERIES, **PATHS}.get(name), "dx_mm": p["dx"] * 1e3,
            "moved_beyond_half_dx": None if dist is None else bool(dist > SNAP_FLAG * p["dx"] * 1e3)}


def _attr(g, key):
    v = g.attrs.get(key)
    return v.decode() if isinstance(v, bytes) else (None if v is None else str(v))


def _placement(run, model, name, g, gid) -> dict:
    """Part and material of the probe's point (from the geometry), the part it should
    be in, and ``error`` if it is not there."""
    pid = int(run.f["geometry/part"][gid])
    mid = int(run.f["geometry/material"][gid])
    part = model.part_names[pid] if pid < len(model.part_names) else str(pid)
    mat = model.material_names[mid] if mid < len(model.material_names) else str(mid)
    dist = g.attrs.get("distance")
    info = {"part": part, "material": mat,
            "snap_distance_mm": None if dist is None else float(dist) * 1e3, "error": None}
    want = _attr(g, "requested_part") if "requested_part" in g.attrs else None
    if want is None:
        want = model.probe_parts.get(name)
    if want:
        info["requested_part"] = want
        if not zone_of(part, want):
            info["error"] = (f"its point (gid {gid}) is in part {part!r} (material {mat}), "
                             f"not in part {want!r}")
    elif name in ROCK_PROBES and pid not in model.rock_ids:
        rock = model.part_names[model.rock]
        info["error"] = (f"its point (gid {gid}) is in part {part!r} (material {mat}), not a "
                         f"rock point ({rock!r}); the probe names no part")
    return info


def _series(probes, names):
    have = [n for n in names if n in probes and len(probes[n]["t"]) > 2]
    missing = [n for n in names if n not in have]
    return have, missing


def _bad(probes, names) -> list[dict]:
    """The probes that fail their placement check: shown as errors, never as numbers."""
    return [{"name": n, "error": probes[n]["error"]} for n in names
            if n in probes and probes[n].get("error")]


def radial_stress(probes) -> dict:
    have, missing = _series(probes, SERIES)
    bad = _bad(probes, have)
    have = [n for n in have if not probes[n].get("error")]
    if not have and not bad:
        return na("no probes named A-G with recorded steps")
    pts = []
    for n in have:
        q = probes[n]
        t, pk, interior = fits.peak_time(*arrivals.state_samples(q, -q["sigma_rr"]))
        pts.append({"name": n, "d_mm": q["d"] * 1e3, "paper_d_mm": SERIES[n],
                    "peak_MPa": pk / 1e6, "t_peak_us": t * 1e6, "peak_inside_record": interior,
                    **_first_pulse_peak(q)})
    out = {"points": pts, "missing": missing, "errors": bad}
    out["fit"] = _fit([p for p in pts if p["peak_inside_record"]], "peak_MPa")
    out["excluded_from_fit"] = [p["name"] for p in pts if not p["peak_inside_record"]]
    direct = [p for p in pts if not isinstance(p["first_pulse_peak_MPa"], dict)]
    out["first_pulse_fit"] = _fit(direct, "first_pulse_peak_MPa")
    out["excluded_from_first_pulse_fit"] = {p["name"]: p["first_pulse_peak_MPa"]["not_available"]
                                            for p in pts if p not in direct}
    return out


def _first_pulse_peak(q) -> dict:
    """{first_pulse_peak_MPa, t_first_pulse_peak_us} of a probe: the peak of the direct
    wave (its first pulse), or first_pulse_peak_MPa = {"not_available": why}."""
    a = arrivals.first_arrival(*arrivals.state_samples(q, -q["sigma_rr"]),
                               t_failed=failure_time(q))
    if "not_available" in a:
        return {"first_pulse_peak_MPa": {"not_available": a["not_available"]},
                "t_first_pulse_peak_us": None}
    if not a["first_pulse_complete"]:
        return {"first_pulse_peak_MPa": {"not_available": "the first pulse has not ended by "
                                         "the end of the record"},
                "t_first_pulse_peak_us": None}
    return {"first_pulse_peak_MPa": a["first_pulse_peak_Pa"] / 1e6,
            "t_first_pulse_peak_us": a["t_first_pulse_peak_s"] * 1e6}


def _fit(pts, key) -> dict:
    """Power law over the probes given: those whose peak lies inside the record (a peak
    at the last step means the wave has not yet passed: that probe's peak is not known),
    or whose first pulse has a peak."""
    try:
        return fits.power_law([p["d_mm"] for p in pts], [p[key] for p in pts])
    except fits.FitError as e:
        return na(f"{e} (probes whose peak is at the end of the record are left out)")


def failure_time(q) -> float | None:
    """Time (s, of the state sampled: ``t_state`` where recorded) of the first sample at
    which the probe's point has failed: zero strength and zero deviatoric stress (a failed
    point carries neither); None if it never fails or records no strength."""
    st = np.asarray(q["strength"], float)
    failed = np.flatnonzero(np.isfinite(st) & (st == 0) & (np.asarray(q["s"]) == 0))
    if not len(failed):
        return None
    return float(np.asarray(q.get("t_state", q["t"]), float)[failed[0]])


def wave_speed(probes, radial: dict) -> dict:
    """First-arrival speed over A–G (judged), with the paper's peak-arrival speed beside
    it (``peak_arrival``, information)."""
    if "points" not in radial:
        return na(radial["not_available"])
    late = [p["name"] for p in radial["points"] if not p["peak_inside_record"]]
    pts = [p for p in radial["points"] if p["peak_inside_record"]]
    rows, skipped = [], {}
    for p in pts:
        q = probes[p["name"]]
        a = arrivals.first_arrival(*arrivals.state_samples(q, -q["sigma_rr"]),
                                   t_failed=failure_time(q))
        if "not_available" in a:
            skipped[p["name"]] = a["not_available"]
            continue
        rows.append({"name": p["name"], "d_mm": p["d_mm"], "t_us": a["t_s"] * 1e6,
                     "threshold_MPa": a["threshold_Pa"] / 1e6, "t_peak_us": p["t_peak_us"],
                     "first_pulse_end_us": a["first_pulse_end_s"] * 1e6,
                     "peak_in_first_pulse": a["peak_in_first_pulse"]})
    later = [r["name"] for r in rows if not r["peak_in_first_pulse"]]
    out = {"method": "first arrival", "threshold": arrivals.THRESHOLD_TEXT,
           "probes": [r["name"] for r in rows], "arrivals": rows,
           "excluded_peak_at_record_end": late, "excluded_no_arrival": skipped,
           "probe_errors": radial.get("errors", [])}
    fit = arrivals.speed([r["name"] for r in rows], [r["d_mm"] * 1e-3 for r in rows],
                         [r["t_us"] * 1e-6 for r in rows])
    if "speed_m_s" in fit:
        out.update(speed_m_s=fit["speed_m_s"], r2=fit["r2"])
    else:
        out.update(fit)
        if "not_available" in fit:
            out["not_available"] += f"; peaks at the end of the record: {', '.join(late) or 'none'}"
    out["peak_arrival"] = _peak_arrival(pts, later)
    out["first_pulse_peak_arrival"] = _first_pulse_peak_arrival(radial["points"])
    out["threshold_study"] = _threshold_study(probes, [r["name"] for r in rows],
                                              [r["d_mm"] * 1e-3 for r in rows])
    return out


def _threshold_study(probes, names, d) -> list[dict]:
    """Speed from the arrivals at each fraction of ``arrivals.STUDY`` (information),
    over the probes of the judged fit."""
    out = []
    for frac in arrivals.STUDY:
        t = [arrivals.first_arrival(*arrivals.state_samples(probes[n], -probes[n]["sigma_rr"]),
                                    frac, failure_time(probes[n])) for n in names]
        row = {"fraction": frac}
        if any("not_available" in a for a in t):
            row["not_available"] = "; ".join(f"{n}: {a['not_available']}"
                                             for n, a in zip(names, t) if "not_available" in a)
        else:
            fit = arrivals.speed(names, d, [a["t_s"] for a in t])
            row.update(fit)
            row["t_us"] = [a["t_s"] * 1e6 for a in t]
        out.append(row)
    return out


def _peak_arrival(pts, later) -> dict:
    """The paper's method: slope of d against the arrival time of each probe's peak.
    Peak times that do not increase with distance give no speed (a slope through
    them is not a wave speed: it came out negative or above 10 km/s), but
    ``not_available`` with the probes out of order."""
    note = ("peak is a later pulse than the first (a reflection): " + ", ".join(later)
            if later else "every probe's peak lies in its first pulse")
    names = [p["name"] for p in pts]
    f = arrivals.speed(names, [p["d_mm"] * 1e-3 for p in pts], [p["t_peak_us"] * 1e-6 for p in pts])
    rows = [{"name": p["name"], "d_mm": p["d_mm"], "t_us": p["t_peak_us"]} for p in pts]
    if "speed_m_s" not in f:
        why = f.get("error", f.get("not_available", "")).replace("first-arrival", "peak")
        return {"not_available": why, "later_pulse": later, "note": note, "arrivals": rows}
    return {"speed_m_s": f["speed_m_s"], "r2": f["r2"], "probes": names,
            "later_pulse": later, "note": note, "arrivals": rows}


def _first_pulse_peak_arrival(pts) -> dict:
    """The paper's method on the direct wave (Fig. 16b: "the arrival time of the peak
    stress ... the slope of the linear fitting line"): the slope of d against the time of
    each probe's first-pulse peak (:func:`_first_pulse_peak`), the wave the paper's
    peaks belong to ("a series of stress waves with reducing magnitude", §3.3).  A probe
    without a first-pulse peak is left out with its reason; times that do not increase
    with distance give no speed, as in :func:`_peak_arrival`.  The times are the sampled
    ones of the first-pulse peak (not refined by a parabola as the whole-run peaks' are).
    A far probe's first pulse can run into the next compression in a fracturing run
    (§38 of studies/validation/notes.md): read the R² and the times, not the speed alone."""
    have = [p for p in pts if p.get("t_first_pulse_peak_us") is not None]
    left = {p["name"]: p["first_pulse_peak_MPa"]["not_available"] for p in pts
            if p.get("t_first_pulse_peak_us") is None
            and isinstance(p.get("first_pulse_peak_MPa"), dict)}
    rows = [{"name": p["name"], "d_mm": p["d_mm"], "t_us": p["t_first_pulse_peak_us"]}
            for p in have]
    f = arrivals.speed([p["name"] for p in have], [p["d_mm"] * 1e-3 for p in have],
                       [p["t_first_pulse_peak_us"] * 1e-6 for p in have])
    if "speed_m_s" not in f:
        why = f.get("error", f.get("not_available", "")).replace("first-arrival",
                                                                 "first-pulse peak")
        return {"not_available": why, "excluded": left, "arrivals": rows}
    return {"speed_m_s": f["speed_m_s"], "r2": f["r2"], "probes": [r["name"] for r in rows],
            "excluded": left, "arrivals": rows}


def ppv(probes) -> dict:
    have, missing = _series(probes, SERIES)
    bad = _bad(probes, have)
    have = [n for n in have if not probes[n].get("error")]
    if not have:
        return na("no probes named A-G with recorded steps" + (
            f" in the rock ({', '.join(b['name'] for b in bad)}: error)" if bad else ""))
    pts = []
    for n in have:
        a = np.abs(probes[n]["v_r"])
        k = int(np.argmax(a))
        pts.append({"name": n, "d_mm": probes[n]["d"] * 1e3, "ppv_m_s": float(a[k]),
                    "peak_inside_record": 0 < k < len(a) - 1})
    out = {"points": pts, "missing": missing, "errors": bad, "source": "probes (every step)"}
    out["fit"] = _fit([p for p in pts if p["peak_inside_record"]], "ppv_m_s")
    out["excluded_from_fit"] = [p["name"] for p in pts if not p["peak_inside_record"]]
    return out


def jh2_envelope(jh2, p: np.ndarray, strain_rate=0.0) -> tuple[np.ndarray, np.ndarray]:
    """Intact and fractured JH2 strength (Pa) at pressures p (Pa) and strain rate edot
    (1/s; the default 0 is edot* = 1): sigma_HEL (sigma_i*, sigma_f*) of
    :func:`mpipd.materials.jh2.strength_envelope` at p* = p / p_HEL, T* = T / p_HEL."""
    rate = rate_factor(strain_rate, jh2.C, jh2.rate_norm)
    si, sf = strength_envelope(np.asarray(p, float) / jh2.p_HEL, rate, jh2.A, jh2.N,
                               jh2.B, jh2.M, jh2.T / jh2.p_HEL)
    return jh2.sigma_hel * si, jh2.sigma_hel * sf


def pressure_stress(probes) -> dict:
    have, missing = _series(probes, PATHS)
    bad = _bad(probes, have)
    have = [n for n in have if not probes[n].get("error")]
    if not have and not bad:
        return na("no probes named P1-P3 with recorded steps")
    pts = []
    for n in have:
        q = probes[n]
        st = q["strength"]
        yl = np.flatnonzero(np.isfinite(st) & (st > 0) & (q["s"] >= YIELD_TOL * st))
        first = int(yl[0]) if len(yl) else None
        tf = failure_time(q)
        pts.append({"name": n, "d_mm": q["d"] * 1e3, "paper_d_mm": PATHS[n],
                    "peak_p_MPa": float(q["p"].max()) / 1e6,
                    "peak_s_MPa": float(q["s"].max()) / 1e6,
                    "yielded": first is not None,
                    "p_at_yield_MPa": None if first is None else float(q["p"][first]) / 1e6,
                    "s_at_yield_MPa": None if first is None else float(q["s"][first]) / 1e6,
                    "failed_at_us": None if tf is None else tf * 1e6,
                    "strength_recorded": bool(np.isfinite(st).any())})
    return {"points": pts, "missing": missing, "errors": bad}
