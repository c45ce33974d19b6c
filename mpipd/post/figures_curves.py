"""Line plots of the report (all drawn from the ``metrics`` dict and the probes).

Fig. 12 crack density per zone beside the experiment's ranges; Fig. 15
pressure–stress paths at P1–P3 with the JH2 envelopes; Fig. 16a radial stress
histories at A–G; Fig. 16b first-arrival and peak-arrival times against distance; Fig. 17
peak radial stress against distance (log–log, p = C d^-n); Fig. 18 PPV against
distance (Holmberg–Persson); Fig. 7 explosive pressure along the borehole, the
every-step peaks and Table 2's p_CJ and p(1, e0); Fig. 20 energy in the rock and
the run's energy ledger.  Radial stress is plotted compression-positive
(-sigma_rr).
"""
from __future__ import annotations

import numpy as np

from . import probe_metrics as pm
from .plotting import plain_log, pyplot, save

EXPERIMENT_DENSITY = ((0.30, 0.46), (0.10, 0.18), (0.05, 0.13))     # mm/mm^2, zones 1-3


def crack_density(fracture, label, out) -> str:
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6, 3.8))
    names = list(fracture["sections"])
    w = 0.8 / max(len(names), 1)
    for k, (lo, hi) in enumerate(EXPERIMENT_DENSITY):
        ax.add_patch(plt.Rectangle((k + 0.55, lo), 0.9, hi - lo, color="0.85", zorder=0,
                                   label="experiment (Banadaki 2010)" if k == 0 else None))
    for j, name in enumerate(names):
        sec = fracture["sections"][name]
        d = [z["density_mm_per_mm2"] for z in sec["zones"]]
        ax.bar(np.arange(1, 4) - 0.4 + w * (j + 0.5), d, w * 0.9,
               label=f"{name} (z = {sec['z_mm']:.2f} mm)")
    ax.set_xticks([1, 2, 3], ["zone 1 (inner)", "zone 2", "zone 3 (outer)"])
    ax.set_ylabel("crack density (mm/mm²)")
    ax.set_xlabel("ring between the borehole wall and the outer boundary")
    ax.set_title(f"{label}: crack density per zone, {fracture['criterion']} (cf. paper Fig. 12)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    return save(fig, out)


def radial_histories(probes, radial, label, out) -> str:
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 3.8))
    for p in radial["points"]:
        q = probes[p["name"]]
        ax.plot(q["t"] * 1e6, -q["sigma_rr"] / 1e6, lw=0.9,
                label=f"{p['name']} ({p['d_mm']:.1f} mm)")
    ax.set_xlabel("time after detonation (µs)")
    ax.set_ylabel("radial stress −σ_rr (MPa, compression positive)")
    ax.set_title(f"{label}: radial stress at A–G (cf. paper Fig. 16a)")
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    return save(fig, out)


