"""All the report's measures of one run (paper §3.2–3.5), computed collectively.

``analyse(run, model)`` returns ``(metrics, data)``:

* ``metrics`` — JSON-ready numbers, the same on every rank (what report.md,
  report.json and ``compare`` print); a measure that cannot be computed is
  ``{"not_available": reason}``;
* ``data`` — the gathered sections, the axial plane and the probes, on rank 0
  only (what the figures draw).

Fracture measures (:mod:`mpipd.post.cracks`) use the last frame on three
sections, the two end faces and mid-thickness (paper §3.2, Fig. 12); the
headline is the mean over the three sections for crack density and the crushed
zone, and the median for the count of major radial cracks (information beside the
paper's measures below); the paper's own measures:

* major radial cracks (judged) on Fig. 11's sections, 5 mm from the detonation face,
  mid-thickness and 5 mm from the far face, failed points linked only as lattice
  neighbours (1.5 dx: :data:`mpipd.post.cracks.LATTICE_LINK`, why there), at the
  last frame; the headline is the median of the three sections' counts;
* the crushed zone at first damage (judged): the same rule
  (:func:`mpipd.post.cracks.crushed_zone`) at the frame nearest 4 µs (Fig. 9a:
  "damage is first observed surrounding the borehole as all points within a zone of
  approximately one radius of the borehole are damaged"), if one lies within 1 µs of
  it, on the same three sections; judged on the detonation end face, the view of
  Fig. 9(a) (at 4 µs the detonation has not reached the far face), with the mean of
  the three beside it; the last frame's mean (above) is information.

The crack orientation
(:mod:`mpipd.post.crack_orientation`: radial, oblique, circumferential, and the
ring arcs) on the same sections, and the ring arcs again at every saved frame (a ring that
forms and is overrun shows only there).  The lattice bias
(:mod:`mpipd.post.lattice_bias`: 4- and 8-fold Fourier amplitudes of the failed
points' angles in the zone-2 ring) is measured on every gathered section at the
last frame.

Peaks (gas, wall, PPV profile) are over every step (:mod:`mpipd.post.peaks`, the
probes), never over the saved frames alone; impossible values are gathered in
``errors`` (:mod:`mpipd.post.errors`) and shown as errors, not numbers.
"""
from __future__ import annotations

import numpy as np

from . import crack_orientation, cracks, errors, explosive, lattice_bias, ledger, peaks, volume
from . import probe_metrics as pm
from . import sections as secs
from .targets import TARGETS, verdict

CRACK_SECTIONS = (secs.NAMED[0], secs.NAMED[2], secs.NAMED[4])
FIG11_SECTIONS = secs.FIG11  # the paper's count of major radial cracks (Fig. 11)
PPV_THRESHOLD = 2.5          # m/s: the paper's "2500" (mm/s) of Bauer & Calder, Fig. 18
FIRST_DAMAGE_US = 4.0        # Fig. 9(a): the crushed zone when damage is first seen
FIRST_DAMAGE_TOL_US = 1.0    # the frame used must lie this close to it


def first_damage_frame(times) -> dict:
    """The saved frame nearest FIRST_DAMAGE_US (Fig. 9a, 4 µs; the first such frame on
    a tie): ``{"frame", "t_us"}``, or not available if none lies within
    FIRST_DAMAGE_TOL_US of it."""
    t_us = np.asarray(times, float) * 1e6
    if not len(t_us):
        return {"not_available": "no frame"}
    k = int(np.argmin(np.abs(t_us - FIRST_DAMAGE_US)))
    if abs(t_us[k] - FIRST_DAMAGE_US) > FIRST_DAMAGE_TOL_US + 1e-9:     # saved times' rounding
        return {"not_available": f"no saved frame within {FIRST_DAMAGE_TOL_US:g} µs of "
                                 f"{FIRST_DAMAGE_US:g} µs (the nearest is at {t_us[k]:.3g} µs)"}
    return {"frame": k, "t_us": float(t_us[k])}


def pattern_frames(times, n=4, wanted_us=None) -> list[int]:
    """Frames shown in the fracture pattern (Fig. 9: 4, 20, 40, 60 us): the frames
    nearest ``wanted_us``, or ``n`` frames evenly spaced after t = 0 ending at the last."""
    last = len(times) - 1
    if wanted_us:
        return sorted({int(np.argmin(np.abs(np.asarray(times) * 1e6 - w))) for w in wanted_us})
    if last == 0:
        return [0]
    return sorted({int(round(v)) for v in np.linspace(last / n, last, n)})


