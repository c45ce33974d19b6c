"""Whole-model quantities, in one pass over the frames (each rank reads one frame
of one field of its own slice at a time).

* Energy in the rock (Fig. 20), per frame, over the rock points i:
      E_k = sum_i V_i rho |v_i|^2 / 2,   E_s = sum_i V_i W_i,   E = E_k + E_s
  with rho from the stored scene and W the ``strain_energy`` field (J/m^3); sums
  are formed per z level and added in level order (bit-identical on any number
  of reading ranks).
* PPV against distance from the frames (Fig. 18, a fallback and a profile beside
  the probes): per rock point max over frames of |v_r|, averaged in rings of
  width dx of distance d = r - R_b, over the points still intact at the last
  frame (failed points fly off freely and are not the rock's particle velocity).  Frames are sampled every ``output.every``
  steps, so these peaks are lower bounds of the every-step probe peaks.
* Borehole wall (§3.1: 1600 MPa estimated at the wall): over the wall layer, the
  rock points with r < R_b + dx, the peak over frames of the normal stress on the
  wall, -sigma_rr = -(c^2 s_xx + s^2 s_yy + 2 c s s_xy) (the load the rock takes;
  needs the ``stress`` field), and of the mean pressure p = -tr(sigma)/3.
* Explosive (Fig. 7): the peak gas pressure over frames, and the mean pressure of
  the charge points of each z level at a few frames (pressure along the borehole).
* Failure modes (Fig. 13): rock points per failure_mode at the last frame
  (0 intact, 1 JH2 plastic, 2 JH2 tensile, 3 tension model).
"""
from __future__ import annotations

import numpy as np

MODES = {0: "intact", 1: "JH2 plastic (D >= 1)", 2: "JH2 tensile (p < -T)",
         3: "tension model (Eq. 38)"}