def arrivals(ws, label, out) -> str:
    """First arrivals (judged) and peak arrivals (the paper's method) against distance;
    a fit line only where the speed is a number."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(5.6, 3.9))
    d = np.array([a["d_mm"] for a in ws["arrivals"]])
    t = np.array([a["t_us"] for a in ws["arrivals"]])
    ax.plot(d, t, "o", color="C0", label="first arrival (10 % of the first pulse's peak)")
    for a in ws["arrivals"]:
        ax.annotate(a["name"], (a["d_mm"], a["t_us"]), textcoords="offset points", xytext=(4, -8))
    pa = ws.get("peak_arrival", {})
    if pa.get("arrivals"):
        dp = np.array([a["d_mm"] for a in pa["arrivals"]])
        tp = np.array([a["t_us"] for a in pa["arrivals"]])
        late = set(pa.get("later_pulse", []))
        mk = np.array([a["name"] in late for a in pa["arrivals"]])
        ax.plot(dp[~mk], tp[~mk], "s", mfc="none", color="C2", label="peak arrival")
        if mk.any():
            ax.plot(dp[mk], tp[mk], "x", color="C3", label="peak arrival, a later pulse")
    dd = np.linspace(0, max(d.max(), 1.0) * 1.05, 50) if len(d) else np.linspace(0, 1, 2)
    if "speed_m_s" in ws:
        c = ws["speed_m_s"]
        t0 = np.mean(t) - np.mean(d) / c * 1e3
        ax.plot(dd, t0 + dd / c * 1e3, "-", color="C0",
                label=f"first arrivals: {c:.0f} m/s (R² {ws['r2']:.3f})")
    if "speed_m_s" in pa:
        c = pa["speed_m_s"]
        tp0 = np.mean(tp) - np.mean(dp) / c * 1e3
        ax.plot(dd, tp0 + dd / c * 1e3, "--", color="C2", lw=0.8,
                label=f"peak arrivals: {c:.0f} m/s (information)")
    if len(d):
        ax.plot(dd, np.mean(t) + (dd - np.mean(d)) / 4535 * 1e3, ":", color="0.4",
                label="4535 m/s (measured P wave), through the mean first arrival")
    title = f"{label}: wave speed (cf. paper Fig. 16b)"
    if "error" in ws:
        title += "\nERROR: first arrivals do not increase with distance"
    ax.set_xlabel("distance from the borehole wall d (mm)")
    ax.set_ylabel("arrival time (µs)")
    ax.set_title(title, fontsize=8)
    ax.legend(fontsize=6)
    fig.tight_layout()
    return save(fig, out)


def _loglog(ax, pts, key, fit, unit, law, ref=None):
    """Probe peaks against distance (open markers: peak at the end of the record, not
    fitted) and the fitted power law over the fitted probes' range."""
    ok = np.array([p.get("peak_inside_record", True) for p in pts])
    d = np.array([p["d_mm"] for p in pts])
    y = np.array([p[key] for p in pts])
    ax.loglog(d[ok], y[ok], "o", color="C0", label="probes")
    if (~ok).any():
        ax.loglog(d[~ok], y[~ok], "o", mfc="none", color="C0",
                  label="probes, peak at the end of the record (not fitted)")
    for p in pts:
        ax.annotate(p["name"], (p["d_mm"], p[key]), textcoords="offset points", xytext=(4, 2))
    if "n" in fit:
        dd = np.geomspace(d[ok].min() * 0.8, d[ok].max() * 1.25, 40)
        ax.loglog(dd, fit["C"] * dd ** -fit["n"], "-", color="C1",
                  label=f"{law} = {fit['C']:.3g} d^-{fit['n']:.3f} {unit} (R² {fit['r2']:.3f})")
    if ref is not None:
        dd = np.geomspace(5, 65, 40)
        ax.loglog(dd, ref[0] * (dd / ref[1]) ** -ref[2], ":", color="0.4", label=ref[3])
    ax.set_xlabel("distance from the borehole wall d (mm)")
    plain_log(ax)


def peak_stress(radial, label, out) -> str:
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(5.4, 4.0))
    _loglog(ax, radial["points"], "peak_MPa", radial["fit"], "MPa", "p",
            ref=(130.0, 6.8, 0.798, "paper: 130 MPa at 6.8 mm, n = 0.798"))
    ax.set_ylabel("peak radial stress (MPa)")
    ax.set_title(f"{label}: peak radial stress, p = C d^-n (cf. paper Fig. 17)", fontsize=8)
    ax.legend(fontsize=7)
    fig.tight_layout()
    return save(fig, out)


def ppv(ppv_probes, profile, label, out) -> str:
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(5.6, 4.0))
    if "points" in ppv_probes:
        _loglog(ax, ppv_probes["points"], "ppv_m_s", ppv_probes["fit"], "m/s", "PPV")
    if "mean_m_s" in profile:
        d = np.array(profile["d_mm"])
        ok = d > 0
        ax.loglog(d[ok], np.array(profile["mean_m_s"])[ok], "-", lw=0.8, color="0.3",
                  label="ring mean over intact points of peak |v|, every step")
        ax.loglog(d[ok], np.array(profile["max_m_s"])[ok], "--", lw=0.6, color="0.5",
                  label="ring max over intact points")
    for (lo, hi), txt, col in (((0.4, 0.8), "radial cracking", "C1"),
                               ((1.5, 2.5), "heavy damage", "C3")):
        ax.axhspan(lo, hi, color=col, alpha=0.15, label=f"{txt} ({lo}–{hi} m/s)")
    ax.set_xlabel("distance from the borehole wall d (mm)")
    ax.set_ylabel("peak particle velocity (m/s)")
    plain_log(ax)
    ax.set_title(f"{label}: PPV against distance, Holmberg–Persson fit (cf. paper Fig. 18)",
                 fontsize=8)
    ax.legend(fontsize=6)
    fig.tight_layout()
    return save(fig, out)