def profile_frames(times, n=4) -> list[int]:
    """Frames for the explosive pressure along the borehole (Fig. 7: 2, 5, 8, 12 us)."""
    want = [2e-6, 5e-6, 8e-6, 12e-6]
    t = np.asarray(times)
    if t[-1] >= want[-1]:
        return sorted({int(np.argmin(np.abs(t - w))) for w in want})
    return sorted({int(round(v)) for v in np.linspace((len(t) - 1) / n, len(t) - 1, n)})


def ring_history(sections, model, frames, times, r_min_mm=None) -> dict:
    """Ring arcs frame by frame: :func:`mpipd.post.crack_orientation.measure` on the
    crack sections (CRACK_SECTIONS) at each of ``frames``, as the report applies it at
    the last frame.  A ring that forms and is later overrun by radial damage (Table 3's
    case 5, studies/validation/notes.md §45) shows here and not at the last frame.

    Arcs at a radius within ``r_min_mm[section]`` (the report passes each section's
    crushed zone at the last frame) are left out: the wall layer's first circumferential
    failures, which the crushed zone later takes in, are not the spalls the measure is
    for (every blast_paper row shows one at r = 4 mm at 8 µs, notes §45).

    Per section and frame: the ring arcs, their total length (mm) and radii (mm), the
    failed rings' radii (mm).  Per frame: the mean total length over the sections (the
    last frame's headline basis); ``largest``: the largest of those means, with its
    frame and time (the first such frame on a tie)."""
    per, r_min_mm = {}, dict(r_min_mm or {})
    for name in CRACK_SECTIONS:
        if name not in sections:
            continue
        sec, rows, r_min = sections[name], [], r_min_mm.get(name, 0.0)
        for k in frames:
            failed, _ = cracks.failed_points(sec, k)
            o = crack_orientation.measure(sec["x"], sec["y"], failed, model.center, sec["h"],
                                          model.r_wall, model.r_out, horizon=sec["link"])
            arcs = [a for a in o["rings"] if a["r_mm"] > r_min]
            rows.append({"ring_arcs": len(arcs),
                         "ring_arc_length_mm": float(sum(a["length_mm"] for a in arcs)),
                         "radii_mm": [a["r_mm"] for a in arcs],
                         "failed_rings_mm": [r["r_mm"] for r in o["failed_rings"]]})
        per[name] = rows
    if not per or not len(frames):
        return {"not_available": "no crack section or no frame after t = 0"}
    mean = [float(np.mean([per[n][i]["ring_arc_length_mm"] for n in per]))
            for i in range(len(frames))]
    i = int(np.argmax(mean))
    t_us = [float(times[k]) * 1e6 for k in frames]
    return {"frames": [int(k) for k in frames], "t_us": t_us, "sections": per,
            "r_min_mm": {n: r_min_mm.get(n, 0.0) for n in per}, "mean_length_mm": mean,
            "largest": {"length_mm": mean[i], "frame": int(frames[i]), "t_us": t_us[i]}}


def _fig11(data_sections, model, last, fig11) -> dict:
    """Major radial cracks on Fig. 11's sections (``fig11``: name -> the gathered
    section holding its level), failed points linked as lattice neighbours
    (:data:`mpipd.post.cracks.LATTICE_LINK` dx), at the last frame; the median of the
    sections' counts."""
    per = {}
    for name in FIG11_SECTIONS:
        src = (fig11 or {}).get(name)
        if src is None or src not in data_sections["sections"]:
            continue
        sec = data_sections["sections"][src]
        failed, _ = cracks.failed_points(sec, last)
        rc = cracks.radial_cracks(sec["x"], sec["y"], failed, model.center, sec["h"],
                                  model.r_wall, model.r_out,
                                  horizon=cracks.LATTICE_LINK * sec["h"])
        per[name] = {"z_mm": data_sections["levels"][src] * 1e3, "section": src, **rc}
    if not per:
        return {"not_available": "no Fig. 11 section in the rock"}
    counts = [per[n]["count"] for n in per]
    return {"sections": per, "link_dx": cracks.LATTICE_LINK,
            "major_radial_cracks": float(np.median(counts)),
            "rule": f"failed points linked within {cracks.LATTICE_LINK:g} dx (max-norm: the "
                    "nearest and diagonal lattice neighbours, not the horizon); a crack is "
                    "major when it runs from zone 1 into the outer 2 dx; median of the "
                    f"{len(per)} sections"}