def scan(run, model, profile_frames) -> dict:
    x = run.geometry("x")
    pid = run.geometry("part")
    mat = run.geometry("material")
    vol = run.geometry("volume")
    rock = pid == model.rock
    r = model.radius(x)
    c, s = (x[:, 0] - model.center[0]) / np.maximum(r, 1e-300), \
        (x[:, 1] - model.center[1]) / np.maximum(r, 1e-300)
    rho = np.array([model.density.get(int(m), np.nan) for m in range(int(mat.max()) + 1)]
                   )[mat] if len(mat) else np.zeros(0)
    has_v, has_w = run.has_field("v"), run.has_field("strain_energy")
    has_p = run.has_field("pressure")
    rock_rho_known = bool(run.min(float(np.all(np.isfinite(rho[rock]))) if len(rho) else 1.0))
    nf = run.frames
    ek = np.zeros((len(run.levels), nf))
    es = np.zeros((len(run.levels), nf))
    peak_vr = np.zeros(len(x))
    wall = rock & (r < model.r_wall + model.dx)
    if run.has_field("failure_mode"):
        intact = rock & (run.field("failure_mode", nf - 1) == 0)
    elif run.has_field("damage"):
        intact = rock & (run.field("damage", nf - 1) < 1.0 - 1e-9)
    else:
        intact = rock
    charge = (pid == model.charge) if model.charge is not None else np.zeros(len(x), bool)
    wall_p = np.full(nf, -np.inf)
    wall_s = np.full(nf, -np.inf)
    has_s = run.has_field("stress")
    iw = np.flatnonzero(wall)
    gas_p = np.full(nf, -np.inf)
    prof = {}
    for k in range(nf):
        if has_v:
            v = run.field("v", k)
            if rock_rho_known:
                ek[:, k] = run.per_level(np.where(rock, 0.5 * vol * rho * (v ** 2).sum(1), 0.0))
            vr = np.abs(v[:, 0] * c + v[:, 1] * s)
            np.maximum(peak_vr, np.where(rock, vr, 0.0), out=peak_vr)
        if has_w:
            es[:, k] = run.per_level(np.where(rock, vol * run.field("strain_energy", k), 0.0))
        if has_s and len(iw):
            sg = run.field("stress", k, span=(int(iw[0]), int(iw[-1]) + 1))[iw - iw[0]]
            cw, sw = c[iw], s[iw]
            wall_s[k] = float((-(cw * cw * sg[:, 0] + sw * sw * sg[:, 1]
                                 + 2 * cw * sw * sg[:, 5])).max())
        if has_p:
            p = run.field("pressure", k)
            wall_p[k] = p[wall].max() if wall.any() else -np.inf
            gas_p[k] = p[charge].max() if charge.any() else -np.inf
            if k in profile_frames and charge.any():
                prof[k] = np.stack([run.per_level(np.where(charge, p, 0.0)),
                                    run.per_level(charge.astype(float))], axis=1)
    out = {"time_s": run.time.tolist()}
    # energy in the rock
    if not has_v:
        out["energy"] = {"not_available": "the run has no v field"}
    elif not rock_rho_known:
        out["energy"] = {"not_available": "the rock density is not in the stored scene"}
    else:
        kin = run.level_total(ek)
        out["energy"] = {"kinetic_J": kin.tolist(),
                         "strain_J": run.level_total(es).tolist() if has_w else None,
                         "total_J": (kin + run.level_total(es)).tolist() if has_w else None,
                         "note": "" if has_w else "no strain_energy field: kinetic energy only"}
    # PPV profile in rings of width dx
    if has_v:
        nb = max(1, int(np.ceil((model.r_out - model.r_wall) / model.dx)))
        b = np.clip(((r - model.r_wall) / model.dx).astype(int), 0, nb - 1)
        cnt = run.level_total(run.per_level_bins(b, intact, nb))
        tot = run.level_total(run.per_level_bins(b, intact, nb, peak_vr))
        mx = np.zeros(nb)
        np.maximum.at(mx, b[intact], peak_vr[intact])
        mx = run.max_array(mx)
        ok = cnt > 0
        out["ppv_profile"] = {"d_mm": ((np.arange(nb) + 0.5) * model.dx * 1e3)[ok].tolist(),
                              "mean_m_s": (tot[ok] / cnt[ok]).tolist(),
                              "max_m_s": mx[ok].tolist(), "points": cnt[ok].astype(int).tolist()}
    else:
        out["ppv_profile"] = {"not_available": "the run has no v field"}
    # wall and gas pressure
    out["wall_radial_stress"] = (_peak(run.max_array(wall_s), run.time,
                                       "-sigma_rr of the rock points with r < R_b + dx")
                                 if has_s else {"not_available": "the run has no stress field"})
    if not has_p:
        out["wall_pressure"] = {"not_available": "the run has no pressure field"}
        out["gas_pressure"] = {"not_available": "the run has no pressure field"}
    else:
        wp = run.max_array(wall_p)
        gp = run.max_array(gas_p)
        out["wall_pressure"] = _peak(wp, run.time, "rock points with r < R_b + dx")
        out["gas_pressure"] = (_peak(gp, run.time, "charge points")
                               if model.charge is not None and np.isfinite(gp).any()
                               else {"not_available": "the run has no explosive (jwl) part"})
        lev_z = run.all_levels(run.level_z)
        out["gas_profiles"] = []
        for k in sorted(profile_frames):
            if k not in prof and model.charge is None:
                continue
            a = run.all_levels(prof.get(k, np.zeros((len(run.levels), 2))))
            ok = a[:, 1] > 0
            out["gas_profiles"].append({"frame": int(k), "t_us": float(run.time[k]) * 1e6,
                                        "z_mm": (lev_z[ok] * 1e3).tolist(),
                                        "p_MPa": (a[ok, 0] / a[ok, 1] / 1e6).tolist()})
    # failure modes at the last frame
    if run.has_field("failure_mode"):
        m = run.field("failure_mode", nf - 1)[rock].astype(int)
        cnt = run.sum_array(np.bincount(np.clip(m, 0, 3), minlength=4).astype(np.int64))
        out["failure_modes"] = {MODES[i]: int(cnt[i]) for i in range(4)}
    elif "failed_points_by_mode" in run.f.attrs:
        cnt = run.f.attrs["failed_points_by_mode"]
        out["failure_modes"] = {MODES[i]: int(cnt[i]) for i in range(4)}
        out["failure_modes"]["note"] = "whole model, from the file's failed_points_by_mode"
    else:
        out["failure_modes"] = {"not_available": "no failure_mode field or attribute"}
    return out


def _peak(series, t, where) -> dict:
    if not np.isfinite(series).any():
        return {"not_available": f"no {where}"}
    k = int(np.nanargmax(np.where(np.isfinite(series), series, -np.inf)))
    return {"peak_MPa": float(series[k]) / 1e6, "t_us": float(t[k]) * 1e6, "where": where,
            "series_MPa": (np.where(np.isfinite(series), series, np.nan) / 1e6).tolist(),
            "sampling": "frames only"}