def pressure_stress(probes, ps, jh2, label, out) -> str:
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(5.8, 4.2))
    pmax = 0.0
    for k, p in enumerate(ps["points"]):
        q = probes[p["name"]]
        dead = np.flatnonzero(q["strength"] == 0)          # failed: no stress from here on
        n = int(dead[0]) if len(dead) else len(q["p"])
        pp, ss, st = q["p"][:n] / 1e6, q["s"][:n] / 1e6, q["strength"][:n] / 1e6
        ax.plot(pp, ss, "-", color=f"C{k}", lw=1.0,
                label=f"{p['name']} ({p['d_mm']:.1f} mm): von Mises s")
        if p["strength_recorded"]:
            ax.plot(pp, st, ":", color=f"C{k}", lw=0.9,
                    label=f"{p['name']}: JH2 strength at the point")
        if len(dead) and n > 0:
            ax.plot(pp[-1], ss[-1], "x", color=f"C{k}", ms=7,
                    label=f"{p['name']} fails at {q['t'][n] * 1e6:.2f} µs")
        pmax = max(pmax, float(q["p"].max()))
    if jh2 is not None:
        pp = np.linspace(-jh2.T, max(pmax, 50e6) * 1.1, 200)
        si, sf = pm.jh2_envelope(jh2, pp)
        ax.plot(pp / 1e6, si / 1e6, "k-", lw=0.7, label="JH2 intact, ε̇* = 1")
        ax.plot(pp / 1e6, sf / 1e6, "k--", lw=0.7, label="JH2 fractured, ε̇* = 1")
    ax.set_xlabel("pressure p (MPa, compression positive)")
    ax.set_ylabel("equivalent stress s (MPa)")
    ax.set_title(f"{label}: pressure–stress paths at P1–P3 (cf. paper Fig. 15)")
    ax.legend(fontsize=6)
    fig.tight_layout()
    return save(fig, out)


def explosive_pressure(m, label, out) -> str:
    plt = pyplot()
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(9.5, 3.8))
    for g in m["gas_profiles"]:
        a1.plot(g["z_mm"], g["p_MPa"], "-", label=f"t = {g['t_us']:.2f} µs")
    a1.set_xlabel("z along the borehole (mm), detonation at z0")
    a1.set_ylabel("mean explosive pressure on the z level (MPa)")
    a1.set_title("explosive pressure along the borehole")
    if m["gas_profiles"]:
        a1.legend(fontsize=7)
    t = np.array(m["time_us"])
    fs = m["frame_series"]
    for key, txt, col in (("gas_pressure_MPa", "largest gas pressure", "C0"),
                          ("wall_radial_stress_MPa", "largest −σ_rr, rock wall layer", "C1"),
                          ("wall_pressure_MPa", "largest mean pressure, rock wall layer", "C2")):
        if fs.get(key):
            a2.plot(t, fs[key], "o-", ms=3, color=col, label=f"{txt} (saved frames)")
    for key, txt, col in (("gas_pressure", "peak gas pressure, every step", "C0"),
                          ("wall_radial_stress", "peak wall −σ_rr, every step", "C1")):
        if "peak_MPa" in m[key]:
            a2.axhline(m[key]["peak_MPa"], color=col, lw=1.2, label=txt)
    ref = m["explosive_reference"]
    if "p_CJ_MPa" in ref:
        a2.axhline(ref["p_CJ_MPa"], color="k", ls="-.", lw=0.8,
                   label=f"p_CJ = {ref['p_CJ_MPa']:.0f} MPa (Table 2)")
        a2.axhline(ref["p_constant_volume_MPa"], color="k", ls=":", lw=0.8,
                   label=f"p(1, e0) = {ref['p_constant_volume_MPa']:.0f} MPa (Table 2)")
    a2.axhline(1800, color="0.4", ls=":", lw=0.8, label="paper: up to 1800 MPa (gas)")
    a2.axhline(1600, color="0.6", ls="--", lw=0.8, label="1600 MPa (FEM, wall)")
    a2.set_yscale("log")
    a2.set_xlabel("time after detonation (µs)")
    a2.set_ylabel("pressure (MPa)")
    a2.set_title("histories at the saved frames; lines: peaks over every step", fontsize=8)
    a2.legend(fontsize=6)
    fig.suptitle(f"{label}: explosive and borehole-wall pressure (cf. paper Fig. 7)")
    fig.tight_layout()
    return save(fig, out)