def _first_damage(data_sections, model, first) -> dict:
    """The crushed zone (:func:`mpipd.post.cracks.crushed_zone`) at the frame nearest
    4 µs (``first``: :func:`first_damage_frame`) on CRACK_SECTIONS; the headline is
    the detonation end face's (Fig. 9a's view), the mean of the sections beside it."""
    if "not_available" in first:
        return first
    k, per = first["frame"], {}
    for name in CRACK_SECTIONS:
        if name not in data_sections["sections"]:
            continue
        sec = data_sections["sections"][name]
        try:
            failed, _ = cracks.failed_points(sec, k)
        except KeyError:
            return {"not_available": f"no damage or failure_mode at frame {k}"}
        per[name] = cracks.crushed_zone(sec["x"], sec["y"], failed, model.center, sec["h"],
                                        model.r_wall, model.r_out,
                                        mode=sec.get(("failure_mode", k)))
    face = per.get(secs.NAMED[0])
    if face is None:
        return {"not_available": "no detonation end face section"}
    return {"frame": k, "t_us": first["t_us"], "section": secs.NAMED[0], "sections": per,
            "extent_mm": face["extent_mm"], "extent_borehole_radii": face["extent_borehole_radii"],
            "mean_extent_borehole_radii": float(np.mean(
                [c["extent_borehole_radii"] for c in per.values()])),
            "mean_extent_mm": float(np.mean([c["extent_mm"] for c in per.values()]))}


def _fracture(data_sections, model, last, history=None, times=None, fig11=None,
              first=None) -> dict:
    out = {}
    crit = None
    for name, z in data_sections["levels"].items():
        if name not in CRACK_SECTIONS:
            continue
        sec = data_sections["sections"][name]
        try:
            failed, crit = cracks.failed_points(sec, last)
        except KeyError as e:
            return {"not_available": str(e).strip("'\"")}
        args = (sec["x"], sec["y"], failed, model.center, sec["h"], model.r_wall, model.r_out)
        out[name] = {"z_mm": z * 1e3, "zones": cracks.crack_density(*args),
                     "radial_cracks": cracks.radial_cracks(*args, horizon=sec["link"]),
                     "crushed_zone": cracks.crushed_zone(*args, mode=sec.get(("failure_mode", last))),
                     "orientation": crack_orientation.measure(*args, horizon=sec["link"])}
    names = [n for n in CRACK_SECTIONS if n in out]
    crushed = {n: out[n]["crushed_zone"]["r_c_mm"] for n in names}
    hist = (ring_history(data_sections["sections"], model, history, times, crushed)
            if history is not None else
            {"not_available": "no damage field written (the history reads it at every frame)"})
    dens = [[out[n]["zones"][k]["density_mm_per_mm2"] for n in names] for k in range(3)]
    return {"criterion": crit, "sections": out,
            "mean_density_mm_per_mm2": [float(np.mean(d)) for d in dens],
            "major_radial_cracks": float(np.median([out[n]["radial_cracks"]["count"]
                                                    for n in names])),
            "crushed_extent_borehole_radii": float(np.mean(
                [out[n]["crushed_zone"]["extent_borehole_radii"] for n in names])),
            "crushed_extent_mm": float(np.mean([out[n]["crushed_zone"]["extent_mm"]
                                                for n in names])),
            "mean_circumferential_density_mm_per_mm2": [float(np.mean(
                [out[n]["orientation"]["zones"][k]["circumferential_density_mm_per_mm2"]
                 for n in names])) for k in range(3)],
            "ring_arc_length_mm": float(np.mean([out[n]["orientation"]["ring_arc_length_mm"]
                                                 for n in names])),
            "ring_arcs": float(np.median([out[n]["orientation"]["ring_arcs"] for n in names])),
            "ring_history": hist,
            "fig11": _fig11(data_sections, model, last, fig11),
            "first_damage": _first_damage(data_sections, model,
                                          first or {"not_available": "not computed"})}


def _lattice_bias(data_sections, model, last) -> dict:
    out = {}
    for name in data_sections["levels"]:
        sec = data_sections["sections"][name]
        try:
            failed, _ = cracks.failed_points(sec, last)
        except KeyError as e:
            return {"not_available": str(e).strip("'\"")}
        out[name] = lattice_bias.measure(sec["x"], sec["y"], failed, model.center, sec["h"],
                                         model.r_wall, model.r_out, horizon=sec["link"])
    return {**out, "ring": lattice_bias.RING}


def _ppv_radius(ppv, profile) -> dict:
    """Distance from the wall within which PPV > 2.5 m/s: from the probes' power law
    (inside the probes' distance range only), else from the frame profile."""
    fit = ppv.get("fit", {}) if isinstance(ppv, dict) else {}
    if "n" in fit and fit["n"] > 0:
        d = (fit["C"] / PPV_THRESHOLD) ** (1.0 / fit["n"])
        ds = [p["d_mm"] for p in ppv["points"] if p["peak_inside_record"]]
        if min(ds) <= d <= max(ds):
            return {"value_mm": d, "source": "Holmberg–Persson fit to the probes"}
    if "mean_m_s" in profile:
        above = np.asarray(profile["mean_m_s"]) > PPV_THRESHOLD
        d = np.asarray(profile["d_mm"])
        if above.all():
            return {"not_available": "PPV exceeds 2.5 m/s over the whole specimen"}
        if above[0]:
            k = int(np.argmin(above))
            return {"value_mm": float(d[k - 1] + 0.5 * (d[1] - d[0] if len(d) > 1 else 0)),
                    "source": "peak_speed profile (ring means of |v| over every step)"}
        return {"not_available": "PPV is below 2.5 m/s already at the wall"}
    return {"not_available": "no probes A-G in the rock and no peak_speed field"}


def crack_sections(run, model, requests) -> dict | None:
    """The crack sections (CRACK_SECTIONS: the end faces and mid-thickness) of the
    run's rock with ``requests`` = [(field, frame)], as
    :func:`mpipd.post.sections.gather_sections` gives them (rank 0; None elsewhere)."""
    zoned = secs.named_levels(secs.zone_levels(run, model), model)
    return secs.gather_sections(run, model, {n: z for n, z in zoned.items()
                                             if n in CRACK_SECTIONS}, requests)


def analyse(run, model, pattern_us=None) -> tuple[dict, dict | None]:
    times = run.time
    last = run.frames - 1
    frames = pattern_frames(times, wanted_us=pattern_us)
    if last not in frames:
        frames.append(last)
    levels = secs.zone_levels(run, model)
    zoned = secs.named_levels(levels, model)
    named = {k: secs.section_z(v, model) for k, v in zoned.items()}
    fig11 = {n: secs.same_level(n, levels[model.rock], named, model) for n in FIG11_SECTIONS}
    first = first_damage_frame(times)
    history = [k for k in range(run.frames) if times[k] > 0]     # ring arcs at every frame
    reqs = ([("damage", k) for k in sorted(set(frames) | set(history))]
            + [("failure_mode", k) for k in sorted({last, first.get("frame", last)})])
    gathered = secs.gather_sections(run, model, zoned, reqs)
    sec_data = {"levels": named, "sections": gathered}
    prof_frames = profile_frames(times)
    vol = volume.scan(run, model, prof_frames)
    plane = (secs.gather_plane(run, model, "pressure", prof_frames)
             if run.has_field("pressure") else None)
    probes = pm.load_probes(run, model)
    radial = pm.radial_stress(probes)
    metrics = {"model": model.summary(), "frames": run.frames,
               "t_end_us": float(times[-1]) * 1e6, "pattern_frames": frames,
               "pattern_times_us": [float(times[k]) * 1e6 for k in frames],
               "sections_mm": {k: v * 1e3 for k, v in named.items()},
               "radial_stress": radial, "wave_speed": pm.wave_speed(probes, radial),
               "ppv": pm.ppv(probes), "pressure_stress": pm.pressure_stress(probes),
               "probes": {n: {"d_mm": p["d"] * 1e3, "gid": p["gid"], "part": p["part"],
                              "material": p["material"],
                              "requested_part": p.get("requested_part"),
                              "snap_distance_mm": p["snap_distance_mm"], "error": p["error"],
                              **pm.snap(p, n)}
                          for n, p in probes.items()}}
    metrics.update({k: vol[k] for k in ("energy", "failure_modes", "frame_series",
                                         "gas_containment", "tube_containment")})
    metrics.update(peaks.scan(run, model, probes))
    metrics["explosive_reference"] = explosive.reference(model, metrics["gas_pressure"],
                                                         metrics["wall_radial_stress"])
    metrics["gas_profiles"] = vol.get("gas_profiles", [])
    metrics["time_us"] = [t * 1e6 for t in vol["time_s"]]
    metrics["energy_ledger"] = ledger.read(run)
    metrics["global_energy_J"] = metrics["energy_ledger"].get("series_J", {})
    fr = (_fracture(sec_data, model, last, history if run.has_field("damage") else None,
                    times, fig11, first) if run.root else None)
    metrics["fracture"] = run.comm.bcast(fr, root=0)
    lb = _lattice_bias(sec_data, model, last) if run.root else None
    metrics["lattice_bias"] = run.comm.bcast(lb, root=0)
    metrics["ppv_radius"] = _ppv_radius(metrics["ppv"], metrics["ppv_profile"])
    metrics["errors"] = errors.collect(metrics, probes)
    metrics["targets"] = targets_table(metrics)
    data = {"sections": sec_data, "plane": plane, "probes": probes,
            "plane_frames": prof_frames} if run.root else None
    return metrics, data