def energy(m, label, out) -> str:
    plt = pyplot()
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(9.5, 3.8))
    t = np.array(m["time_us"])
    e = m["energy"]
    a1.plot(t, e["kinetic_J"], label="kinetic")
    if e.get("elastic_J") is not None:
        a1.plot(t, e["elastic_J"], label="elastic (recoverable)")
        a1.plot(t, e["total_J"], "k-", lw=1.4, label="total (kinetic + elastic)")
    a1.set_xlabel("time after detonation (µs)")
    a1.set_ylabel("energy in the rock (J)")
    a1.set_title("energy in the rock " + (f"({e['note']})" if e.get("note") else ""),
                 fontsize=7)
    a1.legend(fontsize=7)
    led = m["energy_ledger"]
    for k, v in m["global_energy_J"].items():
        a2.plot(t[:len(v)], v, label=k)
    bad = [x["measure"].split(": ")[1] for x in led.get("errors", [])]
    a2.set_xlabel("time after detonation (µs)")
    a2.set_ylabel("energy, whole model (J)")
    a2.set_title("energy ledger of the run (/energy)"
                 + (f"; not drawn (error): {', '.join(bad)}" if bad else ""), fontsize=8)
    if led.get("balance") is not None:
        ax3 = a2.twinx()
        ax3.plot(t[:len(led["balance"])], led["balance"], "k:", lw=0.9, label="balance")
        ax3.set_ylabel("relative closure error (balance)")
        ax3.legend(fontsize=6, loc="lower right")
    if m["global_energy_J"]:
        a2.legend(fontsize=6, ncol=2)
    fig.suptitle(f"{label}: energy (cf. paper Fig. 20)")
    fig.tight_layout()
    return save(fig, out)


def compare_curves(entries, out_energy, out_stress) -> list[str]:
    """Figs. 20 and 21 for several runs: ``entries`` = [(label, metrics)]."""
    plt = pyplot()
    written = []
    fig, ax = plt.subplots(figsize=(6, 4))
    for label, m in entries:
        e = m["energy"]
        if "kinetic_J" in e:
            y = e["total_J"] if e.get("total_J") is not None else e["kinetic_J"]
            ax.plot(m["time_us"], y, label=label + ("" if e.get("total_J") else " (kinetic)"))
    ax.set_xlabel("time after detonation (µs)")
    ax.set_ylabel("energy in the rock, kinetic + elastic (J)")
    ax.set_title("energy in the rock of each run (cf. paper Fig. 20)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    written.append(save(fig, out_energy))
    fig, ax = plt.subplots(figsize=(6, 4))
    for k, (label, m) in enumerate(entries):
        r = m["radial_stress"]
        if "points" in r:
            ax.loglog([p["d_mm"] for p in r["points"]], [p["peak_MPa"] for p in r["points"]],
                      "o-", color=f"C{k}", label=label)
    ax.set_xlabel("distance from the borehole wall d (mm)")
    ax.set_ylabel("peak radial stress (MPa)")
    plain_log(ax)
    ax.set_title("peak radial stress of each run (cf. paper Fig. 21)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    written.append(save(fig, out_stress))
    return written