def _point(block, name, key):
    if "not_available" in block:
        return block
    for p in block.get("points", []):
        if p["name"] == name:
            return p[key]
    for p in block.get("errors", []):
        if p["name"] == name:
            return {"error": f"probe {name}: {p['error']}"}
    return {"not_available": f"no probe {name}"}


def _get(block, *keys):
    """``block[k1][k2]...``, or the first ``{"not_available": ...}`` met on the way."""
    for k in keys:
        if isinstance(block, dict) and ("not_available" in block or "error" in block):
            return block
        try:
            block = block[k]
        except (KeyError, IndexError, TypeError):
            return {"not_available": f"no {k}"}
    return block


def target_values(m: dict) -> dict:
    fr = m["fracture"]
    dens = fr.get("mean_density_mm_per_mm2") if "not_available" not in fr else None
    ps = m["pressure_stress"]

    def yields(name):
        y = _point(ps, name, "yielded")
        return y if isinstance(y, dict) else float(bool(y))
    return {
        "wave_speed": _get(m["wave_speed"], "speed_m_s"),
        "wave_speed_peak": _get(m["wave_speed"].get("peak_arrival", m["wave_speed"]),
                                "speed_m_s"),
        "wave_speed_first_pulse_peak": _get(m["wave_speed"].get(
            "first_pulse_peak_arrival", m["wave_speed"]), "speed_m_s"),
        "peak_sigma_rr_A": _point(m["radial_stress"], "A", "peak_MPa"),
        "peak_sigma_rr_G": _point(m["radial_stress"], "G", "peak_MPa"),
        "attenuation_n": _get(m["radial_stress"], "fit", "n"),
        "peak_sigma_rr_A_first_pulse": _point(m["radial_stress"], "A", "first_pulse_peak_MPa"),
        "attenuation_n_first_pulse": _get(m["radial_stress"], "first_pulse_fit", "n"),
        **{f"crack_density_zone{k + 1}": (dens[k] if dens else fr) for k in range(3)},
        "major_radial_cracks": _get(fr, "major_radial_cracks"),
        "major_radial_cracks_fig11": _get(fr, "fig11", "major_radial_cracks"),
        "crushed_zone": _get(fr, "crushed_extent_borehole_radii"),
        "crushed_zone_first_damage": _get(fr, "first_damage", "extent_borehole_radii"),
        "gas_outside_tube": _get(m["tube_containment"], "max_outside"),
        "gas_beyond_tube_ends": _get(m["tube_containment"], "max_beyond_ends"),
        "ring_arc_length": _get(fr, "ring_arc_length_mm"),
        "ring_arc_length_largest": _get(fr, "ring_history", "largest", "length_mm"),
        "ppv_radius_2p5": _get(m["ppv_radius"], "value_mm"),
        "peak_gas_pressure": _get(m["gas_pressure"], "peak_MPa"),
        "peak_wall_pressure": _get(m["wall_radial_stress"], "peak_MPa"),
        "P1_yields": yields("P1"), "P2_yields": yields("P2"), "P3_yields": yields("P3"),
    }


def _bases(m: dict) -> dict:
    """How each headline value was formed (shown beside it)."""
    fr = m["fracture"]
    ns = len(fr.get("sections", {}))
    ws, rs = m["wave_speed"], m["radial_stress"]
    pa = ws.get("peak_arrival", {})
    fp = ws.get("first_pulse_peak_arrival", {})
    out = {"wave_speed": f"{len(ws['probes'])} probes" if "probes" in ws else "",
           "wave_speed_peak": (f"{len(pa['probes'])} probes" if "probes" in pa else "")
           + (f"; later pulse at {', '.join(pa['later_pulse'])}" if pa.get("later_pulse")
              else ""),
           "wave_speed_first_pulse_peak": (f"{len(fp['probes'])} probes" if "probes" in fp
                                           else ""),
           "attenuation_n": (f"{rs['fit']['n_points']} probes"
                             if "fit" in rs and "n_points" in rs["fit"] else ""),
           "attenuation_n_first_pulse": (f"{rs['first_pulse_fit']['n_points']} probes"
                                         if "n_points" in rs.get("first_pulse_fit", {})
                                         else ""),
           "major_radial_cracks": f"median of {ns} sections (end faces, mid-thickness), "
                                  "linked within the horizon",
           "major_radial_cracks_fig11": _fig11_basis(fr),
           "crushed_zone": f"mean of {ns} sections, last frame",
           "crushed_zone_first_damage": _first_damage_basis(fr),
           "gas_outside_tube": _tube_basis(m["tube_containment"]),
           "gas_beyond_tube_ends": _tube_basis(m["tube_containment"], "beyond_ends"),
           "ring_arc_length": f"mean of {ns} sections",
           "ring_arc_length_largest": (
               f"mean of {ns} sections, largest at {fr['ring_history']['largest']['t_us']:.3g} µs"
               if "largest" in fr.get("ring_history", {}) else ""),
           "ppv_radius_2p5": m["ppv_radius"].get("source", ""),
           "peak_gas_pressure": m["gas_pressure"].get("basis", ""),
           "peak_wall_pressure": m["wall_radial_stress"].get("basis", "")}
    out.update({f"crack_density_zone{k}": f"mean of {ns} sections" for k in (1, 2, 3)})
    return out


def _fig11_basis(fr) -> str:
    f = fr.get("fig11", {})
    if "sections" not in f:
        return ""
    return (f"median of {len(f['sections'])} Fig. 11 sections ("
            + ", ".join(str(s["count"]) for s in f["sections"].values())
            + f"), linked within {f['link_dx']:g} dx")


def _first_damage_basis(fr) -> str:
    f = fr.get("first_damage", {})
    if "frame" not in f:
        return ""
    return (f"detonation end face at {f['t_us']:.3g} µs; mean of {len(f['sections'])} "
            f"sections {f['mean_extent_borehole_radii']:.2f}")


def _tube_basis(tc, key="outside") -> str:
    if "t_us" not in tc:
        return ""
    series = tc[key]
    bad = [i for i, v in enumerate(series) if v > 0]
    if not bad:
        return f"largest over {len(series)} frames: 0 at every frame to {tc['t_us'][-1]:.3g} µs"
    i = bad[0]
    return (f"largest over {len(series)} frames; first nonzero at {tc['t_us'][i]:.3g} µs "
            f"(frame {i}: {series[i]} points)")


def target_bounds(m: dict) -> dict:
    """key -> (lo, hi) of the consistency rows, from the run's own explosive_reference
    (also applied to a report.json by :mod:`mpipd.post.validation`)."""
    ref = m["explosive_reference"]
    return {"peak_gas_pressure": tuple(ref["consistency_MPa"])
            if "consistency_MPa" in ref else None}


def targets_table(m: dict) -> list[dict]:
    vals = target_values(m)
    bases = _bases(m)
    ref = m["explosive_reference"]
    bounds = target_bounds(m)
    band = {"peak_gas_pressure": explosive.band_text(ref)}
    rows = []
    for t in TARGETS:
        v = vals[t.key]
        rows.append({"key": t.key, "label": t.label, "unit": t.unit, "kind": t.kind,
                     "value": None if isinstance(v, dict) else float(v),
                     "basis": bases.get(t.key, "") if not isinstance(v, dict) else "",
                     "paper": t.paper, "experiment": t.experiment,
                     "band": band.get(t.key, t.band),
                     "verdict": verdict(t.key, v, bounds.get(t.key))})
    return rows
